r"""A closed sub-mechanism's model with its output joints as the independent coordinates.

With the loops closed, the sub-mechanism's joints are (locally) functions of the outputs ``o``. With ``J_c`` the
closure Jacobian split into the outputs' columns ``J_o`` and the others' ``J_d``:

* ``G = ∂q/∂o`` (nv x k): ``G_o = I``, ``G_d = -J_d⁺ J_o``; the idle motions ``N`` (a rod's spin between two
  balls: what ``J_d`` leaves free with the outputs held and no motor sees) are removed in the mass metric, as pkm's
  actuator-space model removes them (:mod:`pkm.core.differential.idle`): ``Ĝ = G - N (Nᵀ M N)⁺ Nᵀ M G``;
* ``Ġ ȯ`` (nv): the joint accelerations at ``ö = 0``: ``J_d a_d = -gamma`` (``gamma = J̇_c v``, :func:`~pkm.core.kinematics.
  constraints.drift`), ``a_o = 0``, the idle part removed in the mass metric;
* the Khalil / constraint projection with the outputs as the independent coordinates:

$$
M_o = \hat G^\top M \hat G, \qquad h_o = \hat G^\top \big(h(q, \hat G \dot o) + M \dot G \dot o\big)
    = \hat G^\top \mathrm{rnea}(q, \hat G \dot o, \dot G \dot o)
$$

with ``M`` Pinocchio's mass matrix with the motors' reflected inertia on its diagonal (the rotors included) and
``h`` the Coriolis, centrifugal and gravity efforts, less the joint springs' ``τ_s`` (``[springs]``,
:mod:`pkm.core.model.springs`; those off the outputs are what a serial-equivalent model lacks, in ``Δh``). The motors'
rates are ``Ĝ_m ȯ`` (``Ĝ_m = ∂m/∂o``, the inverse of
the velocity map ``J = ∂o/∂m``), so the effort maps are ``τ_m = Jᵀ τ_o = Ĝ_m⁻ᵀ τ_o`` and ``τ_o = Ĝ_mᵀ τ_m``.

Checked (tests) against the independent route of pkm's actuator-space model (the motors independent):
``pkm.mass_matrix = Jᵀ M_o J`` and ``pkm.bias_efforts = Jᵀ (h_o + M_o J̇ q̇_m)`` (``J̇ q̇_m`` the outputs'
acceleration at ``q̈_m = 0``, :func:`pkm.accelerations`) to 1e-10 relative; ``Ġ ȯ`` against finite differences of
``Ĝ`` along the motion.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pkm.core.differential.idle import joint_inertia, without_idle
from pkm.core.differential.velocity import RTOL, homogenised_pinv
from pkm.core.kinematics import constraints
from pkm.core.model.mechanism import Mechanism
from pkm.core.model.scale import JacobianScales
from pkm.errors import ConvergenceError

#: The transmissions' position solvers' tolerance on the closure residual, relative to the sub-mechanism's
#: characteristic length (:func:`closure_tol`; 1e-13 m on a sub-mechanism of 0.1 m, where it was 1e-13 m on any):
#: tight, so that a round trip motors -> outputs -> motors comes back to 1e-12.
CLOSURE_RTOL = 1e-12


@dataclass(frozen=True)
class OutputSplit:
    """The sub-mechanism's kinematics at ``q`` with the outputs independent (module doc).

    Attributes:
        G: ``Ĝ`` (nv x k): joint rates from output rates, mass-orthogonal to the idle motions.
        Jd_pinv: ``J_d⁺`` (n_d x n_constraints), ``d`` the joints other than the outputs.
        idle: The idle motions (nv x n_idle, orthonormal in joint rates).
        M: Pinocchio's mass matrix (nv x nv), the reflected inertias on its diagonal [kg m^2, kg].
        motor_leak: The largest motor component of an idle motion (0 when the outputs hold the motors; more: the
            outputs are singular, the motors move with the outputs held).
        dependence: ``‖J_c Ĝ‖ / ‖J_c‖`` (homogenised): 0 when the closures leave the outputs independent.
        sigma: The smallest singular value of ``J_d`` kept, relative to its largest (homogenised).
    """

    G: np.ndarray
    Jd_pinv: np.ndarray
    idle: np.ndarray
    M: np.ndarray
    motor_leak: float
    dependence: float
    sigma: float


def output_split(sub: Mechanism, q: np.ndarray, out_v: np.ndarray, motor_v: np.ndarray) -> OutputSplit:
    """:class:`OutputSplit` of the sub-mechanism ``sub`` at ``q`` (closed), outputs at velocity indices ``out_v``."""
    scales = JacobianScales.of(sub)
    Jc, G, Jd_pinv, s, r, null = _split(sub, q, out_v)
    smax = float(s[0]) if s.size else 0.0
    idle = scales.joint_motions(null)
    leak = float(np.max(np.abs(null[motor_v]), initial=0.0))
    dependence = float(np.linalg.norm(scales.constraint_rows[:, None] * (Jc @ G) * scales.columns[out_v], 2)
                       / max(float(np.linalg.norm(scales.constraint(Jc), 2)), 1e-300))
    M = joint_inertia(sub, q)
    return OutputSplit(without_idle(M, idle, G), Jd_pinv, idle, M, leak, dependence,
                       float(s[r - 1]) / smax if r else 0.0)


def output_rates(sub: Mechanism, q: np.ndarray, out_v: np.ndarray) -> np.ndarray:
    """``Ĝ`` alone (:attr:`OutputSplit.G`, the same numbers): what an effort map ``τ_o = Ĝ_mᵀ τ_m`` needs, without
    the split's diagnostics, and the mass matrix only where there are idle motions to remove."""
    _, G, _, _, _, null = _split(sub, q, out_v)
    if not null.shape[1]:
        return G
    return without_idle(joint_inertia(sub, q), JacobianScales.of(sub).joint_motions(null), G)


