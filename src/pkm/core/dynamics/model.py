r"""The dynamic model of any closed-loop mechanism in its actuated coordinates.

The closures leave ``na`` degrees of freedom, driven by the actuated joints: the state is the configuration ``q``
(assembled) and the actuated rates ``qd`` (``q̇_a``). With ``J_c = [J_a J_p]`` the closure Jacobian split into
actuated and passive columns (:mod:`pkm.core.kinematics.constraints`), ``M`` Pinocchio's joint-space mass matrix
(``crba``, the actuators' reflected inertia on its diagonal, :mod:`pkm.core.model.actuators`) and ``b`` its
non-linear effects (``rnea``):

* ``Ĝ``: joint rates from actuated rates, ``v = Ĝ qd`` (:func:`~pkm.core.differential.velocity.passive_map`,
  :func:`pkm.velocities`);
* the **idle motions** ``N`` (a rod spinning between two balls: passive motions the closures and the task leave
  free with the actuators locked) are **kept out of the state** by pkm's one idle-motion convention
  (:mod:`pkm.core.differential.idle`): rates and accelerations carry none in the mass metric, ``Ĝ = G - N (Nᵀ M
  N)⁺ Nᵀ M G`` (``G`` the minimum-norm map), so that ``Nᵀ M Ĝ = 0`` and the spin carries no momentum of its own.
  For a rod whose inertia is symmetric about the line of its two balls (any cylinder, any point mass) ``Ĝ = G``: the
  spin decouples exactly and a spin started at zero stays zero; otherwise the spin is slaved to carry no momentum
  (exact for a spin-free start to first order). No idle acceleration changes an effort (``Ĝᵀ M N = 0``);
* ``a = Ĝ qdd + a_b`` (:func:`pkm.accelerations`), ``a_b`` the closure's drift compensation (``J_c a_b + gamma =
  0``, no actuated acceleration, no idle acceleration in the mass metric).

Then, with :math:`\tau_a` the actuator efforts,

$$
M_a(q)\,\ddot q_a + h_a(q, \dot q_a) = \tau_a + f_a(q, \dot q_a), \qquad
M_a = \hat G^\top M \hat G, \qquad h_a = \hat G^\top \left(\mathrm{rnea}(q, \hat G \dot q_a, a_b) - \tau_s(q)\right)
$$

where :math:`h_a` holds the Coriolis, centrifugal, gravity and spring terms and the drift of the closures,
:math:`\tau_s = -K (q - q_{rest})` the joint springs' efforts (``[springs]``, :mod:`pkm.core.model.springs`; zero
without springs), :math:`g_a = \hat G^\top (g(q) - \tau_s(q))` the static efforts, gravity's and the springs' (the
efforts that hold the mechanism still: :func:`gravity_efforts`; the springs' share
:math:`s_a = -\hat G^\top \tau_s` is :func:`spring_efforts`), and :math:`f_a = \hat G^\top (-D v - F \operatorname{sgn}(v))` the joints' friction (Pinocchio's
``damping`` ``D`` and ``friction`` ``F``, the actuators' viscous and Coulomb friction and the springs' damping among
them; ``sgn`` a sign
smoothed over ``coulomb_velocity``). :math:`\tfrac{1}{2} \dot q_a^\top M_a \dot q_a` is the kinetic energy. The
Coriolis matrix :math:`C_a` is built from the Christoffel symbols of :math:`M_a` (:func:`coriolis_matrix`), so that
:math:`\dot M_a - 2 C_a` is skew-symmetric; the derivatives of ``M_a``
are Richardson-extrapolated central differences on the closed mechanism (steps of 2e-5 and 1e-5 in the actuated
coordinates).

In task coordinates (a task of ``na`` coordinates, :math:`\dot y = J \dot q_a`),
:math:`\Lambda = J^{-\top} M_a J^{-1}` (Khatib's operational-space inertia) and
:math:`\mu = J^{-\top} h_a - \Lambda \ddot y_b` (:math:`\ddot y_b` the task acceleration at :math:`\ddot q_a = 0`):
:math:`J^{-\top} \tau_a = \Lambda \ddot y + \mu`.

**A floating base** (``spec.floating_base``, a free-flyer on the world carrying the tree) is **free** by default
(``base="free"``): no wrench acts on it unless one is applied, and its acceleration comes from its own six rows of
the equations of motion. With ``Ĝ_b`` the joint rates of a unit base twist (the actuators locked, the passive joints
following the closures; in Pinocchio's free-flyer velocity: linear then angular, in the base's own frame),
``M_bb = Ĝ_bᵀ M Ĝ_b`` the locked robot's spatial inertia and ``M_ba = Ĝ_bᵀ M Ĝ``, the base rows
``M_bb a_b + M_ba q̈_a + Ĝ_bᵀ rnea = w_b`` (``w_b`` the wrench applied to the base, default zero) are solved for
the base acceleration and eliminated: the model above holds with ``Ĝ`` replaced by ``Ĝ - Ĝ_b M_bb⁻¹ M_ba`` (the
actuated map mass-orthogonal to the base motions) and ``a_b`` by ``a_b - Ĝ_b M_bb⁻¹ Ĝ_bᵀ rnea(q, v, a_b)`` (gravity
and the velocity terms accelerate the base). The state is then ``(q, q̇_a, v_base)``: ``v = Ĝ q̇_a + Ĝ_b v_base``,
the base's twist read from the joint rates' free-flyer entries (zero where only actuated rates are given). This is
the motion Pinocchio's ``constraintDynamics`` gives (tests: 1e-8). ``base="fixed"`` holds the base where ``q`` puts
it, at rest (its reaction is what :func:`pkm.base_inverse_dynamics` reports): the model of a fixed-base mechanism,
and of the transmissions' sub-mechanisms. The idle-motion rule (no motion in the mass metric) is *not* the base's:
an idle spin has no force of its own to answer, a base has gravity. The choice is named by every result
(:attr:`ActuatorSpaceModel.base`).

Redundant closures (a planar loop closed with a 6-D frame) are handled by rank: ``J_p``'s pseudo-inverse drops the
dependent rows; no regularisation is involved. A direct singularity (a passive motion the actuators do not hold)
and an actuated motion that moves no mass raise :class:`~pkm.errors.SingularityError`.

Checks (tests): ``M_a qdd + h_a`` equals :func:`pkm.inverse_dynamics` to 1e-10 relative; ``½ qdᵀ M_a qd`` equals
Pinocchio's kinetic energy; ``Ṁ_a - 2C_a`` is skew against finite differences of ``M_a``; the forward dynamics
equals Pinocchio's ``constraintDynamics`` (proximal where closures are redundant).
"""

