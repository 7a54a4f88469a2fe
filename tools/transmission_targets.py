"""Every transmission of the transmission tests' robots (tests/core/transmissions/robots.py: the shipped humanoid
ankle and knee, the SDF slider-crank, the acceptance set's ankle and knee, Gepetto's battobot and Talos-like bipeds):
the compiled C kernels against the Python reference (:class:`pkm.Transmission`: FK, IK, velocity and effort maps, ΔM,
Δh), and JAX and Warp (CPU) against the C on every kernel. Slow (JAX and Warp compile kernels of up to 25,000
instructions): a tool, not a test; the tests run the same checks on the ankle and the knee.

The states: motor positions within ±0.05 rad of the reference, each kernel's Newton warm-started from the reference's
solution a tick (0.01 rad) away (Python's route solves them first): what a controller gives the kernels.

Usage: ``python tools/transmission_targets.py [--robots NAME ...] [--no-jax] [--no-warp] [--json FILE]``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "src"), str(ROOT)]

from pkm.core.transmissions.kernels import KERNELS, TransmissionKernels  # noqa: E402
from tests.core.transmissions.robots import ROBOTS, transmissions  # noqa: E402

N, SPREAD, TICK = 8, 0.05, 0.01


def check(t, jax_on: bool, warp_on: bool) -> dict:
    tk = TransmissionKernels.of(t)
    m, k = t.mechanism, t.k
    rng = np.random.default_rng(0)
    qm = m.actuated_q(m.q_reference) + rng.uniform(-SPREAD, SPREAD, (N, k))
    ref = [t.outputs_from_motors(x, m.q_reference, tol=1e-14) for x in qm]  # (Python's route, polished)
    warm = np.array([t.outputs_from_motors(x - TICK, r[1])[1] for x, r in zip(qm, ref)])
    q, qo, st, _ = tk.run("fk", warm, qm)
    out: dict = {"k": k, "nq": m.nq, "instructions": {n: tk.function(n).n_instructions() for n in KERNELS}}
    err = out["c_vs_python"] = {}
    err["fk"] = float(np.abs(qo - np.array([r[0] for r in ref])).max())
    _, qm2, st2, _ = tk.run("ik", warm, qo)
    err["round_trip"] = float(np.abs(qm2 - qm).max())
    out["statuses"] = sorted({int(x) for x in np.concatenate([st, st2]).ravel()})
    J, Ji, _ = (x.reshape(-1, k, k).transpose(0, 2, 1) for x in tk.run("maps", q))
    err["velocity_map"] = max(float(np.abs(t.velocity_map(q[i]) - J[i]).max()) for i in range(N))
    err["effort_map"] = max(float(np.abs(t.effort_map(q[i]) - J[i].T).max()) for i in range(N))
    err["inverse_effort_map"] = max(float(np.abs(t.inverse_effort_map(q[i]) - Ji[i].T).max()) for i in range(N))
    qdo = rng.uniform(-1.0, 1.0, (N, k))
    dM, dh, _ = tk.run("delta", q, qdo)
    dM = dM.reshape(-1, k, k).transpose(0, 2, 1)
    rel = []
    for i in range(N):
        M_o, h_o = t.output_model(q[i], qdo[i])
        rel.append((float(np.abs(t.delta_mass(q[i]) - dM[i]).max() / np.abs(M_o).max()),
                    float(np.abs(t.delta_bias(q[i], qdo[i]) - dh[i]).max() / max(np.abs(h_o).max(), 1e-300))))
    err["delta_mass_relative"], err["delta_bias_relative"] = (max(r[j] for r in rel) for j in (0, 1))
    inputs = {"fk": [warm, qm], "ik": [warm, qo], "maps": [q], "delta": [q, qdo], "fk_j_dm": [warm, qm]}
    c = {n: tk.run(n, *a) for n, a in inputs.items()}
    if jax_on:
        import jax

        t0 = time.perf_counter()
        out["jax_vs_c"] = {n: max(float(np.abs(np.asarray(x) - y).max()) for x, y in
                                  zip(jax.vmap(tk.jax(n))(*a), c[n])) for n, a in inputs.items()}
        out["jax_s"] = time.perf_counter() - t0
    if warp_on:
        import warp as wp

        from pkm.core.twin.warpgen import launch, warp_module

        wp.config.log_level = wp.LOG_WARNING
        t0 = time.perf_counter()
        module = warp_module([tk.looped(n) for n in KERNELS])
        out["warp_vs_c"] = {n: max(float(np.abs(x - y).max()) for x, y in
                                   zip(launch(getattr(module, tk.function(n).name()), tk.function(n), *a), c[n]))
                            for n, a in inputs.items()}
        out["warp_s"] = time.perf_counter() - t0
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--robots", nargs="+", default=list(ROBOTS))
    ap.add_argument("--no-jax", action="store_true")
    ap.add_argument("--no-warp", action="store_true")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    results = {}
    for r in args.robots:
        for t in transmissions(r):
            results[f"{r}/{t.name}"] = res = check(t, not args.no_jax, not args.no_warp)
            worst = {key: max(res[key].values()) for key in ("c_vs_python", "jax_vs_c", "warp_vs_c") if key in res}
            print(f"{r}/{t.name}: k={res['k']} statuses {res['statuses']} " +
                  ", ".join(f"{key} {v:.1e}" for key, v in worst.items()), flush=True)
    if args.json:
        args.json.write_text(json.dumps(results, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
