"""What a sweep returns: its table, its manifest and how the run went; best designs and Pareto fronts."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from pkm.errors import InvalidInputError, UnknownNameError
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
        """A parameter or objective as floats (NaN where null)."""
        if name not in self.table.column_names:
            raise UnknownNameError("column", name, self.table.column_names, "the sweep's results")
        return np.asarray(self.table.column(name).to_numpy(), dtype=float)  # (pyarrow: a null float is NaN)

    @property
    def ok(self) -> np.ndarray:
        return np.array([s == "ok" for s in self.table.column("status").to_pylist()])

    def failures(self) -> list[dict[str, Any]]:
        """The failed designs: ``{design, error, message, **parameters}``."""
        rows = self.table.to_pylist()
        return [{k: r[k] for k in ("design", "error", "message", *self.parameters)} for r in rows
                if r["status"] == "failed"]

    def _signed(self, names: Sequence[str]) -> np.ndarray:
        """The objectives as columns to maximise (NaN where null)."""
        if isinstance(names, str) or not names:
            raise InvalidInputError("objectives", "name one objective or more (a list)", names)
        cols = []
        for n in names:
            sense = self.objectives.get(n, {}).get("sense", "")
            if sense not in ("max", "min"):
                raise InvalidInputError("objectives", f"{n} has no sense (max or min): give one to rank by it", n)
            cols.append(self.column(n) * (1.0 if sense == "max" else -1.0))
        return np.column_stack(cols)

    def best(self, by: str, n: int = 1) -> list[dict[str, Any]]:
        """The ``n`` best designs by objective ``by`` (its sense), as rows (dicts); designs without a value of it
        (null, failed) are not ranked."""
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise InvalidInputError("n", f"how many designs: an integer >= 1, got {n!r}", n)
        score = self._signed([by])[:, 0]
        order = [int(k) for k in np.argsort(-np.where(np.isnan(score), -np.inf, score), kind="stable")
                 if not np.isnan(score[k])]
        return self.table.take(order[:n]).to_pylist()

    def pareto(self, names: Sequence[str]) -> np.ndarray:
        """Indices (rows) of the designs on the Pareto front of ``names`` (each by its sense; rows with a null out)."""
        return pareto_front(self._signed(names))

    @classmethod
    def read(cls, path) -> SweepResult:
        """The results file a sweep wrote."""
        import pyarrow.parquet as pq

        if Path(path).is_dir():
            raise InvalidInputError("path", f"{path} holds the parts of an unfinished sweep: run the same sweep again "
                                            "(same out) to finish it", str(path))
        manifest = read_manifest(path)
        return cls(pq.read_table(path), manifest)


def pareto_front(F: np.ndarray) -> np.ndarray:
    """Rows of ``F`` (n x m, each column to maximise; rows with NaN excluded) that no other row dominates, sorted
    (equal rows both kept). Two columns: one sort, O(n log n); more: each row against the front so far."""
    F = np.asarray(F, dtype=float)
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
