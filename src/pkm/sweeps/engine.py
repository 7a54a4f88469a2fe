"""Running a sweep: designs in chunks on Dask workers, results in Parquet, resumable.

:func:`sweep` draws the space, splits the designs into chunks, and evaluates each chunk on a worker; what every
chunk needs (the family and the objectives: a mechanism's name and fixed values, or its URDF and spec texts) is
scattered to the workers once, the chunks carry only their designs' values. Without a scheduler it starts a
``LocalCluster`` with one single-threaded worker process per core of the machine (the CPU affinity); ``scheduler=
"tcp://host:8786"`` or ``client=Client(...)`` sends the same chunks to an existing cluster (its workers must import
pkm); ``scheduler="serial"`` evaluates them in this process, one after the other (the reference the parallel runs
are tested against, and the route for a debugger).

With ``out="results.parquet"`` every finished chunk is written at once, and a sweep started again with the same
output resumes (:mod:`pkm.sweeps.store`): designs already written are not evaluated again, and the table is the
one an uninterrupted run gives (the values of a design do not depend on its chunk, worker or order); a sampled
space given no seed takes the one the output records, so that it draws the same designs again. A different sweep
on an existing output is refused unless ``overwrite=True``.

Each design is evaluated alone: an exception in an objective fails that design (``status="failed"``, the first
failing objective's error class and message; that objective's cell null, the others kept), not the sweep; a design
that kills its worker process (after Dask's retries) is recorded as failed with ``KilledWorker``, the other designs
of its chunk run again one by one. A sweep whose every design failed returns (and writes) its table as any other;
:meth:`SweepResult.check() <pkm.sweeps.SweepResult.check>` raises :class:`~pkm.errors.SweepError` naming how many
and the first failure (as ``pkm sweep`` does), and ranking by an objective that no design has is one too. Designs
lost to the cluster itself are not recorded: the sweep raises :class:`~pkm.errors.SweepError` after keeping the
chunks that finished, and a rerun resumes.

Every Dask client and local cluster a sweep makes is its own, and is closed before :func:`sweep` returns or raises
(an error, a ``KeyboardInterrupt``), a client whose constructor failed part way included (:func:`_construct`);
nothing is left to the garbage collector. Not one client kept per process: a sweep's local cluster is shaped by its
call (``workers``, the allocator settings of :func:`local_cluster`), its workers hold the imports and memory of the
mechanism swept, and a cluster a design damaged (killed workers) would carry over into the next sweep; starting one
costs about a second, small beside a sweep worth distributing. And closing late is not only a leak: dask closes a
forgotten client from its ``__del__``, wherever the collector runs, and when that is inside the next client's
start both wait on dask's one loop-runner lock: the process hangs for good. A ``client=`` given by the caller is
the caller's: used, never closed.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import logging
import math
import multiprocessing
import os
import shutil
import time
import traceback
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from pkm._moved import renamed_keywords
from pkm._optional import require
from pkm.core.model.spec import as_path
from pkm.errors import InvalidInputError, PkmError, SweepError
from pkm.sweeps.family import Family, family_of
from pkm.sweeps.objectives import Objective, objective
from pkm.sweeps.results import Stats, SweepResult
from pkm.sweeps.space import Designs, Space
from pkm.sweeps.store import (
    chunk_table,
    combine,
    count_failed,
    manifest_of,
    parts_folder,
    recorded_seed,
    resume,
    write_atomic,
)

if TYPE_CHECKING:
    from pkm.core.model.mechanism import Mechanism

MAX_CHUNK = 500
#: glibc's allocator settings of the local workers (see :func:`local_cluster`) [bytes].
WORKER_MALLOC = {"MALLOC_MMAP_THRESHOLD_": 32 * 2**20, "MALLOC_TRIM_THRESHOLD_": 128 * 2**20}


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


def _unpickle(blob: bytes) -> _Context:
    import cloudpickle

    return cloudpickle.loads(blob)


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
    statistical profiler is off (it samples the running thread every 10 ms: 25 % slower). Its scheduler gives a
    worker one chunk at a time (``worker-saturation`` 1.0, dask's default 1.1 queues two on a single thread): a
    design that kills its worker then takes no other chunk's retries with it. The workers of an existing cluster
    keep their own configuration (docs/tour/sweeps.md, "On a cluster", says how to set the same).

    Raises:
        SweepError: the workers could not start.
        MissingDependencyError: the ``sweeps`` extra is not installed (``pip install "pkm-robotics[sweeps]"``).
    """
    require("sweeps", "a local Dask cluster")
    import dask
    from dask.distributed import LocalCluster

    n = _local_workers() if workers is None else workers
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InvalidInputError("workers", f"a positive integer, got {workers!r}", workers)
    if multiprocessing.current_process().daemon:  # (dask's nannies would fail, after seconds and tracebacks)
        raise SweepError(f"could not start {n} local Dask workers (daemonic processes are not allowed to have "
                         "children: this is one, a multiprocessing pool's worker or the like): run the sweep from a "
                         "script (with an `if __name__ == '__main__':` guard), a notebook or `pkm sweep`, or pass "
                         "scheduler='serial'")
    environ = {**(dask.config.get("distributed.nanny.pre-spawn-environ", None) or {}), **WORKER_MALLOC}
    try:
        with dask.config.set({"distributed.nanny.pre-spawn-environ": environ,
                              "distributed.worker.profile.enabled": False,
                              "distributed.scheduler.worker-saturation": 1.0}):
            return _construct(LocalCluster, n_workers=n, threads_per_worker=1, processes=True,
                              dashboard_address=None, silence_logs=logging.ERROR)
    except RuntimeError as exc:  # the workers could not start (a __main__ they cannot re-import: stdin, -c)
        raise SweepError(f"could not start {n} local Dask workers ({exc}): run the sweep from a script (with an "
                         "`if __name__ == '__main__':` guard), a notebook or `pkm sweep`, or pass "
                         "scheduler='serial'") from None


