"""The questions the service answers about a model: each a function ``(mech, body, kernels) -> answer`` over one sample
or a batch (every array input given as one sample, or as a list of samples of the same length). Batches of the
forward kinematics, the Jacobians and the dynamic model run through the model's compiled kernels (``kernels``, a
:class:`pkm.Kernels`, where they build; the same answers to 1e-12) and fall back to the library's Python route, sample
by sample, where the kernels refuse a sample.

Inputs follow the Python API's and the CLI's conventions: positions (``qa``, ``q``, ``y``, ``seed``) and rates
(``qd``) are numbers in SI or strings with a unit of their kind (``"10deg"``, ``"5mm"``; ``"-30deg/s"``, ``"300rpm"``:
:mod:`pkm.units`, each entry by its column's unit, :func:`_input_units`), accelerations (``qdd``) numbers; where a
configuration is asked, either the full ``q`` or the actuated ``qa`` (the loops then closed from ``seed``, default
the reference, each sample from the previous one's solution), exactly one of the two. Inputs are checked by pkm's own validation: a bad one is a
:class:`~pkm.errors.PkmError` naming the field, which the service answers with 422.

Every answer carries ``units`` for every quantity it returns (SI: ``m``, ``rad``, ``N``, ``N m``, per coordinate;
a matrix's per entry) and what certifies it: the status of each sample (``"ok"``, ``"outside_limits"`` or
``"failed"``), ``outside_limits`` (per sample, the joints outside the position limits the model states, each with
its value and limits: pkm's solvers report limits, they do not enforce them) and, where some failed, ``failures``
(each one's sample, error and message). A failed sample's values are ``None`` (JSON ``null``), the
batch keeps its length; a query given ONE sample (not a list of samples) whose sample fails raises that sample's
:class:`~pkm.errors.PkmError` instead (the service's 4xx). Counts (``iterations``) are integers.
"""

from __future__ import annotations

import functools
import weakref
from collections.abc import Callable, Mapping, Sequence
from typing import Any, TypeVar

import numpy as np

import pkm
from pkm.core.kinematics import constraints
from pkm.core.model.mechanism import Mechanism
from pkm.errors import InvalidInputError, PkmError
from pkm.units import KIND_OF_UNIT, joint_unit, parse_quantity
from pkm.validation import as_array, bounded

#: Samples in one request at most.
MAX_SAMPLES = 100_000

_F = TypeVar("_F", bound=Callable[..., Any])


def _per_mechanism(fn: _F) -> _F:
    """``fn(mech, *args)`` computed once per mechanism and arguments (units and names: asked on every request)."""
    cache: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

    @functools.wraps(fn)
    def cached(mech: Mechanism, *args: Any) -> Any:
        per = cache.setdefault(mech, {})
        if args not in per:
            per[args] = fn(mech, *args)
        return per[args]

    return cached  # type: ignore[return-value]


def _unit(mech: Mechanism, joint: str, kind: str = "position") -> str:
    return joint_unit(mech.joints[joint].revolute, kind)


@_per_mechanism
def _task_units(mech: Mechanism) -> dict[str, str]:
    """The units of the task's tangent coordinates (:attr:`TaskMap.keys`: a pose's x y z roll pitch yaw)."""
    task = pkm.TaskMap.of(mech)
    kinds = task.kinds
    out = {k: ("m" if kinds.get(k) == "length" else "rad") for k in task.keys}
    return out


@_per_mechanism
def _value_units(mech: Mechanism) -> list[str]:
    """The units of the task value's entries (:attr:`TaskMap.value_names`: a pose's x y z qx qy qz qw, whose
    quaternion is unitless, ``"1"``)."""
    task = pkm.TaskMap.of(mech)
    return [("m" if task.kinds[k] == "length" else "rad") if k in task.kinds else "1" for k in task.value_names]


def _joint_units(mech: Mechanism, which: int) -> list[str]:
    """The unit letters of every coordinate of ``q`` (``which`` 0) or ``v`` (1): ``m`` (a length: the leading
    entries :func:`~pkm.core.model.scale.length_entries` counts), ``r`` (an angle: a bounded revolute's coordinate,
    every other velocity entry), ``1`` (unitless: a quaternion's entries, an unbounded revolute's cosine and sine)."""
    from pkm.core.model.scale import length_entries

    out = ["1" if which == 0 else "r"] * (mech.nq if which == 0 else mech.nv)
    for j in mech.joints.values():
        at, n = (j.idx_q, j.nq) if which == 0 else (j.idx_v, j.nv)
        lengths = min(length_entries(j.kind), n)
        out[at:at + n] = ["m"] * lengths + ["r" if which == 1 or j.revolute else "1"] * (n - lengths)
    return out


