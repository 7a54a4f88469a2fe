"""Running a sweep: designs in chunks on Dask workers, results in Parquet, resumable.

:func:`sweep` draws the space, splits the designs into chunks, and evaluates each chunk on a worker; what every
chunk needs (the family and the objectives: a mechanism's name and fixed values, or its URDF and spec texts) is
scattered to the workers once, the chunks carry only their designs' values. Without a scheduler it starts a
``LocalCluster`` with one single-threaded worker process per core of the machine (the CPU affinity); ``scheduler=
"tcp://host:8786"`` or ``client=Client(...)`` sends the same chunks to an existing cluster (its workers must import
pkm); ``scheduler="serial"`` evaluates them in this process, one after the other (the reference the parallel runs
are tested against, and the route for a debugger).

With ``out="results.parquet"``, every finished chunk is written at once to ``results.parquet.parts/`` (a file per
chunk, written whole or not at all) beside a manifest of the sweep (family, space with its seed, objectives); when
every design is done the parts become the one file ``results.parquet`` (the manifest in its metadata) and the folder
goes. A sweep started again with the same output resumes: designs already in a part are not evaluated again, and
the table is the same as that of an uninterrupted run (the values of a design do not depend on the chunk, the
worker or the order). A different sweep on an existing output is refused unless ``overwrite=True``.

Each design is evaluated alone: an exception in an objective fails that design (``status="failed"``, the first
failing objective's error class and message; that objective's cell null, the others kept), not the sweep; a chunk whose worker dies (Dask retries it on others first) records its designs as failed with the
scheduler's error.
"""

from __future__ import annotations

import json
import logging
import math
import os
import shutil
import time
import traceback
import uuid
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from pkm.errors import InvalidInputError, PkmError, SweepError
from pkm.sweeps.family import Family, family_of
from pkm.sweeps.objectives import Objective, objective
from pkm.sweeps.space import Designs, Space

FORMAT = "pkm.sweep/1"
MAX_CHUNK = 500
#: glibc's allocator settings of the local workers (see :func:`local_cluster`) [bytes].
WORKER_MALLOC = {"MALLOC_MMAP_THRESHOLD_": 32 * 2**20, "MALLOC_TRIM_THRESHOLD_": 128 * 2**20}


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
        startup_seconds: Starting the local cluster and sending the sweep's data (0 when given a client).
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


class _Context:
    """What every chunk needs: travels to each worker once (scattered)."""

    def __init__(self, family: Family, names: tuple[str, ...], objectives: Sequence[Objective]):
        self.family, self.names, self.objectives = family, names, tuple(objectives)
        self._bound: list[Callable[[Any], float | None]] | None = None

    def __getstate__(self):
        return {"family": self.family, "names": self.names, "objectives": self.objectives}

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._bound = None

    def evaluate(self, values: Sequence[float]) -> tuple[list[float | None], str, str, str]:
        """One design: its objectives, status, and the first failure's error class and message."""
        if self._bound is None:
            self._bound = [o.bind(self.family) for o in self.objectives]
        design = self.family.candidate(dict(zip(self.names, (float(v) for v in values))))
        out: list[float | None] = []
        first: tuple[str, str] | None = None
        for fn, o in zip(self._bound, self.objectives):
            try:
                out.append(_as_value(fn(design), o.column))
            except Exception as exc:  # a failure is a cell of the results, never the sweep's end
                out.append(None)
                if first is None:
                    first = type(exc).__name__, f"{o.column}: {_message(exc)}"
        return (out, "ok", "", "") if first is None else (out, "failed", *first)


def _message(exc: BaseException) -> str:
    text = str(exc).strip() or repr(exc)
    if not isinstance(exc, PkmError):  # a bug or a library's error: where it came from helps
        frame = traceback.extract_tb(exc.__traceback__)[-1:] if exc.__traceback__ else []
        text += "".join(f" (at {Path(f.filename).name}:{f.lineno})" for f in frame)
    return text


def _as_value(v, column: str) -> float | None:
    if v is None:
        return None
    if isinstance(v, (bool, np.bool_)):
        return float(v)
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise InvalidInputError(column, f"an objective returns a number or None, got {type(v).__name__}", v) from None
    return None if math.isnan(x) else x


def _prepare(registered: str | None) -> None:
    """On a worker: import what evaluating designs needs (pkm, the mechanism's package)."""
    import pkm.sweeps

    if registered:
        import pkm

        pkm.mechanism_module(registered)


