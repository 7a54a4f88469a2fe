"""Design spaces: which designs a sweep evaluates, one row per design, one column per parameter.

Four kinds, each a frozen description that :meth:`Space.designs` turns into the table of values (SI) once the
sweep knows each parameter's unit (the family's, :mod:`pkm.sweeps.family`):

* :func:`grid`: the full Cartesian product of per-parameter axes, ``a="30cm:80cm:11"`` (``START:STOP:COUNT``,
  both ends included) or explicit values ``a=[0.3, 0.4]``; the first parameter varies slowest.
* :func:`sobol` and :func:`latin_hypercube`: ``n`` samples over per-parameter bounds ``a="30cm:80cm"``
  (scrambled Sobol' points or a Latin hypercube, :mod:`scipy.stats.qmc`), from a seed that is recorded: a
  sweep given no seed draws one and stores it, so that the same space can be drawn again.
* :func:`table`: explicit designs, as rows (mappings), as columns, or a CSV / Parquet file.
"""

from __future__ import annotations

import csv
import math
import secrets
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from pkm._optional import require
from pkm.errors import InvalidInputError
from pkm.units import parse_quantity, split_range
from pkm.validation import as_scalar

KINDS = ("grid", "sobol", "latin_hypercube", "table")
MAX_DESIGNS = 10**7  # a space beyond this is a typo (a grid of 8 axes of 10 values), refused before it is built

#: ``name -> (kinds a unit suffix may have, the unit as documented)``: how a family tells the space its units.
Units = Callable[[str], tuple[set[str | None], str]]


@dataclass(frozen=True)
class Designs:
    """A space drawn: the parameter values of every design (SI).

    Attributes:
        names: The parameters, in column order.
        values: ``(n, len(names))`` floats, read-only; row ``k`` is design ``k``.
        kind: One of :data:`KINDS`.
        seed: The seed the samples were drawn from (None for grids and tables).
        description: What drew them, JSON-able (stored with the results).
    """

    names: tuple[str, ...]
    values: np.ndarray
    kind: str
    seed: int | None
    description: dict[str, Any]

    def __len__(self) -> int:
        return len(self.values)


@dataclass(frozen=True)
class Space:
    """A design space, not yet drawn (see the module doc); build it with :func:`grid`, :func:`sobol`,
    :func:`latin_hypercube` or :func:`table`."""

    kind: str
    specs: tuple[tuple[str, Any], ...]
    n: int | None = None
    seed: int | None = None
    rows: tuple[tuple[Any, ...], ...] = field(default=(), repr=False)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(n for n, _ in self.specs)

    def with_seed(self) -> Space:
        """This space with its seed fixed: the given one, or a new random one for a sampled space without."""
        if self.kind in ("sobol", "latin_hypercube") and self.seed is None:
            return Space(self.kind, self.specs, self.n, secrets.randbits(63), self.rows)
        return self

    def designs(self, units: Units) -> Designs:
        """The designs (SI), each parameter's text read in the unit ``units(name)`` gives.

        Raises:
            InvalidInputError: a malformed range or value, an empty axis, bounds out of order, or a space of
                more than :data:`MAX_DESIGNS` designs.
            UnitError: a unit of another kind than the parameter's.
        """
        space = self.with_seed()
        names = space.names
        description: dict[str, Any]
        if space.kind == "grid":
            axes = [_axis(name, spec, units) for name, spec in space.specs]
            total = math.prod(len(a) for a in axes)
            _check_size(total)
            mesh = np.meshgrid(*[np.asarray(a, dtype=float) for a in axes], indexing="ij")  # first axis slowest
            values = np.stack([m.ravel() for m in mesh], axis=1).reshape(total, len(axes))
            description = {"axes": {n: [float(x) for x in a] for n, a in zip(names, axes)}}
        elif space.kind in ("sobol", "latin_hypercube"):
            from scipy.stats import qmc

            bounds = np.array([_bounds(name, spec, units) for name, spec in space.specs])
            rng = np.random.default_rng(space.seed)
            if space.kind == "sobol":
                import warnings

                with warnings.catch_warnings():  # first n of a scrambled sequence: balanced when n is a power of 2
                    warnings.filterwarnings("ignore", "The balance properties", UserWarning)
                    unit = qmc.Sobol(len(names), scramble=True, rng=rng).random(space.n)
            else:
                unit = qmc.LatinHypercube(len(names), rng=rng).random(space.n)
            values = qmc.scale(unit, bounds[:, 0], bounds[:, 1]) if len(names) else unit
            description = {"bounds": {n: [float(lo), float(hi)] for n, (lo, hi) in zip(names, bounds)}, "n": space.n}
        else:
            values = np.array([[_value(name, v, units) for name, v in zip(names, row)] for row in space.rows],
                              dtype=float).reshape(len(space.rows), len(names))
            description = {"rows": len(space.rows)}
        values.setflags(write=False)
        return Designs(names, values, space.kind, space.seed, {"kind": space.kind, **description,
                                                                **({"seed": space.seed} if space.seed is not None
                                                                   else {})})