from __future__ import annotations

import warnings
import weakref
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.differential.idle import joint_inertia, without_idle
from pkm.core.differential.velocity import RTOL, homogenised_pinv  # (one rank threshold with pkm.diagnose's)
from pkm.core.kinematics import constraints
from pkm.core.kinematics.solve import close_loops
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism, check_mechanism, require_independent_actuators
from pkm.core.model.plausibility import require_physical
from pkm.core.model.scale import JacobianScales
from pkm.errors import InvalidInputError, PkmWarning, SingularityError, SpecError
from pkm.validation import as_scalar, as_tolerance, as_vector, finite_result

COULOMB_VELOCITY = 1e-3  # [rad/s or m/s]: the Coulomb friction's sign is smoothed as tanh(v / this)
_FD_STEP = 2e-5
#: How a floating base moves in the dynamics: ``"free"`` (its own equations, no wrench unless applied; the default
#: where the mechanism has one) or ``"fixed"`` (held where ``q`` puts it; the only choice without a floating base).
BASES = ("free", "fixed")


def base_choice(mech: Mechanism, base: str | None) -> str:
    """``base`` checked: ``"free"`` or ``"fixed"``; None gives ``"free"`` where ``mech`` has a floating base, else
    ``"fixed"``.

    Raises:
        InvalidInputError: another value, or ``"free"`` on a mechanism without a floating base.
    """
    if base is None:
        return "free" if mech.base is not None else "fixed"
    if not isinstance(base, str) or base not in BASES:
        raise InvalidInputError("base", f"use one of {list(BASES)}, got {base!r}", base)
    if base == "free" and mech.base is None:
        raise InvalidInputError("base", "the mechanism has no floating base (spec.floating_base): its base is fixed",
                                base)
    return base


_WARNED: weakref.WeakSet[Mechanism] = weakref.WeakSet()


def _warn_idle_free_flyer(mech: Mechanism, idle: np.ndarray) -> None:
    """Warn (once per mechanism) where an idle motion moves a passive free-flyer on the world: a body that is a
    floating base but not declared one, whose acceleration the idle-motion rule sets where gravity should."""
    if mech in _WARNED:
        return
    for j in mech.joints.values():
        if j.kind == "JointModelFreeFlyer" and mech.model.parents[j.id] == 0 and \
                np.any(idle[j.idx_v:j.idx_v + 6] != 0.0):
            _WARNED.add(mech)
            warnings.warn(f"the free-flyer {j.name!r} on the world is a passive joint the actuators do not move: pkm "
                          "sets its acceleration by the idle-motion rule (no motion in the mass metric), not by its "
                          "own equations (gravity acts on it): declare it the spec's floating_base for a free "
                          "base's dynamics", PkmWarning, stacklevel=4)
            return


_WARNED_SPRINGS: weakref.WeakSet[Mechanism] = weakref.WeakSet()


def _warn_idle_springs(mech: Mechanism, idle: np.ndarray) -> None:
    """Warn (once per mechanism) where an idle motion moves a sprung joint (Cassie's leaf springs): the motion is a
    freedom of its own, which the idle-motion rule sets (no motion in the mass metric) where the springs and the
    bodies' inertia should (issue 51)."""
    springs = mech.springs
    if mech in _WARNED_SPRINGS or not springs:
        return
    moved = [name for name, iv in zip(springs.names, springs.idx_v) if np.max(np.abs(idle[iv]), initial=0.0) > 1e-9]
    if moved:
        _WARNED_SPRINGS.add(mech)
        warnings.warn(f"the idle motions move the sprung joints {moved}: pkm sets their rates and accelerations by the "
                      "idle-motion rule (no motion in the mass metric), not by the springs and the bodies' inertia: "
                      "the actuated coordinates' dynamics is exact, these joints' motion is not (a passive freedom "
                      "the actuators do not hold, such as a leaf spring, is not simulated as one)", PkmWarning,
                      stacklevel=4)