@_per_mechanism
def _q_units(mech: Mechanism) -> list[str]:
    """The unit of every coordinate of ``q``: ``rad`` (a revolute joint), ``m`` (a prismatic one, a free-flyer's
    position), ``1`` (a quaternion's entries, an unbounded revolute's cosine and sine)."""
    return [{"m": "m", "r": "rad"}.get(u, "1") for u in _joint_units(mech, 0)]


@_per_mechanism
def _v_units(mech: Mechanism, order: int = 1) -> list[str]:
    """The unit of every coordinate of the velocity ``v`` (``order`` 1) or acceleration (2)."""
    per = "/s" if order == 1 else "/s^2"
    return [("m" if u == "m" else "rad") + per for u in _joint_units(mech, 1)]


def _per(a: str, b: str) -> str:
    """The unit of a ratio: ``1`` where the two are the same, ``a/b`` else (``b`` in parentheses when composite)."""
    if a == b:
        return "1"
    return f"{a}/({b})" if " " in b or "/" in b else f"{a}/{b}"


def _matrix_units(rows: Sequence[str], columns: Sequence[str]) -> list[list[str]]:
    """Every entry's unit of a matrix mapping ``columns`` quantities to ``rows`` ones."""
    return [[_per(r, c) for c in columns] for r in rows]


def _rates(units: Sequence[str], per: str = "/s") -> list[str]:
    return [u + per for u in units]


#: The order (:data:`pkm.units.JOINT_UNITS`) of each actuated input.
_ACTUATED = {"qa": "position", "qd": "rate", "qdd": "acceleration", "tau": "effort"}


@_per_mechanism
def _input_units(mech: Mechanism, what: str) -> tuple[str, ...]:
    """The unit of every entry of the input ``what``: ``q``, ``y`` (positions), ``qa``, ``qd``, ``qdd``, ``tau``
    (the actuated positions, rates, accelerations, efforts); a string entry takes a suffix of its unit's kind."""
    if what in _ACTUATED:
        return tuple(_actuated_units(mech, _ACTUATED[what]))
    return tuple({"q": _q_units, "y": _value_units}[what](mech))


def _kinds(units: Sequence[str]) -> list[str | None]:
    """The :mod:`pkm.units` kind of each unit (``m`` -> length, ``rad`` -> angle), None where a unit string cannot
    be given (a unitless entry: a plain number only)."""
    return [KIND_OF_UNIT.get(u) for u in units]


def _with_units(raw: Any, key: str, units: Sequence[str]) -> Any:
    """``raw`` (one sample or a list of samples) with every string entry converted to SI by its column's unit (a
    suffix of its kind, :func:`pkm.units.parse_quantity`; a unit without suffixes, ``rad/s^2``: a plain number)."""
    kinds = _kinds(units)

    def convert(sample: Any, where: str) -> Any:
        if not isinstance(sample, (list, tuple)):
            return sample
        out = []
        for i, v in enumerate(sample):
            if isinstance(v, str):
                kind = kinds[i] if i < len(kinds) else None
                unit = units[i] if i < len(units) and units[i] != "1" else "a plain number"
                v = parse_quantity(v, set() if kind is None else {kind}, f"{where}[{i}]", unit)
            out.append(v)
        return out

    if isinstance(raw, (list, tuple)) and raw and isinstance(raw[0], (list, tuple)):
        return [convert(s, f"{key}[{k}]") for k, s in enumerate(raw)]
    return convert(raw, key)


def _has_string(raw: Any) -> bool:
    if isinstance(raw, str):
        return True
    if isinstance(raw, np.ndarray):
        return raw.dtype.kind in "UO" and _has_string(raw.tolist())
    if isinstance(raw, (list, tuple)):
        return any(_has_string(v) for v in raw)
    return False


def _optional(body: Mapping[str, Any], key: str, size: int, units: Sequence[str]) -> np.ndarray | None:
    """``body[key]`` as an (n, size) array (a single sample as n = 1), finite, at most :data:`MAX_SAMPLES` rows;
    None when absent. ``units`` (one per column, :func:`_input_units`): an entry may be a string with a unit of
    its column's kind (``"10deg"``, ``"-30deg/s"``, ``"2 N m"``: :func:`pkm.units.parse_quantity`)."""
    if key not in body or body[key] is None:
        return None
    return _array(body, key, size, units)


