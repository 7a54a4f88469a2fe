"""Choice of the hexapod's reconfiguration angle: proxqp SQP against a dense grid sweep, same run.

* ``beta*`` of pose T (paper sec. 4) for ``w_rot`` and ``w_tras``: time of
  :func:`pkm.mechanisms.hexapod.reconfiguration.optimal_beta` (reachable interval, grid start, SQP)
  next to a dense 0.1-deg sweep of the reachable interval (vectorised index, argmax refined by a
  parabola through the 3 best nodes); ratio sweep / SQP; ``|beta*_SQP - beta*_sweep|`` [deg].
* The 101-pose spiral: time of :func:`~pkm.mechanisms.hexapod.reconfiguration.beta_profile` (reachable
  intervals, pointwise optima, rate-limited profile) next to the same 0.1-deg sweep at every pose;
  ratio; largest difference of the pointwise optima [deg].
* One index evaluation: the batch route (closed-form IK + screw Jacobians) against the generic
  core (closed-form configuration + ``pkm.twist_jacobian``).

Times are the best of ``--repeat`` runs. Goals (issue 3): beta* <= 2 ms, profile <= 100 ms,
differences <= 0.01 deg.

Usage: ``python -m pkm.bench.hexapod [--json] [--quick] [--repeat 5]``.
"""

from __future__ import annotations

import math

import numpy as np

import pkm
from pkm.bench import best_time, main
from pkm.mechanisms import hexapod as hx
from pkm.mechanisms.hexapod import indices as hi
from pkm.mechanisms.hexapod import reconfiguration as hr
from pkm.papers.hexapod import pose_T_placement, spiral_poses

STEP = math.radians(0.1)


QUICK = {"repeat": 1}


def sweep(f: hi.PoseIndex, k: int, lo: float, up: float) -> float:
    """argmax of the index of pose k on a 0.1-deg grid of [lo, up], refined by a parabola [rad]."""
    grid = np.arange(lo, up, STEP)
    v = f(np.full(grid.size, k), grid)
    i = int(np.argmax(v))
    if 0 < i < grid.size - 1:
        den = v[i - 1] - 2 * v[i] + v[i + 1]
        return float(grid[i] + 0.5 * STEP * (v[i - 1] - v[i + 1]) / den) if den < 0 else float(grid[i])
    return float(grid[i])


def bench(repeat: int) -> dict:
    p = hx.Params()
    R, P = pose_T_placement()
    out: dict = {"pose_T": {}, "spiral": {}}
    for idx in hi.INDICES:
        def sqp(idx: str = idx) -> hr.BetaChoice:
            return hr.optimal_beta(p, R, P, idx)

        t_qp, choice = best_time(sqp, repeat)

        def grid_search(idx=idx):
            f = hi.PoseIndex(p, [(R, P)], idx)
            (lo, up), = hr.reachable_intervals(p, R, P)
            return sweep(f, 0, lo + hr.EDGE, up)

        t_grid, b_grid = best_time(grid_search, repeat)
        out["pose_T"][idx] = {"sqp_ms": 1e3 * t_qp, "sweep_ms": 1e3 * t_grid, "ratio_sweep_over_sqp": t_grid / t_qp,
                              "beta_sqp_deg": choice.beta_deg, "beta_sweep_deg": math.degrees(b_grid),
                              "diff_deg": abs(choice.beta_deg - math.degrees(b_grid)),
                              "sqp_iterations": choice.optimum.iterations}
    poses = spiral_poses()
    for idx in hi.INDICES:
        def profile(idx: str = idx) -> hr.BetaProfile:
            return hr.beta_profile(p, poses, idx)

        t_qp, prof = best_time(profile, repeat)

        def grid_search(idx=idx):
            f = hi.PoseIndex(p, poses, idx)
            return np.array([sweep(f, k, *hr.reachable_intervals(p, *poses[k])[0]) for k in range(len(poses))])

        t_grid, b_grid = best_time(grid_search, max(1, repeat // 2))
        r = prof.result
        out["spiral"][idx] = {"profile_ms": 1e3 * t_qp, "sweep_ms": 1e3 * t_grid,
                              "ratio_sweep_over_profile": t_grid / t_qp,
                              "max_diff_pointwise_deg": float(np.degrees(np.abs(prof.pointwise - b_grid)).max()),
                              "max_profile_minus_pointwise_deg":
                                  float(np.degrees(np.abs(prof.beta - prof.pointwise)).max()),
                              "sqp_iterations": r.iterations, "qp_solves": r.qp_solves,
                              "qp_iterations": r.qp_iterations, "cold_restarts": r.cold_restarts,
                              "objective_gain_over_start": r.objective - r.start_objective}
    mech = hx.build(p)
    f = hi.PoseIndex(p, [(R, P)], "w_rot")
    n = 200
    betas = np.linspace(-0.5, 0.5, n)
    t_batch, _ = best_time(lambda: f(np.zeros(n, int), betas), repeat)

    def core():
        for b in betas[:20]:
            q = hx.closed_form_configuration(mech, hx.task_vector(R, P, b))
            pkm.twist_jacobian(mech, q)

    t_core, _ = best_time(core, repeat)
    out["index_evaluation"] = {"batch_us": 1e6 * t_batch / n, "generic_core_us": 1e6 * t_core / 20,
                               "ratio_core_over_batch": (t_core / 20) / (t_batch / n)}
    return out


def add_arguments(ap) -> None:
    ap.add_argument("--repeat", type=int, default=5, help="runs per case (best is kept)")


def run(args) -> dict:
    return bench(args.repeat)


def table(res: dict) -> str:
    lines = []
    for idx, r in res["pose_T"].items():
        lines.append(f"pose T {idx:6s}: SQP {r['sqp_ms']:.2f} ms, sweep {r['sweep_ms']:.2f} ms "
                     f"(x{r['ratio_sweep_over_sqp']:.1f}), beta* {r['beta_sqp_deg']:.4f} deg, "
                     f"diff {r['diff_deg']:.2e} deg")
    for idx, r in res["spiral"].items():
        lines.append(f"spiral {idx:6s}: profile {r['profile_ms']:.1f} ms, sweep {r['sweep_ms']:.1f} ms "
                     f"(x{r['ratio_sweep_over_profile']:.1f}), max diff {r['max_diff_pointwise_deg']:.2e} deg")
    e = res["index_evaluation"]
    lines.append(f"one index evaluation: batch {e['batch_us']:.1f} us, generic core {e['generic_core_us']:.0f} us "
                 f"(x{e['ratio_core_over_batch']:.0f})")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main("hexapod"))
