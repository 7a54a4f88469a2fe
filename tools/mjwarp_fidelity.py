"""Fidelity of the humanoid ankle and knee and of Gepetto's battobot's two ankles (``gepetto:battobot_6d``'s
``foot_assembly``, right, and ``foot_assembly_2``, left: each alone, its root held, as (a) runs it) in MuJoCo Warp
(issue 56): the same 1 s motor-torque chirp
(:func:`pkm.core.transmissions.fidelity.profiles`, 0.5 to 4 Hz over 1 s) from the reference at rest, RK4 at 1 ms, on

* (a) the closed loop, :func:`pkm.simulate` (float64; closure exact);
* (w) MuJoCo Warp with pkm's transmission exact inside the step (:class:`pkm.learn.mjwarp.TransmissionWorlds`,
  float32 state, float64 kernels);
* (w64) the same algorithm in CPU MuJoCo, float64 (:func:`pkm.core.transmissions.fidelity.serial_run`, ``exact``):
  (w) against (w64) is what MuJoCo Warp's float32 costs;
* (s) soft-loop MJCF in MuJoCo Warp, the torques on its motors' joints, its joint damping and limits off as
  pkm.simulate has none here: the ankle's own file (``examples/humanoid_ankle/ankle.xml``: the rods on ball joints,
  the loops ``<equality><connect>`` with its ``solref="0.002 1"``) and (s_pkm) pkm's MJCF writer's
  (:func:`pkm.core.formats.to_mjcf.mjcf_from_mechanism`: stiff connects between sites, ``solref = (2 dt,
  0.5)``, ``solimp`` 0.9999), the knee's only that one;
* (b) the constant-armature serial model in MuJoCo Warp (``exact=False``: ΔM's diagonal at the reference, no Δh,
  the effort map exact).

The torque is evaluated at every stage of every RK4 step from the stage's time, in every route (a Warp kernel of the
chirp here). Errors: the largest deviation of pitch and roll from (a) [rad]; closure residual: (w) the transmission
kernel's Newton residual and pkm's own closure residual at its configuration, (s) the distance of each
``<connect>``'s two anchors [m], after 1 s. Energy drift: 1 s under constant motor torques (the holding torques plus
half the chirp's amplitude, opposite on the two motors) from the reference at rest, ``E = T + V - τ_m · q_m``
(conserved), its largest change over the run relative to the largest kinetic energy; (a) and (w) from pkm's closed-loop
model in output coordinates at each sampled state, (s) from MuJoCo's energy.

    PYTHONPATH=src python tools/mjwarp_fidelity.py [OUT_DIR] [--only=battobot_ankle_right,...]

Writes ``OUT_DIR/mjwarp_fidelity.json`` and ``.md`` (default ``tools/reports``); ``--only`` runs those robots and keeps
the others' results from the JSON already there. Needs the ``mjwarp`` and ``bench`` extras. Takes a few minutes per
robot on a CPU.

(b) can leave the workspace (a battobot ankle's does, as in ``tools/transmission_fidelity.py``): its error is then
over the time before, the time said (MuJoCo Warp's: the transmission kernel's closure solve failing at its outputs;
CPU MuJoCo's: :func:`serial_run`'s NaN). A ``<weld>``'s residual (battobot's 6-D loops) is its sites' distance [m]
and the angle between their frames [rad]. MuJoCo Warp itself has no float64 build: its arrays and kernels are
typed with Python's ``float``, which Warp compiles as float32, and no option changes it; (w64), the same algorithm
in CPU MuJoCo in float64, is what (w) is held against.
"""

from __future__ import annotations

import json
import platform
import sys
import time
from pathlib import Path

import mujoco
import mujoco_warp as mjw
import numpy as np
import pinocchio as pin
import warp as wp

import pkm
from pkm.core.kinematics.constraints import residual
from pkm.core.transmissions.fidelity import closed_loop, profiles, serial_run
from pkm.learn.mjwarp import STAGES, TransmissionWorlds

ROOT = Path(__file__).resolve().parents[1]
ANKLE = ROOT / "examples" / "humanoid_ankle"
DURATION, DT = 1.0, 1e-3
F0, F1 = 0.5, 4.0  # (profiles' chirp)


