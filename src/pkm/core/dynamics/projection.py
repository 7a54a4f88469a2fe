"""Inverse dynamics of closed-loop mechanisms by Khalil's projection, and its independent checks.

The mechanism is cut at its closures into *legs* and a *platform* (Khalil & Ibrahim 2007):

* the **platform** is the subtree of the Pinocchio model that carries the end-effector
  frame (a free joint, or the massless guide joints of a Delta); its joint velocity
  ``v_p`` (``n_p`` coordinates) is the platform's motion;
* a **leg** is a subtree hanging from the base whose tip frames meet platform frames
  through closures; legs that share a joint are merged into one.

With the constraint Jacobian rows of leg ``k`` written ``J_k qd_k = P_k v_p`` (leg tip
velocity = velocity of the platform point it meets), an SVD of the leg's own Jacobian
``J_k = U S V^T`` splits them into

* the leg's inverse kinematics of velocity, ``qd_k = L_k v_p``, ``L_k = V S^-1 U_r^T P_k``
  (undefined when the leg loses rank: an inverse singularity of that leg);
* the motions of the platform the leg forbids, ``K_k v_p = 0``, ``K_k = U_n^T P_k``
  (the leg's constraint wrenches).

Stacking the actuated rows of the ``L_k`` (``A``) and the ``K_k`` gives the square
``M = [A; K]``; ``J_k = M^-1 [I; 0]`` maps actuated rates to the platform motion
(undefined where ``M`` loses rank: a direct singularity). Then

    ``tau = h_a + J_k^T (f_p + sum_k L_{k,p}^T h_{k,p} - P_e^T w)``        (paper eq. 38)

where ``h`` is the tree's inverse dynamics (``pin.rnea``: each leg is its own serial chain,
so this is the recursive Newton-Euler of every leg, and the platform's free joint gives its
Newton-Euler wrench ``f_p``), ``h_a``/``h_{k,p}`` its actuated/passive leg entries, ``L_{k,p}``
the passive rows of ``L_k`` (the paper's ``G_2``) and ``w`` an external wrench on the
platform (world-aligned, at the end-effector frame: force then moment) of Jacobian ``P_e``.
The joint springs (``[springs]``, :mod:`pkm.core.model.springs`) are efforts on the tree's joints: ``h`` is
``rnea - τ_s`` on every route (their damping is friction, which the inverse dynamics leaves out), and
:func:`constraint_dynamics` applies ``τ_s`` with the actuators' efforts.

Independent routes, used by the tests: :func:`virtual_work_dynamics` (``G^T h`` with the
core's passive map ``G = dq/dq_a``), :func:`constraint_dynamics` (Pinocchio's
``constraintDynamics``: the forces must give back the accelerations) and :func:`energy`
(power balance).
"""

from __future__ import annotations

import warnings
import weakref
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.differential.idle import idle_inertia_inverse, joint_inertia
from pkm.core.differential.velocity import idle_motions, passive_map
from pkm.core.dynamics import model as actuator_space
from pkm.core.kinematics import constraints
from pkm.core.kinematics.configuration import Configuration
from pkm.core.model.joints import has_mimic
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.plausibility import require_physical
from pkm.core.model.scale import JacobianScales
from pkm.errors import InvalidInputError, PkmError, PkmWarning, SingularityError, SpecError
from pkm.validation import as_choice, as_count, as_scalar, as_tolerance, as_vector, finite_result

RTOL = 1e-9
#: A free base "needs" a wrench where the one the motion asks of it exceeds this, relative to the wrenches it sums
#: (inertia, velocity and gravity terms, external loads; moments over the characteristic length).
BASE_WRENCH_RTOL = 1e-8


@dataclass(frozen=True)
class Leg:
    """One leg of the cut mechanism.

    Attributes:
        closures: Names of the closures at the leg's tips.
        rows: Their rows in the constraint Jacobian.
        v: Velocity indices of the leg's joints (tree order).
        actuated: Positions in ``v`` of the actuated joints.
        actuated_index: Their positions in ``mech.actuated`` (the order of ``tau``).
        passive: Positions in ``v`` of the passive joints.
    """

    closures: tuple[str, ...]
    rows: np.ndarray
    v: np.ndarray
    actuated: np.ndarray
    actuated_index: np.ndarray
    passive: np.ndarray


@dataclass(frozen=True)
class Partition:
    """The platform's velocity indices and the legs."""

    platform_v: np.ndarray
    legs: tuple[Leg, ...]


def _support_v(model: pin.Model, joint_id: int) -> set[int]:
    out: set[int] = set()
    for j in model.supports[joint_id]:
        if j > 0:
            jm = model.joints[j]
            out.update(range(jm.idx_v, jm.idx_v + jm.nv))
    return out


