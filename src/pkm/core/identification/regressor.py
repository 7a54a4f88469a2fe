"""The regressor of any mechanism: ``τ_a = Y_a θ``, the efforts linear in the dynamic parameters.

The tree's joint efforts are linear in every body's standard parameters, ``rnea(q, v, a) = Y(q, v, a) θ_b +
armature · a`` (Pinocchio's ``computeJointTorqueRegressor`` gives ``Y``); the actuator efforts are their projection
``G^T`` onto the actuated joints (``G = dq/dq_a``, :func:`~pkm.core.differential.velocity.passive_map`), the way
:func:`pkm.inverse_dynamics` projects them, plus the drives' terms, which act on the actuated joints only (``G``'s
actuated rows are the identity): ``armature_j q̈_j + viscous_j q̇_j + coulomb_j tanh(q̇_j / COULOMB_VELOCITY) +
offset_j`` (the efforts the actuator supplies: friction opposes the motion, so it enters with the rates' sign).

Mimic joints (the hexapod's β coupling): Pinocchio 4.1's regressor refuses them, so the columns are taken from the
linearity of ``rnea`` in the parameters itself: column ``k`` is ``rnea(θ₀ + e_k) - rnea(θ₀)`` on a copy of the model
(``θ₀`` a unit mass at each joint's origin with a unit inertia), exact up to rounding since ``rnea`` is linear in
``θ`` (not a finite difference: no step, no truncation). The tests check both routes against each other where both
run, and each against :func:`pkm.inverse_dynamics`.

Idle motions (a rod spinning between two balls) follow pkm's convention (:mod:`pkm.core.differential.idle`): the
regressor takes :func:`~pkm.core.dynamics.model.actuator_model`'s map ``Ĝ`` (mass-orthogonal to the idle motions,
so that no idle acceleration changes the projected efforts), rates ``v = Ĝ q̇_a`` and accelerations. ``Ĝ`` depends on
the model's own parameters where a rod's inertia is not symmetric about its axis (elsewhere it is the kinematic map):
``Y_a`` is then the regressor at those parameters. Passive joints' armature and friction are not parameters (none
of pkm's mechanisms has any armature); the joint springs (``[springs]``) and the passive joints' friction (a spring's
damping) are known efforts, not parameters: :func:`known_efforts`, which the estimates subtract from the measured
efforts, but for the springs :func:`pkm.estimate` is asked to identify (``springs=``: two columns each,
:func:`spring_regressor`, ``k`` and ``k rest``). With that, ``Y_a θ_true`` equals :func:`pkm.inverse_dynamics` plus the drives' friction, less the springs'
share (tests: 1e-10 relative, every shipped mechanism and the acceptance set).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.dynamics.model import COULOMB_VELOCITY, RTOL, _check_state, _evaluate
from pkm.core.model.bodies import BODY_FIELDS, BODY_UNITS, body_names
from pkm.core.model.joints import has_mimic
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import CompilerError, InvalidInputError, SpecError
from pkm.validation import as_array, finite_result

if TYPE_CHECKING:
    from pkm.core.twin.kernels import Kernels

DRIVE_FIELDS = ("armature", "viscous", "coulomb", "offset")
"""Per actuator: the reflected inertia, viscous and Coulomb friction, an effort offset."""


@dataclass(frozen=True)
class Parameters:
    """The dynamic parameters of a mechanism, in the regressor's column order.

    Attributes:
        names: ``"<body>.<field>"`` for every body (:data:`BODY_FIELDS`), then ``"<joint>.<field>"`` for every
            actuator (:data:`DRIVE_FIELDS`).
        values: The mechanism's own values (its model file's and spec's).
        units: Each one's unit for a revolute actuator (a prismatic one's drive terms: kg, N s/m, N, N).
        bodies: The bodies' names, one per Pinocchio joint (the link the joint moves, fixed links merged in).
        n_body: ``10 * len(bodies)``: the body columns come first.
    """

    names: tuple[str, ...]
    values: np.ndarray
    units: tuple[str, ...]
    bodies: tuple[str, ...]

    @property
    def n_body(self) -> int:
        return 10 * len(self.bodies)

    def __len__(self) -> int:
        return len(self.names)


def parameters(mech: Mechanism) -> Parameters:
    """The dynamic parameters of ``mech`` (module doc): names, values and units in the regressor's column order.

    Examples:
        >>> import pkm
        >>> theta = pkm.parameters(pkm.load("delta"))
        >>> len(theta.names), theta.names[:4], theta.units[:4]
        (132, ('arm_1.m', 'arm_1.mx', 'arm_1.my', 'arm_1.mz'), ('kg', 'kg m', 'kg m', 'kg m'))
    """
    mech = check_mechanism(mech)
    model = mech.model
    bodies = body_names(model)
    names = [f"{b}.{f}" for b in bodies for f in BODY_FIELDS]
    values = [model.inertias[j].toDynamicParameters() for j in range(1, model.njoints)]
    drives = []
    for a in mech.actuators:
        names += [f"{a.joint}.{f}" for f in DRIVE_FIELDS]
        drives += [a.reflected_inertia, a.viscous, a.coulomb, 0.0]
    units = BODY_UNITS * len(bodies) + ("kg m^2", "N m s/rad", "N m", "N m") * mech.na
    return Parameters(tuple(names), np.concatenate([*values, np.array(drives)]), units, bodies)


def tree_regressor(mech: Mechanism, q: ArrayLike, v: ArrayLike, a: ArrayLike) -> np.ndarray:
    """``Y`` (nv x 10 n_bodies): the tree's joint efforts ``rnea(q, v, a)`` (armature left out) as ``Y θ_b``;
    Pinocchio's regressor, or the linearity route where the model has mimic joints (module doc)."""
    mech = check_mechanism(mech)
    q, v, a = mech.check_q(q), mech.check_v(v), mech.check_v(a, "a")
    model = mech.model
    if not has_mimic(model):
        return pin.computeJointTorqueRegressor(model, mech.data, q, v, a).copy()
    return _linear_columns(mech, q, v, a)


