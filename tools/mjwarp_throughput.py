"""Throughput of the humanoid ankle in MuJoCo Warp (issue 56): steps per second (worlds x steps / wall second, and per
CPU second of this process) at N worlds for

* ``serial``: the plain serial-equivalent model (constant armature, the outputs' ``<motor>`` driven through ``ctrl``);
* ``exact``: the same model with pkm's transmission exact inside the step (:class:`pkm.learn.mjwarp.TransmissionWorlds`:
  the fused kernel at every evaluation, ΔM into M, τ_o - Δh applied, and once more after the step for the motor
  states);
* ``soft``: the soft-loop MJCF (``examples/humanoid_ankle/ankle.xml``, ``<connect>`` equalities, rods on ball joints),
  the torques on its motors' joints;

all semi-implicit Euler at 1 ms (a training setting), constant torques, after two warm-up steps, the least time of
three runs of 50 steps (20 from 4,096 worlds). Warp's CPU device
runs a kernel's threads one after the other on one core; on a shared host the wall time counts the other jobs' share,
so the overhead of the exact transmissions is stated by CPU time (``exact_overhead_cpu``) as well as by wall time.

    PYTHONPATH=src python tools/mjwarp_throughput.py [--device cpu] [--sizes 1,64,1024,4096] [OUT_DIR]

Writes ``OUT_DIR/mjwarp_throughput_<device>.json`` (default ``tools/reports``). The GPU run is this same command with
``--device cuda:0`` where a GPU is lent.
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
import warp as wp

import pkm
from pkm.learn.mjwarp import TransmissionWorlds

ROOT = Path(__file__).resolve().parents[1]
ANKLE = ROOT / "examples" / "humanoid_ankle"
DT = 1e-3


def timed(step, steps: int, repeats: int = 3) -> tuple[float, float]:
    """(wall, CPU) seconds of ``steps`` calls of ``step``, synchronised: the least of ``repeats`` runs each (the
    host is shared: the least is the one the other jobs disturbed least)."""
    step()
    step()
    wp.synchronize()
    walls, cpus = [], []
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        for _ in range(steps):
            step()
        wp.synchronize()
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    return min(walls), min(cpus)


def plain(mjm, n: int, device: str):
    with wp.ScopedDevice(device):
        m = mjw.put_model(mjm)
        d = mjw.make_data(mjm, nworld=n)
    return lambda: mjw.step(m, d), d


def main(argv: list[str]) -> None:
    wp.config.quiet = True
    device = argv[argv.index("--device") + 1] if "--device" in argv else "cpu"
    sizes = [int(x) for x in (argv[argv.index("--sizes") + 1] if "--sizes" in argv else "1,64,1024,4096,8192").split(",")]
    rest = [a for i, a in enumerate(argv) if not a.startswith("--") and (i == 0 or not argv[i - 1].startswith("--"))]
    out_dir = Path(rest[0]) if rest else ROOT / "tools" / "reports"
    robot = pkm.load(ANKLE / "ankle.closures.toml")
    (t,) = pkm.transmissions(robot)
    hold = pkm.gravity_efforts(t.mechanism, t.q_reference)
    tau = hold + 0.05 * np.array([1.0, -1.0])
    se = pkm.serial_equivalent(robot, [t], limits=False)
    serial = mujoco.MjModel.from_xml_string(se.mjcf(timestep=DT))
    serial.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    soft = mujoco.MjModel.from_xml_path(str(ANKLE / "ankle.xml"))
    soft.opt.timestep, soft.opt.integrator = DT, mujoco.mjtIntegrator.mjINT_EULER
    soft_dofs = [soft.jnt_dofadr[soft.joint(n).id] for n in t.motors]
    rows = []
    for n in sizes:
        steps = 50 if n <= 1024 else 20
        row: dict = {"N": n, "steps": steps}
        step, d = plain(serial, n, device)
        d.ctrl.assign(np.repeat((t.inverse_effort_map(t.q_reference) @ tau)[None, :], n, axis=0).astype(np.float32))
        row["serial"] = timed(step, steps)
        worlds = TransmissionWorlds(robot, n, transmissions=[t], dt=DT, integrator="euler", limits=False, device=device)
        worlds.set_motor_torques(tau)
        row["exact"] = timed(worlds.step, steps)
        step, d = plain(soft, n, device)
        f = np.zeros((n, soft.nv), dtype=np.float32)
        f[:, soft_dofs] = tau
        d.qfrc_applied.assign(f)
        row["soft"] = timed(step, steps)
        for key in ("serial", "exact", "soft"):
            wall, cpu = row[key]
            row[key] = {"wall_s": wall, "cpu_s": cpu, "steps_per_s": n * steps / wall, "steps_per_cpu_s": n * steps / cpu}
        row["exact_overhead_cpu"] = row["exact"]["cpu_s"] / row["serial"]["cpu_s"] - 1.0
        row["exact_overhead_wall"] = row["exact"]["wall_s"] / row["serial"]["wall_s"] - 1.0
        rows.append(row)
        print(f"N={n}: " + ", ".join(f"{k} {row[k]['steps_per_s']:.3g}/s ({row[k]['steps_per_cpu_s']:.3g}/CPU s)"
                                     for k in ("serial", "exact", "soft")) + f", overhead {row['exact_overhead_cpu']:.0%} (CPU)",
              flush=True)
    result = {"robot": "humanoid_ankle", "integrator": "Euler", "dt_s": DT, "device": device,
              "machine": f"{platform.machine()}, Warp '{device}', shared 2-core host (other jobs running)",
              "command": f"PYTHONPATH=src python tools/mjwarp_throughput.py --device {device}",
              "warp": wp.config.version, "gpu": "missing: no GPU was lent to this session", "rows": rows}
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / f"mjwarp_throughput_{device.replace(':', '')}.json").write_text(json.dumps(result, indent=2) + "\n")


if __name__ == "__main__":
    main(sys.argv[1:])