def _split(sub: Mechanism, q: np.ndarray, out_v: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int, np.ndarray]:
    """``(J_c, G, J_d⁺, J_d's singular values, its rank, its null space in joint rates (homogenised))`` at ``q``:
    ``G`` before the idle motions are removed (module doc)."""
    scales = JacobianScales.of(sub)
    Jc = constraints.jacobian(sub, q)
    d_v = np.array([i for i in range(sub.nv) if i not in set(out_v)], dtype=int)
    Jd_pinv, s, Vt, r = homogenised_pinv(Jc[:, d_v], scales.constraint_rows, scales.columns[d_v], RTOL)
    k = len(out_v)
    G = np.zeros((sub.nv, k))
    G[out_v, np.arange(k)] = 1.0
    G[d_v] = -Jd_pinv @ Jc[:, out_v]
    null = np.zeros((sub.nv, Vt.shape[0] - r))
    null[d_v] = Vt[r:].T
    return Jc, G, Jd_pinv, s, r, null


def output_model(sub: Mechanism, q: np.ndarray, qd_o: np.ndarray, out_v: np.ndarray,
                 motor_v: np.ndarray) -> tuple[np.ndarray, np.ndarray, OutputSplit]:
    """``(M_o, h_o, split)``: the closed-loop model in output coordinates at ``(q, ȯ)`` (module doc)
    [kg m^2, N m; kg, N for prismatic outputs]."""
    sp = output_split(sub, q, out_v, motor_v)
    v = sp.G @ qd_o
    tau = pin.rnea(sub.model, sub.data, q, v, drift_acceleration(sub, q, v, sp, out_v)) - sub.springs.efforts(q)
    return sp.G.T @ sp.M @ sp.G, sp.G.T @ tau, sp


def drift_acceleration(sub: Mechanism, q: np.ndarray, v: np.ndarray, sp: OutputSplit,
                       out_v: np.ndarray) -> np.ndarray:
    """``Ġ ȯ`` (nv): the joint accelerations at ``ö = 0`` with joint rates ``v = Ĝ ȯ`` (module doc)
    [rad/s^2, m/s^2]."""
    a = np.zeros(sub.nv)
    d_v = np.array([i for i in range(sub.nv) if i not in set(out_v)], dtype=int)
    a[d_v] = -sp.Jd_pinv @ constraints.drift(sub, q, v)
    return without_idle(sp.M, sp.idle, a)


