"""Measurements for identification: positions and efforts read from a table, rates and accelerations derived.

**The table** (CSV with a header row, or Parquet): ``time`` [s], then for each actuated joint ``q.<joint>`` [rad or
m] and ``tau.<joint>`` [N m or N] (:attr:`pkm.Mechanism.actuated_names`: the columns of pkm's own samples tables,
:mod:`pkm.core.dynamics.samples`, which ``pkm simulate`` and ``pkm excite`` write; other columns are ignored).

**Rates and accelerations** (Gautier's practice, zero phase): the positions are low-pass filtered by a Butterworth
filter of order :data:`ORDER` run forward and backward (``scipy.signal.sosfiltfilt``: zero phase, the magnitude
response squared), then differentiated by central differences (second order in the step), each derivative filtered
the same way; the efforts are filtered by the same filter ("parallel filtering": what the filter does to the
motion's high frequencies it does to the efforts too), and every series is then decimated to one sample in
``decimate`` (the rows the estimate stacks), the first and last :data:`EDGE` cutoff periods left out (a zero-phase
filter's start-up transients: the series are extended that far by odd reflection before filtering, then cut). The cutoff [Hz] defaults to a tenth of the sampling rate; it should sit well above
the motion's highest frequency (an excitation's ``L / T``) and below the noise.

**What is refused** (:class:`~pkm.errors.InvalidInputError` naming the column or row, its ``name`` the column):
a missing column (every missing one named), an empty cell, text or a non-finite value (the first such row, counted
from 1 after the header), a time that does not increase (its row), a sampling that is not uniform to 1 % (its row),
positions outside a joint's limits or beyond what a revolute joint can hold (a table in degrees, or in mm for a
prismatic joint beyond 10 m), fewer rows than the filter needs.
"""

from __future__ import annotations

import csv
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.signal
from numpy.typing import ArrayLike

from pkm._optional import module
from pkm.core.model.joints import stated_limits
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import InvalidInputError, PkmError
from pkm.validation import as_array, as_count, as_scalar

ORDER = 4  # the Butterworth filter's order (run twice: 8 in magnitude)
EDGE = 3.0  # cutoff periods left out at each end (the filter's transients)
UNIFORM = 0.01  # sampling steps may differ from their median by this fraction
MAX_REVOLUTE = 4.0 * np.pi  # |q| [rad] beyond this on an unbounded revolute joint: a table in degrees, surely
MAX_PRISMATIC = 10.0  # |q| [m] beyond this on an unbounded prismatic joint: a table in mm


@dataclass(frozen=True)
class Measurements:
    """Samples ready for :func:`pkm.estimate`.

    Attributes:
        t: Times [s] (N).
        Q: Closed configurations (N x nq), the loops closed along the filtered positions.
        QD: Actuated rates (N x na); ``QDD``: accelerations.
        TAU: Filtered efforts (N x na) [N m or N].
        cutoff: The filter's cutoff [Hz]; ``rate``: the table's sampling rate [Hz]; ``decimate``: one row in this
            many kept.
        source: Where the table came from.
        table_rows: The table's rows (the samples kept are ``len(self)``: one in ``decimate``, less the filter's
            transients at each end).
    """

    t: np.ndarray
    Q: np.ndarray
    QD: np.ndarray
    QDD: np.ndarray
    TAU: np.ndarray
    cutoff: float
    rate: float
    decimate: int
    source: str = ""
    table_rows: int = 0

    def __len__(self) -> int:
        return len(self.t)