def grid(**axes) -> Space:
    """The full grid of ``axes``: ``name="START:STOP:COUNT"`` (units allowed, both ends included), a number, or a
    sequence of values; the first parameter varies slowest (the row order of :func:`itertools.product`)."""
    return Space("grid", _specs(axes, "grid"))


def sobol(n: int, *, seed: int | None = None, **bounds) -> Space:
    """``n`` scrambled Sobol' points over ``bounds`` (``name="LOW:HIGH"`` or ``(low, high)``); ``seed`` None: drawn
    at random and recorded with the results. Balanced when ``n`` is a power of 2 (its first ``n`` points otherwise)."""
    return Space("sobol", _specs(bounds, "sobol"), _count(n), _seed(seed))


def latin_hypercube(n: int, *, seed: int | None = None, **bounds) -> Space:
    """``n`` Latin-hypercube samples over ``bounds`` (as :func:`sobol`)."""
    return Space("latin_hypercube", _specs(bounds, "latin_hypercube"), _count(n), _seed(seed))


def table(designs) -> Space:
    """Explicit designs: a sequence of mappings ``{name: value}`` (all with the same names), a mapping of
    columns ``{name: values}``, or a ``.csv`` (header row of names) or ``.parquet`` file. Values may carry units."""
    if isinstance(designs, (str, Path)):
        designs = _read_table(Path(designs))
    if isinstance(designs, Mapping):
        names = list(designs)
        cols = [list(np.atleast_1d(np.asarray(designs[n], dtype=object))) for n in names]
        if len({len(c) for c in cols}) > 1:
            raise InvalidInputError("designs", "columns of different lengths: " + ", ".join(
                f"{n}: {len(c)}" for n, c in zip(names, cols)), designs)
        rows = list(zip(*cols)) if cols else []
    elif isinstance(designs, Sequence) and all(isinstance(r, Mapping) for r in designs):
        names = list(designs[0]) if designs else []
        for k, r in enumerate(designs):
            if set(r) != set(names):
                raise InvalidInputError("designs", f"row {k} names {sorted(r)}, row 0 names {sorted(names)}", r)
        rows = [tuple(r[n] for n in names) for r in designs]
    else:
        raise InvalidInputError("designs", "give rows ({name: value} mappings), columns ({name: values}) or a .csv "
                                           "/ .parquet file", designs)
    if not rows:
        raise InvalidInputError("designs", "the table holds no design", designs)
    _check_size(len(rows))
    return Space("table", tuple((n, None) for n in _names(names)), rows=tuple(tuple(r) for r in rows))


# ---------------------------------------------------------------------- parsing
def _names(names) -> list[str]:
    names = list(names)
    if not names:
        raise InvalidInputError("parameters", "name at least one parameter to vary")
    for n in names:
        if not isinstance(n, str) or not n:
            raise InvalidInputError("parameters", f"parameter names are non-empty strings, got {n!r}", n)
    return names


def _specs(axes: Mapping[str, Any], kind: str) -> tuple[tuple[str, Any], ...]:
    _names(axes)
    return tuple((n, tuple(v) if isinstance(v, (list, np.ndarray)) else v) for n, v in axes.items())


