"""3-PRS inverse dynamics: time per call, per sample in a batch, and per evaluation in C.

Routes, all on the Table 2 design (P-actuated), from (z_p, beta, phi) and derivatives to forces:

* ``pkm``: :meth:`Prs3Dynamics.forces`, the public single-call API (the twin's expression graph);
* ``pkm_batch``: :meth:`Prs3Dynamics.batch` over 10^5 samples (vectorised numpy);
* ``pinocchio_khalil``: closed-form IK, the core's velocities and accelerations, RNEA and the
  generic Khalil projection (:meth:`Prs3Dynamics.pinocchio`);
* ``constraint_dynamics`` (the baseline): the same state, then the forces from Pinocchio's
  ``constraintDynamics``, which is affine in the efforts: 4 calls identify it, a 3x3 solve inverts it;
* ``c``: the twin generated as C, compiled with ``cc -O2``, timed by a C loop (skipped without a
  C compiler).

Every route's forces are compared with the baseline's on the timed samples (max difference, N).

Usage: ``python -m pkm.bench.dynamics [--json] [--quick] [-n 100000]``.
"""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from pkm.bench import best_time, main, median_us
from pkm.core.dynamics.projection import forward_dynamics
from pkm.mechanisms.prs3.dynamics import Prs3Dynamics, generate_c

QUICK = {"n": 500, "repeat": 10, "c_evaluations": 5000}

HARNESS = r"""
#include <stdio.h>
#include <time.h>
#include "twin.h"
int main(void) {
  casadi_int sz_arg, sz_res, sz_iw, sz_w;
  NAME_work(&sz_arg, &sz_res, &sz_iw, &sz_w);
  casadi_real w[4096]; casadi_int iw[64];
  casadi_real y[3] = {0.81, 0.05, -0.04}, yd[3] = {0.01, 0.2, -0.1}, ydd[3] = {0.1, -0.5, 0.3}, tau[3];
  const casadi_real* arg[16] = {y, yd, ydd}; casadi_real* res[16] = {tau};
  if (sz_w > 4096 || sz_iw > 64) return 2;
  const long n = N_EVALUATIONS; double acc = 0.0; struct timespec a, b;
  clock_gettime(CLOCK_MONOTONIC, &a);
  for (long k = 0; k < n; ++k) { y[1] = 0.05 + 1e-9 * (k & 1023); NAME(arg, res, iw, w, 0); acc += tau[0]; }
  clock_gettime(CLOCK_MONOTONIC, &b);
  printf("%.6f %.17g\n", ((b.tv_sec - a.tv_sec) * 1e9 + (b.tv_nsec - a.tv_nsec)) / n, acc / n);
  return 0;
}
"""


def via_constraint_dynamics(dyn: Prs3Dynamics, y, yd, ydd) -> np.ndarray:
    """Baseline: forces such that ``constraintDynamics`` gives the prescribed actuated accelerations."""
    mech = dyn.mechanism
    q, v, a = dyn.state(y, yd, ydd)
    a0 = forward_dynamics(mech, q, v, np.zeros(3))[mech.act_v]
    B = np.column_stack([forward_dynamics(mech, q, v, e)[mech.act_v] - a0 for e in np.eye(3)])
    return np.linalg.solve(B, a[mech.act_v] - a0)


def c_time(dyn: Prs3Dynamics, evaluations: int) -> dict | None:
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        return None
    with tempfile.TemporaryDirectory() as d:
        name = generate_c(Path(d) / "twin.c", dyn.params)
        (Path(d) / "main.c").write_text(HARNESS.replace("NAME", name).replace("N_EVALUATIONS", str(evaluations)))
        subprocess.run([cc, "-O2", "-o", f"{d}/bench", f"{d}/twin.c", f"{d}/main.c", "-lm"], check=True)
        ns, mean_tau = subprocess.run([f"{d}/bench"], check=True, capture_output=True, text=True).stdout.split()
    return {"ns_per_eval": float(ns), "mean_F1_N": float(mean_tau), "compiler": cc}


