"""What a sweep returns: its table, its manifest and how the run went; best designs and Pareto fronts."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from pkm._optional import module, require
from pkm.core.model.spec import as_path
from pkm.errors import InvalidInputError, SweepError, UnknownNameError
from pkm.sweeps.store import count_failed, read_manifest


@dataclass(frozen=True)
class Stats:
    """How a run went.

    Attributes:
        designs: Designs in the sweep.
        evaluated: Designs evaluated in this run (the others came from an earlier, interrupted one).
        failed: Designs whose status is ``failed``.
        chunks: Chunks evaluated in this run.
        chunk_size: Designs per chunk.
        workers: Worker processes (1 for ``serial``).
        wall_seconds: From the first chunk submitted to the last result written.
        work_seconds: Sum of the chunks' evaluation times on the workers.
        startup_seconds: Starting the local cluster (when the sweep starts one), importing pkm on the workers and
            sending them the sweep's data.
    """

    designs: int
    evaluated: int
    failed: int
    chunks: int
    chunk_size: int
    workers: int
    wall_seconds: float
    work_seconds: float
    startup_seconds: float

    @property
    def overhead(self) -> float:
        """Time the workers were not evaluating designs, as a fraction of the work:
        ``(workers x wall - work) / work`` (scheduling, transfers, writing, and the tail where some workers idle)."""
        return (self.workers * self.wall_seconds - self.work_seconds) / self.work_seconds if self.work_seconds \
            else math.nan


class SweepResult:
    """The results of a sweep: one row per design, in design order.

    Attributes:
        table: The ``pyarrow.Table`` (``design``, the parameters [SI], the objectives, ``status``, ``error``,
            ``message``), as written to the Parquet file.
        manifest: What was swept (family, space and seed, objectives with their senses and units).
        stats: How the run went (:class:`Stats`); zeros for a result read from a file.
    """

    def __init__(self, table, manifest: Mapping[str, Any], stats: Stats | None = None):
        pa = module("pyarrow", extra="sweeps", what="pkm.sweeps.SweepResult (a pyarrow table)")

        if not isinstance(table, pa.Table) or not {"design", "status", "error", "message"} <= set(table.column_names):
            raise InvalidInputError("table", "a sweep's pyarrow.Table (columns design, the parameters, the "
                                             "objectives, status, error, message)", table)
        if not isinstance(manifest, Mapping):
            raise InvalidInputError("manifest", f"a sweep's manifest (a mapping), got {type(manifest).__name__}",
                                    manifest)
        self.table = table
        self.manifest = dict(manifest)
        self.stats = stats or Stats(table.num_rows, 0, count_failed(table), 0, 0, 0, 0.0, 0.0, 0.0)

    def __len__(self) -> int:
        return self.table.num_rows

    def __repr__(self) -> str:
        return (f"SweepResult({len(self)} designs of {self.manifest['family']}, {self.stats.failed} failed; "
                f"objectives {list(self.objectives)})")

    @property
    def parameters(self) -> tuple[str, ...]:
        return tuple(self.manifest["parameters"])

    @property
    def objectives(self) -> dict[str, dict[str, str]]:
        """``{column: {"spec", "sense", "unit"}}``."""
        return {o["column"]: o for o in self.manifest["objectives"]}

    def column(self, name: str) -> np.ndarray:
        """A parameter or objective (or ``design``) as floats (NaN where null).

        Raises:
            UnknownNameError: no such column (the columns listed).
            InvalidInputError: a column of text (``status``, ``error``, ``message``: read them from :attr:`table`).
        """
        import pyarrow as pa

        if not isinstance(name, str) or name not in self.table.column_names:
            raise UnknownNameError("column", str(name), self.table.column_names, "the sweep's results")
        col = self.table.column(name)
        if not (pa.types.is_floating(col.type) or pa.types.is_integer(col.type) or pa.types.is_null(col.type)):
            raise InvalidInputError("name", f"{name} holds text, not numbers: read it from .table.column({name!r})",
                                    name)
        return np.asarray(col.to_numpy(zero_copy_only=False), dtype=float)  # (pyarrow: a null float is NaN)

    @property
    def ok(self) -> np.ndarray:
        return np.array([s == "ok" for s in self.table.column("status").to_pylist()])

    def failures(self) -> list[dict[str, Any]]:
        """The failed designs: ``{design, error, message, **parameters}``."""
        rows = self.table.to_pylist()
        return [{k: r[k] for k in ("design", "error", "message", *self.parameters)} for r in rows
                if r["status"] == "failed"]

    def check(self) -> SweepResult:
        """This result, or :class:`~pkm.errors.SweepError` when every design failed (what ``pkm sweep`` ends with,
        after writing the failures): how many, and the first one's parameters, error and message.

        Raises:
            SweepError: every design of the sweep failed (``path``: None).
        """
        if len(self) and self.stats.failed == len(self):
            raise SweepError(self._all_failed())
        return self

    def _all_failed(self) -> str:
        first = self.failures()[0]
        units = self.manifest.get("units", {})
        where = ", ".join(f"{p}={first[p]:.6g}{' ' + units[p] if units.get(p) else ''}" for p in self.parameters)
        text = " ".join(f"{first['error']}: {first['message']}".split())  # (one line)
        return f"all {len(self)} designs failed; the first, design {first['design']} ({where}): {text}"

    def _no_value(self, names: Sequence[str]) -> SweepError:
        """Why no design has a value of every one of ``names``."""
        what = " and ".join(names)
        if not len(self):
            return SweepError(f"no design has a value of {what}: the results hold no design")
        if self.stats.failed == len(self):
            return SweepError(f"no design has a value of {what}: {self._all_failed()}")
        why = f"{self.stats.failed} of {len(self)} designs failed, the others have none (null)" if self.stats.failed \
            else f"all {len(self)} designs have none (null)"
        return SweepError(f"no design has a value of {what}: {why}")

    def _signed(self, names: Sequence[str], what: str = "objectives") -> np.ndarray:
        """The objectives as columns to maximise (NaN where null)."""
        if isinstance(names, str) or not isinstance(names, Sequence) or not names \
                or not all(isinstance(n, str) for n in names):
            raise InvalidInputError(what, f"name one objective or more (a list of column names), got {names!r}",
                                    names)
        cols = []
        for n in names:
            if n not in self.objectives:
                if n in self.parameters:
                    raise InvalidInputError(what, f"{n} is a parameter, not an objective: rank by one of "
                                                  f"{list(self.objectives)}", n)
                raise UnknownNameError("objective", n, self.objectives, "the sweep's results")
            sense = self.objectives[n].get("sense", "")
            if sense not in ("max", "min"):
                raise InvalidInputError(what, f"{n} has no sense (max or min): give one to rank by it", n)
            cols.append(self.column(n) * (1.0 if sense == "max" else -1.0))
        return np.column_stack(cols) if cols[0].size else np.zeros((0, len(cols)))

    def best(self, by: str, n: int = 1) -> list[dict[str, Any]]:
        """The ``n`` best designs by objective ``by`` (its sense), as rows (dicts), fewer when fewer have a value of
        it; designs without a value of it (null, failed) are not ranked.

        Raises:
            UnknownNameError: ``by`` is no objective of the sweep.
            InvalidInputError: ``by`` is a parameter or has no sense; ``n`` is not an integer >= 1.
            SweepError: no design has a value of ``by`` (every design failed, say: the first failure named).
        """
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise InvalidInputError("n", f"how many designs: an integer >= 1, got {n!r}", n)
        if not isinstance(by, str):
            raise InvalidInputError("by", f"one objective's column name, got {by!r}", by)
        score = self._signed([by], "by")[:, 0]
        ranked = np.flatnonzero(~np.isnan(score))
        if not len(ranked):
            raise self._no_value([by])
        order = ranked[np.argsort(-score[ranked], kind="stable")][:n]
        return self.table.take(np.asarray(order, dtype=np.int64)).to_pylist()

    def pareto(self, names: Sequence[str]) -> np.ndarray:
        """Indices (rows) of the designs on the Pareto front of ``names`` (each by its sense; rows with a null out).

        Raises:
            UnknownNameError, InvalidInputError: as :meth:`best`.
            SweepError: no design has a value of every one of ``names``.
        """
        F = self._signed(names)
        if np.isnan(F).any(axis=1).all():
            raise self._no_value(names)
        return pareto_front(F)

    @classmethod
    def read(cls, path) -> SweepResult:
        """The results file a sweep wrote.

        Raises:
            MissingDependencyError: pyarrow is not installed (``pip install "pkm-robotics[sweeps]"``).
        """
        require("sweeps", "reading a sweep's Parquet results", ("pyarrow",))
        import pyarrow as pa
        import pyarrow.parquet as pq

        path = as_path(path, "path")
        if path.is_dir():
            raise InvalidInputError("path", f"{path} holds the parts of an unfinished sweep: run the same sweep again "
                                            "(same out) to finish it", str(path))
        manifest = read_manifest(path)
        try:
            table = pq.read_table(path)
        except (OSError, pa.ArrowException) as exc:  # (its schema read, its data damaged)
            raise InvalidInputError("path", f"{path} cannot be read ({exc})", str(path)) from None
        return cls(table, manifest)


def pareto_front(F: np.ndarray) -> np.ndarray:
    """Rows of ``F`` (n x m, each column to maximise; rows with NaN excluded) that no other row dominates, sorted
    (equal rows both kept). Two columns: one sort, O(n log n); more: each row against the front so far.

    Raises:
        InvalidInputError: ``F`` is not an n x m matrix of numbers (m >= 1).
    """
    try:
        F = np.asarray(F, dtype=float)
    except (TypeError, ValueError, OverflowError):  # (OverflowError: an integer beyond a float)
        raise InvalidInputError("F", "an n x m matrix of numbers (a row per design, a column per objective)",
                                F) from None
    if F.ndim != 2 or F.shape[1] < 1:
        raise InvalidInputError("F", f"an n x m matrix (a row per design, a column per objective), got shape "
                                     f"{F.shape}", F)
    keep = np.flatnonzero(~np.isnan(F).any(axis=1))
    G = F[keep]
    if len(G) == 0:
        return keep
    order = np.lexsort(tuple(-G[:, j] for j in reversed(range(G.shape[1]))))  # best first, lexicographically
    if G.shape[1] == 2:
        a, b = G[order, 0], G[order, 1]
        new_a = np.r_[True, a[1:] != a[:-1]]  # the first row of each value of the first column
        group = np.cumsum(new_a) - 1
        top = b[new_a][group]  # the best second column within the row's group
        before = np.r_[-np.inf, np.maximum.accumulate(b[new_a])[:-1]][group]  # best of the groups before
        front = order[(b == top) & (top > before)]
    else:
        chosen: list[int] = []
        for i in order:
            if not chosen:
                chosen.append(int(i))
                continue
            R = G[chosen]
            if not np.any(np.all(R >= G[i], axis=1) & np.any(R > G[i], axis=1)):
                chosen.append(int(i))
        front = np.array(chosen, dtype=int)
    return np.sort(keep[front])


def read(path) -> SweepResult:
    """:meth:`SweepResult.read`."""
    return SweepResult.read(path)


__all__ = ["Stats", "SweepResult", "pareto_front", "read"]
