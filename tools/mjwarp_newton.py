"""pkm's exact transmissions inside Newton's MuJoCo solver (issue 56, item 1: "also through Newton's MuJoCo solver").

Newton's ``SolverMuJoCo`` converts a Newton model to a MuJoCo model and steps it with ``mujoco_warp.step``, the engine
:class:`pkm.learn.mjwarp.TransmissionWorlds` drives; :meth:`TransmissionWorlds.attach` puts pkm's transmission
kernels on its ``mjw_model.callback.control``. Here the humanoid ankle's serial-equivalent model, written by pkm as
USD (:func:`pkm.core.formats.to_usd.serial_usd`) and read by ``newton.ModelBuilder.add_usd`` (the outputs' armature,
ΔM's diagonal, set to zero for the exact route, left for the constant-armature one), steps in Newton from the
reference at rest under constant motor torques (the chirp of :func:`pkm.core.transmissions.fidelity.profiles` at
0.25 s, held), RK4 at 1 ms for 0.5 s, against

* (a) the closed loop, :func:`pkm.simulate` (float64);
* (w) pkm's own :class:`TransmissionWorlds` (the serial MJCF in MuJoCo Warp, the same kernels);
* (n) Newton's ``SolverMuJoCo`` with the transmission attached, exact; (nb) the same, ``exact=False``: the constant
  armature of the file.

Newton is no pkm extra. Its ``sim`` extra pins MuJoCo Warp 3.17; pkm's ``mjwarp`` extra has 4.0, with which Newton
1.8.0 runs, warning of the mismatch. So Newton goes into pkm's environment without its dependencies (its one
required dependency, Warp, is there; ``usd-core`` is pkm's ``usd`` extra):

    pip install --no-deps newton==1.8.0 newton-usd-schemas   # into pkm's venv (with the mjwarp and usd extras)
    PYTHONPATH=src python tools/mjwarp_newton.py [OUT_DIR]

Writes ``OUT_DIR/mjwarp_newton.json`` (default ``tools/reports``).
"""

from __future__ import annotations

import json
import platform
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import warp as wp

import pkm
from pkm.core.formats.to_usd import serial_usd
from pkm.core.kinematics.constraints import residual
from pkm.core.transmissions.fidelity import closed_loop, profiles
from pkm.learn.mjwarp import TransmissionWorlds

ROOT = Path(__file__).resolve().parents[1]
DURATION, DT, AT = 0.5, 1e-3, 0.25


def newton_route(robot, t, tau: np.ndarray, usd: Path, exact: bool) -> dict:  # type: ignore[no-untyped-def]
    """(n) or (nb): the outputs (N+1, k), the kernels' closure residual and pkm's at their configuration, CPU s."""
    import newton

    builder = newton.ModelBuilder()
    builder.add_usd(str(usd))
    model = builder.finalize(device="cpu", skip_validation_inertia=True)
    labels = [str(x) for x in model.joint_label]
    starts = model.joint_qd_start.numpy()
    dofs = [int(starts[next(i for i, x in enumerate(labels) if x.split("/")[-1] == o)]) for o in t.outputs]
    if exact:  # (ΔM whole goes into M: the file's armature, its diagonal, out)
        armature = model.joint_armature.numpy()
        armature[dofs] = 0.0
        model.joint_armature.assign(armature)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        solver = newton.solvers.SolverMuJoCo(model, integrator="rk4", disable_contacts=True)
    mjm = solver.mj_model
    joints = {o: next(mjm.joint(j).name for j in range(mjm.njnt) if mjm.joint(j).name.endswith("_" + o))
              for o in t.outputs}
    worlds = TransmissionWorlds.attach(robot, mjm, solver.mjw_model, solver.mjw_data, transmissions=[t],
                                       joints=joints, exact=exact)
    worlds.set_motor_torques(tau)
    state, other, control = model.state(), model.state(), model.control()
    n = round(DURATION / DT)
    out = np.zeros((n + 1, t.k))
    out[0] = worlds.output_q[0]
    start = time.process_time()
    for i in range(n):
        solver.step(state, other, control, None, DT)
        state, other = other, state
        out[i + 1] = state.joint_q.numpy()[dofs]
    cpu = time.process_time() - start
    q_end = worlds.sub_q(0)[0]
    return {"out": out, "kernel_residual": float(worlds.residual.max()),
            "pkm_residual": float(np.abs(residual(t.mechanism, q_end)).max()), "cpu_s": cpu,
            "integrator": int(mjm.opt.integrator), "newton_warnings": sorted({str(w.message)[:160] for w in caught})}


def pkm_route(robot, t, tau: np.ndarray) -> tuple[np.ndarray, float]:  # type: ignore[no-untyped-def]
    """(w): pkm's own TransmissionWorlds, the same step and torques."""
    worlds = TransmissionWorlds(robot, 1, transmissions=[t], dt=DT, integrator="rk4", limits=False)
    worlds.set_motor_torques(tau)
    n = round(DURATION / DT)
    out = np.zeros((n + 1, t.k))
    out[0] = worlds.output_q[0]
    for i in range(n):
        worlds.step()
        out[i + 1] = worlds.output_q[0]
    return out, float(worlds.residual.max())


def main(argv: list[str]) -> dict:
    import newton

    wp.config.quiet = True
    out_dir = Path(argv[0]) if argv else ROOT / "tools" / "reports"
    robot = pkm.load(ROOT / "examples" / "humanoid_ankle" / "ankle.closures.toml")
    (t,) = pkm.transmissions(robot)
    tau = profiles(t, 1.0)["chirp"](AT)
    a = closed_loop(t, lambda _time: tau, DURATION, DT)
    w, w_res = pkm_route(robot, t, tau)
    with tempfile.TemporaryDirectory() as tmp:
        usd = Path(tmp) / "ankle_serial.usda"
        serial_usd(pkm.serial_equivalent(robot, limits=False), usd)
        n = newton_route(robot, t, tau, usd, exact=True)
        nb = newton_route(robot, t, tau, usd, exact=False)
    result = {
        "command": "PYTHONPATH=src python tools/mjwarp_newton.py (newton 1.8.0 importable beside the mjwarp extra: "
                   "installed --no-deps, or its package directory on PYTHONPATH)",
        "device": f"Warp 'cpu' ({platform.machine()}); GPU: missing, no GPU was lent to this session",
        "newton": newton.__version__, "warp": wp.config.version, "duration_s": DURATION, "dt_s": DT,
        "integrator": "RK4", "motor_torques": tau.tolist(), "motion_rad": float(np.abs(a - a[0]).max()),
        "error_vs_pkm_simulate_rad": {"w": float(np.abs(w - a).max()), "n": float(np.abs(n["out"] - a).max()),
                                      "nb": float(np.abs(nb["out"] - a).max())},
        "newton_vs_pkm_worlds_rad": float(np.abs(n["out"] - w).max()),
        "closure_residual_m": {"w_kernel": w_res, "n_kernel": n["kernel_residual"], "n_pkm": n["pkm_residual"]},
        "cpu_s": {"n": n["cpu_s"], "nb": nb["cpu_s"]}, "newton_warnings": n["newton_warnings"]}
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "mjwarp_newton.json").write_text(json.dumps(result, indent=1) + "\n")
    print(json.dumps(result, indent=1))
    return result


if __name__ == "__main__":
    main(sys.argv[1:])
