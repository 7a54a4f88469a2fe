"""Long computations as jobs: every assembly mode, every working mode, a workspace map (with capability indices), a
design sweep (pkm's Dask engine).

``POST /models/{model}/jobs/{kind}`` starts one and answers its id at once (202); ``GET /jobs/{id}`` gives its state
(``queued``, ``running``, ``done``, ``failed``, ``cancelled``), its progress (0 to 1) and its error;
``GET /jobs/{id}/result`` its result as JSON (or msgpack), ``?format=parquet`` as a Parquet table (one row per mode
or per map node, the ``sweeps`` extra's pyarrow); ``DELETE /jobs/{id}`` cancels it (a queued job never starts; a
running one is told to stop and its result dropped: pkm's solvers run to their end in their thread). Jobs run on
their own worker threads, apart from the queries' (:class:`JobManager`); finished jobs are kept for
:data:`KEEP_SECONDS`.
"""

from __future__ import annotations

import threading
import time
import uuid
from collections.abc import Callable, Mapping
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np

import pkm
from pkm.core.model.mechanism import Mechanism
from pkm.errors import InvalidInputError, PkmError, UnknownNameError

#: How long a finished job's result is kept [s]; jobs kept at most.
KEEP_SECONDS = 3600.0
MAX_JOBS = 256


@dataclass
class Job:
    """One job (see the module doc)."""

    id: str
    kind: str
    model: str
    state: str = "queued"
    progress: float = 0.0
    error: dict[str, str] | None = None
    result: dict[str, Any] | None = field(default=None, repr=False)
    rows: dict[str, np.ndarray] | None = field(default=None, repr=False)
    created: float = field(default_factory=time.time)
    finished: float | None = None
    cancel: threading.Event = field(default_factory=threading.Event, repr=False)
    future: Future | None = field(default=None, repr=False)
    defect: bool = field(default=False, repr=False)  # (failed on an unexpected exception, not on a PkmError)

    def summary(self) -> dict[str, Any]:
        return {"id": self.id, "kind": self.kind, "model": self.model, "state": self.state,
                "progress": self.progress, "error": self.error, "created": self.created, "finished": self.finished}


def _outside(mech: Mechanism, Q: np.ndarray) -> list[list[dict[str, Any]]]:
    """Per mode, the joints outside the position limits the model states (joint, value, limit)."""
    return [[v._asdict() for v in mech.limit_violations(q)] for q in Q]


def _modes(mech: Mechanism, body: Mapping[str, Any], job: Job) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """Every assembly mode at ``qa`` (:func:`pkm.assembly_modes`)."""
    from pkm.core.modes import assembly_modes
    from pkm.serve.queries import _array, _input_units, _q_units, _value_units

    qa = _array(body, "qa", mech.na, _input_units(mech, "qa"))[0]
    s = assembly_modes(mech, qa)
    Q = np.array([m.q for m in s.modes]) if s.modes else np.zeros((0, mech.nq))
    task = pkm.TaskMap.of(mech)
    Y = np.array([task.value(q) for q in Q]) if len(Q) else np.zeros((0, task.value_size))
    residual = np.array([m.residual for m in s.modes])
    out = {"count": len(s.modes), "complete": bool(s.complete), "q": Q, "y": Y, "residual": residual,
           "labels": [str(m.label) for m in s.modes], "outside_limits": _outside(mech, Q), "seconds": s.seconds,
           "units": {"q": _q_units(mech), "y": _value_units(mech), "residual": "m or rad", "seconds": "s"}}
    return out, {"mode": np.arange(len(Q)), **{f"q{i}": Q[:, i] for i in range(Q.shape[1])},
                 **{f"y{i}": Y[:, i] for i in range(Y.shape[1])}, "residual": residual}


def _working(mech: Mechanism, body: Mapping[str, Any], job: Job) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """Every working mode at the task value ``y`` (:func:`pkm.working_modes`)."""
    from pkm.core.modes import working_modes
    from pkm.serve.queries import _actuated_units, _array, _input_units, _q_units

    y = _array(body, "y", pkm.TaskMap.of(mech).value_size, _input_units(mech, "y"))[0]
    s = working_modes(mech, y)
    Q = np.array([m.q for m in s.modes]) if s.modes else np.zeros((0, mech.nq))
    QA = Q[:, mech.act_q] if len(Q) else np.zeros((0, mech.na))
    out = {"count": len(s.modes), "complete": bool(s.complete), "q": Q, "qa": QA,
           "labels": [str(m.label) for m in s.modes], "outside_limits": _outside(mech, Q), "seconds": s.seconds,
           "units": {"q": _q_units(mech), "qa": _actuated_units(mech), "seconds": "s"}}
    return out, {"mode": np.arange(len(Q)), **{f"qa{i}": QA[:, i] for i in range(QA.shape[1])}}