def read_table(path: str | Path) -> dict[str, np.ndarray]:
    """The columns of a CSV (header row, numbers) or Parquet file, by name.

    Raises:
        InvalidInputError: no such file, not readable, a row of the wrong length, a cell that is not a number.
    """
    file = Path(path)
    if not file.is_file():
        raise InvalidInputError("data", f"{path}: no such file", str(path))
    if file.suffix.lower() in (".parquet", ".pq"):
        pq = module("pyarrow.parquet", extra="sweeps", what="reading measurements from Parquet (or give a CSV)")
        try:
            table = pq.read_table(file)
        except Exception as exc:  # (pyarrow's errors have no common base)
            raise InvalidInputError("data", f"{path}: not a readable Parquet file ({exc})", str(path)) from None
        out = {}
        for name in table.column_names:
            try:
                out[name] = np.asarray(table.column(name).to_numpy(zero_copy_only=False), dtype=float)
            except (TypeError, ValueError):
                raise InvalidInputError(name, f"{path}: column {name!r} is not numbers", name) from None
        return out
    try:
        with file.open(newline="", encoding="utf-8") as fh:
            rows = [row for row in csv.reader(fh) if row and any(c.strip() for c in row)]
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise InvalidInputError("data", f"{path}: not a readable CSV file ({exc})", str(path)) from None
    if not rows:
        raise InvalidInputError("data", f"{path}: empty", str(path))
    header = [c.strip() for c in rows[0]]
    values = np.empty((len(rows) - 1, len(header)))
    for k, row in enumerate(rows[1:]):
        if len(row) != len(header):
            raise InvalidInputError("data", f"{path}, row {k + 1}: {len(row)} values for {len(header)} columns", row)
        for i, cell in enumerate(row):
            try:
                values[k, i] = float(cell)
            except ValueError:
                raise InvalidInputError(header[i], f"{path}, row {k + 1}, column {header[i]!r}: {cell!r} is not a "
                                                   f"number", cell) from None
    return {name: values[:, i] for i, name in enumerate(header)}


def read_columns(data: str | Path | Mapping[str, ArrayLike], wanted: Sequence[str], expected: str) \
        -> tuple[np.ndarray, str]:
    """The columns ``wanted`` of a table (a path: :func:`read_table`; or columns by name, each through
    :func:`~pkm.validation.as_array`) stacked (rows x len(wanted)), and the table's name for messages (the path, or
    ``"columns"``). The one reading of pkm's measurement tables (identification, calibration).

    Raises:
        InvalidInputError: not a path or a mapping; a missing column (every one named, then ``expected``); a column
            that is not one value per row, as many as the first's; a value that is not a finite number (its row,
            counted from 1, and column).
    """
    source = str(data) if isinstance(data, (str, Path)) else "columns"
    if isinstance(data, (str, Path)):
        cols = read_table(data)
    elif isinstance(data, Mapping):
        cols = {str(k): as_array(v, str(k)) for k, v in data.items()}
    else:
        raise InvalidInputError("data", "expected a path or a dict of columns", type(data).__name__)
    missing = [c for c in wanted if c not in cols]
    if missing:
        raise InvalidInputError(missing[0], f"{source}: missing column{'s' * (len(missing) > 1)} "
                                            f"{', '.join(missing)} (expected {expected})", missing)
    n0 = cols[wanted[0]].shape
    for c in wanted:
        shape = cols[c].shape
        if len(shape) != 1 or shape != n0:
            raise InvalidInputError(c, f"{source}: column {c!r} has shape {shape}, {wanted[0]} {n0}: expected one "
                                       f"value per row, as many as {wanted[0]!r}'s", shape)
    table = np.column_stack([cols[c] for c in wanted])
    bad = ~np.isfinite(table)
    if bad.any():
        row, col = np.argwhere(bad)[0]
        raise InvalidInputError(wanted[col], f"{source}, row {row + 1}, column {wanted[col]!r}: "
                                             f"{table[row, col]} is not a finite number", table[row, col])
    return table, source


def check_positions(mech: Mechanism, QA: np.ndarray, columns: Sequence[str], source: str) -> None:
    """Refuse actuated positions (rows x na, columns named ``columns``) outside their joints' stated limits
    (:func:`~pkm.core.model.joints.stated_limits`) or beyond :data:`MAX_REVOLUTE` [rad] / :data:`MAX_PRISMATIC` [m]
    (a table in degrees or mm).

    Raises:
        InvalidInputError: the first such value, its row (from 1) and column.
    """
    lo, hi = stated_limits(mech.model, mech.act_q)
    for j, name in enumerate(mech.actuated_names):
        prismatic = not mech.joints[name].revolute
        cap = MAX_PRISMATIC if prismatic else MAX_REVOLUTE
        low, high = max(lo[j], -cap), min(hi[j], cap)
        out = np.flatnonzero((QA[:, j] < low - 1e-9) | (QA[:, j] > high + 1e-9))
        if out.size:
            r = int(out[0])
            raise InvalidInputError(columns[j], f"{source}, row {r + 1}, column {columns[j]!r}: {QA[r, j]:.6g} is "
                                                f"outside the joint's range [{low:.6g}, {high:.6g}] (SI units: is "
                                                f"the table in {'mm' if prismatic else 'degrees'}?)", QA[r, j])


def _lowpass(x: np.ndarray, sos: np.ndarray, pad: int) -> np.ndarray:
    return scipy.signal.sosfiltfilt(sos, x, axis=0, padlen=min(pad, len(x) - 1))