def _run_chunk(context: _Context, ids: np.ndarray, values: np.ndarray) -> tuple[dict[str, list], float]:
    """Evaluate a chunk (on a worker): its columns and the seconds it took."""
    t0 = time.perf_counter()
    cols: dict[str, list] = {o.column: [] for o in context.objectives}
    cols.update(status=[], error=[], message=[])
    for row in values:
        out, status, error, message = context.evaluate(row)
        for o, v in zip(context.objectives, out):
            cols[o.column].append(v)
        cols["status"].append(status)
        cols["error"].append(error)
        cols["message"].append(message)
    cols["design"] = [int(i) for i in ids]
    return cols, time.perf_counter() - t0


# ---------------------------------------------------------------------- the results table
def _schema(names: Sequence[str], objectives: Sequence[Objective]):
    import pyarrow as pa

    return pa.schema([("design", pa.int64())] + [(n, pa.float64()) for n in names]
                     + [(o.column, pa.float64()) for o in objectives]
                     + [("status", pa.string()), ("error", pa.string()), ("message", pa.string())])


def _chunk_table(designs: Designs, objectives: Sequence[Objective], cols: Mapping[str, list]):
    import pyarrow as pa

    ids = np.asarray(cols["design"], dtype=np.int64)
    data: dict[str, Any] = {"design": ids}
    for k, n in enumerate(designs.names):
        data[n] = designs.values[ids, k]
    for o in objectives:
        data[o.column] = cols[o.column]
    for key in ("status", "error", "message"):
        data[key] = cols[key]
    return pa.Table.from_pydict(data, schema=_schema(designs.names, objectives))


def _write_atomic(table, path: Path, metadata: Mapping[str, str] | None = None) -> None:
    import pyarrow.parquet as pq

    if metadata:
        table = table.replace_schema_metadata({**(table.schema.metadata or {}), **metadata})
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    pq.write_table(table, tmp)
    os.replace(tmp, path)


def _parts(out: Path) -> Path:
    return out.with_name(out.name + ".parts")


def _manifest(family: Family, designs: Designs, objectives: Sequence[Objective]) -> dict[str, Any]:
    import pkm

    return {"format": FORMAT, "pkm": pkm.__version__, "family": family.describe(), "space": designs.description,
            "parameters": list(designs.names), "units": {n: family.units(n)[1] for n in designs.names},
            "designs": len(designs),
            "objectives": [o.describe(family) for o in objectives],
            "values_sha256": _sha(designs.values)}


def _sha(values: np.ndarray) -> str:
    import hashlib

    return hashlib.sha256(np.ascontiguousarray(values, dtype="<f8").tobytes()).hexdigest()


def _same(a: Mapping[str, Any], b: Mapping[str, Any]) -> bool:
    keys = ("format", "family", "parameters", "designs", "objectives", "values_sha256")
    return all(json.dumps(a.get(k), sort_keys=True) == json.dumps(b.get(k), sort_keys=True) for k in keys)


def read_manifest(path) -> dict[str, Any]:
    """The manifest of a results file (or of an unfinished sweep's parts folder)."""
    import pyarrow.parquet as pq

    path = Path(path)
    if path.is_dir():
        return json.loads((path / "manifest.json").read_text(encoding="utf-8"))
    if not path.is_file():
        raise InvalidInputError("path", f"no such file: {path}", str(path))
    try:
        meta = pq.read_schema(path).metadata or {}
    except Exception as exc:  # pyarrow's ArrowInvalid & co.: not Parquet, or damaged
        raise InvalidInputError("path", f"{path} is not a Parquet file ({exc})", str(path)) from None
    if b"pkm.sweep" not in meta:
        raise InvalidInputError("path", f"{path} is not a pkm sweep's results (no manifest in its metadata)", str(path))
    return json.loads(meta[b"pkm.sweep"])


def _resume(out: Path, manifest: dict[str, Any], overwrite: bool):
    """Designs already done (their tables), or None when the output is complete already (then its table)."""
    import pyarrow.parquet as pq

    parts = _parts(out)
    if overwrite:
        shutil.rmtree(parts, ignore_errors=True)
        out.unlink(missing_ok=True)
    if out.exists():
        try:
            old = read_manifest(out)
        except Exception as exc:
            raise SweepError(f"{out} exists and is not a pkm sweep's results ({exc}); pass overwrite=True "
                             "(--overwrite) to replace it", out) from None
        if not _same(old, manifest):
            raise SweepError(f"{out} holds another sweep (other designs, objectives or mechanism); pass "
                             "overwrite=True (--overwrite) to replace it, or choose another output", out)
        return None, pq.read_table(out)
    tables = []
    if parts.exists():
        try:
            old = read_manifest(parts)
        except (OSError, ValueError):
            old = {}
        if not _same(old, manifest):
            raise SweepError(f"{parts} holds the parts of another sweep; pass overwrite=True (--overwrite) to "
                             "start again, or choose another output", parts)
        for p in sorted(parts.glob("part-*.parquet")):
            tables.append(pq.read_table(p))
    else:
        parts.mkdir(parents=True)
        (parts / "manifest.json").write_text(json.dumps(manifest, indent=1), encoding="utf-8")
    return tables, None


