"""Helpers shared by the mechanism modules (geometry, parameter checks, packaging)."""

from __future__ import annotations

import dataclasses
import itertools
import math
import numbers
from collections.abc import Callable, Iterable, Mapping
from typing import TypeVar, cast

import numpy as np
import pinocchio as pin

from pkm.core.model.mechanism import Mechanism
from pkm.core.model.spec import ClosureSpec
from pkm.core.model.urdf import UrdfBuilder
from pkm.errors import InvalidInputError, InvalidParameterError, PkmError, UnreachableError
from pkm.validation import ABSURD, wrap_angle

T = TypeVar("T")


@dataclasses.dataclass(frozen=True)
class Drive:
    """A real drive whose limits a shipped mechanism's actuated joints carry (issue 41: they carried 1000 N m and
    100 rad/s, or 1000 N and 100 m/s, placeholders that made ``pkm capability delta`` report 8.7 kN).

    Attributes:
        name: The product.
        effort: Its continuous torque [N m] or force [N] at the output (the URDF's ``effort``, what a capability
            holds).
        speed: Its no-load (rotary) or largest (linear) speed at the output [rad/s or m/s] (the URDF's ``velocity``).
        source: Its public datasheet.
    """

    name: str
    effort: float
    speed: float
    source: str



#: ROBOTIS DYNAMIXEL-P PM54-040-S250-R (BLDC, 251.417:1), 24 V: continuous torque 3.9 N m, no-load speed 28.4 rev/min
#: (the Delta's, the 3-RRR's and the five-bar's motors).
PM54_040 = Drive("ROBOTIS DYNAMIXEL-P PM54-040-S250-R", 3.9, 28.4 * 2.0 * math.pi / 60.0,
                 "https://emanual.robotis.com/docs/en/dxl/p/pm54-040-s250-r/")
#: ROBOTIS DYNAMIXEL-P PH54-200-S500-R (BLDC, 501.923:1), 24 V: continuous torque 44.7 N m, no-load speed
#: 33.1 rev/min (the hexapod's motors).
PH54_200 = Drive("ROBOTIS DYNAMIXEL-P PH54-200-S500-R", 44.7, 33.1 * 2.0 * math.pi / 60.0,
                 "https://emanual.robotis.com/docs/en/dxl/p/ph54-200-s500-r/")
#: Linearmech (Servomech) SA 2 PD servo-actuator, ball screw BS2 (16 x 10 mm), brushless BM 63 S motor: continuous
#: load at non-zero speed 310 N, largest linear speed 500 mm/s (peak load 1095 N), its catalogue's table 5.1
#: "Technical Data" (the 3-PRS's sliders and the Gough-Stewart platform's legs).
SA2_PD = Drive("Linearmech SA 2 PD servo-actuator (ball screw 16 x 10)", 310.0, 0.5,
               "Linearmech 'Servoactuators SA-PD series' catalogue, 5.1 Technical Data")


def param(default: T, *units: str, length: int | None = None) -> T:
    """A design field: its default, its units (SI: ``"m"``, ``"rad"``, ``"kg"``, ``"kg m^2"``, ``"-"``;
    several for a tuple of mixed quantities, none for text and integers) and, for a tuple, its length
    (default: that of the default), kept in the field's metadata, where the command line and the docs
    read them (``dataclasses.fields(Params)[k].metadata["units"]``, ``["length"]``)."""
    if length is None and isinstance(default, tuple):
        length = len(default)
    return cast(T, dataclasses.field(default=default, metadata={"units": units, "length": length}))


def rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rod_inertia(mass: float, length: float, axis: int) -> np.ndarray:
    """Inertia about the centre of a thin rod of given length along coordinate ``axis``."""
    I = np.full(3, mass * length**2 / 12.0)
    I[axis] = 0.0
    return np.diag(I)


#: The primitive the shipped designs draw a rod-like link as: a cylinder whose axis ends are the link's joint (or
#: closure) points. (A capsule is the better envelope, but yourdfpy, which :func:`pkm.core.model.urdf.load_model`
#: runs, refuses ``<capsule>`` ("Unknown tag"), and urdfdom, under Pinocchio, prints "Could not parse collision
#: element" for it: the designs switch here once the loader reads collision elements itself.)
ROD_SHAPE = "cylinder"