def _array(body: Mapping[str, Any], key: str, size: int, units: Sequence[str]) -> np.ndarray:
    """``body[key]`` as :func:`_optional` gives it, required."""
    what = f"{size} numbers a sample [{', '.join(units)}] or strings with a unit ('10deg', '-30deg/s')"
    if key not in body or body[key] is None:
        raise InvalidInputError(key, f"missing: give {what}, or a list of such samples")
    raw = body[key]
    if isinstance(raw, np.ndarray) and raw.dtype.kind in "UO":
        raw = raw.tolist()
    try:  # (numbers first: a batch of plain numbers is not walked in Python for strings)
        a = as_array(raw, key, what)  # (strings, booleans, ragged lists refused)
    except InvalidInputError:
        if not _has_string(raw):
            raise
        a = as_array(_with_units(raw, key, units), key, what)  # (a unit string: pkm.units)
    if a.ndim == 1:
        a = a[None]
    if a.ndim != 2 or a.shape[1] != size:
        raise InvalidInputError(key, f"expected {what}, got shape {list(np.shape(raw))}")
    if len(a) > MAX_SAMPLES:
        raise InvalidInputError(key, f"more than {MAX_SAMPLES} samples in one request: send them in parts", len(a))
    if not np.all(np.isfinite(a)):
        bad = np.argwhere(~np.isfinite(a))[0]
        raise InvalidInputError(key, f"sample {bad[0]}, entry {bad[1]} is not finite")
    positions = all(u in ("m", "rad", "1") for u in units)
    return bounded(a, key) if positions else a  # (positions: the library's bound, beyond it refused)


def _is_single(body: Mapping[str, Any], *keys: str) -> bool:
    """Whether every array input among ``keys`` that is given is ONE sample (a flat list), not a list of samples."""
    for key in keys:
        v = body.get(key)
        if v is None:
            continue
        if isinstance(v, np.ndarray):
            if v.ndim != 1:
                return False
        elif isinstance(v, (list, tuple)) and v and isinstance(v[0], (list, tuple, np.ndarray)):
            return False
    return True


def _seed(mech: Mechanism, body: Mapping[str, Any]) -> np.ndarray:
    """The configuration the first sample is solved from: ``seed`` (nq, one sample), default the reference."""
    seed = _optional(body, "seed", mech.nq, _input_units(mech, "q"))
    if seed is not None and len(seed) != 1:
        raise InvalidInputError("seed", f"one configuration ({mech.nq} numbers), not {len(seed)}")
    return mech.q_reference if seed is None else seed[0]


def _same_length(**arrays: np.ndarray | None) -> int:
    lengths = {k: len(a) for k, a in arrays.items() if a is not None}
    n = max(lengths.values())
    for k, m in lengths.items():
        if m not in (1, n):
            raise InvalidInputError(k, f"{m} samples where the others have {n}")
    return n


def _row(a: np.ndarray, k: int) -> np.ndarray:
    return a[0] if len(a) == 1 else a[k]


class _Samples:
    """A batch's per-sample outcome: ``errors[k]`` (None where sample k is fine), and the answer's columns."""

    def __init__(self, n: int, single: bool, errors: list[PkmError | None] | None = None):
        self.n, self.single = n, single
        self.errors: list[PkmError | None] = [None] * n if errors is None else errors

    def each(self, fn: Callable[[int], dict[str, Any]], keys: tuple[str, ...]) -> dict[str, Any]:
        """``fn(k)`` for every sample not failed yet; a sample whose computation raises a PkmError is marked failed;
        the answer's columns (see :meth:`columns`)."""
        rows: list[dict[str, Any] | None] = []
        for k in range(self.n):
            if self.errors[k] is not None:
                rows.append(None)
                continue
            try:
                rows.append(fn(k))
            except PkmError as e:
                self.errors[k] = e
                rows.append(None)
        return self.columns({key: [None if r is None else r[key] for r in rows] for key in keys})

    def columns(self, values: Mapping[str, Any]) -> dict[str, Any]:
        """``values`` (each a full array, or a list per sample) with ``status`` and, where samples failed,
        ``failures`` and ``None`` for their values; one sample given alone that failed raises its error."""
        failed = [k for k, e in enumerate(self.errors) if e is not None]
        if self.single and failed:
            raise self.errors[failed[0]]  # type: ignore[misc]
        out: dict[str, Any] = {"status": ["failed" if e is not None else "ok" for e in self.errors]}
        if failed:
            out["failures"] = [{"sample": k, "error": type(e).__name__, "message": str(e)}
                               for k, e in enumerate(self.errors) if e is not None]
        bad = set(failed)
        for key, column in values.items():
            if not bad and (isinstance(column, np.ndarray) or all(v is not None for v in column)):
                out[key] = np.asarray(column) if not isinstance(column, np.ndarray) else column
            else:
                out[key] = [None if k in bad else _value(column[k]) for k in range(self.n)]
        return out