@dataclass(frozen=True)
class _Reduction:
    """What the model needs of the kinematics at ``q``: ``Ĝ``, the passive pseudo-inverse, the idle motions, and for
    a free base ``Ĝ_b``."""

    G: np.ndarray  # nv x na, Ĝ
    Jp_pinv: np.ndarray  # n_passive x n_constraints
    idle: np.ndarray  # nv x k
    M: np.ndarray  # nv x nv, crba with the reflected inertias
    Gb: np.ndarray  # nv x 6 (free base) or nv x 0: joint rates of a unit base twist, the actuators locked


def _reduce(mech: Mechanism, q: np.ndarray, rtol: float, base: str = "fixed", Jc: np.ndarray | None = None
            ) -> _Reduction:
    """The rank of ``J_p`` and the idle motions are judged on the Jacobians homogenised by the mechanism's
    characteristic length (:mod:`pkm.core.model.scale`), as :func:`pkm.diagnose` judges them: the same for the
    mechanism scaled in size. ``Jc``: the constraint Jacobian at ``q`` where the caller has it (the simulation's
    loop closure ends with it), else computed here."""
    scales = JacobianScales.of(mech)
    Jc = constraints.jacobian(mech, q) if Jc is None else Jc
    pv, av = mech.passive_v, mech.act_v
    Jp_pinv, s, Vt, r = homogenised_pinv(Jc[:, pv], scales.constraint_rows, scales.columns[pv], rtol)
    smax = float(s[0]) if s.size else 0.0
    G = np.zeros((mech.nv, mech.na))
    G[av, np.arange(mech.na)] = 1.0
    G[pv] = -Jp_pinv @ Jc[:, av]
    null = Vt[r:].T
    idle = np.zeros((mech.nv, null.shape[1]))
    if null.shape[1]:  # passive motions with the actuators locked: idle (the task does not see them) or singular
        idle[pv] = null
        Jt = scales.task(TaskMap.of(mech).jacobian(q))
        seen = np.linalg.svd(Jt @ idle, compute_uv=False)
        t_ref = max(float(np.linalg.norm(Jt, 2)), 1e-300)
        if seen.size and seen[0] > rtol * t_ref:
            sigma = float(s[r]) if r < s.size else 0.0
            raise SingularityError("direct", sigma,
                                   "with the actuators locked a passive motion moves the task: the actuators do "
                                   "not hold the mechanism here, its dynamics in actuated coordinates is undefined",
                                   distance=sigma / smax if smax > 0.0 else 0.0)
        idle = scales.joint_motions(idle)  # (in joint rates, orthonormal)
        _warn_idle_free_flyer(mech, idle)
        _warn_idle_springs(mech, idle)
    M = joint_inertia(mech, q)
    Gb = np.zeros((mech.nv, 0))
    if base == "free":
        bv = mech.base_v
        Gb = np.zeros((mech.nv, 6))
        Gb[bv, np.arange(6)] = 1.0
        Gb[pv] = -Jp_pinv @ Jc[:, bv]
        gap = float(np.linalg.norm(scales.constraint_rows[:, None] * (Jc @ Gb) * scales.columns[bv], 2))
        if gap > np.sqrt(rtol) * max(float(np.linalg.norm(scales.constraint(Jc), 2)), 1e-300):
            name = mech.base.name if mech.base is not None else ""
            raise SpecError(mech.source, f"the closures hold the floating base {name!r} (a closure to the "
                                         "world?): it cannot move as a free body with the actuators locked (base='fixed' "
                                         "holds it in the model; its reaction is not modelled)")
        Gb = without_idle(M, idle, Gb)
    return _Reduction(without_idle(M, idle, G), Jp_pinv, idle, M, Gb)


