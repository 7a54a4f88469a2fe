"""Simulation (issue 29's acceptance numbers): energy, independent simulators on a chirp, computed torque.

Every run is :func:`pkm.simulate` (RK4 in the actuated coordinates, the loops closed to 1e-12 at every stage) at
``--dt`` (1 ms), no friction unless said.

1. **Energy**, each shipped mechanism and three of the acceptance set (ankle, knee, RSSR; skipped where the
   checkout's ``examples/`` is absent, as from an installed wheel):

   a. *free*: released from rest at the reference under gravity, no effort, ``limits=False``, for ``--duration``
      or until the run's :class:`~pkm.core.dynamics.simulate.Event` (most fall into a direct singularity within
      0.4 s: the free equilibrium is singular); ``max |E(t) - E(0)|`` relative to the largest kinetic energy, over
      the run and up to 50 ms before its event (the passive joints speed up near the singularity);
   b. *spring*: a linear spring on the actuators, ``τ = g_a(q_0) - K (q_a - q_a0)`` with ``K = ω² M_a(q_0) - H``
      (``H = ∂g_a/∂q_a``, the gravity stiffness, by central differences of 1e-5 on the closed mechanism;
      ``ω = 2π · 2 Hz``): the reference holds still, and every mode of the linearised motion has the frequency
      ``ω``, so that the motion stays near the reference (regular) and ``ω dt = 0.013`` whatever the mechanism's
      inertias. Released from rest with every actuator moved by +0.01 rad (or +1 mm); the energy ``E`` counts the
      spring's ``½ Δqᵀ K Δq - g_a(q_0)ᵀ Δq``; ``max |E - E(0)|`` relative to the largest kinetic energy;
   c. *friction*: the same with viscous friction on each actuator (:func:`pkm.with_actuators`), ``c_j = 2 ζ ω /
      (M_a⁻¹)_jj``, ``ζ = 0.1``: ``E`` must not increase from one sample to the next by more than the largest
      change of one step of the frictionless run (b), the integrator's own; ``E + dissipated`` is constant to the
      trapezoidal rule's error of ``dissipated`` (estimated by Richardson: ``|D_h - D_2h| / 3``), and to the
      integrator's with Simpson's rule on the same samples.

2. **Independent simulators on a chirp** (``--chirp-duration``, 2 s), the Delta, the 3-PRS and the ankle. The
   efforts are a closed-loop law that each simulator evaluates on its own state, at every stage of its
   integrator: ``τ = g_a(q_0) + K_p (q_a0 - q_a) - K_d q̇_a + c(t)``, diagonal ``K_p = ω_c² diag M_a(q_0) + 2 max|eig H|``,
   ``K_d = 2 ζ_c ω_c diag M_a(q_0)`` (``ω_c = 2π · 3 Hz``, ``ζ_c = 0.5``), the chirp ``c_j(t) = 0.01 K_pj sin(2π
   (f_0 t + (f_1 - f_0) t² / (2T)) + 2π j / n_a)`` from 0.5 to 5 Hz (0.01 rad or 1 mm of static deflection).

   i. *Baumgarte*: Pinocchio's ``constraintDynamics`` in all the joint coordinates (proximal ``mu`` as
      :func:`pkm.constraint_dynamics` chooses it) with Baumgarte's stabilisation ``Kp = ω_b²``, ``Kd = 2 ω_b``,
      ``ω_b = 100 rad/s`` (critical damping, ``ω_b dt = 0.1``), integrated by RK4 on the configuration manifold
      (Munthe-Kaas: the stages' increments mapped through the inverse of ``pin.dIntegrate``) at the same ``dt``.
      Both solve the same equations; the Baumgarte terms vanish on the closed manifold, so their difference is the
      two integrators' errors (each estimated by a run at ``2 dt``: ``ε = max|x_dt - x_2dt| / 15``) plus the effect
      of the closure drift ``r``. A closure open by ``r`` puts the passive joints ``P r`` off the closed
      configuration (``P`` the passive pseudo-inverse of the closure Jacobian); as ``Ĝᵀ(M a + b) = τ_a`` holds
      whatever the closure forces, the actuated coordinates obey ``M_a q̈_a + h_a + Ĝᵀ M P r̈ + D r = τ_a`` (``D =
      ∂g_a/∂r``, the gravity efforts of the passive joints moved by ``P r``). With the PD, linearised at the
      reference, ``r`` moves them through ``T(s) = -(M_a s² + K_d s + K_p + H)⁻¹ (Ĝᵀ M P s² + D)``: the inertial
      coupling ``M_a⁻¹ Ĝᵀ M P`` at high frequency, the sag ``(K_p + H)⁻¹ D`` at rest. ``S = sup_ω ‖T(iω)‖₂``
      (:func:`sensitivity`). Bound: ``2 (ε_pkm + ε_B) + S max|r|``.
   ii. *MuJoCo* (if ``import mujoco`` works) on :func:`~pkm.core.formats.to_mjcf.mjcf_from_mechanism`'s model, its
      RK4 integrator at the same ``dt``; the PD evaluated natively at every stage (affine actuator bias
      ``-K_p q - K_d q̇``), the rest through ``ctrl`` held over each step at its midpoint value (an O(dt²) error).
      Its equality constraints are soft (``solref``, ``solimp``: MuJoCo's defaults, :data:`MUJOCO_SOFTNESS`, set
      on the compiled model in place of the stiffer ones the MJCF carries): they open by the ``r`` the run reports,
      which moves the actuated coordinates through the same ``T``: bound ``2 S max|r| + 2 ε_pkm`` (the factor 2:
      ``S`` is a gain in energy, not in peak, and the model is linearised). Run again with stiffer equalities
      (``solref = (2 dt, 1)``, ``solimp = (0.99, 0.999, 0.001, 0.5, 2)``): the violation and the difference shrink
      together.

   The closure residual of each: pkm's <= 1e-12 by construction, Baumgarte's drift, MuJoCo's equality violation.

3. **Computed torque**, the Delta and the 3-PRS: ``τ = M_a(q)(q̈_r + K_d ė + K_p e) + h_a(q, q̇)``
   (:func:`pkm.actuator_model`), ``K_p = ω_n²``, ``K_d = 2 ω_n``, ``ω_n = 2π · 5 Hz``, along ``q_r(t) = q_a0 + A_j (1 -
   cos(2π f_j t)) / 2`` (``A`` = 0.05 rad or 5 mm, ``f_j = 0.5 (j + 1)`` Hz; starts at rest). With the exact model the
   error is the integrator's (<= 1e-6); with a controller whose platform is 10 % heavier (mass and rotational
   inertia of the end-effector's body times 1.1, a copy of the Pinocchio model), the error it leaves. ``--out DIR``
   writes the figure ``DIR/simulation_tracking.png`` of both errors over time (matplotlib, ``pkm-robotics[figures]``).

Usage: ``python -m pkm.bench.simulation [--json] [--quick] [--duration 5] [--out DIR] [MECHANISM ...]``.
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

import pkm
from pkm.bench import main
from pkm.bench.mujoco_baseline import unavailable
from pkm.core.differential.idle import joint_inertia
from pkm.core.dynamics.projection import energy
from pkm.core.kinematics import constraints
from pkm.core.model.mechanism import Mechanism

EARLY = 0.05  # [s]: the free runs' drift is also given up to this long before their event
SHIPPED = ("delta", "prs3", "hexapod", "rrr3", "gough_stewart")
#: acceptance-set mechanisms: their files under the checkout's ``examples/``
ACCEPTANCE = {"ankle": "ankle/ankle.closures.toml", "knee": "knee/knee.closures.toml",
              "rssr": "gepetto_rssr/robot.yaml"}
CHIRP = ("delta", "prs3", "ankle")
TRACKING = ("delta", "prs3")
SPRING_HZ, DISPLACEMENT, ZETA = 2.0, (0.01, 0.001), 0.1  # [Hz], ([rad], [m]), [-]
CHIRP_HZ, CHIRP_ZETA, CHIRP_BAND, CHIRP_DEFLECTION = 3.0, 0.5, (0.5, 5.0), (0.01, 0.001)
BAUMGARTE_OMEGA = 100.0  # [rad/s]
STIFF_SOLIMP = (0.99, 0.999, 0.001, 0.5, 2.0)  # MuJoCo's stiffer equality run: with solref (2 dt, 1)
#: MuJoCo's default equality softness ``(solref, solimp)``: the first MuJoCo run's (the MJCF pkm writes is stiffer)
MUJOCO_SOFTNESS = ([0.02, 1.0], [0.9, 0.95, 0.001, 0.5, 2.0])
TRACKING_HZ, TRACKING_AMPLITUDE, MASS_ERROR = 5.0, (0.05, 0.005), 1.1

QUICK = {"duration": 0.1, "chirp_duration": 0.1, "tracking_duration": 0.05, "mechanisms": ["delta", "ankle"]}


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("--duration", type=float, default=5.0, help="energy runs [s] (default 5)")
    ap.add_argument("--chirp-duration", type=float, default=2.0, help="the chirp runs [s] (default 2)")
    ap.add_argument("--tracking-duration", type=float, default=2.0, help="the computed-torque runs [s] (default 2)")
    ap.add_argument("--dt", type=float, default=1e-3, help="sample period and RK4 step [s] (default 1e-3)")
    ap.add_argument("--out", default=None, help="write the tracking figure into this folder")
    ap.add_argument("mechanisms", nargs="*", default=[*SHIPPED, *ACCEPTANCE],
                    help="mechanisms of the energy runs (the chirp and tracking runs take those of theirs listed)")


def examples() -> Path | None:
    """The checkout's ``examples/`` folder, or None (an installed wheel has none)."""
    folder = Path(__file__).resolve().parents[3] / "examples"
    return folder if all((folder / p).is_file() for p in ACCEPTANCE.values()) else None