def _limits(fn: _F) -> _F:
    """``fn``'s answer with, per sample, ``outside_limits`` (its ``q``'s
    :meth:`~pkm.core.Mechanism.limit_violations`, as maps ``joint``, ``value``, ``limit``; None for a failed sample) and the status ``"outside_limits"`` where that is not empty: pkm's solvers report limits, they do not
    enforce them, and an answer outside them is not plain ``"ok"``."""
    @functools.wraps(fn)
    def answer(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
        out = fn(mech, body, kernels)
        status, q = out["status"], out["q"]
        outside: list[list[dict[str, Any]] | None] = [None if st != "ok" else [] for st in status]
        named = [n for n in mech.limits if n in mech.joints]
        if named:
            ok = [k for k, st in enumerate(status) if st == "ok"]
            Q = np.array([q[k] for k in ok], dtype=float).reshape(len(ok), mech.nq)
            idx = [mech.joints[n].idx_q for n in named]
            lo, hi = np.array([mech.limits[n] for n in named]).T
            near = np.flatnonzero(np.any((Q[:, idx] < lo) | (Q[:, idx] > hi), axis=1))  # (then with the tolerance)
            for i in near:
                k = ok[int(i)]
                outside[k] = [v._asdict() for v in mech.limit_violations(Q[i])]
                if outside[k]:
                    status[k] = "outside_limits"
        out["outside_limits"] = outside
        out["units"]["outside_limits"] = "m or rad (each joint's, as in q)"
        return out

    return answer  # type: ignore[return-value]


def _value(v: Any) -> Any:
    """One sample's value: an array as a numpy array, a number as a plain Python one."""
    if v is None or isinstance(v, (bool, int, float)):
        return v
    a = np.asarray(v)
    return a.item() if a.ndim == 0 else a


def _close(mech: Mechanism, qa: np.ndarray, q0: np.ndarray, kernels: Any
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[PkmError | None]]:
    """The loops closed at every actuated sample ``qa``, each from the previous one's solution (the first from
    ``q0``): ``q`` (NaN rows where a sample failed), ``residual`` [m, rad], ``iterations`` (integers) and the errors.
    A batch runs through the compiled kernels first; any sample they cannot solve sends it to the Python route."""
    from pkm.core.kinematics.solve import close_loops

    n = len(qa)
    if kernels is not None and n > 1:
        try:  # (the compiled path, warm-started in C; any sample it cannot solve: the per-sample route below)
            path = kernels.close_loops_path(qa, q0)  # (its residual counts lengths in L: the m and rad reported)
            return (np.asarray(path.q), constraints.largest(mech, np.asarray(path.q)),
                    np.asarray(path.iterations).astype(np.int64), [None] * n)
        except PkmError:
            pass
    Q, residual = np.full((n, mech.nq), np.nan), np.full(n, np.nan)
    iterations = np.zeros(n, dtype=np.int64)
    errors: list[PkmError | None] = [None] * n
    previous = q0
    for k in range(n):
        try:
            r = close_loops(mech, qa[k], previous)
        except PkmError as e:
            errors[k] = e
            continue
        previous = Q[k] = r.q
        residual[k], iterations[k] = r.residual, r.iterations
    return Q, residual, iterations, errors


def _configurations(mech: Mechanism, body: Mapping[str, Any], kernels: Any, *others: str
                    ) -> tuple[np.ndarray, _Samples]:
    """The closed configurations asked: ``q`` as given, or ``qa`` with the loops closed (see the module doc); with
    the samples' outcome (a sample whose loops do not close has failed). ``others``: the other array inputs, for
    whether one sample was given."""
    has_q, has_qa = body.get("q") is not None, body.get("qa") is not None
    if has_q == has_qa:
        raise InvalidInputError("q, qa", f"give exactly one of q (the {mech.nq} coordinates of a closed "
                                         f"configuration) and qa (the {mech.na} actuated values: the loops are then "
                                         "closed from seed, default the reference)")
    single = _is_single(body, "q" if has_q else "qa", *others)
    if has_q:
        q = _array(body, "q", mech.nq, _input_units(mech, "q"))
        return q, _Samples(len(q), single)
    qa = _array(body, "qa", mech.na, _input_units(mech, "qa"))
    q, _, _, errors = _close(mech, qa, _seed(mech, body), kernels)
    return q, _Samples(len(q), single, errors)


@_per_mechanism
def _actuated_units(mech: Mechanism, kind: str = "position") -> list[str]:
    return [_unit(mech, j, kind) for j in mech.actuated_names]


@_limits
def fk(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """Forward kinematics (the loop closure): ``qa`` (na per sample) -> ``q`` (nq), ``y`` (task value), the closure
    ``residual`` [m, rad], the Newton ``iterations``. Samples are solved in order, each from the previous one's
    solution (the first from ``seed``, default the reference): a stream of actuator values stays on one assembly
    mode."""
    qa = _array(body, "qa", mech.na, _input_units(mech, "qa"))
    Q, residual, iterations, errors = _close(mech, qa, _seed(mech, body), kernels)
    samples = _Samples(len(qa), _is_single(body, "qa"), errors)
    task = pkm.TaskMap.of(mech)
    Y = [None if e is not None else task.value(Q[k]) for k, e in enumerate(errors)]
    out = samples.columns({"q": Q, "y": Y, "residual": residual, "iterations": iterations})
    out["units"] = {"q": _q_units(mech), "y": _value_units(mech), "residual": "m or rad", "iterations": "1",
                    "qa": _actuated_units(mech)}
    return out


@_limits
def ik(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """Inverse kinematics: ``y`` (task values, laid out as ``task_value_names``) -> ``q``, ``qa``, ``residual``,
    ``iterations``; each sample from the previous one's solution (the first from ``seed``), in the working mode
    ``branch`` (a named branch of the spec) when given."""
    from pkm.core.kinematics.solve import solve_ik

    y = _array(body, "y", pkm.TaskMap.of(mech).value_size, _input_units(mech, "y"))
    seed = _seed(mech, body)
    branch = body.get("branch")
    if branch is not None and not isinstance(branch, str):
        raise InvalidInputError("branch", "a branch name", branch)
    q = [seed]

    def one(k: int) -> dict[str, Any]:
        r = solve_ik(mech, y[k], q[0], branch=branch)
        q[0] = r.q
        return {"q": r.q, "qa": mech.actuated_q(r.q), "residual": r.residual, "iterations": int(r.iterations)}

    out = _Samples(len(y), _is_single(body, "y")).each(one, ("q", "qa", "residual", "iterations"))
    out["units"] = {"q": _q_units(mech), "qa": _actuated_units(mech), "residual": "m or rad", "iterations": "1",
                    "y": _value_units(mech)}
    return out


@_per_mechanism
def _jacobian_units(mech: Mechanism) -> dict[str, Any]:
    task, act = list(_task_units(mech).values()), _actuated_units(mech)
    return {"J": _matrix_units(task, act), "K": _matrix_units(act, task), "q": _q_units(mech)}


@_limits
def jacobians(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """At closed configurations (``q``, or ``qa`` closed): the forward Jacobian ``J`` (task rates per actuated rate)
    and the inverse ``K`` (actuated rates per task rate), with ``q``."""
    from pkm.core.differential.velocity import forward_jacobian, inverse_jacobian

    q, samples = _configurations(mech, body, kernels)
    out: dict[str, Any] | None = None
    if kernels is not None and len(q) > 1 and not any(samples.errors):
        try:
            out = samples.columns({"q": q, "J": kernels.forward_jacobian(q), "K": kernels.inverse_jacobian(q)})
        except PkmError:
            out = None
    if out is None:
        out = samples.each(lambda k: {"q": q[k], "J": forward_jacobian(mech, q[k]), "K": inverse_jacobian(mech, q[k])},
                           ("q", "J", "K"))
    out["units"] = _jacobian_units(mech)
    return out


@_limits
def diagnose(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """At closed configurations (``q``, or ``qa`` closed): the distances to the direct and inverse singularities
    (:func:`pkm.diagnose`: smallest over largest singular value of the homogenised Jacobians, in [0, 1]), with
    ``q``."""
    from pkm.core.differential.velocity import diagnose as run

    q, samples = _configurations(mech, body, kernels)

    def one(k: int) -> dict[str, Any]:
        d = run(mech, q[k])
        return {"q": q[k], "direct_distance": d.direct_distance, "inverse_distance": d.inverse_distance}

    out = samples.each(one, ("q", "direct_distance", "inverse_distance"))
    out["units"] = {"q": _q_units(mech), "direct_distance": "1", "inverse_distance": "1"}
    return out


@_limits
def velocities(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """At closed configurations (``q``, or ``qa`` closed) and actuated rates ``qd``: every joint's rate ``v`` and the
    task rates ``yd``; with the actuated accelerations ``qdd`` too, every joint's acceleration ``a`` (the loops closed
    at the acceleration level) and the task accelerations ``ydd``."""
    from pkm.core.differential.velocity import accelerations, forward_jacobian, task_acceleration
    from pkm.core.differential.velocity import velocities as joint_rates

    q, configured = _configurations(mech, body, kernels, "qd", "qdd")
    qd = _array(body, "qd", mech.na, _input_units(mech, "qd"))
    qdd = _optional(body, "qdd", mech.na, _input_units(mech, "qdd"))
    n = _same_length(q=q, qd=qd, qdd=qdd)
    samples = _Samples(n, configured.single, [configured.errors[0 if len(q) == 1 else k] for k in range(n)])

    def one(k: int) -> dict[str, Any]:
        qk, qdk = _row(q, k), _row(qd, k)
        v = joint_rates(mech, qk, qdk)
        out = {"q": qk, "v": v, "yd": forward_jacobian(mech, qk) @ qdk}
        if qdd is not None:
            a = accelerations(mech, qk, v, _row(qdd, k))
            out.update(a=a, ydd=task_acceleration(mech, qk, v, a))
        return out

    out = samples.each(one, ("q", "v", "yd") + (("a", "ydd") if qdd is not None else ()))
    task = list(_task_units(mech).values())
    out["units"] = {"q": _q_units(mech), "v": _v_units(mech), "yd": _rates(task), "qd": _actuated_units(mech, "rate"),
                    "a": _v_units(mech, 2), "ydd": _rates(task, "/s^2"), "qdd": _actuated_units(mech, "acceleration")}
    return out


@_limits
def dynamics(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """The actuator-space model at closed states (``q``, or ``qa`` closed; ``qd``, default 0): ``M`` (``M_a``),
    ``h`` (``h_a``), ``g`` (``g_a``), and with ``qdd`` the inverse dynamics ``tau = M_a qdd + h_a`` [N m, N]."""
    from pkm.core.dynamics.model import actuator_model

    q, configured = _configurations(mech, body, kernels, "qd", "qdd")
    qd = _optional(body, "qd", mech.na, _input_units(mech, "qd"))
    qdd = _optional(body, "qdd", mech.na, _input_units(mech, "qdd"))
    n = _same_length(q=q, qd=qd, qdd=qdd)
    samples = _Samples(n, configured.single, [configured.errors[0 if len(q) == 1 else k] for k in range(n)])
    keys = ("q", "M", "h", "g") + (("tau",) if qdd is not None else ())

    def one(k: int) -> dict[str, Any]:
        m = actuator_model(mech, _row(q, k), None if qd is None else _row(qd, k))
        out = {"q": _row(q, k), "M": m.M, "h": m.h, "g": m.g}
        if qdd is not None:
            out["tau"] = m.M @ _row(qdd, k) + m.h
        return out

    out: dict[str, Any] | None = None
    # (the compiled model in batches; not for a floating base, which the model lets move free and the kernels hold)
    if kernels is not None and n > 1 and not any(samples.errors) and mech.base is None:
        try:
            Q = np.ascontiguousarray(np.broadcast_to(q, (n, mech.nq)))
            QD = np.zeros((n, mech.na)) if qd is None else np.ascontiguousarray(np.broadcast_to(qd, (n, mech.na)))
            M, h = kernels.mass_and_bias(Q, QD)
            values = {"q": Q, "M": M, "h": h, "g": kernels.gravity(Q)}
            if qdd is not None:
                values["tau"] = np.einsum("kij,kj->ki", M, np.broadcast_to(qdd, (n, mech.na))) + h
            out = samples.columns(values)
        except PkmError:
            out = None
    if out is None:
        out = samples.each(one, keys)
    effort, acc = _actuated_units(mech, "effort"), _actuated_units(mech, "acceleration")
    out["units"] = {"q": _q_units(mech), "M": _matrix_units(effort, acc), "h": effort, "g": effort, "tau": effort,
                    "qd": _actuated_units(mech, "rate"), "qdd": acc}
    return out


@_limits
def capability(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """At closed configurations (``q``, or ``qa`` closed), the ``kind`` capability (``wrench``, ``twist``,
    ``acceleration``) under the actuators' limits: the largest value along each task axis each way, the largest
    isotropic value per unit, the polytope's vertices (:func:`pkm.capability`), ``origin_inside`` (false where the
    actuators cannot hold the weight: the indices are then 0)."""
    from pkm.core.analysis.capability import KINDS
    from pkm.core.analysis.capability import capability as run

    kind = body.get("kind", "wrench")
    if kind not in KINDS:
        raise InvalidInputError("kind", f"one of {list(KINDS)}", kind)
    q, samples = _configurations(mech, body, kernels)

    def one(k: int) -> dict[str, Any]:
        c = run(mech, q[k], kind)
        return {"q": q[k], "along": np.array(list(c.along.values())), "vertices": c.polytope.vertices,
                "isotropic": np.array(list(c.isotropic.values())), "origin_inside": bool(c.origin_inside)}

    out = samples.each(one, ("q", "along", "vertices", "isotropic", "origin_inside"))
    axes, units, isotropic = _capability_labels(mech, kind)
    out["kind"] = kind
    out["axes"] = list(axes)
    out["units"] = {"q": _q_units(mech), "along": list(units), "vertices": list(units), "isotropic": list(isotropic),
                    "origin_inside": "1"}
    return out


@_per_mechanism
def _capability_labels(mech: Mechanism, kind: str) -> tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]:
    """The ``kind`` capability's axes, their units and its isotropic values' units (the same at every
    configuration: read once per mechanism, at the reference)."""
    from pkm.core.analysis.capability import capability as run

    c0 = run(mech, mech.q_reference, kind)
    return tuple(c0.polytope.axes), tuple(c0.polytope.units), tuple(c0.isotropic)


@_limits
def stiffness(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """At closed configurations (``q``, or ``qa`` closed), the end effector's compliance with the joints' springs
    (``springs`` by name, ``drives`` for every actuated joint not named; the others held rigid or free:
    :func:`pkm.stiffness`), its rank, its principal compliances under a pure force and a pure moment with their
    directions, and with ``wrench`` the exact and the first-order deflection and the tangent stiffness's compliance
    there (:meth:`Stiffness.loaded <pkm.core.compliance.stiffness.Stiffness.loaded>`). ``links``: ``"spec"``
    (default: the spec's ``[links]`` compliances), ``"rigid"``, ``"steel"``, ``"aluminium"`` or ``{"E": Pa, "G": Pa}``:
    the links as beams of their collision cylinders and capsules, the compliant links and those taken rigid said."""
    from pkm.core.compliance import stiffness as run
    from pkm.core.compliance.links import as_links, law_fields
    from pkm.validation import as_scalar

    joints: dict[str, Any] = {}
    if body.get("drives") is not None:
        joints = dict.fromkeys(mech.actuated_names, as_scalar(body["drives"], "drives", low=0.0))
    springs = body.get("springs")
    if springs is not None:
        if not isinstance(springs, Mapping):
            raise InvalidInputError("springs", "a mapping {joint: stiffness} [N m/rad, N/m]", springs)
        joints.update(springs)
    wrench = body.get("wrench")
    links = as_links(body.get("links"))
    q, samples = _configurations(mech, body, kernels)
    sprung: dict[str, float] = {}
    sources: dict[str, str] = {}
    compliant: dict[str, Any] = {}
    rigid: dict[str, str] = {}

    def one(k: int) -> dict[str, Any]:
        K = run(mech, q[k], joints=joints, links=links)
        sprung.update(K.sprung)  # (the same at every sample: the request's, the drives' and the spec's springs)
        sources.update(K.sources)
        compliant.update({n: law_fields(v) for n, v in K.links.items()})
        rigid.update(K.rigid_links)
        out = {"q": q[k], "compliance": K.compliance, "rank": K.rank}
        for load in ("force", "moment"):  # (the principal stiffnesses' reciprocals: 0 along a rigid direction)
            principal, U = K.principal(load)
            out[f"{load}_compliance"], out[f"{load}_directions"] = 1.0 / principal, U.T
        if wrench is not None:
            loaded = K.loaded(wrench)
            d = loaded.deflection
            out.update(displacement=d.displacement, first_order=d.first_order, gap=d.gap,
                       loaded_compliance=loaded.compliance)
        return out

    keys = ("q", "compliance", "rank", "force_compliance", "force_directions", "moment_compliance",
            "moment_directions") + (("displacement", "first_order", "gap", "loaded_compliance")
                                    if wrench is not None else ())
    out = samples.each(one, keys)
    out["sprung"], out["sources"], out["links"], out["rigid_links"] = sprung, sources, compliant, rigid
    out["units"] = {"q": _q_units(mech), "compliance": [["m/N"] * 3 + ["m/(N m)"] * 3] * 3
                    + [["rad/N"] * 3 + ["rad/(N m)"] * 3] * 3, "rank": "1", "force_compliance": "m/N",
                    "force_directions": "1", "moment_compliance": "rad/(N m)", "moment_directions": "1",
                    "displacement": ["m"] * 3 + ["rad"] * 3, "first_order": ["m"] * 3 + ["rad"] * 3, "gap": "1",
                    "sprung": "N m/rad (revolute), N/m (prismatic)", "sources": "1",
                    "loaded_compliance": [["m/N"] * 3 + ["m/(N m)"] * 3] * 3 + [["rad/N"] * 3 + ["rad/(N m)"] * 3] * 3,
                    "links": "m (radius, inner), Pa (E, G); a 6 x 6 compliance as compliance's", "rigid_links": "1"}
    return out


@_limits
def clearance(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """At closed configurations (``q``, or ``qa`` closed), the signed distances between the bodies whose collision
    geometry the model's files carry (:func:`pkm.clearance`; negative: interpenetrating), in the order of ``pairs``,
    the smallest, the index of its pair, whether bodies interfere, and the derivative of the smallest distance by the
    actuated coordinates (None at a direct singularity). A model whose files carry no collision geometry is refused
    (422, ``NoCollisionGeometryError``, saying how to add it)."""
    from pkm.core.collision import CollisionModel
    from pkm.core.collision import clearance as run
    from pkm.errors import SingularityError

    cm = CollisionModel.of(mech).require()
    q, samples = _configurations(mech, body, kernels)

    def one(k: int) -> dict[str, Any]:
        c = run(mech, q[k])
        try:
            gradient: np.ndarray | None = c.gradient
        except SingularityError:
            gradient = None
        return {"q": q[k], "distances": np.array([c.pairs[p] for p in cm.pairs]), "minimum": c.minimum,
                "closest": cm.pairs.index(c.closest), "interferes": c.interferes, "gradient": gradient}

    out = samples.each(one, ("q", "distances", "minimum", "closest", "interferes", "gradient"))
    out["pairs"] = [list(p) for p in cm.pairs]
    out["units"] = {"q": _q_units(mech), "distances": "m", "minimum": "m", "closest": "1", "interferes": "1",
                    "gradient": [f"m/{u}" for u in _actuated_units(mech)]}
    return out


_SCENES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@_limits
def scene(mech: Mechanism, body: Mapping[str, Any], kernels: Any = None) -> dict[str, Any]:
    """At configurations (``q``, or ``qa`` closed): the world placement of every body of the model's 3-D scene (the
    preview page's, :class:`pkm.viz.scene.Scene`), as ``paths`` (meshcat paths) and ``matrices`` (per sample and
    body, the 4 x 4 homogeneous transform's 16 numbers column-major, as meshcat's ``set_transform`` takes them: the
    translation, entries 12 to 14, in m)."""
    from pkm.viz.scene import Scene

    q, samples = _configurations(mech, body, kernels)
    if mech not in _SCENES:
        _SCENES[mech] = Scene.from_mechanism(mech)
    sc = _SCENES[mech]
    paths = [b.path for b in sc.bodies]

    def one(k: int) -> dict[str, Any]:
        placed = sc.transforms(mech.check_q(q[k]))
        return {"q": q[k], "matrices": np.array([np.asarray(placed[p]).T.ravel() for p in paths])}

    out = samples.each(one, ("q", "matrices"))
    out["paths"] = paths
    out["units"] = {"q": _q_units(mech), "matrices": ["1"] * 12 + ["m"] * 3 + ["1"]}
    return out


#: The queries by name (the endpoints ``POST /models/{model}/{name}``).
QUERIES: dict[str, Callable[[Mechanism, Mapping[str, Any], Any], dict[str, Any]]] = {
    "fk": fk, "ik": ik, "jacobians": jacobians, "diagnose": diagnose, "velocities": velocities,
    "dynamics": dynamics, "capability": capability, "scene": scene, "stiffness": stiffness, "clearance": clearance}


def describe(mech: Mechanism) -> dict[str, Any]:
    """What a client needs to ask about ``mech``: its sizes, joint, actuator and task names with their units, the
    reference configuration, the branches."""
    return {"name": mech.name, "nq": mech.nq, "nv": mech.nv, "na": mech.na,
            "joints": list(mech.joints), "actuated": list(mech.actuated_names),
            "actuated_q": [int(i) for i in mech.act_q],
            "actuated_units": _actuated_units(mech),
            "task": list(pkm.TaskMap.of(mech).keys), "task_units": _task_units(mech),
            "task_value_names": list(pkm.TaskMap.of(mech).value_names), "task_value_units": _value_units(mech),
            "q_reference": mech.q_reference, "q_units": _q_units(mech),
            "branches": list(mech.spec.branches), "limits": mech.limits}


__all__ = ["MAX_SAMPLES", "QUERIES", "describe"]