# ---------------------------------------------------------------------- the run
def _local_workers() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


def local_cluster(workers: int | None = None):
    """The ``LocalCluster`` a sweep starts: ``workers`` single-threaded worker processes (default: one per core of
    the CPU affinity), no dashboard (close it when done).

    Two of dask's defaults are changed for them, both measured on the 3-RRR maps (``tools/bench_sweep.py``, 256
    designs on one worker). The environment keeps one BLAS thread per worker, but glibc's allocator is told to keep
    what it frees (:data:`WORKER_MALLOC`: arrays below 32 MiB from the heap, the heap trimmed beyond 128 MiB free);
    with dask's ``MALLOC_TRIM_THRESHOLD_=65536``, which also turns off glibc's adaptive mmap threshold, every array
    the maps allocate went back to the system and was faulted in again (a million page faults, 2.3 s of system time,
    twice the work), and without any setting the tasks' thread arena trimmed its heap as often. And the workers'
    statistical profiler is off (it samples the running thread every 10 ms: 25 % slower). The workers of an
    existing cluster keep their own configuration (the README says how to set the same).

    Raises:
        SweepError: the workers could not start.
    """
    import dask
    from dask.distributed import LocalCluster

    n = _local_workers() if workers is None else workers
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InvalidInputError("workers", f"a positive integer, got {workers!r}", workers)
    environ = {**(dask.config.get("distributed.nanny.pre-spawn-environ", None) or {}), **WORKER_MALLOC}
    try:
        with dask.config.set({"distributed.nanny.pre-spawn-environ": environ,
                              "distributed.worker.profile.enabled": False}):
            return LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                silence_logs=logging.ERROR)
    except RuntimeError as exc:  # the workers could not start (a __main__ they cannot re-import: stdin, -c)
        raise SweepError(f"could not start {n} local Dask workers ({exc}): run the sweep from a script (with an "
                         "`if __name__ == '__main__':` guard), a notebook or `pkm sweep`, or pass "
                         "scheduler='serial'") from None


def _client(scheduler, client, workers: int | None):
    """``(client, what to close when done: the client and its local cluster, or nothing, workers)``."""
    from dask.distributed import Client

    if client is not None:
        if not isinstance(client, Client):
            raise InvalidInputError("client", f"expected a dask.distributed.Client, got {type(client).__name__}",
                                    client)
        return client, (), max(1, len(client.scheduler_info().get("workers", {})))
    if scheduler is None:
        cluster = local_cluster(workers)
        c = Client(cluster)
        return c, (c, cluster), len(cluster.workers)
    if not isinstance(scheduler, str):
        raise InvalidInputError("scheduler", f"expected an address such as tcp://host:8786, got {scheduler!r}",
                                scheduler)
    try:
        c = Client(scheduler)  # within dask's distributed.comm.timeouts.connect
    except (OSError, TimeoutError) as exc:
        raise SweepError(f"cannot reach the Dask scheduler at {scheduler}: {exc}", scheduler) from None
    if workers is None:
        c.wait_for_workers(1, timeout=60)
    else:
        c.wait_for_workers(workers, timeout=60)
    return c, (c,), max(1, len(c.scheduler_info().get("workers", {})))