def _construct(cls, *args, **kwargs):
    """``cls(*args, **kwargs)`` for a dask ``Client`` or cluster, closed at once if its constructor raises (or is
    interrupted) part way: ``Client("tcp://unreachable:8786")`` has started its IO loop (and, made the default,
    registered itself) before its connection fails; the exception does not hand it back, and it would stay open
    until the garbage collector found it (see the module doc)."""
    obj = cls.__new__(cls)
    try:
        obj.__init__(*args, **kwargs)
    except BaseException:
        _close(obj)  # (a client that never connected, status "newly-created", ignores this: its loop goes next)
        runner = getattr(obj, "_loop_runner", None)
        if runner is not None:
            runner.stop()  # (idempotent)
        raise
    return obj


def _close(thing) -> None:
    """Close a client or cluster of ours; a failure to close (the scheduler already gone) is logged, not raised:
    it must not hide the sweep's own outcome."""
    try:
        thing.close()
    except Exception as exc:  # (AttributeError: a constructor that failed before its first attribute)
        logging.getLogger(__name__).debug("closing %s: %r", type(thing).__name__, exc)


def _client(scheduler, client, workers: int | None, stack: contextlib.ExitStack):
    """``(client, workers)``; what this makes (a client, a local cluster) is closed by ``stack``, registered the
    moment it exists. Its clients are not made dask's default (``set_as_default=False``): a ``dask.compute`` of the
    caller's, while a sweep runs, stays on the caller's scheduler."""
    from dask.distributed import Client

    if client is not None:
        if not isinstance(client, Client):
            raise InvalidInputError("client", f"expected a dask.distributed.Client, got {type(client).__name__}",
                                    client)
        if client.status != "running":
            raise InvalidInputError("client", f"the client is {client.status}: give a running one", client)
        return client, max(1, len(client.scheduler_info().get("workers", {})))
    if scheduler is None:
        cluster = local_cluster(workers)
        stack.callback(_close, cluster)
        c = _construct(Client, cluster, set_as_default=False)
        stack.callback(_close, c)
        return c, len(cluster.workers)
    try:
        c = _construct(Client, scheduler, set_as_default=False)  # (within distributed.comm.timeouts.connect)
    except (OSError, TimeoutError, ValueError) as exc:  # (ValueError: not an address)
        raise SweepError(f"cannot reach the Dask scheduler at {scheduler}: {exc}", scheduler) from None
    stack.callback(_close, c)
    try:
        c.wait_for_workers(1 if workers is None else workers, timeout=60)
    except TimeoutError:
        raise SweepError(f"the Dask scheduler at {scheduler} has fewer than {workers or 1} workers after 60 s",
                         scheduler) from None
    return c, max(1, len(c.scheduler_info().get("workers", {})))