@dataclass(frozen=True)
class ActuatorSpaceModel:
    """The dynamic model at one state ``(q, qd)`` in the actuated coordinates (see the module doc).

    Attributes:
        mech: The mechanism.
        q: The configuration (nq,).
        qd: The actuated rates (na,) [rad/s or m/s].
        v: The joint rates ``Ĝ qd`` (nv,).
        G: ``Ĝ`` (nv x na): joint rates from actuated rates, mass-orthogonal to the idle motions.
        drift_acceleration: ``a_b`` (nv,): the joint accelerations at ``qdd = 0`` (closure drift compensated, no idle
            acceleration in the mass metric).
        M: ``M_a`` (na x na) [kg m^2, kg]: symmetric, positive definite away from singularities.
        h: ``h_a`` (na,) [N m, N]: Coriolis, centrifugal, gravity, spring and closure-drift efforts.
        g: ``g_a`` (na,): the static part of ``h_a``, gravity's and the joint springs' (the efforts that hold the
            mechanism still; ``g_a - springs`` is gravity's alone).
        friction: ``f_a`` (na,): the joints' viscous and Coulomb friction at ``v`` (opposes the motion; the springs'
            damping among it).
        springs: ``s_a = Ĝᵀ K (q - rest)`` (na,): the joint springs' part of ``g_a`` and ``h_a``, the efforts that
            hold them (:mod:`pkm.core.model.springs`; zero without springs).
        idle: The idle motions (nv x k, orthonormal), carried by no rate in the mass metric.
        base: How a floating base moves: ``"free"`` (its own equations, no wrench unless applied: ``G``,
            ``drift_acceleration``, ``M``, ``h``, ``g`` and ``friction`` have the base's motion eliminated, module
            doc) or ``"fixed"`` (held at rest where ``q`` puts it; every mechanism without a floating base).
        base_velocity: The base's twist (6,) [m/s, rad/s] (Pinocchio's free-flyer rates: linear then angular, in the
            base's frame) for a free base; empty when fixed.
        base_response: ``Ĝ_b M_bb⁻¹`` (nv x 6, free base; nv x 0 fixed): the joint accelerations of a unit
            generalised force on the base's rows.
        base_friction: ``Ĝ_bᵀ f`` (6,, free base): the joints' friction on the base's rows (the share of ``f``
            that accelerates the base).
    """

    mech: Mechanism
    q: np.ndarray
    qd: np.ndarray
    v: np.ndarray
    G: np.ndarray
    drift_acceleration: np.ndarray
    M: np.ndarray
    h: np.ndarray
    g: np.ndarray
    friction: np.ndarray
    idle: np.ndarray
    _M_joint: np.ndarray
    base: str = "fixed"
    base_velocity: np.ndarray = field(default_factory=lambda: np.zeros(0))
    base_response: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    base_friction: np.ndarray = field(default_factory=lambda: np.zeros(0))
    _friction_joint: np.ndarray = field(default_factory=lambda: np.zeros(0))
    springs: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        for value in vars(self).values():
            if isinstance(value, np.ndarray):
                value.setflags(write=False)

    @property
    def kinetic_energy(self) -> float:
        r"""The kinetic energy :math:`\tfrac{1}{2} \dot q_a^\top M_a \dot q_a` [J] (a free base: the bodies'
        :math:`\tfrac{1}{2} v^\top M v`, the base's own motion in it)."""
        if self.base == "free":
            return float(0.5 * self.v @ self._M_joint @ self.v)
        return float(0.5 * self.qd @ self.M @ self.qd)

    @property
    def friction_power(self) -> float:
        """The power of the joints' friction at this state [W] (<= 0): ``f_a · q̇_a``, with a free base the bodies'
        ``f · v`` (the base's motion in it)."""
        if self.base == "free":
            return float(self._friction_joint @ self.v)
        return float(self.friction @ self.qd)

    def efforts(self, qdd: ArrayLike) -> np.ndarray:
        r""":math:`M_a \ddot q_a + h_a` (na,) [N m, N]: the efforts for actuated accelerations ``qdd`` (no friction)."""
        qdd = self.mech.check_actuated(qdd, "qdd")
        return finite_result(self.M @ qdd + self.h, "actuator efforts")

    def accelerations(self, tau: ArrayLike, *, friction: bool = True,
                      base_wrench: ArrayLike | None = None) -> np.ndarray:
        r""":math:`\ddot q_a = M_a^{-1} (\tau_a + f_a - h_a)` (na,) for actuator efforts ``tau`` (with the friction,
        by default).

        Args:
            base_wrench: A free base only: the wrench applied to the base (6,), Pinocchio's free-flyer force: ``(f [N],
                m [N m])`` in the base's frame, about its origin (default none: the base is free).

        Raises:
            SingularityError: ``kind="inertia"``: an actuated motion moves no mass (``M_a`` singular).
        """
        tau = self.mech.check_actuated(tau, "tau", order="effort")
        rhs = tau + (self.friction if friction else 0.0) - self.h
        w = self._base_wrench(base_wrench)
        if w is not None:
            rhs = rhs + self.G[self.mech.base_v].T @ w  # (the applied wrench through the eliminated base rows)
        return finite_result(_solve_inertia(self.M, rhs, JacobianScales.of(self.mech).actuated),
                             "actuated accelerations")

    def joint_accelerations(self, qdd: ArrayLike, *, friction: bool = False,
                            base_wrench: ArrayLike | None = None) -> np.ndarray:
        """All joint accelerations (nv,) for actuated ones: ``Ĝ qdd + a_b``, as :func:`pkm.accelerations` gives them
        (no idle acceleration in the mass metric); a free base's acceleration is that of its own equations, with the
        joints' friction on its rows where ``friction`` (as :meth:`accelerations` had it) and ``base_wrench``
        applied (as there). Both change nothing on a fixed base."""
        qdd = self.mech.check_actuated(qdd, "qdd")
        a = self.G @ qdd + self.drift_acceleration
        if self.base == "free":
            w = self._base_wrench(base_wrench)
            force = self.base_friction.copy() if friction else np.zeros(6)
            if w is not None:
                force += w
            a = a + self.base_response @ force
        return finite_result(a, "joint accelerations")

    def _base_wrench(self, base_wrench: ArrayLike | None) -> np.ndarray | None:
        if base_wrench is None:
            return None
        if self.base != "free":
            raise InvalidInputError("base_wrench", "the base is fixed (held: no wrench to apply to it); a wrench "
                                                   "on a free base only", base_wrench)
        return as_vector(base_wrench, 6, "base_wrench")