def add_arguments(ap) -> None:
    ap.add_argument("-n", type=int, default=100_000, help="samples in the batch (default 10^5)")
    ap.add_argument("--repeat", type=int, default=2000, help="timed calls per single-call route (a fifth for the "
                                                              "Pinocchio routes)")
    ap.add_argument("--c-evaluations", type=int, default=2_000_000, help="evaluations timed in C")


def run(args) -> dict:
    dyn = Prs3Dynamics()
    rng = np.random.default_rng(0)
    n = args.n
    Y = np.array([0.81, 0.0, 0.0]) + rng.uniform(-1, 1, (n, 3)) * [0.05, 0.15, 0.15]
    Yd, Ydd = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    sample = [(Y[k], Yd[k], Ydd[k]) for k in range(min(200, len(Y)))]

    base = np.array([via_constraint_dynamics(dyn, *s) for s in sample])
    slow = max(1, args.repeat // 5)
    t_base = median_us(lambda *s: via_constraint_dynamics(dyn, *s), sample, repeat=slow)
    t_khalil = median_us(dyn.pinocchio, sample, repeat=slow)
    t_pkm = median_us(dyn.forces, sample, repeat=args.repeat)
    dyn.batch(Y[:1000], Yd[:1000], Ydd[:1000])
    best, res = best_time(lambda: dyn.batch(Y, Yd, Ydd), 3)
    t_batch = best / n * 1e6
    diff = {
        "pkm": float(np.abs(np.array([dyn.forces(*s) for s in sample]) - base).max()),
        "pkm_batch": float(np.abs(res.tau[:200] - base).max()),
        "pinocchio_khalil": float(np.abs(np.array([dyn.pinocchio(*s) for s in sample]) - base).max()),
    }
    c = c_time(dyn, args.c_evaluations)
    return {
        "design": "Table 2, P-actuated, slider below; samples z in 0.81 +- 0.05 m, beta, phi in +- 0.15 rad",
        "us_per_call": {"constraint_dynamics": t_base, "pinocchio_khalil": t_khalil, "pkm": t_pkm},
        "us_per_sample_batch": {"pkm_batch": t_batch, "n": n},
        "ratio_to_constraint_dynamics": {"pinocchio_khalil": t_base / t_khalil, "pkm": t_base / t_pkm,
                                         "pkm_batch": t_base / t_batch},
        "max_force_difference_to_baseline_N": diff,
        "c": None if c is None else {**c, "ratio_to_constraint_dynamics": t_base * 1e3 / c["ns_per_eval"]},
        "goals": {"pkm_us": 50, "batch_us_per_sample": 1, "c_us": 1},
    }


def table(out: dict) -> str:
    t = out["us_per_call"]
    t_base, t_khalil, t_pkm = t["constraint_dynamics"], t["pinocchio_khalil"], t["pkm"]
    t_batch = out["us_per_sample_batch"]["pkm_batch"]
    lines = [f"{'route':24s} {'time':>12s} {'speed-up vs constraintDynamics':>32s}",
             f"{'constraint_dynamics':24s} {t_base:9.1f} us {1.0:32.1f}",
             f"{'pinocchio_khalil':24s} {t_khalil:9.1f} us {t_base / t_khalil:32.1f}",
             f"{'pkm (single call)':24s} {t_pkm:9.1f} us {t_base / t_pkm:32.1f}",
             f"{'pkm batch (per sample)':24s} {t_batch:9.3f} us {t_base / t_batch:32.1f}"]
    c = out["c"]
    if c is not None:
        lines.append(f"{'C (per evaluation)':24s} {c['ns_per_eval'] / 1e3:9.3f} us "
                     f"{t_base * 1e3 / c['ns_per_eval']:32.1f}")
    lines.append("max |F - F_baseline| [N]: " + ", ".join(
        f"{k} {v:.2e}" for k, v in out["max_force_difference_to_baseline_N"].items()))
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main("dynamics"))