def rod_collision(b: UrdfBuilder, link: str, start, end, radius: float) -> None:
    """A rod of ``radius`` [m] on ``link`` from ``start`` to ``end`` (two points of the link's frame [m]): a
    :data:`ROD_SHAPE` along the segment, its axis' two end centres at the two points."""
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    d = end - start
    length = float(np.linalg.norm(d))
    R = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), d / length).matrix()
    b.collision(link, ROD_SHAPE, (start + end) / 2.0, R, radius=float(radius), length=length)


def disc_collision(b: UrdfBuilder, link: str, centre, axis, radius: float, thickness: float) -> None:
    """A flat cylinder (a plate) on ``link``: ``radius`` and ``thickness`` [m], its mid-plane through ``centre``
    normal to ``axis`` (in the link's frame)."""
    n = np.asarray(axis, dtype=float)
    R = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), n / np.linalg.norm(n)).matrix()
    b.collision(link, "cylinder", centre, R, radius=float(radius), length=float(thickness))


def _circle_sphere_rho_k(u, v, w, arm: float, rod: float) -> tuple[np.ndarray, ...]:
    """``(u, v, rho, K)`` of :func:`circle_sphere` (arrays; inf or NaN beyond the float range)."""
    u, v, w = (np.asarray(x, dtype=float) for x in (u, v, w))
    with np.errstate(over="ignore", invalid="ignore"):
        return u, v, np.hypot(u, v), (u * u + v * v + w * w + arm * arm - rod * rod) / (2.0 * arm)


def _meets(rho: np.ndarray, K: np.ndarray) -> np.ndarray:
    """The rod meets the circle: ``|K| <= rho`` but for the round-off of a double root (and ``rho`` finite: a point
    beyond the float range reaches nothing)."""
    with np.errstate(invalid="ignore", over="ignore"):
        return (np.abs(K) <= rho * (1.0 + 1e-12)) & (rho < np.inf)


def _circle_sphere_terms(u, v, w, arm: float, rod: float) -> tuple[np.ndarray, ...]:
    """``(u, v, rho, K, 1 / rho, cos delta)`` of :func:`circle_sphere` (arrays; inf or NaN beyond the float range)."""
    u, v, rho, K = _circle_sphere_rho_k(u, v, w, arm, rod)
    with np.errstate(over="ignore", invalid="ignore"):
        inv = 1.0 / np.maximum(rho, 1e-300)  # rho = 0: the point on the axis, any t
        return u, v, rho, K, inv, np.clip(K / np.maximum(rho, 1e-300), -1.0, 1.0)


