r"""Fidelity: one motor-torque profile on the closed loop and on two serial-equivalent models in MuJoCo.

For a transmission and a motor-torque profile ``τ_m(t)`` (open loop: the same numbers in every run), from the
reference at rest:

* **(a) closed loop**: :func:`pkm.simulate` of the sub-mechanism (RK4 at ``dt``; no friction, no saturation, no limit
  watched);
* **(b) constant armature**: MuJoCo's serial-equivalent model of the sub-mechanism (the outputs only, the rods and
  cranks welded at the reference, the rotors removed: :func:`~pkm.core.transmissions.serial.serial_equivalent`) with each output's armature ``ΔM``'s
  diagonal at the reference (today's practice), driven by the output efforts ``τ_o = J⁻ᵀ τ_m`` (the exact effort map
  at the current outputs: today's firmware does as much);
* **(c) exact**: the same model without that armature, with ``ΔM`` and ``Δh`` applied at every evaluation of the
  dynamics through ``qfrc_applied``, from MuJoCo's control callback (``mjcb_control``, which MuJoCo calls after it
  has computed the mass matrix ``M_s`` and the bias ``h_s`` of the state, at every stage of its RK4): the
  acceleration is first solved exactly, ``ö = (M_s + ΔM)⁻¹ (τ_o - h_s - Δh)``, then ``qfrc_applied = τ_o - ΔM ö -
  Δh``, so that MuJoCo's own ``M_s ö + h_s = qfrc_applied`` gives that ``ö``: no lag, no iteration (a fixed point
  ``ö_{k+1} = M_s⁻¹(τ_o - ΔM ö_k - …)`` would diverge where ``ΔM`` outweighs ``M_s``, as on an ankle whose rods and
  rotors add 25 times the foot's own inertia about pitch).

Both MuJoCo runs use MuJoCo's RK4 (``integrator="RK4"``) at ``dt``; each state's sub-mechanism configuration is the
closure at its outputs, warm-started from the previous one
(:func:`~pkm.core.transmissions.coordinates.close_at_outputs`). The errors are the largest output deviation
from (a) over the run [rad or m]; each integrator's own error is estimated by the same run at ``dt / 2``.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pkm._optional import module
from pkm.core.dynamics.model import mass_matrix
from pkm.core.dynamics.simulate import simulate
from pkm.core.transmissions.coordinates import close_at_outputs, output_model, output_rates
from pkm.core.transmissions.serial import SerialEquivalent, serial_equivalent
from pkm.core.transmissions.transmission import Transmission
from pkm.errors import ConvergenceError, InvalidInputError

Profile = Callable[[float], np.ndarray]


def profiles(t: Transmission, duration: float = 2.0, *, amplitude: float = 0.02) -> dict[str, Profile]:
    """The two motor-torque profiles ``{"chirp": τ(t), "swing": τ(t)}`` [N m or N] about the torques that hold the
    sub-mechanism at its reference (:func:`pkm.gravity_efforts`): a chirp from 0.5 to 4 Hz over ``duration`` and a
    walking-like swing (1 Hz with its second harmonic), each motor's amplitude the torque that swings its own
    inertia (``M_a``'s diagonal entry) by ``amplitude`` [rad or m] at 2 Hz, the motors a quarter period apart."""
    from pkm.core.dynamics.model import gravity_efforts

    sub = t.mechanism
    hold = gravity_efforts(sub, t.q_reference)
    A = amplitude * np.diag(mass_matrix(sub, t.q_reference)) * (4.0 * np.pi) ** 2
    phase = 0.5 * np.pi * np.arange(t.k)
    f0, f1 = 0.5, 4.0

    def chirp(time: float) -> np.ndarray:
        return hold + A * np.sin(2.0 * np.pi * (f0 * time + 0.5 * (f1 - f0) * time ** 2 / duration) + phase)

    def swing(time: float) -> np.ndarray:
        w = 2.0 * np.pi * time
        return hold + A * (np.sin(w + phase) + 0.3 * np.sin(2.0 * w + 0.5 + phase))

    return {"chirp": chirp, "swing": swing}


def closed_loop(t: Transmission, torque: Profile, duration: float, dt: float) -> np.ndarray:
    """(a): the outputs (N+1, k) [rad or m] at ``0, dt, ..., duration`` under ``torque``, by :func:`pkm.simulate`."""
    sim = simulate(t.mechanism, t.q_reference, None, duration, dt, lambda time, q, v: torque(time), friction=False,
                   saturate=False, limits=False, backend="python")
    if sim.event is not None:
        raise InvalidInputError("torque", f"the closed-loop run stopped early: {sim.event}", sim.event)
    return np.asarray(sim.q)[:, t.out_q]


def serial_run(t: Transmission, torque: Profile, duration: float, dt: float, *, exact: bool) -> np.ndarray:
    """(b) (``exact=False``) or (c) (``exact=True``): the outputs (N+1, k) [rad or m] of MuJoCo's serial model at
    ``0, dt, ..., duration`` under ``torque`` (module doc); NaN from the first step whose outputs no closed
    configuration of the sub-mechanism reaches (the serial model went where the mechanism cannot)."""
    mujoco = module("mujoco", extra="bench", what="the serial-equivalent model's MuJoCo run")
    se, compiled = _serial(t)
    m = copy.copy(compiled)  # (MuJoCo's copy of the model: this run's timestep and armature its own)
    m.opt.timestep = dt
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    qadr = np.array([m.jnt_qposadr[m.joint(o).id] for o in t.outputs])
    dadr = np.array([m.jnt_dofadr[m.joint(o).id] for o in t.outputs])
    if exact:
        m.dof_armature[dadr] -= [se.armature[o] for o in t.outputs]
    state = {"q": t.q_reference.copy()}
    full = np.zeros((m.nv, m.nv))

    sub = t.mechanism

    def control(_m: object, data: object) -> None:
        qo, od = data.qpos[qadr], data.qvel[dadr]  # type: ignore[attr-defined]
        q = close_at_outputs(sub, qo, state["q"], t.out_q, t.out_v)
        state["q"] = q
        if not exact:  # (the effort map alone: Ĝ, not the output model)
            G = output_rates(sub, q, t.out_v)
            data.qfrc_applied[dadr] = G[sub.act_v].T @ torque(float(data.time))  # type: ignore[attr-defined]
            return
        M_o, h_o, sp = output_model(sub, q, od, t.out_v, sub.act_v)
        tau_o = sp.G[sub.act_v].T @ torque(float(data.time))  # type: ignore[attr-defined]  # (J⁻ᵀ τ_m)
        mujoco.mj_fullM(m, data, full)
        M_s, h_s = full[np.ix_(dadr, dadr)], data.qfrc_bias[dadr]  # type: ignore[attr-defined]
        M_t, h_t = t.serial_model(q, od)
        dM, dh = M_o - M_t, h_o - h_t
        odd = np.linalg.solve(M_s + dM, tau_o - h_s - dh)
        data.qfrc_applied[dadr] = tau_o - dM @ odd - dh  # type: ignore[attr-defined]

    n = round(duration / dt)
    out = np.full((n + 1, t.k), np.nan)
    out[0] = d.qpos[qadr]
    mujoco.set_mjcb_control(control)
    try:
        for i in range(n):
            try:
                mujoco.mj_step(m, d)
            except ConvergenceError:  # (the serial model's outputs left the sub-mechanism's workspace: NaN after)
                break
            out[i + 1] = d.qpos[qadr]
    finally:
        mujoco.set_mjcb_control(None)
    return out


def _serial(t: Transmission) -> tuple[SerialEquivalent, Any]:
    """``t``'s serial-equivalent model and its MuJoCo model, built once per transmission (and reference): every run
    of a table copies the compiled model (its timestep set, :class:`mujoco.MjModel` the same as one compiled at it)."""
    key = t.mechanism.q_reference.tobytes()
    cached = t.__dict__.get("_fidelity_serial")
    if cached is None or cached[0] != key:
        mujoco = module("mujoco", extra="bench", what="the serial-equivalent model's MuJoCo run")
        se = serial_equivalent(t.mechanism, [t], limits=False)
        cached = (key, se, mujoco.MjModel.from_xml_string(se.mjcf()))
        t.__dict__["_fidelity_serial"] = cached  # (as functools.cached_property keeps its values)
    return cached[1], cached[2]


@dataclass(frozen=True)
class FidelityRow:
    """One row of :func:`fidelity`'s table: the largest output deviations from the closed loop [rad or m].

    Attributes:
        transmission: The transmission's name.
        profile: ``"chirp"`` or ``"swing"``.
        duration: The run's length [s]; ``dt`` its step [s].
        motion: The largest output excursion of (a) from the reference [rad or m] (the scale of the errors).
        constant_armature: (b)'s error (over the time it stayed in the sub-mechanism's workspace).
        exact: (c)'s error (inf if it left the workspace).
        left_workspace: The time (b) reached outputs the sub-mechanism cannot [s], or None.
        mujoco_integrator: (c) at ``dt`` against (c) at ``dt / 2``: MuJoCo's RK4's own error.
        pkm_integrator: (a) at ``dt`` against (a) at ``dt / 2``: :func:`pkm.simulate`'s.
        traces: The outputs of each run, ``{"a": ..., "b": ..., "c": ...}`` ((N+1) x k, at ``0, dt, ...``).
    """

    transmission: str
    profile: str
    duration: float
    dt: float
    motion: float
    constant_armature: float
    exact: float
    mujoco_integrator: float
    pkm_integrator: float
    left_workspace: float | None = None
    traces: dict[str, np.ndarray] = field(default_factory=dict, repr=False, compare=False)


def fidelity(t: Transmission, duration: float = 2.0, dt: float = 1e-3, *, amplitude: float = 0.02,
             which: tuple[str, ...] = ("chirp", "swing"), integrators: bool = True) -> list[FidelityRow]:
    """The fidelity table of ``t`` (module doc): one row per profile of :func:`profiles` named in ``which``;
    ``integrators=False`` skips the runs at ``dt / 2`` (the integrators' errors are then NaN)."""
    rows = []
    for name, torque in profiles(t, duration, amplitude=amplitude).items():
        if name not in which:
            continue
        a = closed_loop(t, torque, duration, dt)
        b = serial_run(t, torque, duration, dt, exact=False)
        c = serial_run(t, torque, duration, dt, exact=True)
        nan = np.full_like(a, np.nan)
        a2 = closed_loop(t, torque, duration, dt / 2)[::2] if integrators else nan
        c2 = serial_run(t, torque, duration, dt / 2, exact=True)[::2] if integrators else nan
        gone = np.flatnonzero(np.isnan(b[:, 0]))
        rows.append(FidelityRow(t.name, name, duration, dt, float(np.abs(a - a[0]).max()),
                                float(np.nanmax(np.abs(b - a))), _worst(c - a), _worst(c - c2), _worst(a - a2),
                                float(gone[0] * dt) if gone.size else None, {"a": a, "b": b, "c": c}))
    return rows


def _worst(x: np.ndarray) -> float:
    """The largest deviation; inf where a run stopped early (NaN), NaN where it was not run."""
    if np.all(np.isnan(x)):
        return float("nan")
    return float("inf") if np.any(np.isnan(x)) else float(np.abs(x).max())


def table(rows: list[FidelityRow]) -> str:
    """The rows as a Markdown table (errors in the outputs' units: rad or m)."""
    lines = ["| transmission | profile | motion | (b) constant armature | (c) serial + ΔM + Δh | MuJoCo RK4 (dt vs dt/2) "
             "| pkm RK4 (dt vs dt/2) |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        left = f" (left the workspace at {r.left_workspace:.3g} s)" if r.left_workspace is not None else ""
        lines.append(f"| {r.transmission} | {r.profile} | {r.motion:.3g} | {r.constant_armature:.2e}{left} | {r.exact:.2e} "
                     f"| {r.mujoco_integrator:.1e} | {r.pkm_integrator:.1e} |")
    return "\n".join(lines)


__all__ = ["FidelityRow", "closed_loop", "fidelity", "profiles", "serial_run", "table"]