def partition(mech: Mechanism) -> Partition:
    """Cut ``mech`` into platform and legs (see the module doc).

    Raises:
        SpecError: The structure does not fit the projection: a closure that does not join a
            leg to the platform, an actuated joint on the platform side, a joint that belongs to
            no leg, or mimic joints (not supported).
    """
    mech = check_mechanism(mech)
    model = mech.model
    src = mech.source
    if has_mimic(model):
        raise SpecError(src, "the Khalil projection does not support mimic joints yet")
    if mech.base is not None:
        raise SpecError(src, "the Khalil projection cuts a fixed base; a floating base takes the virtual-work route")
    plat = _support_v(model, model.frames[mech.ee_frame].parentJoint)
    if not plat:
        raise SpecError(src, f"end effector {mech.spec.end_effector!r} is fixed to the base: no platform to cut")
    act = {int(v): k for k, v in enumerate(mech.act_v)}
    if plat & set(act):
        raise SpecError(src, "an actuated joint drives the platform directly: the projection expects actuated "
                             "joints in the legs")
    groups: list[tuple[list[str], list[int], set[int]]] = []
    row = 0
    for c, (fa, fb) in zip(mech.spec.closures, mech.closure_frames):
        n = 3 if c.type == "point" else 6
        sa, sb = (_support_v(model, model.frames[f].parentJoint) for f in (fa, fb))
        leg = sa - plat if sb <= plat and not sa <= plat else sb - plat if sa <= plat and not sb <= plat else None
        if not leg or (sa & sb) - plat:
            raise SpecError(src, f"closure {c.name!r} does not join a leg to the platform: the projection needs "
                                 "every closure between a leg tip and the platform")
        rows = list(range(row, row + n))
        row += n
        merged = [g for g in groups if g[2] & leg]
        for g in merged:
            groups.remove(g)
            rows = g[1] + rows
            leg = leg | g[2]
        groups.append(([n for g in merged for n in g[0]] + [c.name], rows, leg))
    covered = plat.union(*(g[2] for g in groups))
    if len(covered) != model.nv:
        raise SpecError(src, f"joints with velocity indices {sorted(set(range(model.nv)) - covered)} belong to "
                             "neither the platform nor a leg")
    legs = []
    for names, rows, vs in groups:
        v = np.array(sorted(vs))
        a = [i for i, vi in enumerate(v) if int(vi) in act]
        legs.append(Leg(tuple(names), np.array(sorted(rows)), v, np.array(a, dtype=int),
                        np.array([act[int(v[i])] for i in a], dtype=int),
                        np.array([i for i in range(len(v)) if i not in a], dtype=int)))
    return Partition(np.array(sorted(plat)), tuple(legs))


@dataclass(frozen=True)
class Projection:
    """The projection matrices at one configuration.

    Attributes:
        Jk: Platform joint velocity from actuated rates (``n_p x n_a``).
        L: Per leg, its joint rates from the platform velocity (``n_k x n_p``).
        sigma_leg: Per leg, the smallest singular value of its Jacobian (inverse singularity measure), homogenised by
            the characteristic length (:mod:`pkm.core.model.scale`).
        sigma_direct: Smallest singular value of ``M = [A; K]`` (direct singularity measure), homogenised.
    """

    Jk: np.ndarray
    L: tuple[np.ndarray, ...]
    sigma_leg: tuple[float, ...]
    sigma_direct: float