def _map(mech: Mechanism, body: Mapping[str, Any], job: Job) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """A workspace map (:func:`pkm.workspace_map`): ``axes`` ``{name: [start, stop, count]}`` (SI, or start and stop
    with units: ``["-5cm", "5cm", 11]``, as ``pkm map --axis x=-5cm:5cm:11``), ``fixed``, ``length`` (units allowed
    too); with ``index`` (``wrench``, ``twist``, ``acceleration``) the capability at every node."""
    from pkm.core.analysis.maps import MAX_NODES, workspace_map
    from pkm.units import quantity

    axes_in = body.get("axes")
    if not isinstance(axes_in, Mapping) or not 1 <= len(axes_in) <= 3:
        raise InvalidInputError("axes", "give {name: [start, stop, count]} for 1 to 3 task coordinates", axes_in)
    axes = {}
    kinds = pkm.TaskMap.of(mech).kinds
    for name, spec in axes_in.items():
        if not (isinstance(spec, (list, tuple)) and len(spec) == 3
                and all(isinstance(x, (int, float, str)) and not isinstance(x, bool) for x in spec[:2])
                and isinstance(spec[2], (int, float)) and float(spec[2]).is_integer() and 1 <= spec[2] <= MAX_NODES):
            raise InvalidInputError(f"axes.{name}", "[start, stop, count] (SI numbers or strings with a unit, count a "
                                                    "positive integer)", spec)
        if name not in kinds:
            raise UnknownNameError("task coordinate", str(name), list(kinds), mech.name)
        start, stop = (quantity(x, kinds[name], f"axes.{name}") for x in spec[:2])
        axes[str(name)] = np.linspace(start, stop, int(spec[2]))
    fixed = body.get("fixed")
    if fixed is not None and not isinstance(fixed, Mapping):
        raise InvalidInputError("fixed", "{task coordinate: value}", fixed)
    length = body.get("length")
    index = body.get("index")
    length = pkm.TaskMap.of(mech).default_length(None if length is None else quantity(length, "length", "length"))
    m = workspace_map(mech, axes, fixed, length=length,
                      configurations=index is not None)
    job.progress = 0.7
    grids = np.meshgrid(*[v for _, v in reversed(m.axes)], indexing="ij")
    rows: dict[str, np.ndarray] = {name: g.ravel() for (name, _), g in zip(reversed(m.axes), grids)}
    rows["reachable"] = m.reachable.ravel()
    rows["ci_2"] = m.condition_index("2").ravel()
    out: dict[str, Any] = {"axes": {n: v for n, v in m.axes}, "reachable": m.reachable,
                           "condition_index": m.condition_index("2"), "nodes": m.nodes, "size": m.size,
                           "gci": m.gci("2"), "how": m.how, "length": length,
                           "units": {"axes": {n: ("m" if k == "length" else "rad") for (n, _), k in zip(m.axes, m.kinds)},
                                     "size": m.size_unit, "condition_index": "1", "gci": "1", "length": "m"}}
    if m.within_limits is not None:  # (the joints' limits and the interference, where the map checked them)
        rows["within_limits"] = m.within_limits.ravel()
        out["within_limits"] = m.within_limits
    if m.clearance is not None and m.interferes is not None:
        rows["clearance"], rows["interferes"] = m.clearance.ravel(), m.interferes.ravel()
        out["clearance"], out["interferes"] = m.clearance, m.interferes
        out["units"]["clearance"] = "m"
    out["feasible"] = m.feasible
    if index is not None:
        from pkm.core.analysis.capability import map_capability

        cm = map_capability(mech, m, str(index))
        out["capability"] = {"kind": cm.kind, "units": cm.units, "isotropic": cm.isotropic,
                             "along": {a: {"plus": p, "minus": n} for a, (p, n) in cm.along.items()}}
        for u, v in cm.isotropic.items():
            rows[f"isotropic [{u}]"] = v.ravel()
    return out, rows