def mechanism(name: str) -> Mechanism | str:
    """The mechanism ``name`` (shipped, or of the acceptance set), or why it is not available."""
    if name in SHIPPED:
        return pkm.build(name)
    if name not in ACCEPTANCE:
        return f"unknown here (use one of {[*SHIPPED, *ACCEPTANCE]})"
    folder = examples()
    return pkm.load(folder / ACCEPTANCE[name]) if folder is not None else "examples/ absent (an installed wheel)"


def _kind(mech: Mechanism, revolute: float, prismatic: float) -> np.ndarray:
    return np.array([revolute if j.revolute else prismatic for j in mech.actuated])


def gravity_stiffness(mech: Mechanism, q0: np.ndarray, step: float = 1e-5) -> np.ndarray:
    """``H = ∂g_a/∂q_a`` (na x na, symmetrised) at ``q0``: central differences on the closed mechanism."""
    qa0 = mech.actuated_q(q0)
    H = np.empty((mech.na, mech.na))
    for k in range(mech.na):
        e = step * np.eye(mech.na)[k]
        up = pkm.close_loops(mech, qa0 + e, q0, tol=1e-13).q
        down = pkm.close_loops(mech, qa0 - e, q0, tol=1e-13).q
        H[:, k] = (pkm.gravity_efforts(mech, up) - pkm.gravity_efforts(mech, down)) / (2.0 * step)
    return 0.5 * (H + H.T)