def sweep(mechanism: str | os.PathLike[str] | Mechanism | Family, space: Space,
          objectives: str | Objective | Callable[..., Any] | Sequence[str | Objective | Callable[..., Any]], *,
          out: str | os.PathLike[str] | None = None, fixed: Mapping[str, Any] | None = None,
          scheduler: str | None = None, client: Any = None, workers: int | None = None,
          chunk_size: int | None = None, progress: bool | None = None, overwrite: bool = False) -> SweepResult:
    """Evaluate ``objectives`` on every design of ``space`` (see the module doc).

    Args:
        mechanism: A registered name (``"rrr3"``), a :class:`pkm.Mechanism`, or a closure spec's path (or a
            :class:`~pkm.sweeps.family.Family`).
        space: :func:`~pkm.sweeps.grid`, :func:`~pkm.sweeps.sobol`, :func:`~pkm.sweeps.latin_hypercube` or
            :func:`~pkm.sweeps.table`.
        objectives: Specs (``"gci:step=1cm"``), callables or :class:`~pkm.sweeps.objectives.Objective`\\ s.
        out: A ``.parquet`` path to write (and resume from), or None: results in memory only.
        fixed: A registered mechanism's parameters not swept (SI or with units; the paper's by default).
        scheduler: None: a local cluster; ``"serial"``: this process; else a Dask scheduler's address.
        client: A ``dask.distributed.Client`` to use instead (typed ``Any``: Dask is an optional extra).
        workers: Worker processes of the local cluster (default: one per core); with a scheduler, how many to
            wait for.
        chunk_size: Designs per chunk (default: about 32 chunks per worker, at most :data:`MAX_CHUNK`).
        progress: A tqdm bar (None: when writing to a terminal).
        overwrite: Start afresh: delete what ``out`` holds (another sweep's results, or this one's parts).

    Raises:
        UnknownNameError: an unknown mechanism, parameter or objective.
        InvalidInputError: a malformed space, objective or option.
        SweepError: ``out`` holds another sweep; the scheduler cannot be reached or has no workers; designs were
            lost to the cluster (the finished chunks kept: a rerun resumes).
        MissingDependencyError: the ``sweeps`` extra (Dask, pyarrow, cloudpickle) is not installed: ``pip install
            "pkm-robotics[sweeps]"``.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> from pkm import sweeps
        >>> space = sweeps.grid(a="30cm:60cm:3", b="40cm", h="10cm")
        >>> res = pkm.sweep("rrr3", space, ["gci:step=4cm"], scheduler="serial", progress=False)
        >>> res
        SweepResult(3 designs of {'registered': 'rrr3', 'fixed': {}}, 0 failed; objectives ['gci:step=4cm'])
        >>> np.round(res.column("gci:step=4cm"), 4)
        array([0.4576, 0.3477, 0.2184])
    """
    require("sweeps", "pkm.sweep (design sweeps on Dask, results in Parquet)")
    if scheduler is not None and not isinstance(scheduler, str):
        raise InvalidInputError("scheduler", f"'serial' or an address such as tcp://host:8786, got {scheduler!r}",
                                scheduler)
    if scheduler is not None and client is not None:
        raise InvalidInputError("client", "give a scheduler or a client, not both", client)
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1
                                or scheduler == "serial" or client is not None):
        raise InvalidInputError("workers", "a positive integer, for a local cluster or to wait for on a scheduler "
                                           f"(not with 'serial' or a client), got {workers!r}", workers)
    if chunk_size is not None and (isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1):
        raise InvalidInputError("chunk_size", f"a positive integer, got {chunk_size!r}", chunk_size)
    family = family_of(mechanism, fixed)
    if not isinstance(space, Space):
        raise InvalidInputError("space", "give pkm.sweeps.grid(...), sobol(...), latin_hypercube(...) or "
                                         f"table(...), got {type(space).__name__}", space)
    if family.renamed:  # deprecated former parameter names: warned, swept under the new ones
        specs = renamed_keywords(f"pkm.sweep({family.registered!r})", dict(space.specs), family.renamed)
        space = dataclasses.replace(space, specs=tuple(specs.items()))
        fixed = {family.renamed.get(k, k): v for k, v in fixed.items()} if fixed else fixed
    for name in space.names:
        family.units(name)  # UnknownNameError listing the parameters
        if family.integer(name) and space.kind in ("sobol", "latin_hypercube"):
            raise InvalidInputError(name, f"{name} takes integers: give it as a grid axis or a table column, not "
                                          "sampled", name)
    both = sorted(set(space.names) & set(fixed or {}))
    if both:
        raise InvalidInputError("fixed", f"{both} are swept and fixed at once", both)
    out_path = None if out is None else as_path(out, "out")
    if out_path is not None and space.seed is None and space.kind in ("sobol", "latin_hypercube") and not overwrite:
        space = dataclasses.replace(space, seed=recorded_seed(out_path))  # resuming: the samples drawn before
    designs = space.designs(family.units)
    given = [objectives] if isinstance(objectives, (str, Objective)) or callable(objectives) else objectives
    chosen: list[Objective] = [objective(o) for o in given]
    if not chosen:
        raise InvalidInputError("objectives", "name at least one objective (see pkm.sweeps.OBJECTIVES)")
    columns = [o.column for o in chosen]
    clash = sorted({c for c in columns if columns.count(c) > 1} | (set(columns) & set(designs.names)))
    if clash:
        raise InvalidInputError("objectives", f"columns named twice: {clash} (name them: 'label=spec')", clash)
    context = _Context(family, designs.names, chosen)
    for o in chosen:
        o.bind(family)  # a route that does not exist fails here, not in every design
    manifest = manifest_of(family, designs, chosen)
    done_tables: list = []
    if out_path is not None:
        if out_path.suffix != ".parquet" or (out_path.exists() and not out_path.is_file()):
            raise InvalidInputError("out", f"the results are a .parquet file, got {out_path}", str(out_path))
        done_tables, complete = resume(out_path, manifest, overwrite)
        if done_tables is None:
            return SweepResult(complete, manifest)  # (nothing evaluated: its stats say so)
    done = np.zeros(len(designs), dtype=bool)
    for t in done_tables:
        done[np.asarray(t.column("design"))] = True
    todo = np.flatnonzero(~done)

    t_start = time.perf_counter()
    in_process = scheduler == "serial" or not len(todo)  # (nothing left to do: no cluster to start)
    with contextlib.ExitStack() as owned:  # closes the client and cluster made here, however this block ends
        cl, n_workers = (None, 1) if in_process else _client(scheduler, client, workers, owned)
        size = chunk_size if chunk_size is not None else max(1, min(MAX_CHUNK, math.ceil(len(todo) / (32 * n_workers))))
        chunks = [todo[k:k + size] for k in range(0, len(todo), size)]
        shared: Any = context
        if cl is not None:
            try:
                cl.run(_prepare, family.registered)  # the imports, once per worker, before the clock of the work
            except OSError as exc:  # (CommClosedError: the scheduler or its workers gone)
                raise SweepError(f"the Dask cluster was lost before the sweep started ({type(exc).__name__}: "
                                 f"{_message(exc)})", scheduler) from None
            # a task, not scattered data: a worker that dies takes its copy with it, and Dask recomputes a task's
            # result where scattered data would be lost (with every chunk waiting on it)
            import cloudpickle

            shared = cl.submit(_unpickle, cloudpickle.dumps(context), pure=False)
        startup = time.perf_counter() - t_start
        t0 = time.perf_counter()
        new_tables, work = [], 0.0
        bar = _bar(progress, len(designs), int(done.sum()))
        try:
            for ids, cols, seconds in _results(cl, shared, chunks, designs, chosen):
                table = chunk_table(designs, chosen, cols)
                if out_path is not None:
                    write_atomic(table, parts_folder(out_path) / f"part-{ids[0]:09d}-{ids[-1]:09d}.parquet")
                new_tables.append(table)
                work += seconds
                if bar is not None:
                    bar.update(len(ids))
        finally:
            if bar is not None:
                bar.close()
        wall = time.perf_counter() - t0
    table = combine(done_tables + new_tables, designs, chosen)
    if out_path is not None:
        write_atomic(table, out_path, {"pkm.sweep": json.dumps(manifest)})
        shutil.rmtree(parts_folder(out_path), ignore_errors=True)
    evaluated = int(sum(len(c) for c in chunks))
    return SweepResult(table, manifest, Stats(len(designs), evaluated, count_failed(table), len(chunks), size, n_workers,
                                              wall, work, startup))