class KhalilProjection:
    """Actuator efforts of a closed-loop mechanism by Khalil's projection (module doc).

    Args:
        mech: The mechanism; its platform and legs are found by :func:`partition`.
        rtol: Relative singular-value threshold for the rank decisions.
    """

    def __init__(self, mech: Mechanism, *, rtol: float = RTOL):
        self.mech = check_mechanism(mech)
        self.partition = partition(mech)
        self.rtol = as_tolerance(rtol, "rtol")

    def projection(self, q: ArrayLike) -> Projection:
        """``J_k`` and the legs' velocity maps at ``q`` (assembled).

        Raises:
            SingularityError: ``"inverse"`` where a leg's Jacobian loses rank (leg named in the
                message), ``"direct"`` where ``M`` does.
        """
        return self._projection(constraints.jacobian(self.mech, self.mech.check_q(q)))

    def _projection(self, Jc: np.ndarray) -> Projection:
        # (computed on the Jacobian homogenised by the characteristic length, so that every rank decision is the same
        # for the mechanism scaled in size; the maps are given back in joint rates at the end)
        mech, part = self.mech, self.partition
        scales = JacobianScales.of(mech)
        Jc = scales.constraint(finite_result(Jc, "constraint Jacobian"))
        na, n_p = mech.na, len(part.platform_v)
        A = np.zeros((na, n_p))
        K, Ls, sig = [], [], []
        for leg in part.legs:
            Jl = Jc[np.ix_(leg.rows, leg.v)]
            P = -Jc[np.ix_(leg.rows, part.platform_v)]
            U, s, Vt = np.linalg.svd(Jl)
            r = len(leg.v)
            sig.append(float(s[r - 1]) if len(s) >= r else 0.0)
            if len(s) < r or s[r - 1] <= self.rtol * float(s[0]):
                raise SingularityError("inverse", sig[-1], f"leg of closures {', '.join(leg.closures)} loses rank: "
                                                           "its joint rates are not fixed by the platform motion",
                                       distance=sig[-1] / float(s[0]) if len(s) and s[0] > 0.0 else 0.0)
            L = Vt.T @ ((U[:, :r].T @ P) / s[:r, None])
            Ls.append(L)
            K.append(U[:, r:].T @ P)
            A[leg.actuated_index] = L[leg.actuated]
        M = np.vstack([A, *K])
        sv = np.linalg.svd(M, compute_uv=False)
        smin = float(sv[n_p - 1]) if len(sv) >= n_p else 0.0
        if smin <= self.rtol * float(sv[0]):
            raise SingularityError("direct", smin, "the actuated legs do not fix the platform motion",
                                   distance=smin / float(sv[0]) if sv[0] > 0.0 else 0.0)
        rhs = np.zeros((M.shape[0], na))
        rhs[:na] = np.eye(na)
        Jk = np.linalg.lstsq(M, rhs, rcond=None)[0]
        if not scales.trivial:
            c, cp = scales.columns, scales.columns[part.platform_v]
            Jk = cp[:, None] * Jk / scales.actuated
            Ls = [c[leg.v][:, None] * L / cp for leg, L in zip(part.legs, Ls)]
        return Projection(Jk, tuple(Ls), tuple(sig), smin)

    def inverse_dynamics(self, q: ArrayLike, v: ArrayLike, a: ArrayLike, wrench: ArrayLike | None = None, *, wrenches: Mapping[str, ArrayLike] | None = None) \
            -> np.ndarray:
        """Actuator efforts (N or N m, in ``mech.actuated`` order) for a consistent state. Under redundant actuation
        (the efforts not unique) one valid distribution, the least-squares platform map's, not pkm's convention (the
        virtual work's, :func:`inverse_dynamics`).

        Args:
            q: Assembled configuration (nq,).
            v: Joint velocities satisfying the closures (nv,).
            a: Joint accelerations satisfying the closures (nv,).
            wrench: Optional external wrench on the platform at the end-effector frame,
                world-aligned ``(f [N], m [N m])``, shape (6,).
            wrenches: Optional external wrenches on any frames, ``{frame name: (f, m)}``, each
                world-aligned at the frame's origin.
        """
        mech, part = self.mech, self.partition
        q, v, a = mech.check_q(q), mech.check_v(v), mech.check_v(a, "a")
        c = Configuration.compute(mech, q)
        proj = self._projection(c.constraint_jacobian)
        h = _external(mech, q, _tree_efforts(mech, q, v, a), wrench, wrenches, c)
        f = h[part.platform_v].copy()
        tau = np.zeros(mech.na)
        for leg, L in zip(part.legs, proj.L):
            hk = h[leg.v]
            tau[leg.actuated_index] = hk[leg.actuated]
            p = leg.passive
            f += L[p].T @ hk[p]
        return finite_result(tau + proj.Jk.T @ f, "actuator efforts", "the state is too large for the inertias "
                                                                      "(overflow); check the units")