@dataclass(frozen=True)
class Spring:
    """The preloaded spring of the energy runs: ``τ = g0 - K (q_a - qa0)``, potential ``½ Δqᵀ K Δq - g0ᵀ Δq``."""

    qa0: np.ndarray
    g0: np.ndarray
    K: np.ndarray
    M: np.ndarray  # M_a(q_0)
    H: np.ndarray

    @classmethod
    def at(cls, mech: Mechanism, q0: np.ndarray, hz: float = SPRING_HZ) -> Spring:
        model = pkm.actuator_model(mech, q0)
        H = gravity_stiffness(mech, q0)
        return cls(mech.actuated_q(q0), model.g.copy(), (2.0 * math.pi * hz) ** 2 * model.M - H, model.M.copy(), H)

    def efforts(self, qa: np.ndarray) -> np.ndarray:
        return self.g0 - self.K @ (qa - self.qa0)

    def potential(self, qa: np.ndarray) -> np.ndarray:
        """The spring's potential at samples ``qa`` (N x na) [J]."""
        dq = qa - self.qa0
        return 0.5 * np.einsum("ij,jk,ik->i", dq, self.K, dq) - dq @ self.g0


def _event(sim: pkm.Simulation) -> dict:
    return {"kind": sim.event.kind, "time_s": sim.event.time, "detail": sim.event.detail} if sim.event else {}


def free_run(mech: Mechanism, duration: float, dt: float) -> dict:
    """(a): released from rest under gravity, no effort, no limits watched."""
    t0 = time.perf_counter()
    sim = pkm.simulate(mech, None, None, duration, dt, limits=False, friction=False)
    E = sim.energy
    k_max = float(sim.kinetic.max())
    drift = float(np.abs(E - E[0]).max())
    early = sim.time <= sim.time[-1] - (EARLY if sim.event else 0.0)  # (the last EARLY s near a singularity: fast)
    early_drift = float(np.abs(E[early] - E[0]).max(initial=0.0))
    return {"seconds": sim.time[-1], "wall_s": time.perf_counter() - t0, "event": _event(sim),
            "max_kinetic_J": k_max, "drift_J": drift, "drift_relative": drift / k_max if k_max > 0.0 else None,
            "drift_relative_before_event": early_drift / k_max if k_max > 0.0 else None}


