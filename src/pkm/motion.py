"""Motions in task coordinates, described in data files: position, velocity and acceleration in closed form.

A motion file (format ``pkm.motion/1``, TOML) names the coordinates and, per case, a duration, a
sampling step and one law per coordinate::

    format = "pkm.motion/1"
    mechanism = "prs3"
    coordinates = ["z", "beta", "phi"]

    [case.2]
    description = "harmonic vertical motion"
    source = "sec. 5, eqs. (41)-(43)"
    duration = 5.0
    dt = 0.01
    z = { law = "cosine", offset = 0.81, amplitude = 0.005, omega = 1.0471975511965976 }
    beta = { law = "constant", value = 0.0 }
    phi = { law = "constant", value = 0.0 }

Laws, with ``t`` in seconds: ``constant`` (``value``), ``linear`` (``start + rate t``),
``cosine`` (``offset + amplitude (1 - cos(omega t))``) and ``fourier`` (Swevers' finite Fourier series
``offset + Σ_l a_l / (omega l) sin(omega l t) - b_l / (omega l) cos(omega l t)``, ``a`` and ``b`` lists of as many
harmonics: identification's excitations, :mod:`pkm.core.identification.excitation`) and ``hermite`` (a sampled
motion, ``t`` [s] increasing, ``position`` and ``velocity`` at each: the piecewise-cubic Hermite interpolant, exact at
the knots, C¹; held at its end values with zero rate outside ``[t_0, t_n]``: what ``pkm plan`` writes). Their
derivatives are exact.

``space = "actuated"`` (top level; default ``"task"``) says the coordinates are actuated joints, by name, rather
than task coordinates: an excitation trajectory is one.

What the loader refuses (:class:`~pkm.errors.SpecError`): a path that is not a regular file
(FIFOs and devices are not opened for reading), a file over 16 MiB or not UTF-8, TOML that does
not parse or nests too deeply, another ``format``, a case without a law for every coordinate,
unknown keys, numbers that are not finite or beyond 1e6 (SI), booleans or strings for numbers,
``dt > duration`` and a case of more than 10^7 samples.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pkm.core.model.spec import as_path, parse_toml, read_text_file
from pkm.data import dynamics_path
from pkm.errors import InvalidInputError, SpecError
from pkm.validation import ABSURD, as_array, finite_result

FORMAT = "pkm.motion/1"
MAX_SAMPLES = 10_000_000  #: samples of one case at most (memory)
MAX_TIME = 1e9  #: |t| [s] accepted by :meth:`Motion.sample`
LAWS = {"constant": ("value",), "linear": ("start", "rate"), "cosine": ("offset", "amplitude", "omega"),
        "fourier": ("offset", "omega", "a", "b"), "hermite": ("t", "position", "velocity")}
LISTS = {"a", "b", "t", "position", "velocity"}  #: keys holding a list (one number per harmonic, or per knot)
MAX_KNOTS = 1_000_000  #: knots of a ``hermite`` law at most
SPACES = ("task", "actuated")
MAX_HARMONICS = 1000


@dataclass(frozen=True)
class Law:
    """One coordinate's law of motion: ``kind`` (a key of :data:`LAWS`) and its coefficients (SI)."""

    kind: str
    coef: tuple[float, ...]

    def __call__(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity and acceleration at times ``t`` [s]."""
        t = np.asarray(t, dtype=float)
        z = np.zeros_like(t)
        if self.kind == "constant":
            return z + self.coef[0], z, z
        if self.kind == "linear":
            start, rate = self.coef
            return start + rate * t, z + rate, z
        if self.kind == "hermite":
            from scipy.interpolate import CubicHermiteSpline

            n = len(self.coef) // 3
            knots, pos, vel = (np.array(self.coef[i * n:(i + 1) * n]) for i in range(3))
            spline = CubicHermiteSpline(knots, pos, vel)
            tc = np.clip(t, knots[0], knots[-1])
            inside = (t >= knots[0]) & (t <= knots[-1])
            return spline(tc), np.where(inside, spline(tc, 1), 0.0), np.where(inside, spline(tc, 2), 0.0)
        if self.kind == "fourier":
            off, om, *ab = self.coef
            L = len(ab) // 2
            a, b = np.array(ab[:L]), np.array(ab[L:])
            wl = om * np.arange(1, L + 1)
            s, c = np.sin(np.multiply.outer(t, wl)), np.cos(np.multiply.outer(t, wl))
            return off + (s * (a / wl) - c * (b / wl)).sum(-1), (c * a + s * b).sum(-1), (c * b * wl - s * a * wl).sum(-1)
        off, amp, om = self.coef
        c, s = np.cos(om * t), np.sin(om * t)
        return off + amp * (1.0 - c), amp * om * s, amp * om * om * c


@dataclass(frozen=True)
class Motion:
    """A motion case: laws per coordinate over ``[0, duration]``, sampled every ``dt``.

    Attributes:
        name: The case's name in its file.
        coordinates: Coordinate names, in task order.
        laws: One :class:`Law` per coordinate.
        duration: [s].
        dt: Sampling step [s].
        description: What the motion is.
        source: Where it comes from.
    """

    name: str
    coordinates: tuple[str, ...]
    laws: tuple[Law, ...]
    duration: float
    dt: float
    description: str = ""
    source: str = ""
    space: str = "task"

    def times(self) -> np.ndarray:
        """Sample times ``0, dt, 2 dt, ...`` up to ``duration`` [s], and ``duration`` itself where ``dt`` does not
        divide it (a last, shorter step): the samples never stop short of the case nor run past it."""
        n = math.floor(self.duration / self.dt + 1e-9)
        t = np.arange(n + 1) * self.dt
        return t if t[-1] >= self.duration * (1.0 - 1e-12) else np.append(t, self.duration)

    def sample(self, t=None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(t, Y, Yd, Ydd)``: times (N,) and positions, velocities, accelerations (N, n)."""
        t = self.times() if t is None else np.atleast_1d(as_array(t, "t", "times [s]"))
        if t.ndim != 1 or not np.all(np.isfinite(t)):
            raise InvalidInputError("t", f"expected finite times of shape (N,), got shape {t.shape}")
        if t.size and np.max(np.abs(t)) > MAX_TIME:
            raise InvalidInputError("t", f"times beyond {MAX_TIME:g} s are refused (are they in seconds?)", t)
        parts = [law(t) for law in self.laws]
        out = tuple(np.column_stack([p[k] for p in parts]) for k in range(3))
        finite_result(out, f"motion {self.name!r}", "a law overflows at these times")
        return (t, *out)


def load_motions(file: str | Path) -> dict[str, Motion]:
    """Every case of a motion file; a bare name is looked up in the shipped ``dynamics/`` data.

    Raises:
        SpecError: The file is missing, not TOML, of another format, or a case is malformed.
    """
    path = as_path(file, "file")
    path = path if path.parent != Path(".") or path.exists() else dynamics_path(str(path))
    src = str(path)
    raw = parse_toml(read_text_file(path, "motion file"), src)
    if raw.get("format") != FORMAT:
        raise SpecError(src, f"format {raw.get('format')!r}; this pkm reads {FORMAT!r}")
    coords = raw.get("coordinates")
    if not (isinstance(coords, list) and coords and all(isinstance(c, str) for c in coords)):
        raise SpecError(src, "'coordinates' must be a non-empty list of names")
    cases = raw.get("case")
    if not isinstance(cases, dict) or not cases:
        raise SpecError(src, "no [case.NAME] tables")
    space = raw.get("space", "task")
    if space not in SPACES:
        raise SpecError(src, f"'space' must be one of {list(SPACES)}, got {space!r}")
    return {name: _motion(src, name, body, tuple(coords), space) for name, body in cases.items()}


def _number(src: str, where: str, v) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or abs(v) > ABSURD:
        raise SpecError(src, f"{where} must be a finite number of magnitude <= {ABSURD:g} (SI units), got {v!r}")
    return float(v)


def _coefficients(src: str, where: str, spec: dict, keys: tuple[str, ...]) -> tuple[float, ...]:
    out: list[float] = []
    for k in keys:
        v = spec.get(k)
        if k in LISTS:
            most = MAX_KNOTS if keys == LAWS["hermite"] else MAX_HARMONICS
            if not isinstance(v, list) or not 1 <= len(v) <= most:
                raise SpecError(src, f"{where}.{k} must be a list of 1 to {most} numbers")
            out += [_number(src, f"{where}.{k}", x) for x in v]
        else:
            out.append(_number(src, f"{where}.{k}", v))
    if len(keys) == 4 and keys[2:] == ("a", "b") and len(spec["a"]) != len(spec["b"]):
        raise SpecError(src, f"{where}: a and b must have as many harmonics ({len(spec['a'])} and {len(spec['b'])})")
    if keys == LAWS["hermite"]:
        n = len(spec["t"])
        if len(spec["position"]) != n or len(spec["velocity"]) != n or n < 2 or not np.all(np.diff(out[:n]) > 0.0):
            raise SpecError(src, f"{where}: t, position and velocity must be lists of as many numbers (2 or more), t "
                                 "increasing")
    if keys == LAWS["fourier"] and not out[1] > 0.0:
        raise SpecError(src, f"{where}.omega must be positive, got {out[1]}")
    return tuple(out)


def _motion(src: str, name: str, body, coords: tuple[str, ...], space: str = "task") -> Motion:
    if not isinstance(body, dict):
        raise SpecError(src, f"case {name!r} must be a table")
    duration = _number(src, f"case {name!r} duration", body.get("duration"))
    dt = _number(src, f"case {name!r} dt", body.get("dt"))
    if not (0.0 < dt <= duration <= 1e6):
        raise SpecError(src, f"case {name!r}: need 0 < dt <= duration <= 1e6 s, got dt={dt}, duration={duration}")
    if duration / dt > MAX_SAMPLES:
        raise SpecError(src, f"case {name!r}: duration / dt = {duration / dt:.3g} samples, more than {MAX_SAMPLES}; "
                             "take a larger dt")
    laws = []
    for c in coords:
        spec = body.get(c)
        if not isinstance(spec, dict) or not isinstance(spec.get("law"), str) or spec["law"] not in LAWS:
            raise SpecError(src, f"case {name!r}: coordinate {c!r} needs a law, one of {sorted(LAWS)}")
        keys = LAWS[spec["law"]]
        extra = set(spec) - {"law", *keys}
        if extra:
            raise SpecError(src, f"case {name!r}: coordinate {c!r} ({spec['law']}) has unknown keys {sorted(extra)}")
        laws.append(Law(spec["law"], _coefficients(src, f"case {name!r} {c}", spec, keys)))
    return Motion(name, coords, tuple(laws), duration, dt, str(body.get("description", "")),
                  str(body.get("source", "")), space)


def write_motion(path: str | Path, coordinates: tuple[str, ...], name: str, t: np.ndarray, position: np.ndarray,
                 rate: np.ndarray, *, space: str = "task", mechanism: str = "", description: str = "",
                 source: str = "") -> Path:
    """A motion file of one case ``name`` whose laws are ``hermite`` (module doc): ``position`` and ``rate``
    (N x len(coordinates)) at times ``t`` (N,) [s], numbers written as ``repr`` of floats (exact); read back by
    :func:`load_motions`.

    Raises:
        InvalidInputError: arrays of mismatched shapes, times not increasing, not finite.
    """
    t = np.asarray(t, dtype=float)
    P, R = np.atleast_2d(np.asarray(position, dtype=float)), np.atleast_2d(np.asarray(rate, dtype=float))
    if t.ndim != 1 or len(t) < 2 or P.shape != (len(t), len(coordinates)) or R.shape != P.shape \
            or not np.all(np.diff(t) > 0.0) or not (np.all(np.isfinite(P)) and np.all(np.isfinite(R))):
        raise InvalidInputError("position", f"expected {len(t)} x {len(coordinates)} finite samples at increasing "
                                            "times", P.shape)
    if space not in SPACES:
        raise InvalidInputError("space", f"use one of {list(SPACES)}", space)

    laws = {c: f'law = "hermite", t = {toml_floats(t - t[0])}, position = {toml_floats(P[:, j])}, '
               f"velocity = {toml_floats(R[:, j])}" for j, c in enumerate(coordinates)}
    return motion_file(path, name, laws, space=space, mechanism=mechanism, description=description, source=source,
                       duration=float(t[-1]), dt=float(np.min(np.diff(t))))


def toml_floats(x: np.ndarray) -> str:
    """A TOML array of ``x``'s floats, each its ``repr`` (read back exactly)."""
    return "[" + ", ".join(repr(float(v)) for v in np.ravel(x)) + "]"


def motion_file(path: str | Path, case: str, laws: dict[str, str], *, space: str, mechanism: str, description: str,
                source: str, duration: float, dt: float) -> Path:
    """A motion file (module doc) of one case: ``laws`` maps each coordinate to its law's TOML fields (the text
    inside its braces); the names and strings quoted as TOML basic strings. Shared by :func:`write_motion` and the
    excitation's writer (:func:`pkm.core.identification.excitation.write_motion`)."""
    q = json.dumps  # (a JSON string is a TOML basic string)
    lines = [f'format = "{FORMAT}"', f"mechanism = {q(mechanism)}", f"space = {q(space)}",
             "coordinates = [" + ", ".join(q(c) for c in laws) + "]", "", f"[case.{q(case)}]",
             f"description = {q(description)}", f"source = {q(source)}", f"duration = {float(duration)!r}",
             f"dt = {float(dt)!r}"]
    lines += [f"{q(c)} = {{ {law} }}" for c, law in laws.items()]
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return out


__all__ = ["FORMAT", "LAWS", "SPACES", "Law", "Motion", "load_motions", "motion_file", "toml_floats", "write_motion"]