def _tree_efforts(mech: Mechanism, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """The open tree's joint efforts for ``(q, v, a)``: ``rnea(q, v, a) - τ_s(q)``, Pinocchio's inverse dynamics
    less the joint springs' efforts (``τ_s = -K (q - rest)``, :mod:`pkm.core.model.springs`; a new array)."""
    out = pin.rnea(mech.model, mech.data, q, v, a).copy()
    if mech.springs:
        out -= mech.springs.efforts(q)
    return out


def _external(mech: Mechanism, q: np.ndarray, h: np.ndarray, wrench: ArrayLike | None,
              wrenches: Mapping[str, ArrayLike] | None,
              c: Configuration | None = None) -> np.ndarray:
    """``h - sum_f J_f^T w_f``: the tree's joint forces less those of the external wrenches (world-aligned at
    each frame's origin, force then moment); ``wrench`` acts at the end-effector frame. ``c``: the
    configuration's kinematics when the caller has them (computed here only when a wrench needs them)."""
    if wrenches is not None and not (isinstance(wrenches, Mapping) and all(isinstance(k, str) for k in wrenches)):
        raise InvalidInputError("wrenches", "expected {frame name: (fx, fy, fz, mx, my, mz)}", wrenches)
    loads = dict(wrenches or {})
    out = h.copy()
    if wrench is not None:
        c = Configuration.compute(mech, q) if c is None else c
        out -= c.ee_jacobian.T @ as_vector(wrench, 6, "wrench")
    m = mech.model
    if loads:
        pin.computeJointJacobians(m, mech.data, q)
        pin.updateFramePlacements(m, mech.data)
    for name, w in loads.items():
        J = pin.getFrameJacobian(m, mech.data, mech.frame_id(name), pin.LOCAL_WORLD_ALIGNED)
        out -= J.T @ as_vector(w, 6, f"wrenches[{name!r}]")
    return out


_KHALIL: weakref.WeakKeyDictionary[Mechanism, KhalilProjection | SpecError] = weakref.WeakKeyDictionary()


def _khalil(mech: Mechanism) -> KhalilProjection | SpecError:
    """The mechanism's Khalil projection, or the SpecError saying why its structure does not allow one (cached)."""
    if mech not in _KHALIL:
        try:
            _KHALIL[mech] = KhalilProjection(mech)
        except SpecError as exc:
            _KHALIL[mech] = exc
    return _KHALIL[mech]


METHODS = ("auto", "khalil", "virtual_work")
_IDLE: weakref.WeakKeyDictionary[Mechanism, bool] = weakref.WeakKeyDictionary()


def _settle_idle(mech: Mechanism, q: ArrayLike, v: ArrayLike, a: ArrayLike, wrench: ArrayLike | None,
                 wrenches: Mapping[str, ArrayLike] | None) -> ArrayLike:
    """``a`` with its idle-motion part set by the dynamics, ``a + N alpha`` with ``N^T (rnea(q, v, a') - J^T w) = 0``:
    for Khalil's projection, whose implicit passive map need not be mass-orthogonal to the idle motions.

    The kinematics fixes no idle acceleration (:func:`~pkm.core.differential.velocity.idle_motions` ``N``: a rod spinning
    between two ball joints). Efforts projected by a map ``Ĝ`` with ``Nᵀ M Ĝ = 0`` (:func:`pkm.passive_map`: the
    virtual-work route) do not depend on it; those of another map only once the idle motions' generalised force
    vanishes, as nothing drives them. Mechanisms with no idle motion at their reference skip it (cached per
    mechanism); massless idle directions (:mod:`pkm.core.differential.idle`) keep the acceleration given.
    """
    if mech not in _IDLE:
        _IDLE[mech] = idle_motions(mech, mech.q_reference).shape[1] > 0
    if not _IDLE[mech]:
        return a
    q, v, a = mech.check_q(q), mech.check_v(v), mech.check_v(a, "a")
    N = idle_motions(mech, q)
    if not N.shape[1]:
        return a
    h = _external(mech, q, _tree_efforts(mech, q, v, a), wrench, wrenches)
    return a - N @ (idle_inertia_inverse(joint_inertia(mech, q), N) @ (N.T @ h))


def inverse_dynamics(mech: Mechanism, q: ArrayLike, v: ArrayLike, a: ArrayLike, wrench: ArrayLike | None = None, *,
                     wrenches: Mapping[str, ArrayLike] | None = None, method: str = "auto",
                     base: str | None = None) -> np.ndarray:
    """Actuator efforts (N or N m, in ``mech.actuated`` order) of any mechanism at a consistent state.

    A floating base (``spec.floating_base``) is free by default (``base="free"``, :mod:`pkm.core.dynamics.model`):
    motors alone cannot drive a free body, so a motion ``a`` is one of the free robot only where it asks no wrench
    of the base. The efforts returned are those of the motion with the base given whatever wrench it asks; where
    that wrench is not zero (:data:`BASE_WRENCH_RTOL`) a free base warns (:class:`~pkm.errors.PkmWarning`: the
    motion is not the free robot's). :func:`base_inverse_dynamics` returns the wrench with the efforts;
    ``base="fixed"`` says the base is held (no warning).

    Args:
        mech: The mechanism.
        q, v, a: Assembled configuration, joint velocities and accelerations satisfying the closures
            (:func:`pkm.velocities`, :func:`pkm.accelerations` or their inverse-kinematics twins).
        wrench: External wrench at the end-effector frame, world-aligned ``(f [N], m [N m])``.
        wrenches: External wrenches on any frames, ``{frame name: (f, m)}``, world-aligned at each origin.
        method: ``"khalil"`` (:class:`KhalilProjection`: legs cut from the platform; refuses the
            structures it cannot cut, such as actuators on the platform chain or mimic joints),
            ``"virtual_work"`` (:func:`virtual_work_dynamics`: ``G^T`` of the tree's forces, any
            structure: mimic couplings, idle motions, redundant planar closures), or ``"auto"``: Khalil's
            where the structure allows it, virtual work otherwise. Both give the same efforts to 1e-10
            where both apply (tests), but under redundant actuation, where the efforts are not unique
            (:attr:`~pkm.core.Mechanism.dependent_actuators`): every distribution ``tau`` with ``Tᵀ tau`` the
            independent actuators' efforts (``T`` the actuated rates of theirs) does the motion's work. pkm's
            convention there is the virtual work's, which ``"auto"`` then takes: ``tau = Gᵀ h`` with the
            homogenised pseudo-inverse's ``G`` (:func:`pkm.passive_map`), i.e. the closure multipliers of least
            norm (lengths in the characteristic length; not the efforts of least norm), as
            :func:`pkm.actuator_model` and :meth:`pkm.Kernels.inverse_dynamics <pkm.core.twin.kernels.Kernels.inverse_dynamics>`
            give them; ``"khalil"`` gives another valid one (its platform map by least squares).
        base: A floating base ``"free"`` (default where there is one) or ``"fixed"`` (held).

    Raises:
        SingularityError: at a direct singularity (and, for ``"khalil"``, where a leg loses rank).
        SpecError: ``"khalil"`` on a structure it cannot cut (says why).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q = pkm.solve_ik(delta, [0.02, 0.0, -0.36]).q
        >>> v = pkm.inverse_velocities(delta, q, [0.0, 0.0, 0.1])
        >>> a = pkm.inverse_accelerations(delta, q, v, [0.0, 0.0, 1.0])
        >>> np.round(pkm.inverse_dynamics(delta, q, v, a), 4)
        array([0.1839, 0.157 , 0.2098])
        >>> push = [0.0, 0.0, -10.0, 0.0, 0.0, 0.0]  # 10 N downwards on the end effector
        >>> np.round(pkm.inverse_dynamics(delta, q, v, a, wrench=push), 4)
        array([0.6013, 0.5016, 0.6976])
    """
    mech = check_mechanism(mech)
    require_physical(mech, "inverse dynamics")
    method = as_choice(method, METHODS, "method")
    if actuator_space.base_choice(mech, base) == "free":
        out = base_inverse_dynamics(mech, q, v, a, wrench, wrenches=wrenches, method=method, base="free")
        if out.needs_base_wrench:
            name = mech.base.name if mech.base is not None else ""
            warnings.warn(f"the motion asks a wrench of the free floating base {name!r} "
                          f"({_wrench_text(out.base_wrench)}, base frame): motors alone cannot give it; the "
                          "efforts are those with the base given it (pkm.base_inverse_dynamics returns it; "
                          "base='fixed' says the base is held)", PkmWarning, stacklevel=2)
        return out.efforts
    return _motor_efforts(mech, q, v, a, wrench, wrenches, method)


def _wrench_text(w: np.ndarray) -> str:
    return f"force {np.array2string(w[:3], precision=4)} N, moment {np.array2string(w[3:], precision=4)} N m"


def _motor_efforts(mech: Mechanism, q: ArrayLike, v: ArrayLike, a: ArrayLike, wrench: ArrayLike | None,
                   wrenches: Mapping[str, ArrayLike] | None, method: str) -> np.ndarray:
    """:func:`inverse_dynamics`'s efforts by ``method`` (checked), the base given what it asks."""
    if method == "virtual_work" or (method == "auto" and mech.dependent_actuators):  # (redundant: the convention)
        return virtual_work_dynamics(mech, q, v, a, wrench, wrenches=wrenches)
    k = _khalil(mech)
    if isinstance(k, SpecError):
        if method == "khalil":
            raise k
        return virtual_work_dynamics(mech, q, v, a, wrench, wrenches=wrenches)
    return k.inverse_dynamics(q, v, _settle_idle(mech, q, v, a, wrench, wrenches), wrench, wrenches=wrenches)


@dataclass(frozen=True)
class BaseInverseDynamics:
    """The inverse dynamics of a floating-base robot: the motors' efforts and the wrench the base needs.

    Attributes:
        efforts: The actuator efforts (na,) [N m, N], in ``mech.actuated`` order, with the base given
            ``base_wrench`` (what :func:`inverse_dynamics` returns).
        base_wrench: The wrench (6,) the motion asks of whatever acts on the base, beyond gravity and the external
            wrenches given: Pinocchio's free-flyer generalised force, ``(f [N], m [N m])`` in the base's own frame
            (the free-flyer's child frame), the moment about its origin. On a held base (``base="fixed"``) it is
            the holder's reaction; on a free base it must be zero for the motion to be the free robot's.
        base: ``"free"`` or ``"fixed"`` (:mod:`pkm.core.dynamics.model`).
        needs_base_wrench: A free base only: ``base_wrench`` is not zero (:data:`BASE_WRENCH_RTOL` of the
            wrenches it sums): ``a`` is not a motion of the free robot and ``efforts`` alone do not produce it.
            False on a held base (the holder gives it).
        base_wrench_world: ``base_wrench`` world-aligned (same point: the base's origin).
    """

    efforts: np.ndarray
    base_wrench: np.ndarray
    base: str
    needs_base_wrench: bool
    base_wrench_world: np.ndarray


def base_inverse_dynamics(mech: Mechanism, q: ArrayLike, v: ArrayLike, a: ArrayLike,
                          wrench: ArrayLike | None = None, *, wrenches: Mapping[str, ArrayLike] | None = None,
                          method: str = "auto", base: str | None = None) -> BaseInverseDynamics:
    """The actuator efforts and the base wrench of a floating-base robot's motion (:class:`BaseInverseDynamics`).

    ``(efforts, base_wrench) = [Ĝ Ĝ_b]ᵀ (rnea(q, v, a) - Σ J_fᵀ w_f)``: ``Ĝ`` the passive map (the efforts, as
    :func:`inverse_dynamics`), ``Ĝ_b`` the joint rates of a unit base twist with the actuators locked
    (:mod:`pkm.core.dynamics.model`). Arguments as :func:`inverse_dynamics`; ``v`` and ``a`` carry the base's twist
    and acceleration on its free-flyer entries (zero: the base at rest).

    Raises:
        InvalidInputError: the mechanism has no floating base (its base's reaction is not modelled).

    Examples:
        >>> import dataclasses
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")  # hung on a free-flyer "pelvis" over a new ground link:
        >>> urdf = delta.urdf.replace('<link name="base">', '<link name="ground"/><joint name="pelvis" '
        ...                           'type="floating"><parent link="ground"/><child link="base"/></joint><link name="base">')
        >>> robot = pkm.from_strings(urdf, dataclasses.replace(delta.spec, floating_base="pelvis", reference={}))
        >>> q = pkm.close_loops(robot, delta.actuated_q(delta.q_reference)).q
        >>> rest = np.zeros(robot.nv)
        >>> held = pkm.base_inverse_dynamics(robot, q, rest, rest, base="fixed")  # the holder carries the weight
        >>> np.round(held.base_wrench, 4) + 0.0  # (+ 0.0: a zero's sign is rounding's, not the model's)
        array([0.    , 0.    , 6.3765, 0.    , 0.    , 0.    ])
        >>> pkm.base_inverse_dynamics(robot, q, rest, rest).needs_base_wrench  # free, it cannot stay at rest
        True
        >>> a = pkm.forward_dynamics(robot, q, rest, held.efforts)  # (free by default: it falls)
        >>> pkm.base_inverse_dynamics(robot, q, rest, a).needs_base_wrench
        False
    """
    mech = check_mechanism(mech)
    require_physical(mech, "inverse dynamics")
    method = as_choice(method, METHODS, "method")
    if mech.base is None:
        raise InvalidInputError("mech", "the mechanism has no floating base (spec.floating_base): its base is the "
                                        "world, whose reaction pkm does not model", mech.base)
    base = actuator_space.base_choice(mech, base)
    q, v, a = mech.check_q(q), mech.check_v(v), mech.check_v(a, "a")
    tau = _motor_efforts(mech, q, v, a, wrench, wrenches, method)
    red = actuator_space._reduce(mech, q, RTOL, "free")
    Gb = red.Gb
    r = _tree_efforts(mech, q, v, a)  # (a copy: _external leaves it as it is)
    h = _external(mech, q, r, wrench, wrenches)
    w = finite_result(Gb.T @ h, "base wrench")
    needs = False
    if base == "free":
        # relative to the wrenches it sums, moments over the characteristic length (the same for any size)
        unit = np.r_[np.ones(3), np.full(3, 1.0 / mech.characteristic_length)]
        bias = _tree_efforts(mech, q, v, np.zeros(mech.nv))
        parts = (Gb.T @ (red.M @ a), Gb.T @ bias, Gb.T @ (h - r))
        scale = sum(float(np.linalg.norm(unit * p)) for p in parts)
        needs = bool(np.linalg.norm(unit * w) > BASE_WRENCH_RTOL * scale)
    R = pin.XYZQUATToSE3(q[mech.base.idx_q:mech.base.idx_q + 7]).rotation
    world = np.r_[R @ w[:3], R @ w[3:]]
    return BaseInverseDynamics(tau, w, base, needs, world)


def virtual_work_dynamics(mech: Mechanism, q: ArrayLike, v: ArrayLike, a: ArrayLike, wrench: ArrayLike | None = None, *, wrenches: Mapping[str, ArrayLike] | None = None) \
        -> np.ndarray:
    """Actuator efforts as ``G^T (rnea(q, v, a) - sum J_f^T w_f)``, ``G = dq/dq_a`` (:func:`pkm.passive_map`, idle
    motions mass-orthogonal: ``G^T M N = 0``, so that no idle acceleration in ``a`` changes the efforts): the
    whole-tree virtual-work route (external wrenches as in :func:`inverse_dynamics`)."""
    mech = check_mechanism(mech)
    require_physical(mech, "inverse dynamics")
    q, v, a = mech.check_q(q), mech.check_v(v), mech.check_v(a, "a")
    G = passive_map(mech, q)
    h = _external(mech, q, _tree_efforts(mech, q, v, a), wrench, wrenches)
    return finite_result(G.T @ h, "actuator efforts")


FORWARD_METHODS = ("model", "constraint_dynamics")


def forward_dynamics(mech: Mechanism, q: ArrayLike, v: ArrayLike, tau_actuated: ArrayLike, *, method: str = "model",
                     mu: float | None = None, base: str | None = None,
                     base_wrench: ArrayLike | None = None) -> np.ndarray:
    """Joint accelerations (nv,) under actuator efforts.

    A floating base is free by default: no wrench on it but ``base_wrench``, its acceleration from its own equations
    (:mod:`pkm.core.dynamics.model`); ``base="fixed"`` holds it.

    Args:
        mech: The mechanism.
        q, v: An assembled configuration and consistent joint rates (nv,) (or, for ``"model"``, the actuated rates).
        tau_actuated: Efforts in ``mech.actuated`` order [N m, N].
        method: ``"model"`` (default): the actuated-coordinate model
            (:func:`pkm.core.dynamics.model.forward_dynamics`), exact by rank on redundant closures;
            ``"constraint_dynamics"``: Pinocchio's, :func:`constraint_dynamics` (the independent check).
        mu: For ``"constraint_dynamics"`` only (see there).
        base: A floating base ``"free"`` (default where there is one) or ``"fixed"`` (held).
        base_wrench: A wrench applied to a free base: Pinocchio's free-flyer force ``(f [N], m [N m])`` in the
            base's frame, about its origin.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q, v = delta.q_reference, np.zeros(delta.nv)
        >>> a = pkm.forward_dynamics(delta, q, v, [0.5, 0.5, 0.5])
        >>> np.round(delta.actuated_q(a), 2)
        array([176.76, 176.76, 176.76])
        >>> np.allclose(pkm.inverse_dynamics(delta, q, v, a), [0.5, 0.5, 0.5])
        True
    """
    method = as_choice(method, FORWARD_METHODS, "method")
    if method == "constraint_dynamics":
        return constraint_dynamics(mech, q, v, tau_actuated, mu=mu, base=base, base_wrench=base_wrench)
    if mu is not None:
        raise InvalidInputError("mu", "the model route needs no regularisation; mu is for "
                                      "method='constraint_dynamics'", mu)
    return actuator_space.forward_dynamics(mech, q, v, tau_actuated, base=base, base_wrench=base_wrench)


def constraint_dynamics(mech: Mechanism, q: ArrayLike, v: ArrayLike, tau_actuated: ArrayLike, *,
                        mu: float | None = None, max_iter: int = 1000, base: str | None = None,
                        base_wrench: ArrayLike | None = None) -> np.ndarray:
    """Joint accelerations by Pinocchio's ``constraintDynamics``: the closures enforced at the acceleration level
    with no Baumgarte correction (the state must be assembled and consistent).

    A floating base is free by default (no generalised force on its rows but ``base_wrench``, as the model's);
    ``base="fixed"`` welds it to the world where ``q`` puts it (a 6-D constraint; its twist in ``v`` must be zero).

    Args:
        mu: The proximal regularisation. Default: 0 where the closure equations are independent, else 1e-9 with
            up to ``max_iter`` proximal iterations (which converge to the exact accelerations; with ``mu=0`` a
            redundant closure, such as a planar loop closed with a 6-D frame, gives wrong accelerations or NaN).
        max_iter: Proximal iterations allowed.
        base: A floating base ``"free"`` (default where there is one) or ``"fixed"`` (welded).
        base_wrench: A wrench applied to a free base (:func:`forward_dynamics`).

    Raises:
        SingularityError: ``mu=0`` on redundant closures.
        InvalidInputError: a held base given a twist, or a wrench.
        PkmError: The model has mimic joints (Pinocchio 4.1's ``constraintDynamics`` does not handle them).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q, v = delta.q_reference, np.zeros(delta.nv)
        >>> a = pkm.constraint_dynamics(delta, q, v, [0.5, 0.5, 0.5])
        >>> np.round(delta.actuated_q(a), 2)
        array([176.76, 176.76, 176.76])
        >>> np.allclose(a, pkm.forward_dynamics(delta, q, v, [0.5, 0.5, 0.5]))
        True
    """
    mech = check_mechanism(mech)
    require_physical(mech, "forward dynamics")
    q, v = mech.check_q(q), mech.check_v(v)
    tau_a = mech.check_actuated(tau_actuated, "tau_actuated", order="effort")
    if has_mimic(mech.model):
        raise PkmError("constraintDynamics does not support mimic joints on Pinocchio 4.1")
    s = np.linalg.svd(JacobianScales.of(mech).constraint(finite_result(constraints.jacobian(mech, q),
                                                                     "constraint Jacobian")), compute_uv=False)
    redundant = bool(s.size) and (s.size < mech.n_constraints or s[-1] <= RTOL * float(s[0]))
    if mu is None:
        mu = 1e-9 if redundant else 0.0
    mu = as_scalar(mu, "mu", low=0.0)
    max_iter = as_count(max_iter, "max_iter")
    if mu == 0.0 and redundant:
        raise SingularityError("constraint", float(s[-1]), "the closure equations are redundant (a planar "
                                                           "mechanism closed with 3-D points?): pass mu > 0, e.g. "
                                                           "mu=1e-9, or use method='model'")
    base = actuator_space.base_choice(mech, base)
    tau = mech.springs.efforts(q)  # (the joint springs' efforts, applied as joint torques)
    tau[mech.act_v] += tau_a
    models, datas = mech.constraint_models, mech.constraint_datas
    if base == "free" and base_wrench is not None:
        tau[mech.base_v] = as_vector(base_wrench, 6, "base_wrench")
    elif base_wrench is not None:
        raise InvalidInputError("base_wrench", "the base is fixed (held: no wrench to apply to it)", base_wrench)
    if base == "fixed" and mech.base is not None:  # (the base welded to the world where q puts it)
        if np.any(v[mech.base_v] != 0.0):
            raise InvalidInputError("v", "a held base (base='fixed') has no twist: zero v on its free-flyer entries",
                                    v[mech.base_v])
        bq = mech.base.idx_q
        weld = pin.RigidConstraintModel(pin.ContactType.CONTACT_6D, mech.model, mech.base.id, pin.SE3.Identity(), 0,
                                        pin.XYZQUATToSE3(q[bq:bq + 7]), pin.LOCAL)
        models = [*models, weld]
        datas = [cm.createData() for cm in models]
    pin.initConstraintDynamics(mech.model, mech.data, models, datas)
    settings = pin.ProximalSettings(1e-14, mu, max_iter if mu > 0.0 else 1)
    a = pin.constraintDynamics(mech.model, mech.data, q, v, tau, models, datas, settings).copy()
    return finite_result(a, "joint accelerations", "constraintDynamics failed (a singular configuration?)")


def energy(mech: Mechanism, q: ArrayLike, v: ArrayLike) -> tuple[float, float]:
    """Kinetic [J] and potential [J] energy of every body: gravity's (``mech.model.gravity``) and the joint
    springs' (``Σ ½ k (q - rest)²``, :mod:`pkm.core.model.springs`)."""
    mech = check_mechanism(mech)
    require_physical(mech, "the energy")
    q, v = mech.check_q(q), mech.check_v(v)
    m, d = mech.model, mech.data
    if not has_mimic(m):
        return (float(pin.computeKineticEnergy(m, d, q, v)),
                float(pin.computePotentialEnergy(m, d, q)) + mech.springs.energy(q))
    # Pinocchio 4.1's energy routines refuse mimic joints (the hexapod): sum over the bodies instead
    pin.forwardKinematics(m, d, q, v)
    bodies = range(1, m.njoints)
    kinetic = sum(0.5 * m.inertias[i].vtiv(d.v[i]) for i in bodies)
    potential = -sum(m.inertias[i].mass * float(m.gravity.linear @ d.oMi[i].act(m.inertias[i].lever)) for i in bodies)
    return float(kinetic), float(potential) + mech.springs.energy(q)


__all__ = ["BASE_WRENCH_RTOL", "FORWARD_METHODS", "METHODS", "BaseInverseDynamics", "KhalilProjection", "Leg", "Partition", "Projection", "base_inverse_dynamics", "constraint_dynamics",
           "energy", "forward_dynamics", "inverse_dynamics",
           "partition", "virtual_work_dynamics"]
