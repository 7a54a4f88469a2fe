"""Position solvers of the four mechanisms: generic core against the papers' closed forms.

For each mechanism, at N random regular configurations near its reference:

* loop closure (generic forward kinematics) seeded from a neighbouring configuration (actuated
  coordinates moved by ``--delta``): median time, median and max iterations to 1e-12;
* loop closure along a path (``PATH_STEPS`` steps to ``--delta`` away from each configuration, each step seeded with
  the last one's result, as a controller or a trajectory follows one): median time of a step;
* the closed-form inverse kinematics (actuated coordinates) and full configuration;
* the generic inverse kinematics from the same neighbouring configuration;
* the paper's forward kinematics, where it has one;
* ratios generic / closed form measured in the same run.

Usage: ``python -m pkm.bench.kinematics [--json] [--quick] [-n 50] [--delta 0.01] [MECH ...]``.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

import pkm
from pkm.bench import best_time, main
from pkm.core import TaskMap, close_loops, solve_ik
from pkm.errors import PkmError
from pkm.mechanisms import module, names

QUICK = {"n": 3}
PATH_STEPS = 10  #: steps of the path followed from each configuration


def _time(fn, repeat: int = 5) -> float:
    return best_time(fn, repeat)[0] * 1e6


def bench(name: str, n: int, delta: float, seed: int = 0) -> dict:
    mech, mod = pkm.load(name), module(name)
    task = TaskMap(mech)
    rng = np.random.default_rng(seed)
    y_ref = task.value(mech.q_reference)
    rows: dict[str, list[float]] = {"closure_us": [], "closure_iters": [], "cf_ik_us": [], "cf_config_us": [], "generic_ik_us": [],
            "generic_ik_iters": [], "cf_fk_us": [], "path_us": []}
    while len(rows["closure_us"]) < n:
        y = task.retract(y_ref, 0.02 * rng.uniform(-1, 1, task.size))
        try:
            q = mod.closed_form_configuration(mech, y)
            qa = mech.actuated_q(q)
            seed_q = close_loops(mech, qa + delta * rng.uniform(-1, 1, mech.na), q).q
            path = qa + delta * np.outer(np.arange(1, PATH_STEPS + 1) / PATH_STEPS, rng.uniform(-1, 1, mech.na))
            _follow_path(mech, path, q)
        except PkmError:
            continue
        res = close_loops(mech, qa, seed_q)
        ik = solve_ik(mech, y, seed_q)
        rows["closure_iters"].append(res.iterations)
        rows["generic_ik_iters"].append(ik.iterations)
        rows["closure_us"].append(_time(lambda qa=qa, seed_q=seed_q: close_loops(mech, qa, seed_q)))
        rows["generic_ik_us"].append(_time(lambda y=y, seed_q=seed_q: solve_ik(mech, y, seed_q)))
        rows["path_us"].append(_path_step_us(mech, path, q))
        rows["cf_ik_us"].append(_time(lambda y=y: mod.closed_form_ik(mech.params, y)))
        rows["cf_config_us"].append(_time(lambda y=y: mod.closed_form_configuration(mech, y)))
        if mod.closed_form_fk is not None:
            rows["cf_fk_us"].append(_time(lambda qa=qa: mod.closed_form_fk(mech.params, qa)))
    med = {k: statistics.median(v) for k, v in rows.items() if v}
    out = {
        "mechanism": name, "samples": n, "seed_delta": delta,
        "closure_median_us": med["closure_us"], "path_closure_step_median_us": med["path_us"],
        "closure_iterations_median": med["closure_iters"], "closure_iterations_max": max(rows["closure_iters"]),
        "generic_ik_median_us": med["generic_ik_us"], "generic_ik_iterations_max": max(rows["generic_ik_iters"]),
        "closed_form_ik_median_us": med["cf_ik_us"], "closed_form_configuration_median_us": med["cf_config_us"],
        "ratio_generic_ik_over_closed_form_ik": med["generic_ik_us"] / med["cf_ik_us"],
    }
    if "cf_fk_us" in med:
        out["closed_form_fk_median_us"] = med["cf_fk_us"]
        out["ratio_generic_fk_over_closed_form_fk"] = med["closure_us"] / med["cf_fk_us"]
    return out


def _follow_path(mech, path: np.ndarray, q: np.ndarray) -> list[float]:
    """Loop closure at each row of ``path`` (actuated coordinates), each seeded with the last result: each step's
    time [s]."""
    times = []
    for qa in path:
        t0 = time.perf_counter()
        q = close_loops(mech, qa, q).q
        times.append(time.perf_counter() - t0)
    return times


def _path_step_us(mech, path: np.ndarray, q: np.ndarray, repeat: int = 5) -> float:
    """The median over the steps of :func:`_follow_path` of each step's best time over ``repeat`` runs [us]."""
    return statistics.median(np.min([_follow_path(mech, path, q) for _ in range(repeat)], axis=0)) * 1e6


def add_arguments(ap) -> None:
    ap.add_argument("-n", type=int, default=50, help="configurations per mechanism")
    ap.add_argument("--delta", type=float, default=0.01, help="seed offset of the actuated coordinates [rad or m]")
    ap.add_argument("mechanisms", nargs="*", default=list(names()))


def run(args) -> list[dict]:
    return [bench(name, args.n, args.delta) for name in args.mechanisms]


def table(results: list[dict]) -> str:
    lines = [(f"{'mechanism':9} {'closure us':>10} {'path us':>8} {'iters med/max':>13} {'gen. IK us':>10} {'CF IK us':>9} "
              f"{'CF q us':>8} {'IK ratio':>8} {'CF FK us':>9} {'FK ratio':>8}")]
    for r in results:
        fk = (f"{r['closed_form_fk_median_us']:9.1f} {r['ratio_generic_fk_over_closed_form_fk']:8.1f}"
              if "closed_form_fk_median_us" in r else f"{'-':>9} {'-':>8}")
        lines.append(f"{r['mechanism']:9} {r['closure_median_us']:10.1f} {r['path_closure_step_median_us']:8.1f} "
                     f"{r['closure_iterations_median']:>6.0f}/{r['closure_iterations_max']:<6d} "
                     f"{r['generic_ik_median_us']:10.1f} {r['closed_form_ik_median_us']:9.1f} "
                     f"{r['closed_form_configuration_median_us']:8.1f} "
                     f"{r['ratio_generic_ik_over_closed_form_ik']:8.1f} {fk}")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main("kinematics"))