@wp.kernel
def chirp(time: wp.array(dtype=wp.float32), offset: wp.float64, hold: wp.array(dtype=wp.float64),
          amp: wp.array(dtype=wp.float64), phase: wp.array(dtype=wp.float64), f0: wp.float64, f1: wp.float64,
          duration: wp.float64, dadr: wp.array(dtype=wp.int32), write: int, tau: wp.array2d(dtype=wp.float64),
          qfrc: wp.array2d(dtype=wp.float32)):
    w, i = wp.tid()
    t = wp.float64(time[w]) + offset
    arg = wp.float64(2.0) * wp.float64(wp.pi) * (f0 * t + wp.float64(0.5) * (f1 - f0) * t * t / duration) + phase[i]
    v = hold[i] + amp[i] * wp.sin(arg)
    tau[i, w] = v
    if write != 0:
        qfrc[w, dadr[i]] = wp.float32(v)


class Chirp:
    """The chirp of :func:`profiles` (its hold, amplitude and phases) as a Warp kernel of each stage's time; with
    ``amp`` zero and ``hold`` any vector, a constant torque."""

    def __init__(self, hold: np.ndarray, amp: np.ndarray, phase: np.ndarray, dadr: np.ndarray, nworld: int):
        self.args = [wp.array(np.asarray(x, dtype=float), dtype=wp.float64) for x in (hold, amp, phase)]
        self.dadr = wp.array(np.asarray(dadr, dtype=np.int32), dtype=wp.int32)
        self.k, self.n = len(hold), nworld
        self.tau = wp.zeros((self.k, nworld), dtype=wp.float64)

    def launch(self, d, offset: float, write: bool, out=None) -> None:
        wp.launch(chirp, dim=(self.n, self.k), inputs=[d.time, offset, *self.args, F0, F1, DURATION, self.dadr,
                                                       int(write)], outputs=[out if out is not None else self.tau,
                                                                             d.qfrc_applied])


