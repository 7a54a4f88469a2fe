"""Time-optimal planning speed: :func:`pkm.time_optimal` on a 1,000-point Delta path (the 25/305/25 mm cycle),
the coefficients by the compiled kernels (:class:`pkm.Kernels`, built before timing) and by the generic core, each
timed in this run, with the share of the toppra solve; the target (issue 46): 1,000 points in 50 ms compiled.

And :func:`pkm.verify_time_optimal` (``simulate=False``: the efforts recomputed at 10x the planning resolution, the
position limits, the active limits) on the humanoid ankle of ``examples/humanoid_ankle`` (two motors, viscous
friction at them, rods whose spin is idle: held by the kernels), a 0.5 rad pitch and 0.12 rad roll on
``--ankle-points`` points (default 1,000: 11,000 check points), by the compiled kernels (``kernels=True``, built
before timing) against the generic core, each timed once in this run in the process's CPU time (the machine may be
shared; the kernels' large batches run on every core, counted): issue 52's target, under 5 s; whether the two
routes' efforts agree (largest difference relative to the largest effort) and the inactive segments are the
plan's. And the plan itself on both routes (the kernels' cycle time against the core's).

Usage: ``python -m pkm.bench.time_optimal [--json] [--quick] [-n 1000] [--ankle-points 100]``.
"""

from __future__ import annotations

import time

from pkm.bench import best_time, main

#: The quick run: 30 points (the generic core's plan, timed once, is most of the run: 0.7 s of CPU at 100 points, 0.17 s
#: at 30), enough for both routes' cycle times to be compared.
QUICK = {"n": 30, "repeat": 1, "ankle_points": 8}
#: The ankle's path: pitch and roll [rad] (within its limits, +-0.6 and +-0.35).
ANKLE_PATH = ((0.0, 0.0), (0.2, 0.05), (0.4, 0.1), (0.5, 0.12))


def add_arguments(ap) -> None:
    ap.add_argument("-n", type=int, default=1000, help="grid points along the path (default 1,000)")
    ap.add_argument("--repeat", type=int, default=5, help="timed repeats (best kept)")
    ap.add_argument("--ankle-points", type=int, default=1000, help="grid points of the ankle's plan that verify checks "
                                                                   "(default 1,000)")


def run(args) -> dict:
    from pkm._optional import missing

    if missing("plan"):  # (an installed wheel without the extra: said, as the other benchmarks say theirs)
        return {"skipped": f"pip install \"pkm-robotics[plan]\" (missing: {', '.join(missing('plan'))})"}
    import pkm
    import pkm.core.timing.solve as solve_mod
    from pkm.core.timing.path import adept_waypoints

    delta = pkm.load("delta")
    path = adept_waypoints([-0.1525, 0.0, -0.33])
    pkm.time_optimal(delta, path, points=args.n, kernels=True)  # (the kernels compiled and loaded)
    inner = solve_mod._toppra
    spent: list[float] = []

    def timed(*a):
        t0 = time.perf_counter()
        out = inner(*a)
        spent.append(time.perf_counter() - t0)
        return out

    runs = []
    solve_mod._toppra = timed
    try:
        for _ in range(max(1, args.repeat)):  # (the best run, with its toppra share)
            spent.clear()
            t0 = time.perf_counter()
            plan = pkm.time_optimal(delta, path, points=args.n, kernels=True)
            runs.append((time.perf_counter() - t0, sum(spent)))
    finally:
        solve_mod._toppra = inner
    compiled, toppra_s = min(runs)
    core, plan_core = best_time(lambda: pkm.time_optimal(delta, path, points=args.n), 1)
    return {"points": args.n, "compiled_s": compiled, "toppra_s": toppra_s, "core_s": core,
            "cycle_time_s": plan.cycle_time, "cycle_time_core_s": plan_core.cycle_time,
            "target_s": 0.05, "within_target": compiled <= 0.05, "ankle": _ankle(args.ankle_points)}


def _ankle(points: int) -> dict:
    """The plan and its verification on the humanoid ankle, compiled and core, each timed once (CPU)."""
    import numpy as np

    import pkm
    from pkm.bench.export import _load

    ankle = _load("humanoid_ankle")
    if ankle is None:
        return {"skipped": "examples/ absent (an installed wheel)"}
    cpu = time.process_time
    warm = pkm.time_optimal(ankle, ANKLE_PATH, points=8, kernels=True)  # (the kernels built and compiled)
    pkm.verify_time_optimal(warm, factor=1, simulate=False, kernels=True)
    plan_s, plan = best_time(lambda: pkm.time_optimal(ankle, ANKLE_PATH, points=points), 1, cpu)
    plan_k_s, plan_k = best_time(lambda: pkm.time_optimal(ankle, ANKLE_PATH, points=points, kernels=True), 1, cpu)
    verify_s, check = best_time(lambda: pkm.verify_time_optimal(plan, simulate=False, kernels=True), 1, cpu)
    core_s, core = best_time(lambda: pkm.verify_time_optimal(plan, simulate=False), 1, cpu)
    return {"points": points, "check_points": len(check.s), "plan_s": plan_s, "plan_compiled_s": plan_k_s,
            "cycle_time_difference": abs(plan_k.cycle_time / plan.cycle_time - 1.0), "verify_s": verify_s,
            "verify_core_s": core_s, "ratio": core_s / verify_s,
            "efforts_difference": float(np.abs(check.efforts - core.efforts).max() / np.abs(core.efforts).max()),
            "route": check.route, "target_s": 5.0, "within_target": verify_s <= 5.0 and check.route != "core",
            "holds": check.holds and core.holds,
            "inactive": len(check.inactive),
            "labels_equal": check.inactive == plan.inactive == core.inactive == plan_k.inactive}


def table(r: dict) -> str:
    if "skipped" in r:
        return f"time-optimal planning: skipped ({r['skipped']})"
    return "\n".join([
        f"time-optimal planning, Delta 25/305/25 mm cycle, {r['points']} points",
        f"  compiled kernels : {r['compiled_s'] * 1e3:8.1f} ms  (toppra {r['toppra_s'] * 1e3:.1f} ms; target "
        f"{r['target_s'] * 1e3:.0f} ms: {'met' if r['within_target'] else 'NOT met'})",
        f"  generic core     : {r['core_s'] * 1e3:8.1f} ms",
        f"  cycle time       : {r['cycle_time_s']:.6f} s (core {r['cycle_time_core_s']:.6f} s)",
        _ankle_row(r.get("ankle", {"skipped": "not run"})),
    ])


def _ankle_row(a: dict) -> str:
    if "skipped" in a:
        return f"  verify, ankle    : skipped ({a['skipped']})"
    return "\n".join([
        f"  verify, ankle    : {a['verify_s']:8.2f} s of CPU compiled, {a['verify_core_s']:.2f} s on the core "
        f"({a['ratio']:.0f}x; {a['check_points']} check points of a {a['points']}-point plan; target "
        f"{a['target_s']:.0f} s: {'met' if a['within_target'] else 'NOT met'}; efforts "
        f"{a['efforts_difference']:.1e} apart; {a['inactive']} inactive segments, "
        f"{'the plan' + chr(39) + 's' if a['labels_equal'] else 'NOT the plan' + chr(39) + 's'})",
        f"  plan, ankle      : {a['plan_compiled_s']:8.2f} s of CPU compiled, {a['plan_s']:.2f} s on the core "
        f"(cycle times {a['cycle_time_difference']:.1e} apart)"])


if __name__ == "__main__":
    raise SystemExit(main("time_optimal"))