def _results(cl, shared, chunks, designs: Designs, objectives):
    """``(ids, columns, seconds)`` of each chunk as it finishes.

    A chunk whose workers died on it (``KilledWorker``, after Dask's retries) is run again one design a task, so
    that only the designs that kill their worker are recorded as failed. A chunk lost to the cluster itself (the
    scheduler gone, a connection closed) is not a result: the chunks that finished are kept and
    :class:`~pkm.errors.SweepError` says how many designs are left for a rerun to resume.
    """
    if cl is None:
        for ids in chunks:
            cols, seconds = _run_chunk(shared, ids, designs.values[ids])
            yield ids, cols, seconds
        return
    from dask.distributed import KilledWorker, as_completed

    def submit(ids):
        return cl.submit(_run_chunk, shared, ids, designs.values[ids], pure=False)

    futures = {submit(ids): ids for ids in chunks}
    pending = as_completed(list(futures), loop=cl.loop)  # (the loop of this client: it is not the default)
    lost: list[tuple[np.ndarray, BaseException]] = []
    for fut in pending:
        ids = futures.pop(fut)
        try:
            cols, seconds = fut.result()
        except KilledWorker as exc:
            if len(ids) > 1:  # find the design(s) that kill their worker
                for one in ids:
                    f = submit(np.array([one]))
                    futures[f] = np.array([one])
                    pending.add(f)
                continue
            cols = {o.column: [None] for o in objectives}
            cols.update(design=[int(ids[0])], status=["failed"], error=["KilledWorker"],
                        message=[f"its worker process died evaluating it ({_message(exc)})"])
            seconds = 0.0
        except Exception as exc:  # the cluster, not the design: nothing to record, left for a rerun
            lost.append((ids, exc))
            continue
        finally:
            fut.release()
        yield ids, cols, seconds
    if lost:
        n = sum(len(ids) for ids, _ in lost)
        raise SweepError(f"{n} designs were lost to the cluster ({type(lost[0][1]).__name__}: {_message(lost[0][1])}); "
                         "the finished chunks are kept: run the same sweep again (same out) to resume")


def _bar(progress: bool | None, total: int, initial: int):
    if progress is not None and not isinstance(progress, bool):
        raise InvalidInputError("progress", f"expected True, False or None, got {type(progress).__name__}", progress)
    if progress is False:
        return None
    from tqdm import tqdm

    return tqdm(total=total, initial=initial, desc="designs", unit="design", disable=None if progress is None
                else not progress)


__all__ = ["MAX_CHUNK", "WORKER_MALLOC", "local_cluster", "sweep"]