def measurements(mech: Mechanism, data: str | Path | Mapping[str, ArrayLike], *, cutoff: float | None = None,
                 decimate: int | None = None) -> Measurements:
    """Read (a path) or take (columns by name) measurements of ``mech`` and derive rates and accelerations (module
    doc). ``cutoff`` [Hz]: the low-pass filter's (default a tenth of the sampling rate); ``decimate``: keep one
    sample in this many (default: the sampling rate over five times the cutoff, at least 1).

    Raises:
        InvalidInputError: the cases of the module doc, naming the column or row.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> t = np.arange(1000) * 0.002
        >>> cols = {"time": t}
        >>> for k, joint in enumerate(delta.actuated_names):
        ...     cols[f"q.{joint}"] = -0.9 + 0.05 * np.sin(np.pi * t + k)
        ...     cols[f"tau.{joint}"] = 0.2 + 0.01 * np.cos(np.pi * t)
        ...
        >>> data = pkm.measurements(delta, cols, cutoff=25.0)
        >>> data.Q.shape, data.QD.shape, round(data.rate, 6), data.decimate
        ((98, 12), (98, 3), 500.0, 9)
    """
    mech = check_mechanism(mech)
    names = mech.actuated_names
    wanted = ["time", *(f"q.{j}" for j in names), *(f"tau.{j}" for j in names)]
    table, source = read_columns(data, wanted, f"time, q.<joint> and tau.<joint> for {', '.join(names)}")
    t = table[:, 0]
    n = len(t)
    if n < 3:
        raise InvalidInputError("time", f"{source}: {n} rows: too few to differentiate", n)
    step = np.diff(t)
    if np.any(step <= 0.0):
        row = int(np.flatnonzero(step <= 0.0)[0]) + 2
        raise InvalidInputError("time", f"{source}, row {row}: time {t[row - 1]!r} does not increase (the row "
                                        f"before: {t[row - 2]!r})", t[row - 1])
    dt = float(np.median(step))
    uneven = np.abs(step - dt) > UNIFORM * dt
    if uneven.any():
        row = int(np.flatnonzero(uneven)[0]) + 2
        raise InvalidInputError("time", f"{source}, row {row}: step {step[row - 2]:.6g} s where the sampling is "
                                        f"{dt:.6g} s (uniform sampling expected, to 1 %)", step[row - 2])
    QA, TAU = table[:, 1:1 + mech.na], table[:, 1 + mech.na:]
    check_positions(mech, QA, [f"q.{j}" for j in names], source)
    rate = 1.0 / dt
    fc = 0.1 * rate if cutoff is None else as_scalar(cutoff, "cutoff")
    if not 2.0 * rate / n < fc < 0.5 * rate:
        raise InvalidInputError("cutoff", f"the cutoff must lie in ({2.0 * rate / n:.6g}, {0.5 * rate:.6g}) Hz (two "
                                          f"cutoff periods in the record, under half the sampling rate), got {fc}",
                                cutoff)
    sos = scipy.signal.butter(ORDER, fc, fs=rate, output="sos")
    edge = int(np.ceil(EDGE * rate / fc))
    if n <= 2 * edge + 3 * (2 * ORDER + 1):
        raise InvalidInputError("time", f"{source}: {n} rows; the filter at {fc:.3g} Hz needs more than "
                                        f"{2 * edge + 3 * (2 * ORDER + 1)} (or a higher cutoff)", n)
    q = _lowpass(QA, sos, edge)
    qd = _lowpass(np.gradient(q, dt, axis=0), sos, edge)
    qdd = _lowpass(np.gradient(qd, dt, axis=0), sos, edge)
    tau = _lowpass(TAU, sos, edge)
    every = max(1, int(rate / (2.0 * fc))) if decimate is None else as_count(decimate, "decimate")
    if every < 1:
        raise InvalidInputError("decimate", f"expected a positive integer, got {decimate}", decimate)
    keep = np.arange(edge, n - edge, every)
    from pkm.core.identification.regressor import close_along

    try:
        Q = close_along(mech, q[keep])
    except PkmError as exc:
        raise InvalidInputError("q", f"{source}: the loops do not close along the measured positions ({exc})",
                                None) from None
    return Measurements(t[keep], Q, qd[keep], qdd[keep], tau[keep], fc, rate, every, source, n)


__all__ = ["MAX_PRISMATIC", "MAX_REVOLUTE", "Measurements", "check_positions", "measurements", "read_columns",
           "read_table"]
