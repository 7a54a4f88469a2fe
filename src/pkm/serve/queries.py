"""The questions the service answers about a model: each a function ``(mech, body, kernels) -> answer`` over one sample
or a batch (every array input given as one sample, or as a list of samples of the same length). Batches of the
forward kinematics, the Jacobians and the dynamic model run through the model's compiled kernels (``kernels``, a
:class:`pkm.Kernels`, where they build; the same answers to 1e-12) and fall back to the library's Python route, sample
by sample, where the kernels refuse a sample.

Every answer carries its units (SI: ``m``, ``rad``, ``N``, ``N m``, per coordinate) and what certifies it: the
residuals of the closures, the status of each sample (``"ok"`` or the error that sample raised, with its data: a
batch does not fail as a whole because one sample is unreachable). Inputs are checked by pkm's own validation: a
bad one is a :class:`~pkm.errors.PkmError` naming the field, which the service answers with 422.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from pkm.core.model.mechanism import Mechanism
from pkm.errors import InvalidInputError, PkmError
from pkm.validation import as_array

#: Samples in one request at most.
MAX_SAMPLES = 100_000


def _unit(mech: Mechanism, joint: str, kind: str = "position") -> str:
    revolute = mech.joints[joint].revolute
    return {"position": "rad" if revolute else "m", "rate": "rad/s" if revolute else "m/s",
            "effort": "N m" if revolute else "N"}[kind]


def _task_units(mech: Mechanism) -> dict[str, str]:
    """The units of the task's tangent coordinates (:attr:`TaskMap.keys`: a pose's x y z roll pitch yaw)."""
    kinds = mech.task_map.kinds
    out = {k: ("m" if kinds.get(k) == "length" else "rad") for k in mech.task_map.keys}
    return out


def _value_units(mech: Mechanism) -> list[str]:
    """The units of the task value's entries (:attr:`TaskMap.value_names`: a pose's x y z qx qy qz qw, whose
    quaternion is unitless, ``"1"``)."""
    kinds = mech.task_map.kinds
    return [("m" if kinds[k] == "length" else "rad") if k in kinds else "1" for k in mech.task_map.value_names]


def _optional(body: Mapping[str, Any], key: str, size: int) -> np.ndarray | None:
    """``body[key]`` as an (n, size) array (a single sample as n = 1), finite, at most :data:`MAX_SAMPLES` rows;
    None when absent."""
    if key not in body or body[key] is None:
        return None
    return _array(body, key, size)


def _array(body: Mapping[str, Any], key: str, size: int) -> np.ndarray:
    """``body[key]`` as :func:`_optional` gives it, required."""
    if key not in body or body[key] is None:
        raise InvalidInputError(key, f"missing: give {size} numbers, or a list of such samples")
    a = as_array(body[key], key, f"numbers ({size} a sample)")  # (strings, booleans, ragged lists refused)
    if a.ndim == 1:
        a = a[None]
    if a.ndim != 2 or a.shape[1] != size:
        raise InvalidInputError(key, f"expected {size} numbers a sample, got shape {list(np.shape(body[key]))}")
    if len(a) > MAX_SAMPLES:
        raise InvalidInputError(key, f"more than {MAX_SAMPLES} samples in one request: send them in parts", len(a))
    if not np.all(np.isfinite(a)):
        bad = np.argwhere(~np.isfinite(a))[0]
        raise InvalidInputError(key, f"sample {bad[0]}, entry {bad[1]} is not finite")
    return a


def _same_length(**arrays: np.ndarray | None) -> int:
    lengths = {k: len(a) for k, a in arrays.items() if a is not None}
    n = max(lengths.values())
    for k, m in lengths.items():
        if m not in (1, n):
            raise InvalidInputError(k, f"{m} samples where the others have {n}")
    return n


def _row(a: np.ndarray, k: int) -> np.ndarray:
    return a[0] if len(a) == 1 else a[k]


def _error(e: PkmError) -> dict[str, Any]:
    return {"error": type(e).__name__, "message": str(e)}


def _each(n: int, fn: Callable[[int], dict[str, Any]]) -> list[dict[str, Any]]:
    """``fn(k)`` for every sample; a sample whose computation raises a PkmError is reported, not fatal."""
    out = []
    for k in range(n):
        try:
            out.append({"status": "ok", **fn(k)})
        except PkmError as e:
            out.append({"status": "failed", **_error(e)})
    return out


def _columns(rows: list[dict[str, Any]], keys: tuple[str, ...]) -> dict[str, Any]:
    """The per-sample dicts as columns (NaN where a sample failed)."""
    out: dict[str, Any] = {"status": [r["status"] for r in rows]}
    failures = [{"sample": k, "error": r["error"], "message": r["message"]} for k, r in enumerate(rows)
                if r["status"] != "ok"]
    if failures:
        out["failures"] = failures
    for key in keys:
        values = [r.get(key) for r in rows]
        shape = next((np.shape(v) for v in values if v is not None), ())
        out[key] = np.array([np.full(shape, np.nan) if v is None else np.asarray(v, dtype=float) for v in values])
    return out


def fk(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """Forward kinematics (the loop closure): ``qa`` (na per sample) -> ``q`` (nq), ``y`` (task value), the closure
    ``residual`` [m, rad]. Samples are solved in order, each from the previous one's solution (the first from
    ``seed``, default the reference): a stream of actuator values stays on one assembly mode."""
    from pkm.core.kinematics.solve import close_loops

    qa = _array(body, "qa", mech.na)
    seed = _optional(body, "seed", mech.nq)
    q = [mech.q_reference if seed is None else seed[0]]
    out: dict[str, Any] | None = None
    if kernels is not None and len(qa) > 1:
        try:  # (the compiled path, warm-started in C; any sample it cannot solve: the per-sample route below)
            path = kernels.close_loops_path(qa, q[0])
            out = {"status": ["ok"] * len(qa), "q": path.q,
                   "y": np.array([mech.task_map.value(x) for x in path.q]), "residual": path.residual,
                   "iterations": path.iterations.astype(float)}
        except PkmError:
            out = None
    if out is None:
        def one(k: int) -> dict[str, Any]:
            r = close_loops(mech, qa[k], q[0])
            q[0] = r.q
            return {"q": r.q, "y": mech.task_map.value(r.q), "residual": r.residual, "iterations": r.iterations}

        out = _columns(_each(len(qa), one), ("q", "y", "residual", "iterations"))
    out["units"] = {"y": _value_units(mech), "residual": "m or rad",
                    "qa": [_unit(mech, j) for j in mech.actuated_names]}
    return out


def ik(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """Inverse kinematics: ``y`` (task values, laid out as ``task_value_names``) -> ``q``, ``qa``, ``residual``;
    each sample from the previous one's solution (the first from ``seed``), in the working mode ``branch`` (a
    named branch of the spec) when given."""
    from pkm.core.kinematics.solve import solve_ik

    y = _array(body, "y", mech.task_map.value_size)
    seed = _optional(body, "seed", mech.nq)
    branch = body.get("branch")
    if branch is not None and not isinstance(branch, str):
        raise InvalidInputError("branch", "a branch name", branch)
    q = [mech.q_reference if seed is None else seed[0]]

    def one(k: int) -> dict[str, Any]:
        r = solve_ik(mech, y[k], q[0], branch=branch)
        q[0] = r.q
        return {"q": r.q, "qa": mech.actuated_q(r.q), "residual": r.residual, "iterations": r.iterations}

    out = _columns(_each(len(y), one), ("q", "qa", "residual", "iterations"))
    out["units"] = {"qa": [_unit(mech, j) for j in mech.actuated_names], "residual": "m or rad"}
    return out


def jacobians(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """At closed configurations ``q``: the forward Jacobian ``J`` (task rates per actuated rate) and the inverse
    ``K`` (actuated rates per task rate)."""
    from pkm.core.differential.velocity import forward_jacobian, inverse_jacobian

    q = _array(body, "q", mech.nq)
    out: dict[str, Any] | None = None
    if kernels is not None and len(q) > 1:
        try:
            out = {"status": ["ok"] * len(q), "J": kernels.forward_jacobian(q), "K": kernels.inverse_jacobian(q)}
        except PkmError:
            out = None
    if out is None:
        out = _columns(_each(len(q), lambda k: {"J": forward_jacobian(mech, q[k]),
                                                "K": inverse_jacobian(mech, q[k])}), ("J", "K"))
    out["units"] = {"rows": list(_task_units(mech).values()),
                    "columns": [_unit(mech, j) for j in mech.actuated_names]}
    return out


def diagnose(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """At closed configurations ``q``: the distances to the direct and inverse singularities and the closure
    residual (:func:`pkm.diagnose`)."""
    from pkm.core.differential.velocity import diagnose as run

    q = _array(body, "q", mech.nq)

    def one(k: int) -> dict[str, Any]:
        d = run(mech, q[k])
        return {"direct_distance": d.direct_distance, "inverse_distance": d.inverse_distance}

    return _columns(_each(len(q), one), ("direct_distance", "inverse_distance"))


def velocities(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """At closed configurations ``q`` and actuated rates ``qd``: every joint's rate ``v`` and the task rates ``yd``;
    with the actuated accelerations ``qdd`` too, every joint's acceleration ``a`` (the loops closed at the
    acceleration level) and the task accelerations ``ydd``."""
    from pkm.core.differential.velocity import accelerations, forward_jacobian, task_acceleration
    from pkm.core.differential.velocity import velocities as joint_rates

    q, qd = _array(body, "q", mech.nq), _array(body, "qd", mech.na)
    qdd = _optional(body, "qdd", mech.na)
    n = _same_length(q=q, qd=qd, qdd=qdd)

    def one(k: int) -> dict[str, Any]:
        qk, qdk = _row(q, k), _row(qd, k)
        v = joint_rates(mech, qk, qdk)
        out = {"v": v, "yd": forward_jacobian(mech, qk) @ qdk}
        if qdd is not None:
            a = accelerations(mech, qk, v, _row(qdd, k))
            out.update(a=a, ydd=task_acceleration(mech, qk, v, a))
        return out

    return _columns(_each(n, one), ("v", "yd") + (("a", "ydd") if qdd is not None else ()))


def dynamics(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """The actuator-space model at closed states ``(q, qd)``: ``M`` (``M_a``), ``h`` (``h_a``), ``g`` (``g_a``), and
    with ``qdd`` the inverse dynamics ``tau = M_a qdd + h_a`` [N m, N]."""
    from pkm.core.dynamics.model import actuator_model

    q = _array(body, "q", mech.nq)
    qd = _optional(body, "qd", mech.na)
    qdd = _optional(body, "qdd", mech.na)
    n = _same_length(q=q, qd=qd, qdd=qdd)

    def one(k: int) -> dict[str, Any]:
        m = actuator_model(mech, _row(q, k), None if qd is None else _row(qd, k))
        out = {"M": m.M, "h": m.h, "g": m.g}
        if qdd is not None:
            out["tau"] = m.M @ _row(qdd, k) + m.h
        return out

    out: dict[str, Any] | None = None
    if kernels is not None and n > 1:
        try:  # (the compiled model in batches)
            Q = np.broadcast_to(q, (n, mech.nq)) if len(q) == 1 else q
            QD = np.zeros((n, mech.na)) if qd is None else np.broadcast_to(qd, (n, mech.na))
            M, h = kernels.mass_and_bias(np.ascontiguousarray(Q), np.ascontiguousarray(QD))
            out = {"status": ["ok"] * n, "M": M, "h": h, "g": kernels.gravity(np.ascontiguousarray(Q))}
            if qdd is not None:
                out["tau"] = np.einsum("kij,kj->ki", M, np.broadcast_to(qdd, (n, mech.na))) + h
        except PkmError:
            out = None
    if out is None:
        out = _columns(_each(n, one), ("M", "h", "g") + (("tau",) if qdd is not None else ()))
    out["units"] = {"tau": [_unit(mech, j, "effort") for j in mech.actuated_names]}
    return out


def capability(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """At closed configurations ``q``, the ``kind`` capability (``wrench``, ``twist``, ``acceleration``) under the
    actuators' limits: the largest value along each task axis each way, the largest isotropic value per unit, the
    polytope's vertices (:func:`pkm.capability`), ``origin_inside`` (1, or 0 where the actuators cannot hold the
    weight: the indices are then 0)."""
    from pkm.core.analysis.capability import KINDS
    from pkm.core.analysis.capability import capability as run

    q = _array(body, "q", mech.nq)
    kind = body.get("kind", "wrench")
    if kind not in KINDS:
        raise InvalidInputError("kind", f"one of {list(KINDS)}", kind)

    def one(k: int) -> dict[str, Any]:
        c = run(mech, q[k], kind)
        return {"along": np.array(list(c.along.values())), "vertices": c.polytope.vertices,
                "isotropic": np.array(list(c.isotropic.values())), "origin_inside": float(c.origin_inside)}

    out = _columns(_each(len(q), one), ("along", "vertices", "isotropic", "origin_inside"))
    c0 = run(mech, mech.q_reference, kind) if len(q) else None
    if c0 is not None:
        out["axes"] = list(c0.polytope.axes)
        out["units"] = {"along": list(c0.polytope.units), "isotropic": list(c0.isotropic)}
    return out


_SCENES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def scene(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """At configurations ``q``: the world placement of every body of the model's 3-D scene (the preview page's,
    :class:`pkm.viz.scene.Scene`), as ``paths`` (meshcat paths) and ``matrices`` (per sample and body, 16 numbers
    column-major, as meshcat's ``set_transform`` takes them)."""
    from pkm.viz.scene import Scene

    q = _array(body, "q", mech.nq)
    if mech not in _SCENES:
        _SCENES[mech] = Scene.from_mechanism(mech)
    sc = _SCENES[mech]
    paths = [b.path for b in sc.bodies]
    matrices = []
    for k in range(len(q)):
        placed = sc.transforms(mech.check_q(q[k]))
        matrices.append([np.asarray(placed[p]).T.ravel() for p in paths])
    return {"paths": paths, "matrices": np.array(matrices)}


#: The queries by name (the endpoints ``POST /models/{model}/{name}``).
QUERIES: dict[str, Callable[[Mechanism, Mapping[str, Any], Any], dict[str, Any]]] = {
    "fk": fk, "ik": ik, "jacobians": jacobians, "diagnose": diagnose, "velocities": velocities,
    "dynamics": dynamics, "capability": capability, "scene": scene}


def describe(mech: Mechanism) -> dict[str, Any]:
    """What a client needs to ask about ``mech``: its sizes, joint, actuator and task names with their units, the
    reference configuration, the branches."""
    return {"name": mech.name, "nq": mech.nq, "nv": mech.nv, "na": mech.na,
            "joints": list(mech.joints), "actuated": list(mech.actuated_names),
            "actuated_q": [int(i) for i in mech.act_q],
            "actuated_units": [_unit(mech, j) for j in mech.actuated_names],
            "task": list(mech.task_map.keys), "task_units": _task_units(mech),
            "task_value_names": list(mech.task_map.value_names), "task_value_units": _value_units(mech),
            "q_reference": mech.q_reference,
            "branches": list(mech.spec.branches), "limits": mech.limits}


__all__ = ["MAX_SAMPLES", "QUERIES", "describe"]