def _linear_columns(mech: Mechanism, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    model = pin.Model(mech.model)
    model.armature = np.zeros(model.nv)
    data = model.createData()
    nb = model.njoints - 1
    base = pin.Inertia(1.0, np.zeros(3), np.eye(3)).toDynamicParameters()
    for j in range(1, model.njoints):
        model.inertias[j] = pin.Inertia.FromDynamicParameters(base)
    tau0 = pin.rnea(model, data, q, v, a).copy()
    Y = np.empty((model.nv, 10 * nb))
    for j in range(1, model.njoints):
        for k in range(10):
            theta = base.copy()
            theta[k] += 1.0
            model.inertias[j] = pin.Inertia.FromDynamicParameters(theta)
            Y[:, 10 * (j - 1) + k] = pin.rnea(model, data, q, v, a) - tau0
        model.inertias[j] = pin.Inertia.FromDynamicParameters(base)
    return Y


def regressor(mech: Mechanism, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> np.ndarray:
    """``Y_a`` (na x p, p = ``len(parameters(mech))``) at a closed ``q`` with actuated rates ``qd`` and
    accelerations ``qdd``: ``Y_a θ`` are the actuator efforts [N m, N] (module doc).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q, qd, qdd = delta.q_reference, np.array([0.5, -0.2, 0.1]), np.array([1.0, 2.0, -1.0])
        >>> Y = pkm.regressor(delta, q, qd, qdd)
        >>> Y.shape
        (3, 132)
        >>> theta = pkm.parameters(delta).values
        >>> np.round(Y @ theta, 4)
        array([0.1819, 0.1859, 0.1752])
        >>> np.allclose(Y @ theta, pkm.actuator_model(delta, q, qd).efforts(qdd))
        True
    """
    mech, q, qd, base, vb = _check_state(mech, q, qd, None)  # (no inertia needed: a non-physical model has one)
    model = _evaluate(mech, q, qd, RTOL, COULOMB_VELOCITY, base, vb)
    qdd = mech.check_actuated(qdd, "qdd")
    a = model.joint_accelerations(qdd)
    Yb = model.G.T @ tree_regressor(mech, model.q, model.v, a)
    drives = np.zeros((mech.na, 4 * mech.na))
    for i, (rate, acc) in enumerate(zip(model.qd, qdd)):
        drives[i, 4 * i:4 * i + 4] = (acc, rate, np.tanh(rate / COULOMB_VELOCITY), 1.0)
    return finite_result(np.hstack([Yb, drives]), "regressor")


def known_efforts(mech: Mechanism, Q: ArrayLike, QD: ArrayLike, without: tuple[str, ...] = ()) -> np.ndarray:
    """The actuator efforts (N, na) [N m, N] at closed configurations ``Q`` (N, nq) and actuated rates ``QD`` (N, na)
    that no parameter carries: the joint springs' share of the static efforts (``[springs]`` stiffness,
    :func:`pkm.spring_efforts`) and the passive joints' friction (a spring's damping, Pinocchio's ``damping`` and
    ``friction`` off the actuated joints) that the actuators overcome. Measured efforts are ``Y_a θ`` plus these: the
    estimates subtract them (:func:`pkm.estimate`, :func:`pkm.consistent_estimate`) and the predictions add them
    (:func:`pkm.validate`). Zero (and not evaluated) without springs or passive friction. ``without``: joints whose
    springs are parameters (:func:`spring_regressor`), their share left out."""
    mech = check_mechanism(mech)
    Q, QD = np.atleast_2d(np.asarray(Q, dtype=float)), np.atleast_2d(np.asarray(QD, dtype=float))
    out = np.zeros((len(Q), mech.na))
    passive = np.ones(mech.nv, dtype=bool)
    passive[mech.act_v] = False
    passive[mech.base_v] = False
    rubbing = bool(np.any(np.asarray(mech.model.damping)[passive] != 0.0)
                   or np.any(np.asarray(mech.model.friction)[passive] != 0.0))
    if not mech.springs and not rubbing:
        return out
    s = mech.springs
    own = np.zeros(mech.nv)  # (the stiffness of the springs that stay known)
    own[s.idx_v] = [0.0 if n in without else k for n, k in zip(s.names, s.stiffness)]
    for i, (q, qd) in enumerate(zip(Q, QD)):
        model = _evaluate(mech, mech.check_q(q), mech.check_actuated(qd, "qd"), RTOL, COULOMB_VELOCITY)
        f = np.where(passive, model._friction_joint, 0.0)
        stretch = np.zeros(mech.nv)
        stretch[s.idx_v] = s.stretch(model.q)
        out[i] = model.G.T @ (own * stretch) - model.G.T @ f  # (= model.springs where every spring is known)
    return out


#: Per identified spring (:func:`spring_regressor`): its stiffness ``k`` and ``k`` times its rest position.
SPRING_FIELDS = ("stiffness", "stiffness_rest")


def spring_joints(mech: Mechanism, joints: object) -> tuple[str, ...]:
    """``joints`` checked as the names of distinct one-coordinate joints (revolute or prismatic, not an unbounded
    revolute) whose springs are to be identified.

    Raises:
        InvalidInputError: not a sequence of names, a joint named twice or of other than one coordinate.
        UnknownNameError: a joint the mechanism lacks.
    """
    from pkm.errors import UnknownNameError

    if isinstance(joints, str) or not isinstance(joints, (list, tuple)):
        raise InvalidInputError("springs", "expected a list of joint names", joints)
    for n in joints:
        if n not in mech.joints:
            raise UnknownNameError("joint", str(n), mech.joints, mech.name)
        if mech.joints[n].nq != 1 or mech.joints[n].nv != 1:
            raise InvalidInputError("springs", f"{n!r}: a spring to identify is on a one-coordinate joint (revolute "
                                               "or prismatic)", n)
    if len(set(joints)) != len(joints):
        raise InvalidInputError("springs", "a joint named twice", joints)
    return tuple(str(n) for n in joints)


def spring_regressor(mech: Mechanism, Q: ArrayLike, QD: ArrayLike, joints: tuple[str, ...]) -> np.ndarray:
    """The springs of ``joints`` as parameters: (N na) x 2 len(joints), sample after sample as
    :func:`regressor_batch` stacks, two columns a joint for its :data:`SPRING_FIELDS`. A spring ``-k (q_j - rest)``
    on joint ``j`` costs the actuators ``Ĝ_jᵀ k (q_j - rest) = (Ĝ_jᵀ q_j) k - Ĝ_jᵀ (k rest)`` (``Ĝ_j`` the map's
    row of ``j``, :func:`~pkm.core.dynamics.model.actuator_model`): linear in ``(k, k rest)``, identifiable where
    the motion excites them (the rest of a spring on an actuated joint is its drive's offset: ``Ĝ_j`` is constant)."""
    mech = check_mechanism(mech)
    Q, QD = np.atleast_2d(np.asarray(Q, dtype=float)), np.atleast_2d(np.asarray(QD, dtype=float))
    out = np.zeros((len(Q) * mech.na, 2 * len(joints)))
    iq = [mech.joints[n].idx_q for n in joints]
    iv = [mech.joints[n].idx_v for n in joints]
    for i, (q, qd) in enumerate(zip(Q, QD)):
        model = _evaluate(mech, mech.check_q(q), mech.check_actuated(qd, "qd"), RTOL, COULOMB_VELOCITY)
        rows = model.G[iv]  # (len(joints), na)
        out[i * mech.na:(i + 1) * mech.na, 0::2] = (rows * model.q[iq][:, None]).T
        out[i * mech.na:(i + 1) * mech.na, 1::2] = -rows.T
    return finite_result(out, "spring regressor")


AUTO_SAMPLES = 2000  # "auto" compiles a mechanism's regressor for batches of at least this many samples
BACKENDS = ("auto", "python", "c")
_KERNELS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # mechanism -> (Kernels or None, why not)


def _compiled(mech: Mechanism) -> tuple[Kernels | None, str]:
    """The mechanism's kernels with the regressor compiled (built once per mechanism), or None and why not: the
    twin cannot build it (idle motions, a joint kind it lacks: ``"spec: ..."``) or no C compiler runs (what the
    compiler search said)."""
    from pkm.core.twin.kernels import Kernels

    if mech not in _KERNELS:
        kernels = Kernels(mech)
        try:
            kernel = kernels.kernel("regressor")
            _KERNELS[mech] = (kernels, "") if kernel.lib is not None else (None, kernel.how)
        except SpecError as exc:
            _KERNELS[mech] = (None, f"spec: {exc}")
    return _KERNELS[mech]


def _kernels(mech: Mechanism) -> Kernels | None:
    """The mechanism's compiled kernels, or None (:func:`_compiled`)."""
    return _compiled(mech)[0]


def close_along(mech: Mechanism, QA: np.ndarray, q0: np.ndarray | None = None) -> np.ndarray:
    """Closed configurations (N x nq) along actuated samples ``QA`` (N x na), each solve warm-started from the last
    (one assembly mode): the compiled closure path (:meth:`pkm.Kernels.close_loops_path`) where the regressor's
    kernels build, else :func:`pkm.close_loops` sample after sample.

    Raises:
        ConvergenceError: a sample does not close (from the previous one).
    """
    from pkm.core.kinematics.solve import close_loops

    q = mech.q_reference if q0 is None else q0
    kernels = _kernels(mech)
    if kernels is not None:
        return np.asarray(kernels.close_loops_path(QA, q).q)
    out = []
    for qa in QA:
        q = close_loops(mech, qa, q).q
        out.append(q)
    return np.array(out)


def regressor_batch(mech: Mechanism, Q: ArrayLike, QD: ArrayLike, QDD: ArrayLike, *,
                    backend: str = "auto") -> np.ndarray:
    """``Y_a`` stacked over N samples ((N na) x p, sample after sample): closed configurations ``Q`` (N, nq),
    actuated rates and accelerations (N, na).

    ``backend``: ``"python"`` calls :func:`regressor` per sample (0.4 to 2 ms each); ``"c"`` runs the twin's
    compiled regressor (:mod:`pkm.core.twin.regressor`: the exact ``∂τ_a/∂θ``, on every core; the hexapod's 10⁵
    samples in 0.34 s once its 1.4 GB are allocated, ``pkm bench identification``), samples under the pivot floor
    redone in Python; ``"auto"``: C for batches of :data:`AUTO_SAMPLES` or more (or when already built) where
    the twin builds the mechanism (no idle motions) and a C compiler runs, else Python.

    Raises:
        InvalidInputError: arrays of different lengths or shapes, non-finite values, an unknown backend, or
            ``backend="c"`` for a mechanism the twin cannot build.
        CompilerError: ``backend="c"`` without a C compiler.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> Q = np.array([pkm.solve_ik(delta, [x, 0.0, -0.36]).q for x in (0.0, 0.02, 0.04)])
        >>> QD, QDD = np.full((3, 3), 0.5), np.ones((3, 3))
        >>> Y = pkm.regressor_batch(delta, Q, QD, QDD, backend="python")
        >>> Y.shape
        (9, 132)
        >>> np.allclose(Y[3:6], pkm.regressor(delta, Q[1], QD[1], QDD[1]))
        True
    """
    mech = check_mechanism(mech)
    if not isinstance(backend, str) or backend not in BACKENDS:
        raise InvalidInputError("backend", f"use one of {list(BACKENDS)}, got {backend!r}", backend)
    Q, QD, QDD = (np.atleast_2d(as_array(x, name)) for x, name in ((Q, "Q"), (QD, "QD"), (QDD, "QDD")))
    if not (len(Q) == len(QD) == len(QDD)):
        raise InvalidInputError("Q", f"expected as many samples of each: {len(Q)}, {len(QD)}, {len(QDD)}", len(Q))
    if backend == "c" or (backend == "auto" and (len(Q) >= AUTO_SAMPLES or _KERNELS.get(mech) is not None)):
        kernels, why = _compiled(mech)
        if kernels is not None:
            Y = kernels.regressor(Q, QD, QDD, lambda q, qd, qdd: regressor(mech, q, qd, qdd))
            return Y.reshape(-1, Y.shape[-1])
        if backend == "c" and why.startswith("spec: "):
            raise InvalidInputError("backend", f"the C route does not build this mechanism: {why[6:]}", backend)
        if backend == "c":
            raise CompilerError("the compiled regressor (backend='c')", why)
    return np.vstack([regressor(mech, q, qd, qdd) for q, qd, qdd in zip(Q, QD, QDD)])


__all__ = ["AUTO_SAMPLES", "BACKENDS", "BODY_FIELDS", "BODY_UNITS", "DRIVE_FIELDS", "SPRING_FIELDS", "Parameters",
           "close_along", "known_efforts", "parameters", "regressor", "regressor_batch", "spring_joints",
           "spring_regressor", "tree_regressor"]