def chirp_parts(t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(hold, amplitude, phase) of :func:`profiles`' chirp, read back from it (checked against it below)."""
    f = profiles(t, DURATION)["chirp"]
    hold = pkm.gravity_efforts(t.mechanism, t.q_reference)
    amp = 0.02 * np.diag(pkm.mass_matrix(t.mechanism, t.q_reference)) * (4.0 * np.pi) ** 2
    phase = 0.5 * np.pi * np.arange(t.k)
    for time_ in (0.0, 0.37, 0.81):  # (the same profile as the CPU routes')
        w = 2 * np.pi * (F0 * time_ + 0.5 * (F1 - F0) * time_ ** 2 / DURATION)
        assert np.allclose(hold + amp * np.sin(w + phase), f(time_), rtol=1e-12, atol=1e-12)
    return hold, amp, phase


def run_transmission(robot, t, torque: Chirp, exact: bool, sample: int = 10):
    """(w) or (b): outputs (N+1, 2), every ``sample`` steps (time, q_sub, output rates, kernel residual), the CPU
    seconds and the time the outputs first left the sub-mechanism's workspace (the kernel's closure solve failing:
    its status not OK), or None."""
    worlds = TransmissionWorlds(robot, 1, transmissions=[t], exact=exact, dt=DT, integrator="rk4", limits=False)
    unit = worlds.units[0]
    worlds.torque_source = lambda w: torque.launch(w.data, w.stage_offset, False, unit.tau_m)
    n = round(DURATION / DT)
    out = np.zeros((n + 1, t.k))
    out[0] = worlds.output_q[0]
    states, left = [], None
    start = time.process_time()
    for i in range(n):
        worlds.step()
        out[i + 1] = worlds.output_q[0]
        if left is None and worlds.status.max() != 0:
            left = (i + 1) * DT
        if (i + 1) % sample == 0:
            states.append(((i + 1) * DT, worlds.sub_q(0)[0], worlds.qvel[0].astype(float), float(worlds.residual.max())))
    return out, states, time.process_time() - start, left


def soft_model(source: Path | str):
    """A soft-loop MJCF (a file, or MJCF text) in MuJoCo (CPU model), RK4 at DT, its joint damping and its joint limits
    off (pkm.simulate has neither here: the ankle's roll reaches the file's 0.35 rad under the constant torques), the
    energy computed."""
    m = mujoco.MjModel.from_xml_path(str(source)) if isinstance(source, Path) else mujoco.MjModel.from_xml_string(source)
    m.opt.timestep, m.opt.integrator = DT, mujoco.mjtIntegrator.mjINT_RK4
    m.dof_damping[:] = 0.0
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_LIMIT  # (pkm.simulate's runs watch no limit either)
    m.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    return m


def connect_residual(m, d) -> tuple[float, float]:
    """The largest distance of a ``<connect>``'s or ``<weld>``'s two anchors [m] at ``d``'s kinematics, and the
    largest angle between a site ``<weld>``'s two frames [rad] (0 without welds)."""
    worst, angle = 0.0, 0.0
    for e in range(m.neq):
        a, b = m.eq_obj1id[e], m.eq_obj2id[e]
        if m.eq_objtype[e] == mujoco.mjtObj.mjOBJ_SITE:  # (pkm's MJCF writer: a site at each closure frame)
            p1, p2 = d.site_xpos[a], d.site_xpos[b]
            if m.eq_type[e] == mujoco.mjtEq.mjEQ_WELD:  # (a frame closure: the sites' frames coincide)
                R = d.site_xmat[a].reshape(3, 3).T @ d.site_xmat[b].reshape(3, 3)
                angle = max(angle, float(np.arccos(np.clip(0.5 * (np.trace(R) - 1.0), -1.0, 1.0))))
        else:  # (bodies, the anchors in eq_data: a connect)
            p1 = d.xpos[a] + d.xmat[a].reshape(3, 3) @ m.eq_data[e, 0:3]
            p2 = d.xpos[b] + d.xmat[b].reshape(3, 3) @ m.eq_data[e, 3:6]
        worst = max(worst, float(np.linalg.norm(p1 - p2)))
    return worst, angle


def run_soft(source, torque_of, t, sample: int = 10):
    """(s): the outputs (N+1, k) of the soft-loop model ``source`` from its reference keyframe (else ``qpos0``), the
    connects' residual at the end, and every ``sample`` steps MuJoCo's energy (potential, kinetic) and the motors'
    positions."""
    mjm = soft_model(source)
    dadr = np.array([mjm.jnt_dofadr[mjm.joint(n).id] for n in t.motors])
    torque = torque_of(dadr)
    qadr = [mjm.jnt_qposadr[mjm.joint(n).id] for n in t.outputs]
    madr = [mjm.jnt_qposadr[mjm.joint(n).id] for n in t.motors]
    start_qpos = mjm.key_qpos[0].copy() if mjm.nkey else mjm.qpos0.copy()
    m = mjw.put_model(mjm)
    d = mjw.make_data(mjm, nworld=1)
    d.qpos.assign(start_qpos[None, :].astype(np.float32))
    stage = [0]
    stages = STAGES[int(mujoco.mjtIntegrator.mjINT_RK4)]

    def control(_m, data):
        torque.launch(data, stages[min(stage[0], 3)] * DT, True)
        stage[0] += 1

    m.callback.control = control
    n = round(DURATION / DT)
    out = np.zeros((n + 1, t.k))
    out[0] = start_qpos[qadr]
    states = []
    start = time.process_time()
    for i in range(n):
        stage[0] = 0
        mjw.step(m, d)
        qpos = d.qpos.numpy()[0]
        out[i + 1] = qpos[qadr]
        if (i + 1) % sample == 0:
            states.append((qpos.astype(float), d.qvel.numpy()[0].astype(float)))
    cpu = time.process_time() - start
    cd = mujoco.MjData(mjm)
    energy = []  # (MuJoCo's energy at each sampled state, in float64 on the CPU model: potential, kinetic)
    for qpos, qvel in [(start_qpos, np.zeros(mjm.nv)), *states]:
        cd.qpos[:], cd.qvel[:] = qpos, qvel
        mujoco.mj_forward(mjm, cd)
        full = np.zeros((mjm.nv, mjm.nv))
        mujoco.mj_fullM(mjm, cd, full)
        kinetic = 0.5 * qvel @ full @ qvel  # (with the rotors' armature)
        energy.append((float(cd.energy[0] + kinetic), qpos[madr], float(kinetic)))
    return out, connect_residual(mjm, cd), energy, cpu


def closed_energy(t, q: np.ndarray, od: np.ndarray, tau: np.ndarray) -> tuple[float, float]:
    """``(E, T)``: ``T + V - τ·q_m`` and ``T`` of the closed loop at ``(q, ȯ)`` (pkm's output-coordinate model)."""
    sub = t.mechanism
    M_o, _ = t.output_model(q, od)
    T = 0.5 * od @ M_o @ od
    V = pin.computePotentialEnergy(sub.model, sub.data, q)
    return float(T + V - tau @ q[sub.act_q]), float(T)


def drift(values: list[tuple[float, float]]) -> float:
    E = np.array([v[0] for v in values])
    T = np.array([v[1] for v in values])
    return float(np.abs(E - E[0]).max() / T.max())


ROBOTS = {  # name: (what pkm.load reads, the transmission (None: the only one), the soft-loop MJCFs: (label, a file or
    # None for pkm's own MJCF writer))
    "humanoid_ankle": (ANKLE / "ankle.closures.toml", None, (("s", ANKLE / "ankle.xml"), ("s_pkm", None))),
    "humanoid_knee": (ROOT / "examples" / "humanoid_knee" / "knee.closures.toml", None, (("s_pkm", None),)),
    "battobot_ankle_right": ("gepetto:battobot_6d", "foot_assembly", (("s_pkm", None),)),
    "battobot_ankle_left": ("gepetto:battobot_6d", "foot_assembly_2", (("s_pkm", None),)),
}
SOFT = {"s": "the file's own `<connect>`s (`solref=\"0.002 1\"`)",
        "s_pkm": "pkm's MJCF writer (`pkm.save`: stiff `<connect>`s or `<weld>`s, `solref=(2 dt, 0.5)`, `solimp` 0.9999)"}


def one_robot(name: str) -> dict:
    from pkm.core.formats.to_mjcf import mjcf_from_mechanism

    path, pick, softs = ROBOTS[name]
    robot = pkm.load(path)
    found = pkm.transmissions(robot)
    (t,) = found if pick is None else [x for x in found if x.name == pick]
    if pick is not None:  # (a whole robot's transmission alone, its root held, as (a) runs it)
        robot = t.mechanism
    hold, amp, phase = chirp_parts(t)
    f = profiles(t, DURATION)["chirp"]
    ks = list(range(t.k))
    sources = {label: (src if src is not None else mjcf_from_mechanism(robot, timestep=DT)) for label, src in softs}
    a = closed_loop(t, f, DURATION, DT)
    w64 = serial_run(t, f, DURATION, DT, exact=True)
    b64 = serial_run(t, f, DURATION, DT, exact=False)
    w, w_states, w_cpu, _ = run_transmission(robot, t, Chirp(hold, amp, phase, ks, 1), True)
    b, _, b_cpu, b_left = run_transmission(robot, t, Chirp(hold, amp, phase, ks, 1), False)
    nan = np.flatnonzero(~np.isfinite(b64).all(axis=1))  # (serial_run: NaN once out of the workspace)
    left = {"b": b_left, "b64": float(nan[0] * DT) if nan.size else None}
    if b_left is not None:  # (the errors over the time before: after, no closed configuration compares)
        b = b[:round(b_left / DT)]
    traces = {"w": w, "w64": w64, "b": b, "b64": b64[:nan[0]] if nan.size else b64}
    cpu = {"w": w_cpu, "b": b_cpu}
    residuals = {}
    for label, src in sources.items():
        traces[label], (residuals[label], angle), _, cpu[label] = run_soft(
            src, lambda dadr: Chirp(hold, amp, phase, dadr, 1), t)
        if any(c.type == "frame" for c in t.mechanism.spec.closures):
            residuals[f"{label}_rad"] = angle
    _, q_end, _, kernel_res = w_states[-1]
    out: dict = {"transmission": t.name, "outputs": list(t.outputs), "motion": float(np.abs(a - a[0]).max()),
                 "error": {key: float(np.abs(x - a[:len(x)]).max()) for key, x in traces.items()},
                 "left_workspace_s": left,
                 "float32_cost": float(np.abs(w - w64).max()),
                 "closure_residual_m": {"w_kernel": kernel_res, "w_pkm": float(np.abs(residual(t.mechanism, q_end)).max()),
                                        **residuals},
                 "cpu_s": cpu, "soft_models": {label: SOFT[label] for label in sources}}
    # energy drift: constant torques from rest
    const = hold + 0.5 * amp * np.where(np.arange(t.k) % 2 == 0, 1.0, -1.0)
    zero = np.zeros_like(amp)
    sim = pkm.simulate(t.mechanism, t.q_reference, None, DURATION, DT, lambda *_: const, friction=False,
                       saturate=False, limits=False, backend="python")
    qs, vs = np.asarray(sim.q), np.asarray(sim.v)
    drifts = {"a": drift([closed_energy(t, qs[i], vs[i][t.out_v], const) for i in range(0, len(qs), 10)])}
    _, w_states, _, _ = run_transmission(robot, t, Chirp(const, zero, zero, ks, 1), True)
    e_w = [closed_energy(t, t.q_reference, np.zeros(t.k), const)]
    drifts["w"] = drift(e_w + [closed_energy(t, q, od, const) for _, q, od, _ in w_states])
    for label, src in sources.items():
        _, _, energy, _ = run_soft(src, lambda dadr: Chirp(const, zero, zero, dadr, 1), t)
        drifts[label] = drift([(float(E - const @ qm), float(T)) for E, qm, T in energy])
    out["energy_drift"] = {"torque": const.tolist(), "relative_to_max_kinetic": drifts}
    return out


def main(argv: list[str]) -> None:
    wp.config.quiet = True
    only = next((a.split("=", 1)[1].split(",") for a in argv if a.startswith("--only=")), None)
    paths = [a for a in argv if not a.startswith("--")]
    out_dir = Path(paths[0]) if paths else ROOT / "tools" / "reports"
    unknown = sorted(set(only or ()) - set(ROBOTS))
    if unknown:
        sys.exit(f"--only: unknown {unknown}; known {sorted(ROBOTS)}")
    previous = json.loads((out_dir / "mjwarp_fidelity.json").read_text())["robots"] if only else {}
    result: dict = {"duration_s": DURATION, "dt_s": DT, "integrator": "RK4",
                    "device": f"Warp 'cpu' ({platform.machine()}); GPU: missing, no GPU was lent to this session",
                    "command": "PYTHONPATH=src python tools/mjwarp_fidelity.py",
                    "mujoco_warp": "4.0.0", "warp": wp.config.version,
                    "robots": {name: (one_robot(name) if only is None or name in only else previous[name])
                               for name in ROBOTS if only is None or name in only or name in previous}}
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "mjwarp_fidelity.json").write_text(json.dumps(result, indent=2) + "\n")
    (out_dir / "mjwarp_fidelity.md").write_text("\n".join(table(result)) + "\n")
    print("\n".join(table(result)))