def _sweep(mech: Mechanism, body: Mapping[str, Any], job: Job) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """A design sweep of a registered mechanism on pkm's Dask engine (:func:`pkm.sweep`): ``grid`` ``{parameter:
    "START:STOP:COUNT"}`` (units as ``pkm sweep`` reads them), ``objectives`` (names or specs), ``fixed`` (other
    parameters), ``scheduler`` (None: a local cluster of ``workers``; ``"serial"``; a scheduler's address)."""
    from pkm import sweeps

    grid, objectives = body.get("grid"), body.get("objectives")
    if not isinstance(grid, Mapping) or not grid or not all(isinstance(v, str) for v in grid.values()):
        raise InvalidInputError("grid", "{parameter: \"START:STOP:COUNT\"}, e.g. {\"R\": \"10cm:20cm:5\"}", grid)
    if not isinstance(objectives, list) or not objectives or not all(isinstance(o, str) for o in objectives):
        raise InvalidInputError("objectives", "a list of objective names or specs", objectives)
    scheduler, workers = body.get("scheduler"), body.get("workers")
    if workers is not None and not (isinstance(workers, int) and 1 <= workers <= 8):
        raise InvalidInputError("workers", "1 to 8 local workers", workers)
    if "@" in job.model:  # (a variant's design would be dropped: its base's sweep with these values in fixed)
        raise InvalidInputError("model", "sweep the registered mechanism and give the variant's parameters in fixed",
                                job.model)
    res = sweeps.sweep(job.model, sweeps.grid(**grid), objectives, fixed=body.get("fixed"), scheduler=scheduler,
                       workers=workers, progress=False)
    table = res.table
    rows = {c: np.asarray(table.column(c).to_pylist(), dtype=object if table.schema.field(c).type == "string"
                          else None) for c in table.column_names}
    out = {"columns": table.column_names, "rows": {c: v.tolist() for c, v in rows.items()},
           "designs": len(res), "failed": int(sum(1 for s in rows.get("status", []) if s != "ok"))}
    return out, rows


#: The job kinds (``POST /models/{model}/jobs/{kind}``).
KINDS: dict[str, Callable[[Mechanism, Mapping[str, Any], Job], tuple[dict[str, Any], dict[str, np.ndarray]]]] = {
    "assembly_modes": _modes, "working_modes": _working, "map": _map, "sweep": _sweep}


class JobManager:
    """Jobs on ``workers`` threads of their own (see the module doc)."""

    def __init__(self, workers: int = 1):
        self._pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="pkm-job")
        self._jobs: dict[str, Job] = {}
        self._lock = threading.Lock()

    def submit(self, kind: str, model: str, mech: Mechanism, body: Mapping[str, Any]) -> Job:
        """Start a job (see :data:`KINDS`).

        Raises:
            UnknownNameError: an unknown kind.
            InvalidInputError: too many jobs kept.
        """
        if kind not in KINDS:
            raise UnknownNameError("job kind", kind, sorted(KINDS))
        self._forget_old()
        with self._lock:
            if len(self._jobs) >= MAX_JOBS:
                raise InvalidInputError("jobs", f"{MAX_JOBS} jobs are kept: delete finished ones first")
            job = Job(uuid.uuid4().hex[:16], kind, model)
            self._jobs[job.id] = job

        def run() -> None:
            if job.cancel.is_set():
                return
            job.state = "running"
            try:
                result, rows = KINDS[kind](mech, body, job)
            except PkmError as e:
                job.state, job.error = "failed", {"error": type(e).__name__, "message": str(e)}
            except Exception as e:  # (a defect: reported on the job, the service goes on)
                job.state, job.error = "failed", {"error": type(e).__name__, "message": f"unexpected: {e}"}
                job.defect = True
            else:
                if job.cancel.is_set():
                    job.state = "cancelled"
                else:
                    job.result, job.rows, job.state, job.progress = result, rows, "done", 1.0
            job.finished = time.time()

        job.future = self._pool.submit(run)
        return job

    def get(self, job_id: str) -> Job:
        with self._lock:
            if job_id in self._jobs:
                return self._jobs[job_id]
            known = list(self._jobs)
        raise UnknownNameError("job", job_id, known)

    def list(self) -> list[Job]:
        with self._lock:
            return list(self._jobs.values())

    def cancel(self, job_id: str) -> Job:
        """Cancel a job: a queued one never starts, a running one's result is dropped; a finished one is forgotten."""
        job = self.get(job_id)
        job.cancel.set()
        if job.state in ("done", "failed", "cancelled"):
            with self._lock:
                self._jobs.pop(job_id, None)
            return job
        if job.future is not None and job.future.cancel():
            job.state, job.finished = "cancelled", time.time()
        return job

    def _forget_old(self) -> None:
        now = time.time()
        with self._lock:
            for k in [k for k, j in self._jobs.items() if j.finished is not None and now - j.finished > KEEP_SECONDS]:
                del self._jobs[k]

    def shutdown(self) -> None:
        self._pool.shutdown(wait=False, cancel_futures=True)


def parquet(rows: Mapping[str, np.ndarray]) -> bytes:
    """A job's rows as a Parquet table (pyarrow, the ``sweeps`` extra)."""
    import io

    from pkm._optional import require

    require("sweeps", "a job's result as Parquet", ["pyarrow"])
    import pyarrow as pa
    import pyarrow.parquet as pq

    buf = io.BytesIO()
    pq.write_table(pa.table({k: np.asarray(v) for k, v in rows.items()}), buf)
    return buf.getvalue()


__all__ = ["KEEP_SECONDS", "KINDS", "MAX_JOBS", "Job", "JobManager", "parquet"]