def circle_sphere(u, v, w, arm: float, rod: float, sign) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Angle ``t`` of an arm turning in its (u, v) plane so that its tip lies at distance ``rod`` from
    the point ``(u, v, w)`` (arm frame: the arm's tip is ``arm (cos t, sin t, 0)``), vectorised over
    the leading axes of ``u, v, w`` (and ``sign``): the one closed form of every arm-and-rod leg
    (:func:`circle_sphere_cs` gives its cosine and sine).

    ``u cos t + v sin t = K`` with ``K = (u^2 + v^2 + w^2 + arm^2 - rod^2) / (2 arm)``, so
    ``t = phi + sign * delta``, ``phi = atan2(v, u)``, ``cos delta = K / rho`` with ``rho = hypot(u, v)``,
    wrapped to (-pi, pi].

    Returns:
        ``(t, reachable, rho, K)``: where ``|K| > rho`` (beyond the round-off of a double root) the
        rod misses the circle, ``reachable`` is False and ``t`` is that of the clipped cosine (the
        nearest elbow position: finite, but no assembly).
    """
    u, v, rho, K, _, cd = _circle_sphere_terms(u, v, w, arm, rod)
    with np.errstate(invalid="ignore"):
        return wrap_angle(np.arctan2(v, u) + sign * np.arccos(cd)), _meets(rho, K), rho, K


def circle_sphere_reach(u, v, w, arm: float, rod: float) -> np.ndarray:
    """The ``reachable`` mask of :func:`circle_sphere` alone (the same test), without the angle's arc functions."""
    _, _, rho, K = _circle_sphere_rho_k(u, v, w, arm, rod)
    return _meets(rho, K)


def circle_sphere_cs(u, v, w, arm: float, rod: float, sign) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(cos t, sin t, rho, K)`` of :func:`circle_sphere`, from products (``(cos phi, sin phi) = (u, v) / rho``,
    ``sin delta = sign sqrt(1 - cos^2 delta)``) without evaluating an angle: for batches that need the
    arm's direction, not its angle."""
    u, v, rho, K, inv, cd = _circle_sphere_terms(u, v, w, arm, rod)
    with np.errstate(invalid="ignore"):
        sd = sign * np.sqrt(1.0 - cd * cd)
        return (u * cd - v * sd) * inv, (v * cd + u * sd) * inv, rho, K


def leg_arm_angles(u, v, w, arm: float, rod: float, signs, detail: Callable[[int], str]) -> np.ndarray:
    """:func:`circle_sphere` for one point per leg (arrays of shape (n,)), or the error of the first leg
    that cannot reach.

    Raises:
        UnreachableError: for that leg (1-based), with how much its rod misses the arm-tip circle [m] and
            ``detail(leg)`` as the explanation.
    """
    t, reachable, rho, K = circle_sphere(u, v, w, arm, rod, np.asarray(signs, dtype=float))
    bad = ~(np.isfinite(K) & np.isfinite(rho) & reachable)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        if not (math.isfinite(K[i]) and math.isfinite(rho[i])):
            raise UnreachableError(i + 1, math.inf, "m", f"{detail(i + 1)} (the point is beyond the float range: "
                                                         "check the units)")
        wi, ri = float(np.asarray(w, dtype=float)[i]), float(rho[i])
        dmin, dmax = math.hypot(wi, ri - arm), math.hypot(wi, ri + arm)
        raise UnreachableError(i + 1, dmin - rod if dmin > rod else rod - dmax, "m", detail(i + 1))
    return t


def leg_branches(branch, valid, n: int, default: str | None = None) -> tuple[str, ...]:
    """A working mode per leg: one name for all ``n`` legs, or a tuple (list) of ``n`` names from ``valid``;
    None stands for ``default`` where one is given.

    Raises:
        InvalidInputError: another value, an unknown name or a tuple of another length.
    """
    if branch is None and default is not None:
        branch = default
    out = (branch,) * n if isinstance(branch, str) else tuple(branch) if isinstance(branch, (tuple, list)) else ()
    if len(out) != n or any(not isinstance(b, str) or b not in valid for b in out):
        raise InvalidInputError("branch", f"use one of {list(valid)} or a tuple of {n} of them, got {branch!r}", branch)
    return out


def real(v) -> float | None:
    """``v`` as a finite float if it is a real number (not a bool, not a string), else None."""
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real):
        return None
    try:
        f = float(v)
    except (OverflowError, ValueError, TypeError):
        return None
    return f if math.isfinite(f) else None


def _check(obj, names, ok, what: str) -> None:
    for n in names:
        v = getattr(obj, n)
        f = real(v)
        if f is None or not ok(f) or abs(f) > ABSURD:
            raise InvalidParameterError(n, f"must be a finite number {what} (SI units: m, kg, rad; |value| <= "
                                           f"{ABSURD:g}), got {v!r}", v)


def check_positive(obj, *names: str) -> None:
    """Each named field of ``obj`` must be a finite number in (0, 1e6] (larger: a unit error)."""
    _check(obj, names, lambda f: f > 0, "> 0")


def check_nonnegative(obj, *names: str) -> None:
    """Each named field of ``obj`` must be a finite number in [0, 1e6]."""
    _check(obj, names, lambda f: f >= 0, ">= 0")


def check_finite(obj, *names: str) -> None:
    """Each named field of ``obj`` must be a finite number of magnitude <= 1e6."""
    _check(obj, names, lambda f: True, "")