def sweep(mechanism, space: Space, objectives, *, out=None, fixed: Mapping[str, Any] | None = None,
          scheduler: str | None = None, client=None, workers: int | None = None, chunk_size: int | None = None,
          progress: bool | None = None, overwrite: bool = False) -> SweepResult:
    """Evaluate ``objectives`` on every design of ``space`` (see the module doc).

    Args:
        mechanism: A registered name (``"rrr3"``), a :class:`pkm.Mechanism`, or a closure spec's path.
        space: :func:`~pkm.sweeps.grid`, :func:`~pkm.sweeps.sobol`, :func:`~pkm.sweeps.latin_hypercube` or
            :func:`~pkm.sweeps.table`.
        objectives: Specs (``"gci:step=1cm"``), callables or :class:`~pkm.sweeps.objectives.Objective`\\ s.
        out: A ``.parquet`` path to write (and resume from), or None: results in memory only.
        fixed: A registered mechanism's parameters not swept (SI or with units; the paper's by default).
        scheduler: None: a local cluster; ``"serial"``: this process; else a Dask scheduler's address.
        client: A ``dask.distributed.Client`` to use instead.
        workers: Worker processes of the local cluster (default: one per core); with a scheduler, how many to
            wait for.
        chunk_size: Designs per chunk (default: about 32 chunks per worker, at most :data:`MAX_CHUNK`).
        progress: A tqdm bar (None: when writing to a terminal).
        overwrite: Replace an output that holds another sweep.

    Raises:
        UnknownNameError: an unknown mechanism, parameter or objective.
        InvalidInputError: a malformed space, objective or option.
        SweepError: ``out`` holds another sweep; the scheduler cannot be reached.
    """
    family = family_of(mechanism, fixed)
    if not isinstance(space, Space):
        raise InvalidInputError("space", "give pkm.sweeps.grid(...), sobol(...), latin_hypercube(...) or "
                                         f"table(...), got {type(space).__name__}", space)
    for name in space.names:
        family.units(name)  # UnknownNameError listing the parameters
    designs = space.designs(family.units)
    if isinstance(objectives, (str, Objective)) or callable(objectives):
        objectives = [objectives]
    objectives = [objective(o) for o in objectives]
    if not objectives:
        raise InvalidInputError("objectives", "name at least one objective (see pkm.sweeps.OBJECTIVES)")
    columns = [o.column for o in objectives]
    clash = sorted({c for c in columns if columns.count(c) > 1} | (set(columns) & set(designs.names)))
    if clash:
        raise InvalidInputError("objectives", f"columns named twice: {clash} (name them: 'label=spec')", clash)
    context = _Context(family, designs.names, objectives)
    for o in objectives:
        o.bind(family)  # a route that does not exist fails here, not in every design
    manifest = _manifest(family, designs, objectives)
    out_path = None if out is None else Path(out)
    done_tables: list = []
    if out_path is not None:
        if out_path.suffix != ".parquet":
            raise InvalidInputError("out", f"the results are a .parquet file, got {out_path}", str(out_path))
        done_tables, complete = _resume(out_path, manifest, overwrite)
        if done_tables is None:
            return SweepResult(complete, manifest, Stats(len(designs), 0, _failed(complete), 0, 0, 0, 0.0, 0.0, 0.0))
    done = np.zeros(len(designs), dtype=bool)
    for t in done_tables:
        done[np.asarray(t.column("design"))] = True
    todo = np.flatnonzero(~done)

    t_start = time.perf_counter()
    serial = scheduler == "serial"
    cl, owned, n_workers = (None, (), 1) if serial else _client(scheduler, client, workers)
    try:
        size = chunk_size if chunk_size is not None else max(1, min(MAX_CHUNK, math.ceil(len(todo) / (32 * n_workers))))
        if isinstance(size, bool) or not isinstance(size, int) or size < 1:
            raise InvalidInputError("chunk_size", f"a positive integer, got {chunk_size!r}", chunk_size)
        chunks = [todo[k:k + size] for k in range(0, len(todo), size)]
        shared: Any = context
        if cl is not None:
            cl.run(_prepare, family.registered)  # the imports, once per worker, before the clock of the work starts
            shared = cl.scatter(context, broadcast=True, hash=False)
        startup = time.perf_counter() - t_start
        t0 = time.perf_counter()
        new_tables, work = [], 0.0
        bar = _bar(progress, len(designs), int(done.sum()))
        try:
            for ids, cols, seconds in _results(cl, shared, chunks, designs, objectives):
                table = _chunk_table(designs, objectives, cols)
                if out_path is not None:
                    _write_atomic(table, _parts(out_path) / f"part-{ids[0]:09d}-{ids[-1]:09d}.parquet")
                new_tables.append(table)
                work += seconds
                if bar is not None:
                    bar.update(len(ids))
        finally:
            if bar is not None:
                bar.close()
        wall = time.perf_counter() - t0
    finally:
        for thing in owned:
            thing.close()
    table = _combine(done_tables + new_tables, designs, objectives)
    if out_path is not None:
        _write_atomic(table, out_path, {"pkm.sweep": json.dumps(manifest)})
        shutil.rmtree(_parts(out_path), ignore_errors=True)
    evaluated = int(sum(len(c) for c in chunks))
    return SweepResult(table, manifest, Stats(len(designs), evaluated, _failed(table), len(chunks), size, n_workers,
                                              wall, work, startup))