def _dissipation_error(t: np.ndarray, loss: np.ndarray, D: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """At the even samples: Richardson's estimate of the trapezoid's error ``|D_h - D_2h| / 3``, and Simpson's
    rule's dissipated energy."""
    even = np.arange(0, len(t), 2)
    h2 = np.diff(t[even])
    trap2 = np.concatenate([[0.0], np.cumsum(0.5 * h2 * (loss[even][1:] + loss[even][:-1]))])
    simpson = (4.0 * D[even] - trap2) / 3.0
    return np.abs(D[even] - trap2) / 3.0, simpson


def spring_runs(mech: Mechanism, duration: float, dt: float) -> dict:
    """(b) and (c): the conservative spring run, then with viscous friction on the actuators."""
    q0 = mech.q_reference
    spring = Spring.at(mech, q0)
    act_q = mech.act_q
    qs = pkm.close_loops(mech, spring.qa0 + _kind(mech, *DISPLACEMENT), q0, tol=1e-13).q
    law = lambda t, q, v: spring.efforts(q[act_q])
    rest = energy(mech, q0, np.zeros(mech.nv))[1]  # the equilibrium's energy
    out: dict[str, Any] = {"omega_rad_s": 2.0 * math.pi * SPRING_HZ, "displacement": list(_kind(mech, *DISPLACEMENT)),
                           "K_eigenvalues": sorted(np.linalg.eigvalsh(spring.K).tolist()),
                           "gravity_stiffness_eigenvalues": sorted(np.linalg.eigvalsh(spring.H).tolist())}
    t0 = time.perf_counter()
    sim = pkm.simulate(mech, qs, None, duration, dt, law, limits=False, friction=False)
    E = sim.energy + spring.potential(sim.actuated)
    k_max = float(sim.kinetic.max())
    step = float(np.abs(np.diff(E)).max(initial=0.0))
    out["spring"] = {"seconds": sim.time[-1], "wall_s": time.perf_counter() - t0, "event": _event(sim),
                     "max_kinetic_J": k_max, "drift_relative": float(np.abs(E - E[0]).max()) / k_max,
                     "max_step_change_J": step}
    c = 2.0 * ZETA * out["omega_rad_s"] / np.diag(np.linalg.inv(spring.M))
    damped = pkm.with_actuators(mech, {j: {"viscous": float(cj)} for j, cj in zip(mech.actuated_names, c)})
    t0 = time.perf_counter()
    sim = pkm.simulate(damped, qs, None, duration, dt, law, limits=False, friction=True)
    E = sim.energy + spring.potential(sim.actuated)
    loss = np.einsum("ij,j,ij->i", sim.actuated_velocity, c, sim.actuated_velocity)
    trap_err, simpson = _dissipation_error(sim.time, loss, sim.dissipated)
    even = np.arange(0, len(E), 2)
    scale = float(E[0] - rest)
    rise = float(np.diff(E).max(initial=-math.inf))
    balance = np.abs(E + sim.dissipated - E[0])
    out["friction"] = {
        "viscous": c.tolist(), "zeta": ZETA, "seconds": sim.time[-1], "wall_s": time.perf_counter() - t0,
        "event": _event(sim), "energy_left": float(E[-1] - rest) / scale,
        "largest_rise_J": rise, "rise_tolerance_J": step, "monotone": rise <= step,
        "balance_trapezoid_relative": float(balance.max()) / scale,
        "trapezoid_error_estimate_relative": float(trap_err.max()) / scale,
        "balance_within_trapezoid_error": bool(np.all(balance[even] <= 2.0 * trap_err + 10.0 * step + 1e-12 * scale)),
        "balance_simpson_relative": float(np.abs(E[even] + simpson - E[0]).max()) / scale}
    return out


def energy_runs(mech: Mechanism, duration: float, dt: float) -> dict:
    return {"free": free_run(mech, duration, dt), **spring_runs(mech, duration, dt)}


# ----------------------------------------------------------------------------------------------- chirp
@dataclass(frozen=True)
class ChirpLaw:
    """``τ = g0 + Kp (qa0 - q_a) - Kd q̇_a + c(t)`` (module doc, 2), diagonal gains."""

    qa0: np.ndarray
    g0: np.ndarray
    Kp: np.ndarray
    Kd: np.ndarray
    amplitude: np.ndarray
    duration: float

    @classmethod
    def at(cls, mech: Mechanism, q0: np.ndarray, duration: float) -> ChirpLaw:
        model = pkm.actuator_model(mech, q0)
        w = 2.0 * math.pi * CHIRP_HZ
        rho = float(np.abs(np.linalg.eigvalsh(gravity_stiffness(mech, q0))).max())
        Kp = w ** 2 * np.diag(model.M) + 2.0 * rho
        return cls(mech.actuated_q(q0), model.g.copy(), Kp, 2.0 * CHIRP_ZETA * w * np.diag(model.M),
                   _kind(mech, *CHIRP_DEFLECTION) * Kp, duration)

    def chirp(self, t: float) -> np.ndarray:
        f0, f1 = CHIRP_BAND
        phase = 2.0 * math.pi * (f0 * t + (f1 - f0) * t * t / (2.0 * self.duration))
        return self.amplitude * np.sin(phase + 2.0 * math.pi * np.arange(len(self.qa0)) / len(self.qa0))

    def efforts(self, t: float, qa: np.ndarray, qd: np.ndarray) -> np.ndarray:
        return self.g0 + self.Kp * (self.qa0 - qa) - self.Kd * qd + self.chirp(t)


def sensitivity(mech: Mechanism, q: np.ndarray, law: ChirpLaw) -> float:
    """``S = sup_ω ‖T(iω)‖₂`` [rad or m per m or rad of closure]: the largest gain from a closure opening ``r`` to the
    actuated coordinates under the chirp's PD (module doc, 2.i), linearised at ``q``:
    ``T(s) = -(M_a s² + K_d s + K_p + H)⁻¹ (Ĝᵀ M P s² + D)``, ``D = ∂g_a/∂r`` (the gravity efforts with the passive
    joints moved by ``P r``, central differences of 1e-6); on 400 frequencies from 0.1 to 10⁴ rad/s and 0. At high
    frequency ``T → M_a⁻¹ Ĝᵀ M P`` (the inertial coupling), at 0 ``(K_p + H)⁻¹ D`` (the sag under gravity)."""
    model = pkm.actuator_model(mech, q)
    M = joint_inertia(mech, q)
    J = constraints.jacobian(mech, q)
    P = np.zeros((mech.nv, J.shape[0]))
    P[mech.passive_v] = np.linalg.pinv(J[:, mech.passive_v], rcond=1e-9)
    B = model.G.T @ M @ P
    D = np.empty((mech.na, J.shape[0]))
    step = 1e-6
    for i in range(J.shape[0]):
        up = pkm.actuator_model(mech, pin.integrate(mech.model, q, step * P[:, i])).g
        down = pkm.actuator_model(mech, pin.integrate(mech.model, q, -step * P[:, i])).g
        D[:, i] = (up - down) / (2.0 * step)
    stiffness = np.diag(law.Kp) + gravity_stiffness(mech, q)
    gains = [np.linalg.norm(np.linalg.solve(-w * w * model.M + 1j * w * np.diag(law.Kd) + stiffness, D - w * w * B), 2)
             for w in np.concatenate([[0.0], np.logspace(-1.0, 4.0, 400)])]
    return float(max(gains))


def pkm_run(mech: Mechanism, q0: np.ndarray, law: ChirpLaw, duration: float, dt: float,
            friction: bool = False) -> pkm.Simulation:
    act_q, act_v = mech.act_q, mech.act_v
    return pkm.simulate(mech, q0, None, duration, dt, lambda t, q, v: law.efforts(t, q[act_q], v[act_v]),
                        friction=friction, limits=False)


def baumgarte_run(mech: Mechanism, q0: np.ndarray, law: ChirpLaw, duration: float, dt: float,
                  omega: float = BAUMGARTE_OMEGA) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pinocchio's ``constraintDynamics`` with Baumgarte's ``Kp = omega²``, ``Kd = 2 omega``, RK4 (Munthe-Kaas) in
    all the joint coordinates from rest at ``q0``. Returns the times, the actuated coordinates (N x na) and the
    closure residual (N,) at each sample."""
    m = mech.model
    d = m.createData()
    cms = [pin.RigidConstraintModel(cm.type, m, cm.joint1_id, cm.joint1_placement, cm.joint2_id,
                                    cm.joint2_placement, cm.reference_frame) for cm in mech.constraint_models]
    for cm in cms:
        cm.m_baumgarte_parameters = pin.BaumgarteCorrectorParameters(omega ** 2, 2.0 * omega)
    cds = [cm.createData() for cm in cms]
    pin.initConstraintDynamics(m, d, cms, cds)
    s = np.linalg.svd(constraints.jacobian(mech, q0), compute_uv=False)
    redundant = s.size < mech.n_constraints or s[-1] <= 1e-9 * max(float(s[0]), 1.0)
    settings = pin.ProximalSettings(1e-14, 1e-9 if redundant else 0.0, 1000 if redundant else 1)
    act_q, act_v = mech.act_q, mech.act_v

    def rates(t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        tau = np.zeros(m.nv)
        tau[act_v] = law.efforts(t, q[act_q], v[act_v])
        return pin.constraintDynamics(m, d, q, v, tau, cms, cds, settings).copy()

    def theta_rate(q: np.ndarray, theta: np.ndarray, v: np.ndarray) -> np.ndarray:  # dexp⁻¹: the increment's rate
        return np.linalg.solve(pin.dIntegrate(m, q, theta, pin.ArgumentPosition.ARG1), v)

    n = math.ceil(duration / dt - 1e-9)
    q, v = q0.copy(), np.zeros(m.nv)
    qa, res = [q[act_q].copy()], [float(np.abs(constraints.residual(mech, q)).max())]
    for k in range(n):
        t = k * dt
        a1 = rates(t, q, v)
        th2, v2 = 0.5 * dt * v, v + 0.5 * dt * a1
        q2 = pin.integrate(m, q, th2)
        a2, k2 = rates(t + 0.5 * dt, q2, v2), theta_rate(q, th2, v2)
        th3, v3 = 0.5 * dt * k2, v + 0.5 * dt * a2
        q3 = pin.integrate(m, q, th3)
        a3, k3 = rates(t + 0.5 * dt, q3, v3), theta_rate(q, th3, v3)
        th4, v4 = dt * k3, v + dt * a3
        q4 = pin.integrate(m, q, th4)
        a4, k4 = rates(t + dt, q4, v4), theta_rate(q, th4, v4)
        q = pin.integrate(m, q, dt / 6.0 * (v + 2.0 * k2 + 2.0 * k3 + k4))
        v = v + dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
        qa.append(q[act_q].copy())
        res.append(float(np.abs(constraints.residual(mech, q)).max()))
    return np.arange(n + 1) * dt, np.array(qa), np.array(res)


def mujoco_run(mech: Mechanism, q0: np.ndarray, law: ChirpLaw, duration: float, dt: float,
               softness: tuple[list[float], list[float]] | None = None, path: str | Path | None = None) \
        -> tuple[np.ndarray, np.ndarray, np.ndarray, dict]:
    """MuJoCo's RK4 on the mechanism's MJCF from rest at ``q0`` (module doc, 2.ii); ``softness``: the equality
    constraints' ``(solref, solimp)`` instead of the MJCF's. Returns the times, the actuated
    coordinates, the largest equality violation at each sample and MuJoCo's settings as read from its model.

    ``path``: the user's own MJCF file (the one ``mech`` was read from) instead of pkm's
    (:func:`~pkm.core.formats.to_mjcf.mjcf_from_mechanism`): MuJoCo starts at its ``qpos0``, which must be ``q0``'s
    actuated coordinates (:class:`ValueError` otherwise), with the file's joint damping, armature and equality
    softness."""
    import mujoco

    from pkm.bench.mujoco_baseline import MujocoRigid, equality_violation

    if path is None:
        rigid = MujocoRigid(mech)
        mm, md = rigid.model, rigid.data
    else:
        mm = mujoco.MjModel.from_xml_path(str(path))
        md = mujoco.MjData(mm)
    mm.opt.timestep = dt
    mm.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    if softness is not None:
        mm.eq_solref[:] = softness[0]
        mm.eq_solimp[:] = softness[1]
    for i in range(mm.nu):
        mm.actuator_biastype[i] = mujoco.mjtBias.mjBIAS_AFFINE
        mm.actuator_biasprm[i, :3] = [0.0, -law.Kp[i], -law.Kd[i]]
        mm.actuator_gainprm[i, 0] = 1.0
    pm = mech.model
    qpos = [int(mm.jnt_qposadr[mujoco.mj_name2id(mm, mujoco.mjtObj.mjOBJ_JOINT, pm.names[j.id])])
            for j in mech.actuated]
    zero = np.zeros(mech.nv)
    if path is None:
        rigid._state(q0, zero, zero)
    elif not np.allclose(mm.qpos0[qpos], mech.actuated_q(q0), rtol=0.0, atol=1e-12):
        raise ValueError(f"{path}: MuJoCo's qpos0 {mm.qpos0[qpos]} is not q0's actuated coordinates")
    md.qvel[:], md.qacc_warmstart[:] = 0.0, 0.0
    def violation() -> float:
        mujoco.mj_fwdPosition(mm, md)
        return equality_violation(mm, md)

    n = math.ceil(duration / dt - 1e-9)
    qa, res = [md.qpos[qpos].copy()], [violation()]
    for k in range(n):
        md.ctrl[:] = law.efforts((k + 0.5) * dt, np.zeros(mech.na), np.zeros(mech.na))  # g0 + Kp qa0 + c(t_mid)
        mujoco.mj_step(mm, md)
        qa.append(md.qpos[qpos].copy())
        res.append(violation())
    settings = {"timestep_s": float(mm.opt.timestep), "integrator": mujoco.mjtIntegrator(mm.opt.integrator).name,
                "solver": mujoco.mjtSolver(mm.opt.solver).name, "iterations": int(mm.opt.iterations),
                "tolerance": float(mm.opt.tolerance), "eq_solref": mm.eq_solref[0].tolist(),
                "eq_solimp": mm.eq_solimp[0].tolist(), "version": mujoco.__version__}
    return np.arange(n + 1) * dt, np.array(qa), np.array(res), settings


def _error_estimate(fine: np.ndarray, coarse: np.ndarray) -> float:
    """RK4's global error at the fine step from the run at twice that step: ``max |x_h - x_2h| / 15``."""
    m = min(len(coarse), (len(fine) + 1) // 2)
    return float(np.abs(fine[::2][:m] - coarse[:m]).max()) / 15.0


def chirp_runs(mech: Mechanism, duration: float, dt: float) -> dict:
    q0 = mech.q_reference
    law = ChirpLaw.at(mech, q0, duration)
    S = sensitivity(mech, q0, law)
    t0 = time.perf_counter()
    sim = pkm_run(mech, q0, law, duration, dt)
    wall = time.perf_counter() - t0
    eps_pkm = _error_estimate(sim.actuated, pkm_run(mech, q0, law, duration, 2.0 * dt).actuated)
    swing = float(np.abs(sim.actuated - law.qa0).max())
    out: dict[str, Any] = {
        "Kp": law.Kp.tolist(), "Kd": law.Kd.tolist(), "chirp_amplitude": law.amplitude.tolist(),
        "band_hz": list(CHIRP_BAND), "sensitivity": S, "swing": swing,
        "pkm": {"seconds": sim.time[-1], "wall_s": wall, "event": _event(sim), "error_estimate": eps_pkm,
                "max_residual": float(sim.residual.max())}}
    t0 = time.perf_counter()
    t_b, qa_b, r_b = baumgarte_run(mech, q0, law, duration, dt)
    wall = time.perf_counter() - t0
    eps_b = _error_estimate(qa_b, baumgarte_run(mech, q0, law, duration, 2.0 * dt)[1])
    n = min(len(sim.time), len(t_b))
    diff = float(np.abs(qa_b[:n] - sim.actuated[:n]).max())
    bound = 2.0 * (eps_pkm + eps_b) + S * float(r_b.max())
    out["baumgarte"] = {"Kp": BAUMGARTE_OMEGA ** 2, "Kd": 2.0 * BAUMGARTE_OMEGA, "wall_s": wall,
                        "error_estimate": eps_b, "max_residual": float(r_b.max()), "max_difference": diff,
                        "bound": bound, "within": diff <= bound}
    reason = unavailable()
    if reason is not None:
        out["mujoco"] = out["mujoco_stiff"] = {"skipped": reason}
        return out
    for key, softness in (("mujoco", MUJOCO_SOFTNESS), ("mujoco_stiff", ([2.0 * dt, 1.0], list(STIFF_SOLIMP)))):
        t0 = time.perf_counter()
        t_m, qa_m, r_m, settings = mujoco_run(mech, q0, law, duration, dt, softness)
        wall = time.perf_counter() - t0
        n = min(len(sim.time), len(t_m))
        diff = float(np.abs(qa_m[:n] - sim.actuated[:n]).max())
        bound = 2.0 * S * float(r_m.max()) + 2.0 * eps_pkm
        out[key] = {**settings, "wall_s": wall, "max_residual": float(r_m.max()), "max_difference": diff,
                    "bound": bound, "within": diff <= bound}
    return out


# ----------------------------------------------------------------------------------------------- tracking
def heavier(mech: Mechanism, factor: float = MASS_ERROR) -> Mechanism:
    """A copy of ``mech`` whose end-effector body (the platform) has ``factor`` times its mass and rotational
    inertia (same centre of mass), in a copy of the Pinocchio model; ``mech`` is not changed."""
    model = pin.Model(mech.model)
    j = model.frames[mech.ee_frame].parentJoint
    I = model.inertias[j]
    model.inertias[j] = pin.Inertia(factor * I.mass, I.lever, factor * I.inertia)
    return Mechanism(model, mech.spec, mech.params, mech.urdf, mech.source)


@dataclass(frozen=True)
class Reference:
    """``q_r(t) = qa0 + A (1 - cos(2π f t)) / 2`` per actuator, with its rates."""

    qa0: np.ndarray
    amplitude: np.ndarray
    hz: np.ndarray

    def __call__(self, t: np.ndarray | float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        w = 2.0 * math.pi * self.hz
        wt = np.multiply.outer(t, w)
        A = 0.5 * self.amplitude
        return self.qa0 + A * (1.0 - np.cos(wt)), A * w * np.sin(wt), A * w ** 2 * np.cos(wt)


def computed_torque(model_mech: Mechanism, ref: Reference, kp: float, kd: float) \
        -> Callable[[float, np.ndarray, np.ndarray], np.ndarray]:
    """``τ = M_a(q)(q̈_r + K_d ė + K_p e) + h_a(q, q̇)`` with the model of ``model_mech``."""
    act_q, act_v = model_mech.act_q, model_mech.act_v

    def law(t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        r, rd, rdd = ref(t)
        model = pkm.actuator_model(model_mech, q, v[act_v])
        return model.M @ (rdd + kd * (rd - v[act_v]) + kp * (r - q[act_q])) + model.h

    return law


def tracking_runs(mech: Mechanism, duration: float, dt: float) -> tuple[dict, dict]:
    """The computed-torque runs: the numbers and the error series (for the figure)."""
    q0 = mech.q_reference
    ref = Reference(mech.actuated_q(q0), _kind(mech, *TRACKING_AMPLITUDE), 0.5 * (np.arange(mech.na) + 1.0))
    w = 2.0 * math.pi * TRACKING_HZ
    kp, kd = w ** 2, 2.0 * w
    unit = "rad" if mech.actuated[0].revolute else "m"
    out: dict[str, Any] = {"Kp": kp, "Kd": kd, "amplitude": ref.amplitude.tolist(), "hz": ref.hz.tolist(),
                           "unit": unit, "mass_error": MASS_ERROR}
    series: dict[str, Any] = {"unit": unit}
    for label, model_mech in (("exact", mech), ("heavier", heavier(mech))):
        t0 = time.perf_counter()
        sim = pkm.simulate(mech, q0, None, duration, dt, computed_torque(model_mech, ref, kp, kd), limits=False,
                           friction=False)
        err = np.abs(ref(sim.time)[0] - sim.actuated).max(axis=1)
        out[label] = {"seconds": sim.time[-1], "wall_s": time.perf_counter() - t0, "event": _event(sim),
                      "max_error": float(err.max()), "max_effort": float(np.abs(np.asarray(sim.efforts)).max())}
        series[label] = (sim.time, err)
    return out, series


def figure(series: dict[str, dict], out_dir: str | Path) -> Path:
    """Both tracking errors over time, one panel per mechanism (log scale), as ``simulation_tracking.png``."""
    from pkm._plot import figure as new_figure
    from pkm._plot import save

    fig, axes = new_figure(ncols=len(series), size=(5.0, 3.6))
    axes = np.asarray(axes).ravel()
    for ax, (name, s) in zip(axes, series.items()):
        for label, text in (("exact", "exact model"), ("heavier", f"platform x{MASS_ERROR:g} in the model")):
            t, err = s[label]
            ax.semilogy(t, np.maximum(err, 1e-16), label=text)
        ax.set_xlabel("time [s]")
        ax.set_ylabel(f"max |q_r - q_a| [{s['unit']}]")
        ax.set_title(name)
        ax.legend()
    fig.suptitle("Computed-torque tracking error (pkm.simulate, RK4, 1 ms)")
    return save(fig, out_dir, "simulation_tracking")


# ----------------------------------------------------------------------------------------------- run, table
def run(args: argparse.Namespace) -> dict:
    result: dict[str, Any] = {"dt": args.dt, "duration": args.duration, "chirp_duration": args.chirp_duration,
                              "tracking_duration": args.tracking_duration, "energy": {}, "chirp": {},
                              "tracking": {}, "figure": None}
    mechs = {name: mechanism(name) for name in dict.fromkeys([*args.mechanisms, *CHIRP, *TRACKING])}
    for name in args.mechanisms:
        mech = mechs[name]
        result["energy"][name] = {"skipped": mech} if isinstance(mech, str) else \
            energy_runs(mech, args.duration, args.dt)
    for name in CHIRP:
        mech = mechs[name]
        result["chirp"][name] = {"skipped": mech} if isinstance(mech, str) else \
            chirp_runs(mech, args.chirp_duration, args.dt)
    series = {}
    for name in TRACKING:
        mech = mechs[name]
        if isinstance(mech, str):
            result["tracking"][name] = {"skipped": mech}
            continue
        result["tracking"][name], series[name] = tracking_runs(mech, args.tracking_duration, args.dt)
    if args.out is not None and series:
        result["figure"] = str(figure(series, args.out))
    return result


def _g(x: Any, fmt: str = ".2e") -> str:
    return "-" if x is None else format(x, fmt)


def table(r: dict) -> str:
    lines = [f"Energy (dt {r['dt'] * 1e3:g} ms; free: until {r['duration']:g} s or the event; drift relative to the "
             "largest kinetic energy)",
             f"{'mechanism':14s} {'free: stop s':>12s} {'why':>13s} {'drift':>9s} {'to -50ms':>9s} {'spring drift':>12s} "
             f"{'friction: rise J':>16s} {'tol J':>9s} {'E+D trap':>9s} {'trap err':>9s} {'E+D Simpson':>11s} "
             f"{'E left':>9s}"]
    for name, e in r["energy"].items():
        if "skipped" in e:
            lines.append(f"{name:14s} skipped: {e['skipped']}")
            continue
        f, s, c = e["free"], e["spring"], e["friction"]
        why = f["event"].get("kind", "end") if f["event"] else "end"
        lines.append(f"{name:14s} {f['seconds']:12.3f} {why:>13s} {_g(f['drift_relative']):>9s} "
                     f"{_g(f['drift_relative_before_event']):>9s} "
                     f"{_g(s['drift_relative']):>12s} {_g(c['largest_rise_J']):>16s} {_g(c['rise_tolerance_J']):>9s} "
                     f"{_g(c['balance_trapezoid_relative']):>9s} {_g(c['trapezoid_error_estimate_relative']):>9s} "
                     f"{_g(c['balance_simpson_relative']):>11s} {c['energy_left']:9.2e}")
        for run_name, run_ in (("spring", s), ("friction", c)):
            if run_["event"]:
                lines.append(f"  {name} {run_name}: stopped at {run_['event']['time_s']:.3f} s: "
                             f"{run_['event']['detail']}")
    lines.append(f"\nChirp ({r['chirp_duration']:g} s): max |q_a - q_a(pkm)| and its bound [rad or m]; closure "
                 "residual of each")
    lines.append(f"{'mechanism':10s} {'swing':>9s} {'S':>8s} {'pkm res':>9s} {'pkm err':>9s} {'Baum diff':>9s} "
                 f"{'bound':>9s} {'Baum res':>9s} {'MuJoCo diff':>11s} {'bound':>9s} {'MuJoCo res':>10s}")
    mj_settings = None
    for name, c in r["chirp"].items():
        if "skipped" in c:
            lines.append(f"{name:10s} skipped: {c['skipped']}")
            continue
        b, m = c["baumgarte"], c["mujoco"]
        mj = (f"{_g(m['max_difference']):>11s} {_g(m['bound']):>9s} {_g(m['max_residual']):>10s}"
              if "skipped" not in m else f"{'-':>11s} {'-':>9s} {'-':>10s}")
        lines.append(f"{name:10s} {c['swing']:9.2e} {c['sensitivity']:8.2f} {_g(c['pkm']['max_residual']):>9s} "
                     f"{_g(c['pkm']['error_estimate']):>9s} {_g(b['max_difference']):>9s} {_g(b['bound']):>9s} "
                     f"{_g(b['max_residual']):>9s} {mj}")
        if "skipped" in m:
            mj_settings = m["skipped"]
        elif mj_settings is None:
            mj_settings = (f"MuJoCo {m['version']}: {m['integrator']} at {m['timestep_s'] * 1e3:g} ms, solver "
                           f"{m['solver']} ({m['iterations']} iterations, tolerance {m['tolerance']:g}), equality "
                           f"solref {m['eq_solref']}, solimp {m['eq_solimp']}")
    lines.append(f"Baumgarte Kp {BAUMGARTE_OMEGA ** 2:g} 1/s^2, Kd {2 * BAUMGARTE_OMEGA:g} 1/s; "
                 f"{mj_settings or 'MuJoCo not run'}")
    stiff = {n: c["mujoco_stiff"] for n, c in r["chirp"].items() if "skipped" not in c.get("mujoco_stiff", c)}
    if stiff:
        first = next(iter(stiff.values()))
        lines.append(f"MuJoCo, stiffer equalities (solref {first['eq_solref']}, solimp {first['eq_solimp']}): " +
                     "; ".join(f"{n} diff {_g(m['max_difference'])} (bound {_g(m['bound'])}, residual "
                               f"{_g(m['max_residual'])})" for n, m in stiff.items()))
    lines.append(f"\nComputed torque ({r['tracking_duration']:g} s): max tracking error")
    for name, c in r["tracking"].items():
        if "skipped" in c:
            lines.append(f"{name:10s} skipped: {c['skipped']}")
            continue
        lines.append(f"{name:10s} exact model {c['exact']['max_error']:.2e} {c['unit']}, platform x{c['mass_error']:g} "
                     f"in the model {c['heavier']['max_error']:.2e} {c['unit']} (reference amplitude "
                     f"{max(c['amplitude']):g} {c['unit']})")
    if r["figure"]:
        lines.append(f"figure: {r['figure']}")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main("simulation"))