def table(result: dict) -> list[str]:
    """The markdown table and notes of ``result`` (the JSON's)."""
    md = ["| robot | route | output error vs pkm.simulate [rad] | closure residual after 1 s [m] | energy drift (rel.) |",
          "|---|---|---|---|---|"]
    for name, r in result["robots"].items():
        e, err, res = r["energy_drift"]["relative_to_max_kinetic"], r["error"], r["closure_residual_m"]
        md += [f"| {name} | (a) pkm.simulate, closed loop (float64) | — | exact (Newton) | {e['a']:.1e} |",
               f"| {name} | (w) MuJoCo Warp + exact transmission (float32 state) | {err['w']:.2e} | "
               f"{res['w_kernel']:.1e} (kernel), {res['w_pkm']:.1e} (pkm) | {e['w']:.1e} |",
               f"| {name} | (w64) CPU MuJoCo + exact transmission (float64) | {err['w64']:.2e} | exact (Newton) | — |"]
        md += [f"| {name} | ({label}) soft loops in MuJoCo Warp: {SOFT[label]} | {err[label]:.2e} | {res[label]:.1e}"
               + (f", {res[label + '_rad']:.1e} rad" if label + "_rad" in res else "") + f" | {e[label]:.1e} |"
               for label in r["soft_models"]]
        gone = {key: "" if at is None else f" (left the workspace at {at:.3g} s)"
                for key, at in r.get("left_workspace_s", {"b": None, "b64": None}).items()}
        md += [f"| {name} | (b) constant armature in MuJoCo Warp | {err['b']:.2e}{gone['b']} | — | — |",
               f"| {name} | (b64) constant armature in CPU MuJoCo | {err['b64']:.2e}{gone['b64']} | — | — |"]
    md += [""] + [f"{name}: motion {r['motion']:.3g} rad; float32's cost, (w) against (w64): {r['float32_cost']:.1e} rad."
                  for name, r in result["robots"].items()]
    return md


if __name__ == "__main__":
    main(sys.argv[1:])