def _results(cl, shared, chunks, designs: Designs, objectives):
    """``(ids, columns, seconds)`` of each chunk as it finishes."""
    if cl is None:
        for ids in chunks:
            cols, seconds = _run_chunk(shared, ids, designs.values[ids])
            yield ids, cols, seconds
        return
    from dask.distributed import as_completed

    futures = {cl.submit(_run_chunk, shared, ids, designs.values[ids], pure=False): ids for ids in chunks}
    for fut in as_completed(futures):
        ids = futures.pop(fut)
        try:
            cols, seconds = fut.result()
        except Exception as exc:  # the worker died on this chunk (after Dask's retries), or the cluster went
            n = len(ids)
            cols = {o.column: [None] * n for o in objectives}
            cols.update(design=[int(i) for i in ids], status=["failed"] * n, error=[type(exc).__name__] * n,
                        message=[_message(exc)] * n)
            seconds = 0.0
        fut.release()
        yield ids, cols, seconds


def _combine(tables, designs: Designs, objectives):
    import pyarrow as pa

    schema = _schema(designs.names, objectives)
    if not tables:
        return schema.empty_table()
    table = pa.concat_tables([t.cast(schema) for t in tables])
    return table.take(np.argsort(np.asarray(table.column("design")), kind="stable"))


def _failed(table) -> int:
    return int(sum(1 for s in table.column("status").to_pylist() if s == "failed"))


def _bar(progress, total: int, initial: int):
    if progress is False:
        return None
    from tqdm import tqdm

    return tqdm(total=total, initial=initial, desc="designs", unit="design", disable=None if progress is None
                else not progress)


# ---------------------------------------------------------------------- results
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
        self.stats = stats or Stats(table.num_rows, 0, _failed(table), 0, 0, 0, 0.0, 0.0, 0.0)

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
            from pkm.errors import UnknownNameError

            raise UnknownNameError("column", name, self.table.column_names, "the sweep's results")
        return np.array([np.nan if v is None else v for v in self.table.column(name).to_pylist()], dtype=float)

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
        cols = []
        for n in names:
            sense = self.objectives.get(n, {}).get("sense", "")
            if sense not in ("max", "min"):
                raise InvalidInputError("objectives", f"{n} has no sense (max or min): give one to rank by it", n)
            cols.append(self.column(n) * (1.0 if sense == "max" else -1.0))
        return np.column_stack(cols)

    def best(self, by: str, n: int = 1) -> list[dict[str, Any]]:
        """The ``n`` best designs by objective ``by`` (its sense), as rows (dicts), nulls last."""
        score = self._signed([by])[:, 0]
        order = [int(k) for k in np.argsort(-np.where(np.isnan(score), -np.inf, score), kind="stable")
                 if not np.isnan(score[k])]
        rows = self.table.take(order[:n]).to_pylist()
        return rows

    def pareto(self, names: Sequence[str]) -> np.ndarray:
        """Indices (rows) of the designs on the Pareto front of ``names`` (each by its sense; rows with a null out)."""
        return pareto_front(self._signed(names))

    @classmethod
    def read(cls, path) -> SweepResult:
        """The results file a sweep wrote."""
        import pyarrow.parquet as pq

        manifest = read_manifest(path)
        return cls(pq.read_table(path), manifest)


def pareto_front(F: np.ndarray) -> np.ndarray:
    """Rows of ``F`` (n x m, each column to maximise; rows with NaN excluded) that no other row dominates, sorted."""
    F = np.asarray(F, dtype=float)
    keep = np.flatnonzero(~np.isnan(F).any(axis=1))
    G = F[keep]
    order = np.lexsort(tuple(-G[:, j] for j in reversed(range(G.shape[1]))))  # best first on the first column
    front: list[int] = []
    for i in order:
        if not any(np.all(G[j] >= G[i]) and np.any(G[j] > G[i]) for j in front):
            front.append(int(i))
    return np.sort(keep[front])


def read(path) -> SweepResult:
    """:meth:`SweepResult.read`."""
    return SweepResult.read(path)


__all__ = ["FORMAT", "MAX_CHUNK", "Stats", "SweepError", "SweepResult", "local_cluster", "pareto_front", "read",
           "sweep"]