def _solve_inertia(M: np.ndarray, rhs: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """``M^-1 rhs`` by Cholesky, refused where the factor's diagonal, homogenised by ``scale`` (the actuated columns'
    factors of :class:`~pkm.core.model.scale.JacobianScales`: ``L`` for a prismatic actuator, so that every entry of
    ``D M D`` is in kg m^2), spans more than ``1 / sqrt(RTOL)``: the same test for the mechanism scaled in size."""
    try:
        L = np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        L = None
    if L is not None:
        d = np.diag(L) * scale
        if d.min() > np.sqrt(RTOL) * d.max():
            return np.linalg.solve(L.T, np.linalg.solve(L, rhs))
    w = np.linalg.eigvalsh(M)
    raise SingularityError("inertia", float(max(w[0], 0.0)), "an actuated motion moves no mass (the actuator-space "
                                                             "mass matrix is singular): give the bodies or the "
                                                             "actuators (rotor_inertia) inertia")


def _held_only(mech: Mechanism, base: str | None) -> str:
    """``base`` checked for the functions that model the held base only (the Christoffel symbols)."""
    if base_choice(mech, base) == "free":
        raise InvalidInputError("base", "the Christoffel symbols of M_a describe a held base (a free base's momentum "
                                        "is a state of its own, not a function of q_a): pass base='fixed'", base)
    return "fixed"


def _check_state(mech: Mechanism, q: ArrayLike, qd: ArrayLike | None, base: str | None = None, name: str = "qd") \
        -> tuple[Mechanism, np.ndarray, np.ndarray, str, np.ndarray]:
    """``(mech, q, qd, base, base_velocity)`` checked: all joint rates (nv,) give the actuated rates and, for a free
    base, its twist; actuated rates (na,) a base at rest; ``name``: the rates' name in an error."""
    mech = check_mechanism(mech)
    base = base_choice(mech, base)
    q = mech.check_q(q)
    rest = np.zeros(6 if base == "free" else 0)
    if qd is None:
        return mech, q, np.zeros(mech.na), base, rest
    try:
        arr = np.asarray(qd, dtype=float) if not isinstance(qd, str) else None
    except (TypeError, ValueError, OverflowError):  # (check_actuated says what is wrong)
        arr = None
    if arr is not None and arr.shape == (mech.nv,) and mech.nv != mech.na:
        arr = mech.check_v(arr, name)
        return mech, q, mech.check_actuated(arr[mech.act_v], name), base, arr[mech.base_v] if len(rest) else rest
    return mech, q, mech.check_actuated(qd, name, order="rate"), base, rest


def _evaluate(mech: Mechanism, q: np.ndarray, qd: np.ndarray, rtol: float,
              coulomb_velocity: float = COULOMB_VELOCITY, base: str = "fixed",
              base_velocity: np.ndarray | None = None, Jc: np.ndarray | None = None) -> ActuatorSpaceModel:
    red = _reduce(mech, q, rtol, base, Jc)
    m, d = mech.model, mech.data
    free = red.Gb.shape[1] > 0
    vb = np.zeros(red.Gb.shape[1]) if base_velocity is None else np.array(base_velocity, dtype=float)
    v = red.G @ qd + red.Gb @ vb
    a_b = np.zeros(mech.nv)
    if mech.n_constraints:
        a_b[mech.passive_v] = -red.Jp_pinv @ constraints.drift(mech, q, v)
        a_b = without_idle(red.M, red.idle, a_b)
    spring = mech.springs.efforts(q)  # (τ_s = -k (q - rest): zero without springs)
    b = pin.rnea(m, d, q, v, a_b) - spring
    g = pin.computeGeneralizedGravity(m, d, q) - spring
    f_joint = -np.asarray(m.damping) * v - np.asarray(m.friction) * np.tanh(v / coulomb_velocity)
    G = red.G
    response, base_friction = np.zeros((mech.nv, 0)), np.zeros(0)
    if free:  # (the base's rows solved for its acceleration and eliminated: module doc)
        Gb = red.Gb
        M_bb = Gb.T @ red.M @ Gb
        try:
            L_inv = np.linalg.inv(np.linalg.cholesky(0.5 * (M_bb + M_bb.T)))
        except np.linalg.LinAlgError:
            raise SingularityError("inertia", float(max(np.linalg.eigvalsh(M_bb)[0], 0.0)),
                                   "the floating base with the actuators locked moves no mass in some direction: "
                                   "a free base needs a spatial inertia") from None
        response = Gb @ (L_inv.T @ L_inv)  # Ĝ_b M_bb⁻¹
        G = G - response @ (Gb.T @ red.M @ G)
        a_b = a_b - response @ (Gb.T @ b)  # (Gᵀ rnea is unchanged by it: the new G is mass-orthogonal to Ĝ_b)
        base_friction = Gb.T @ f_joint
    Gt = G.T
    M_a = Gt @ red.M @ G
    M_a = 0.5 * (M_a + M_a.T)
    return ActuatorSpaceModel(mech, q, qd.copy(), v, G, a_b, finite_result(M_a, "actuator-space mass matrix"),
                              finite_result(Gt @ b, "actuator-space bias"), Gt @ g, Gt @ f_joint, red.idle,
                              red.M, base, vb, response, base_friction, f_joint, -(Gt @ spring))


def actuator_model(mech: Mechanism, q: ArrayLike, qd: ArrayLike | None = None, *, rtol: float = RTOL,
                   coulomb_velocity: float = COULOMB_VELOCITY, base: str | None = None) -> ActuatorSpaceModel:
    r"""The dynamic model of ``mech`` in its actuated coordinates at the state ``(q, qd)``:
    :math:`M_a(q)\,\ddot q_a + h_a(q, \dot q_a) = \tau_a + f_a(q, \dot q_a)` (module doc).

    Args:
        mech: The mechanism.
        q: An assembled configuration (nq,) (:func:`pkm.close_loops`).
        qd: The actuated rates (na,) [rad/s or m/s], or all joint rates (nv,), read on their actuated entries (and
            a free base's twist on its entries; with actuated rates alone a free base is at rest); default zero.
        rtol: Relative rank threshold (redundant closures, idle motions, singularities).
        coulomb_velocity: The speed over which the Coulomb friction's sign is smoothed [rad/s or m/s].
        base: A floating base ``"free"`` (default where there is one: its own equations, no wrench on it) or
            ``"fixed"`` (held; the only choice, and the default, without a floating base). Module doc.

    Raises:
        SingularityError: ``kind="direct"`` at a direct singularity.
        SpecError: ``base="free"`` where the closures hold the base.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> model = pkm.actuator_model(delta, delta.q_reference, [1.0, 0.0, 0.0])
        >>> np.round(model.M, 5)
        array([[ 0.00298, -0.00058, -0.00058],
               [-0.00058,  0.00298, -0.00058],
               [-0.00058, -0.00058,  0.00298]])
        >>> np.round(model.h, 4)
        array([0.1784, 0.1805, 0.1805])
        >>> np.round(model.efforts([10.0, 0.0, 0.0]), 4)
        array([0.2082, 0.1747, 0.1747])
        >>> np.allclose(model.efforts([10.0, 0.0, 0.0]), model.M @ [10.0, 0.0, 0.0] + model.h)
        True
        >>> round(model.kinetic_energy, 6)
        0.001489
    """
    mech, q, qd, base, vb = _check_state(mech, q, qd, base)
    require_physical(mech, "the dynamic model (mass matrix, bias and gravity efforts, forward dynamics)")
    rtol = as_tolerance(rtol, "rtol")
    coulomb_velocity = as_scalar(coulomb_velocity, "coulomb_velocity", low=1e-12)
    return _evaluate(mech, q, qd, rtol, coulomb_velocity, base, vb)


def mass_matrix(mech: Mechanism, q: ArrayLike, *, base: str | None = None) -> np.ndarray:
    r"""The mass matrix in the actuated coordinates :math:`M_a(q) = \hat G^\top M(q) \hat G` (na x na)
    [kg m^2, kg]: the reflected inertias in (module doc: :math:`\hat G` the passive map, :math:`M` Pinocchio's).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> M = pkm.mass_matrix(delta, delta.q_reference)
        >>> np.round(M, 5)
        array([[ 0.00298, -0.00058, -0.00058],
               [-0.00058,  0.00298, -0.00058],
               [-0.00058, -0.00058,  0.00298]])
        >>> bool(np.all(np.linalg.eigvalsh(M) > 0))
        True
    """
    return actuator_model(mech, q, base=base).M.copy()


def bias_efforts(mech: Mechanism, q: ArrayLike, qd: ArrayLike, *, base: str | None = None) -> np.ndarray:
    r"""The bias efforts :math:`h_a(q, \dot q_a)` (na,) [N m, N]: Coriolis, centrifugal, gravity, spring and
    closure-drift efforts, the efforts at :math:`\ddot q_a = 0` in :math:`M_a \ddot q_a + h_a = \tau_a + f_a` (module doc).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q = delta.q_reference
        >>> np.round(pkm.bias_efforts(delta, q, [1.0, 0.0, 0.0]), 4)
        array([0.1784, 0.1805, 0.1805])
        >>> np.allclose(pkm.bias_efforts(delta, q, np.zeros(3)), pkm.gravity_efforts(delta, q))
        True
    """
    return actuator_model(mech, q, qd, base=base).h.copy()


def gravity_efforts(mech: Mechanism, q: ArrayLike, *, base: str | None = None) -> np.ndarray:
    r"""The static efforts :math:`g_a(q) = \hat G^\top (g(q) - \tau_s(q))` (na,) [N m, N]: the actuator efforts that
    hold the mechanism still against gravity and its joint springs (``[springs]``: :func:`spring_efforts` is their
    share, zero without springs; a free base: the efforts that keep the actuated joints still while the whole robot
    falls; ``base="fixed"`` for those that hold it on a held base).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> np.round(pkm.gravity_efforts(delta, delta.q_reference), 4)
        array([0.1797, 0.1797, 0.1797])
    """
    return actuator_model(mech, q, base=base).g.copy()


def spring_efforts(mech: Mechanism, q: ArrayLike, *, base: str | None = None) -> np.ndarray:
    r"""The joint springs' share of the static efforts,
    :math:`s_a(q) = -\hat G^\top \tau_s(q) = \hat G^\top K (q - q_{rest})` (na,) [N m, N]: the actuator efforts that
    hold the springs (``[springs]``,
    :mod:`pkm.core.model.springs`) where ``q`` puts them; zero without springs. :func:`gravity_efforts` includes it.

    Examples:
        >>> import dataclasses
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> sprung = pkm.from_strings(delta.urdf, dataclasses.replace(
        ...     delta.spec, springs={"motor_1": {"stiffness": 2.0, "rest": -0.5}}))  # 2 N m/rad about -0.5 rad
        >>> q = sprung.q_reference
        >>> np.round(pkm.spring_efforts(sprung, q), 4) + 0.0  # (motor_1 at 0.0017 rad: 2 (0.0017 + 0.5) on it alone)
        array([1.0033, 0.    , 0.    ])
        >>> np.allclose(pkm.gravity_efforts(sprung, q) - pkm.spring_efforts(sprung, q), pkm.gravity_efforts(delta, q))
        True
    """
    return actuator_model(mech, q, base=base).springs.copy()


def mass_matrix_derivatives(mech: Mechanism, q: ArrayLike, *, rtol: float = RTOL,
                            base: str | None = None) -> np.ndarray:
    """``∂M_a/∂q_a`` (na x na x na, ``[k]`` the derivative along actuated coordinate ``k``), by Richardson-extrapolated
    central differences on the closed mechanism (``(4 D(h/2) - D(h)) / 3``, ``h`` = 2e-5 rad or m, each point
    closed by :func:`pkm.close_loops`; truncation O(h^4): a plain central difference is 1e-5 off on the hexapod).

    Raises:
        InvalidInputError: ``base="free"`` (the default on a floating base): the base's motion is not a function
            of ``q_a`` (its momentum is a state of its own), so the Christoffel symbols of the eliminated ``M_a``
            do not give its velocity terms; pass ``base="fixed"`` for the held base's.
        StructureError: redundant actuation (:attr:`~pkm.core.Mechanism.dependent_actuators`): a derivative along one
            actuated coordinate alone moves it away from the others' values, where the loops do not close (no
            configuration to difference); the Christoffel symbols need every one. The dependent actuators named;
            load the mechanism with the independent ones actuated (its ``M_a`` and ``C_a`` in their coordinates).
    """
    mech = check_mechanism(mech)
    require_independent_actuators(mech, "moving one actuated coordinate alone opens the loops, so M_a has no "
                                        "derivative along it and its Christoffel symbols (the Coriolis matrix) are "
                                        "undefined in these coordinates", "for them in the independent coordinates")
    require_physical(mech, "the mass matrix's derivatives")
    _held_only(mech, base)
    q = mech.check_q(q)
    rtol = as_tolerance(rtol, "rtol")
    G = _reduce(mech, q, rtol).G
    qa = mech.actuated_q(q)

    def at(k: int, step: float) -> np.ndarray:
        qs = close_loops(mech, qa + step * np.eye(mech.na)[k], pin.integrate(mech.model, q, step * G[:, k])).q
        return _evaluate(mech, qs, np.zeros(mech.na), rtol).M

    out = np.empty((mech.na, mech.na, mech.na))
    for k in range(mech.na):
        wide = (at(k, _FD_STEP) - at(k, -_FD_STEP)) / (2.0 * _FD_STEP)
        narrow = (at(k, 0.5 * _FD_STEP) - at(k, -0.5 * _FD_STEP)) / _FD_STEP
        out[k] = (4.0 * narrow - wide) / 3.0
    return out


def coriolis_matrix(mech: Mechanism, q: ArrayLike, qd: ArrayLike, *, rtol: float = RTOL,
                    base: str | None = None) -> np.ndarray:
    r"""The Coriolis matrix :math:`C_a(q, \dot q_a)` (na x na) from the Christoffel symbols of :math:`M_a`:

    $$
    C_{ij} = \sum_k \tfrac{1}{2} \left( \partial_k M_{ij} + \partial_j M_{ik} - \partial_i M_{jk} \right) \dot q_k,
    $$

    so that :math:`\dot M_a - 2 C_a` is skew-symmetric and :math:`C_a \dot q_a = h_a - g_a` (the derivatives by
    :func:`mass_matrix_derivatives`).

    Pinocchio's own ``computeCoriolisMatrix`` is not used: on Pinocchio 4.1 it is wrong for universal joints (NaN)
    and mimic joints (tested). A floating base must be held (``base="fixed"``: :func:`mass_matrix_derivatives`).
    Under redundant actuation the symbols are undefined in the actuated coordinates (one cannot move alone): a
    :class:`~pkm.errors.StructureError` names the dependent actuators (:func:`mass_matrix_derivatives`).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> q, qd = delta.q_reference, np.array([1.0, -0.5, 0.2])
        >>> C = pkm.coriolis_matrix(delta, q, qd)
        >>> np.round(C @ qd, 4)
        array([-0.0009,  0.001 ,  0.0008])
        >>> np.allclose(C @ qd, pkm.bias_efforts(delta, q, qd) - pkm.gravity_efforts(delta, q))
        True
    """
    mech, q, qd, _, _ = _check_state(mech, q, qd, _held_only(check_mechanism(mech), base))
    dM = mass_matrix_derivatives(mech, q, rtol=rtol, base="fixed")  # dM[k, i, j] = d M_ij / d q_k
    gamma = 0.5 * (dM + np.transpose(dM, (2, 1, 0)) - np.transpose(dM, (2, 0, 1)))  # gamma[k, i, j]
    return finite_result(np.einsum("kij,k->ij", gamma, qd), "Coriolis matrix")


@dataclass(frozen=True)
class OperationalSpace:
    """Khatib's operational-space model at one state: ``J⁻ᵀ τ_a = Λ ÿ + μ`` (task coordinates ``y``).

    Attributes:
        inertia: ``Λ = J⁻ᵀ M_a J⁻¹`` (n x n).
        bias: ``μ = J⁻ᵀ h_a - Λ ÿ_b`` (n,).
        jacobian: ``J``, task rates from actuated rates (n x na, square).
        drift: ``ÿ_b``, the task acceleration at zero actuated acceleration (n,).
        base: A floating base ``"free"`` or ``"fixed"`` (:attr:`ActuatorSpaceModel.base`).
    """

    inertia: np.ndarray
    bias: np.ndarray
    jacobian: np.ndarray
    drift: np.ndarray
    base: str = "fixed"


def operational_space(mech: Mechanism, q: ArrayLike, qd: ArrayLike | None = None, *,
                      rtol: float = RTOL, base: str | None = None) -> OperationalSpace:
    r"""The operational-space inertia :math:`\Lambda = J^{-\top} M_a J^{-1}` and bias :math:`\mu`, such that
    :math:`J^{-\top} \tau_a = \Lambda \ddot y + \mu`, in the task coordinates (needs as many as actuators).

    Raises:
        InvalidInputError: the task does not have ``na`` coordinates.
        SingularityError: ``kind="inverse"`` where ``J`` loses rank.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> osp = pkm.operational_space(delta, delta.q_reference)
        >>> np.round(np.diag(osp.inertia), 4)
        array([0.3011, 0.3011, 0.4505])
        >>> round(float(osp.bias[2]), 4)
        4.908
    """
    mech, q, qd, base, vb = _check_state(mech, q, qd, base)
    require_physical(mech, "the operational-space model")
    if mech.n_task != mech.na:
        raise InvalidInputError("mech", f"the task has {mech.n_task} coordinates for {mech.na} actuators: the "
                                        "operational space needs as many", mech.n_task)
    model = _evaluate(mech, q, qd, as_tolerance(rtol, "rtol"), COULOMB_VELOCITY, base, vb)
    tm = TaskMap.of(mech)
    Jt = tm.jacobian(q)
    J = Jt @ model.G
    scales = JacobianScales.of(mech)  # (homogenised: judged as for the mechanism scaled in size)
    s = np.linalg.svd(scales.forward(J), compute_uv=False)
    if s[-1] <= rtol * max(float(s[0]), 1e-300):
        raise SingularityError("inverse", float(s[-1]), "the task Jacobian J = dy/dq_a loses rank",
                               distance=float(s[-1]) / max(float(s[0]), 1e-300))
    drift = Jt @ model.drift_acceleration + tm.bias(q, model.v)
    Jinv = np.linalg.inv(J)
    Lam = Jinv.T @ model.M @ Jinv
    Lam = 0.5 * (Lam + Lam.T)
    return OperationalSpace(finite_result(Lam, "operational-space inertia"),
                            finite_result(Jinv.T @ model.h - Lam @ drift, "operational-space bias"), J, drift,
                            model.base)


def forward_dynamics(mech: Mechanism, q: ArrayLike, v: ArrayLike, tau_actuated: ArrayLike, *,
                     friction: bool = False, rtol: float = RTOL, base: str | None = None,
                     base_wrench: ArrayLike | None = None) -> np.ndarray:
    """All joint accelerations (nv,) under actuator efforts, from the actuated-coordinate model (exact by rank:
    redundant closures need no regularisation).

    Args:
        mech: The mechanism.
        q: An assembled configuration.
        v: The joint rates (nv,) or the actuated rates (na,); only the actuated rates (and a free base's twist)
            are read (the state).
        tau_actuated: Efforts in ``mech.actuated`` order [N m, N].
        friction: Include the joints' friction (:class:`ActuatorSpaceModel`); off by default, as Pinocchio's
            ``constraintDynamics``.
        rtol: Relative rank threshold.
        base: A floating base ``"free"`` (default where there is one) or ``"fixed"`` (module doc).
        base_wrench: A wrench applied to a free base (:meth:`ActuatorSpaceModel.accelerations`); default none.

    Raises:
        SingularityError: at a direct singularity, or where an actuated motion moves no mass.
    """
    model = actuator_model(mech, q, v, rtol=rtol, base=base)
    qdd = model.accelerations(tau_actuated, friction=friction, base_wrench=base_wrench)
    return model.joint_accelerations(qdd, friction=friction, base_wrench=base_wrench)


__all__ = ["BASES", "COULOMB_VELOCITY", "ActuatorSpaceModel", "OperationalSpace", "actuator_model", "base_choice",
           "bias_efforts",
           "coriolis_matrix", "forward_dynamics", "gravity_efforts", "mass_matrix", "mass_matrix_derivatives",
           "operational_space", "spring_efforts"]