def _count(n) -> int:
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= MAX_DESIGNS:
        raise InvalidInputError("n", f"the number of samples is an integer in [1, {MAX_DESIGNS:.0e}], got {n!r}", n)
    return int(n)


def _seed(seed) -> int | None:
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0):
        raise InvalidInputError("seed", f"a seed is an integer >= 0 (or None: drawn and recorded), got {seed!r}", seed)
    return None if seed is None else int(seed)


def _check_size(total: int) -> None:
    if total > MAX_DESIGNS:
        raise InvalidInputError("space", f"{total:.3g} designs: more than {MAX_DESIGNS:.0e}; sample the space "
                                         "(sobol, latin_hypercube) instead of a full grid", total)


def _value(name: str, v, units: Units) -> float:
    kinds, unit = units(name)
    if isinstance(v, str):
        return parse_quantity(v, kinds, name, unit)
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
        raise InvalidInputError(name, f"expected a finite number (SI, {unit}) or a string with a unit, got {v!r}", v)
    return as_scalar(v, name, unit=unit)


def _axis(name: str, spec, units: Units) -> list[float]:
    """A grid axis: ``"START:STOP:COUNT"``, one value, or a sequence of values."""
    if isinstance(spec, str) and ":" in spec:
        a, b, count = split_range(spec, name, MAX_DESIGNS)
        start, stop = (_value(name, t, units) for t in (a, b))
        with np.errstate(over="ignore", invalid="ignore"):
            axis = np.linspace(start, stop, count)
        if not np.all(np.isfinite(axis)):
            raise InvalidInputError(name, f"{name}={spec!r}: the axis overflows", spec)
        return [float(x) for x in axis]
    given = list(spec) if isinstance(spec, tuple) else [spec]
    if not given:
        raise InvalidInputError(name, f"{name}: an empty axis", spec)
    return [_value(name, v, units) for v in given]


def _bounds(name: str, spec, units: Units) -> tuple[float, float]:
    """Sampling bounds: ``"LOW:HIGH"`` or ``(low, high)``."""
    parts = spec.split(":") if isinstance(spec, str) else list(spec) if isinstance(spec, tuple) else None
    if parts is None or len(parts) != 2:
        raise InvalidInputError(name, f"{name}={spec!r}: expected bounds LOW:HIGH, e.g. 30cm:80cm", spec)
    lo, hi = (_value(name, t, units) for t in parts)
    if not lo < hi:
        raise InvalidInputError(name, f"{name}: the bounds must satisfy LOW < HIGH, got {lo:g} and {hi:g} (SI)", spec)
    return lo, hi


def _read_table(path: Path) -> dict[str, list]:
    if not path.is_file():
        raise InvalidInputError("designs", f"no such file: {path}", str(path))
    if path.suffix.lower() == ".parquet":
        require("sweeps", "a design table in Parquet (a .csv needs nothing)", ("pyarrow",))
        import pyarrow as pa
        import pyarrow.parquet as pq

        try:
            return {k: list(v) for k, v in pq.read_table(path).to_pydict().items()}
        except (OSError, pa.ArrowException) as exc:
            raise InvalidInputError("designs", f"{path} is not a Parquet file ({exc})", str(path)) from None
    if path.suffix.lower() != ".csv":
        raise InvalidInputError("designs", f"{path}: a design table is a .csv or .parquet file", str(path))
    with path.open(newline="", encoding="utf-8-sig") as f:  # (-sig: a spreadsheet's byte-order mark)
        rows = list(csv.reader(f))
    if len(rows) < 2:
        raise InvalidInputError("designs", f"{path}: expected a header row of parameter names and one row per design",
                                str(path))
    header, body = [h.strip() for h in rows[0]], rows[1:]
    if len(set(header)) != len(header):
        raise InvalidInputError("designs", f"{path}: a column is named twice in {header}", str(path))
    if any(len(r) != len(header) for r in body):
        raise InvalidInputError("designs", f"{path}: every row must have {len(header)} cells", str(path))
    return {h: [r[k].strip() for r in body] for k, h in enumerate(header)}


__all__ = ["KINDS", "MAX_DESIGNS", "Designs", "Space", "grid", "latin_hypercube", "sobol", "table"]