def check_numbers(obj, name: str, n: int, what: str) -> tuple[float, ...]:
    """Field ``name`` of ``obj`` must be a tuple or list of ``n`` finite numbers (``what`` describes them).

    The field is stored back as a tuple of floats (the dataclass stays hashable and printable).
    """
    v = getattr(obj, name)
    flat = isinstance(v, (tuple, list)) or (isinstance(v, np.ndarray) and v.ndim == 1)
    vals = [real(x) for x in v] if flat else None
    if vals is None or len(vals) != n or any(x is None or abs(x) > ABSURD for x in vals):
        raise InvalidParameterError(name, f"must be {n} finite numbers {what} (|value| <= {ABSURD:g}), got {v!r}", v)
    out = tuple(float(x) for x in vals if x is not None)  # (none is None here)
    object.__setattr__(obj, name, out)
    return out


def check_params(params, cls: type, name: str = "params"):
    """``params`` itself if it is a ``cls``, else :class:`InvalidParameterError` saying what to pass."""
    if not isinstance(params, cls):
        mod = cls.__module__
        raise InvalidParameterError(name, f"expected a {cls.__name__} ({mod}.Params(...) or the .params of "
                                          f"pkm.load/pkm.build), got {type(params).__name__}", params)
    return params


def best_reference(field: str, candidates: Iterable[T], score: Callable[[T], float], *, minimum: float) -> T:
    """The reference pose of a design that does not state one: the candidate of largest ``score`` (a
    dimensionless distance to singularity, such as an inverse condition number; the first of scores
    equal to 1e-9, so the order of ``candidates`` is the order of preference); candidates where ``score`` raises
    a :class:`~pkm.errors.PkmError` (the pose does not assemble, or is singular) are skipped.

    Raises:
        InvalidParameterError: (``field``) no candidate scores at least ``minimum``: give the pose.
    """
    scored: list[tuple[float, T]] = []
    n, first_error = 0, None
    for c in candidates:
        n += 1
        try:
            s = float(score(c))
        except PkmError as exc:
            first_error = first_error or exc
            continue
        if math.isfinite(s):
            scored.append((s, c))
    best = max((s for s, _ in scored), default=None)
    if best is None or best < minimum:
        found = (f"none of them assembles; the first: {first_error}" if best is None
                 else f"the best is {best:.3g} from singular (< {minimum:g})")
        raise InvalidParameterError(field, f"no reachable, well-conditioned reference pose found for this design among "
                                           f"{n} candidates ({found}); give {field} or other lengths", None)
    return next(c for s, c in scored if s >= best * (1.0 - 1e-9))


def spec_parameters(params) -> dict[str, float | str]:
    """The dataclass fields as a flat table for the closure spec (tuples expanded, tuples of points row by row,
    None left out)."""
    out: dict[str, float | str] = {}
    for f in dataclasses.fields(params):
        v = getattr(params, f.name)
        if v is None:
            continue
        if isinstance(v, (tuple, list, np.ndarray)):
            for k, x in enumerate(np.ravel(np.asarray(v, dtype=float))):  # (points: row by row)
                out[f"{f.name}_{k + 1}"] = float(x)
        elif isinstance(v, str):
            out[f.name] = v
        else:
            out[f.name] = float(v)
    return out


def params_from_table(cls: type, table: Mapping[str, float | str]):
    """The ``cls`` instance a closure spec's ``[parameters]`` table states (the inverse of
    :func:`spec_parameters`: tuple fields were written ``name_1 .. name_n``); fields the table lacks keep
    their defaults, integer fields come back as integers."""
    kw: dict[str, object] = {}
    for f in dataclasses.fields(cls):
        default = f.default
        if isinstance(default, tuple) or (default is None and f"{f.name}_1" in table):
            values = [table[k] for k in itertools.takewhile(table.__contains__,
                                                            (f"{f.name}_{i + 1}" for i in itertools.count()))]
            if values:
                kw[f.name] = tuple(values)
        elif f.name in table:
            v = table[f.name]
            is_int = isinstance(default, int) and not isinstance(default, bool)
            kw[f.name] = int(v) if is_int and isinstance(v, float) and v.is_integer() else v
    return cls(**kw)


def make_mechanism(urdf: str, spec: ClosureSpec, params) -> Mechanism:
    from pkm.core.model.builder import from_strings

    return from_strings(urdf, spec, params, source=f"<{spec.mechanism} generator>")