def close_at_outputs(sub: Mechanism, qo: np.ndarray, guess: np.ndarray, out_q: np.ndarray, out_v: np.ndarray, *,
                     tol: float | None = None, max_iter: int = 20) -> np.ndarray:
    """The closed configuration with the outputs at ``qo`` nearest ``guess``: pkm's bounded Gauss-Newton
    (:func:`pkm.core.kinematics.solve._newton`: its step cap and backtracking) on the closures with the outputs held
    (minimum-norm steps in the other joints), for a warm start a small step away (a simulation's next state);
    :func:`pkm.solve_ik` (continuation, mode checks) is the general route. ``tol`` [m, rad] on the largest closure
    residual, default :data:`CLOSURE_RTOL` times the sub-mechanism's characteristic length.

    Raises:
        ConvergenceError: the closures not within ``tol`` after ``max_iter`` iterations.
    """
    from pkm.core.kinematics.solve import _newton

    tol = closure_tol(sub) if tol is None else tol
    q = np.array(guess, dtype=float)
    q[out_q] = qo
    d_v = np.array([i for i in range(sub.nv) if i not in set(out_v)], dtype=int)
    q, gap, it = _newton(sub, lambda x: constraints.residual_and_jacobian(sub, x), q, d_v, tol, max_iter, 0.5)
    if gap <= tol:
        return q
    raise ConvergenceError("loop closure at given outputs", gap, it, tol, q)


def closure_tol(sub: Mechanism, rtol: float = CLOSURE_RTOL) -> float:
    """The transmissions' position solvers' tolerance on the largest closure residual [m, rad]: ``rtol`` times the
    sub-mechanism's characteristic length (the same for the sub-mechanism scaled in size, as
    :data:`~pkm.core.kinematics.constraints.CLOSED_RTOL` is)."""
    return rtol * sub.characteristic_length


def lumped_inertias(model: pin.Model, outputs: Sequence[str], q_reference: np.ndarray) -> list[pin.Inertia]:
    """``model.inertias`` with every joint but ``outputs`` welded to its parent at ``q_reference``: each such joint's
    body inertia (mass, centre of mass, rotational inertia) moved onto its nearest ancestor that is an output (or
    the root, index 0), placed where ``q_reference`` puts it relative to that ancestor, and its own made zero (what
    ``pinocchio.buildReducedModel`` does to a locked joint's body)."""
    data = model.createData()
    pin.forwardKinematics(model, data, q_reference)
    keep = {model.getJointId(n) for n in outputs}
    out = [pin.Inertia(model.inertias[j]) for j in range(model.njoints)]
    for j in range(1, model.njoints):
        if j in keep:
            continue
        anchor = int(model.parents[j])
        while anchor != 0 and anchor not in keep:
            anchor = int(model.parents[anchor])
        out[anchor] = out[anchor] + (data.oMi[anchor].actInv(data.oMi[j])).act(model.inertias[j])
        out[j] = pin.Inertia.Zero()
    return out


def serial_tree(model: pin.Model, outputs: Sequence[str], q_reference: np.ndarray) -> pin.Model:
    """A copy of ``model`` (a sub-mechanism's) in which every joint but ``outputs`` is welded to its parent at
    ``q_reference`` (:func:`lumped_inertias`: its body's mass carried by the nearest output above it, or by the
    root) and has no armature (the rotors' reflected inertia is left to ``ΔM``). Since every output hangs from the
    root through outputs only, the copy's mass matrix and bias with only the outputs moving, restricted to the
    outputs' rows and columns, are the serial-equivalent model's (:func:`pkm.core.transmissions.serial_equivalent`
    welds the same bodies the same way)."""
    serial = model.copy()
    keep = set(outputs)
    for j, inertia in enumerate(lumped_inertias(model, outputs, q_reference)):
        serial.inertias[j] = inertia
    armature = np.array(serial.armature, dtype=float)
    for j in range(1, serial.njoints):
        if serial.names[j] not in keep:
            jm = serial.joints[j]
            armature[jm.idx_v:jm.idx_v + jm.nv] = 0.0
    serial.armature = armature
    return serial


__all__ = ["CLOSURE_RTOL", "OutputSplit", "close_at_outputs", "closure_tol", "drift_acceleration", "lumped_inertias",
           "output_model", "output_rates", "output_split", "serial_tree"]
