"""Sweeps of one's own mechanism with designs as kernel inputs: one compiled twin for every design, against one
precompiled design and against the closed forms.

Two cases, each timed against its baseline in the same run:

* **Gough-Stewart** (the acceptance set's, loaded from its URDF and spec): ``--designs`` (2,000) designs drawn as
  scrambled Sobol' points (seed 0) moving the six base joints' origins ``u1.x ... u6.y`` by up to ``--spread``
  (3 cm) each, scored by the workspace (``coverage``) and the condition (``gci``) of one map over ``x, y`` in
  ``[-0.2, 0.2] m`` (``--nodes`` per side: 100, 10^4 nodes; ``L = 0.5 m``), on a ``LocalCluster`` of ``--workers``
  (2; 0 runs them in this process).
  Baseline: the same two objectives on the file's design with its kernels already compiled (best of 3). Reported:
  the time a design costs in the sweep (the workers' time / designs) over the baseline (goal <= 2), the sweep's
  wall time (goal <= 10 min), and the largest difference of the rows of ``--check`` (20) designs drawn from the sweep
  against the same objectives through each design's own compiled twin (``parametric=False``; goal <= 1e-12).
* **3-RRR** (registered): ``--rrr-designs`` (1,000) designs over ``a, b in [20, 65] cm``, ``h in [5, 50] cm``, the
  GCI through the generic route (a map of about 20,000 nodes, as the closed form's 1 cm grid; designs as inputs)
  against the closed-form route (the papers' vectorised CI map), both in this process one design after the other
  (goal: generic <= 3x closed form). The two GCIs differ in definition (the closed form averages over its own
  workspace grid): the case compares costs, not values.

Usage: ``python -m pkm.bench.designs [--json] [--quick] [--designs 2000] [--nodes 100] [--rrr-designs 1000]``.
"""

from __future__ import annotations

import time

import numpy as np

from pkm._optional import require
from pkm.bench import main

QUICK = {"designs": 2, "nodes": 8, "check": 1, "rrr_designs": 2, "workers": 0}
GOAL_PER_DESIGN = 2.0
GOAL_WALL_S = 600.0
GOAL_RRR = 3.0
GOAL_EQUAL = 1e-12
GS = ("examples", "gough_stewart", "gough_stewart.closures.toml")


def add_arguments(ap) -> None:
    ap.add_argument("--designs", type=int, default=2000, help="Gough-Stewart designs (default 2000)")
    ap.add_argument("--spread", type=float, default=0.03, help="largest move of a base-joint origin [m] (0.03)")
    ap.add_argument("--nodes", type=int, default=100, help="map nodes per side (default 100: 10^4 nodes)")
    ap.add_argument("--check", type=int, default=20, help="designs checked against their own twins (default 20)")
    ap.add_argument("--rrr-designs", type=int, default=1000, help="3-RRR designs (default 1000)")
    ap.add_argument("--workers", type=int, default=2, help="local Dask workers of the Gough-Stewart sweep (default 2; "
                                                          "0: in this process, no Dask)")


def _gough_stewart():
    from pathlib import Path

    import pkm

    here = Path(__file__).resolve()
    for root in (here.parents[3], Path.cwd()):  # (the source tree's examples; from a wheel: the current folder)
        if root.joinpath(*GS).exists():
            return pkm.load(root.joinpath(*GS))
    raise FileNotFoundError("the Gough-Stewart's files (examples/gough_stewart) are not here: run from the "
                            "source tree")


def _space(mech, n: int, spread: float):
    from pkm import sweeps
    from pkm.core.twin.design import read_design

    base = read_design(mech, [f"u{i}.{c}" for i in range(1, 7) for c in ("x", "y")])
    return sweeps.sobol(n, seed=0, **{k: f"{v - spread!r}:{v + spread!r}" for k, v in base.items()})


def _gs_case(args) -> dict:
    from dask.distributed import Client

    import pkm
    from pkm.core.analysis.maps import workspace_map
    from pkm.sweeps.engine import local_cluster
    from pkm.sweeps.family import ModelFamily

    mech = _gough_stewart()
    region = f"region=x=-0.2:0.2:{args.nodes}/y=-0.2:0.2:{args.nodes},length=0.5"
    objectives = [f"coverage=coverage:{region}", f"gci=gci:{region}"]
    space = _space(mech, args.designs, args.spread)
    axes = {"x": np.linspace(-0.2, 0.2, args.nodes), "y": np.linspace(-0.2, 0.2, args.nodes)}
    K = pkm.Kernels(mech)
    workspace_map(mech, axes, length=0.5, kernels=K)  # (compiled, warmed)

    def one():
        m = workspace_map(mech, axes, length=0.5, kernels=K)
        return float(np.count_nonzero(m.reachable) / m.reachable.size), m.gci()

    base_s = min(_timed(one) for _ in range(3))
    if args.workers:
        with local_cluster(args.workers) as cluster, Client(cluster) as client:
            res = pkm.sweep(ModelFamily(mech), space, objectives, client=client, progress=False)
    else:
        res = pkm.sweep(ModelFamily(mech), space, objectives, scheduler="serial", progress=False)
    st = res.stats
    per_design = st.work_seconds / args.designs
    rows = res.table.to_pydict()
    pick = np.random.default_rng(0).choice(args.designs, size=min(args.check, args.designs), replace=False)
    params = space.names
    chosen = pkm.sweeps.table([{p: rows[p][int(k)] for p in params} for k in sorted(pick)])
    t0 = time.perf_counter()
    own = pkm.sweep(ModelFamily(mech, parametric=False), chosen, objectives, scheduler="serial", progress=False)
    own_s = (time.perf_counter() - t0) / len(pick)
    own_rows = own.table.to_pydict()
    worst = 0.0
    for j, k in enumerate(sorted(pick)):
        for o in ("coverage", "gci"):
            a, b = rows[o][int(k)], own_rows[o][j]
            if a is None or b is None:  # (no value, or a failed design: equal only if both)
                worst = max(worst, 0.0 if a is b else float("inf"))
                continue
            worst = max(worst, 0.0 if a == b else abs(a - b) / max(1.0, abs(b)))
    return {"designs": args.designs, "nodes": args.nodes ** 2, "parameters": list(params), "spread_m": args.spread,
            "objectives": objectives, "failed": st.failed, "workers": st.workers,
            "precompiled_design_s": base_s, "per_design_s": per_design,
            "per_design_over_precompiled": per_design / base_s, "goal_per_design": GOAL_PER_DESIGN,
            "wall_s": st.wall_seconds, "goal_wall_s": GOAL_WALL_S,
            "own_twin_per_design_s": own_s, "checked": len(pick), "largest_difference": worst,
            "goal_equal": GOAL_EQUAL}


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def _rrr_case(args) -> dict:
    import pkm
    from pkm import sweeps

    space = sweeps.sobol(args.rrr_designs, seed=0, a="20cm:65cm", b="20cm:65cm", h="5cm:50cm")
    closed = "gci:step=0.01"
    generic = "gci:route=generic,region=x=-0.2:1.2:141/y=-0.2:1.2:141,pose=yaw=0,length=0.1"
    warm = sweeps.sobol(2, seed=1, a="20cm:65cm", b="20cm:65cm", h="5cm:50cm")
    out = {"designs": args.rrr_designs}
    for name, spec in (("closed_form", closed), ("generic", generic)):
        pkm.sweep("rrr3", warm, [spec], scheduler="serial", progress=False)  # (imports, the shared twin compiled)
        res = pkm.sweep("rrr3", space, [spec], scheduler="serial", progress=False)
        out[name] = {"objective": spec, "per_design_ms": res.stats.work_seconds / args.rrr_designs * 1e3,
                     "failed": res.stats.failed}
    out["generic_over_closed_form"] = out["generic"]["per_design_ms"] / out["closed_form"]["per_design_ms"]
    out["goal"] = GOAL_RRR
    return out


def run(args) -> dict:
    require("sweeps", "the design-sweep benchmark")
    try:
        gs = _gs_case(args)
    except FileNotFoundError as exc:  # (an installed wheel without the source tree's examples)
        gs = {"skipped": str(exc)}
    return {"gough_stewart": gs, "rrr3": _rrr_case(args)}


def table(r: dict) -> str:
    g, t = r["gough_stewart"], r["rrr3"]
    rrr = (f"3-RRR: {t['designs']} designs, GCI: closed form {t['closed_form']['per_design_ms']:.1f} ms a design, "
           f"generic (designs as inputs) {t['generic']['per_design_ms']:.1f} ms = "
           f"{t['generic_over_closed_form']:.2f}x (goal <= {t['goal']})")
    if "skipped" in g:
        return f"Gough-Stewart: skipped ({g['skipped']})\n{rrr}"
    return "\n".join([
        f"Gough-Stewart: {g['designs']} designs ({len(g['parameters'])} base-joint coordinates, +-{g['spread_m']} m), "
        f"coverage and GCI on a {g['nodes']}-node map, {g['workers']} workers ({g['failed']} failed)",
        f"  one precompiled design {g['precompiled_design_s'] * 1e3:.0f} ms; a design in the sweep "
        f"{g['per_design_s'] * 1e3:.0f} ms = {g['per_design_over_precompiled']:.2f}x (goal <= {g['goal_per_design']})",
        f"  sweep wall {g['wall_s']:.0f} s (goal <= {g['goal_wall_s']:.0f}); a design through its own compiled twin "
        f"{g['own_twin_per_design_s']:.2f} s",
        f"  {g['checked']} designs against their own twins: largest difference {g['largest_difference']:.1e} "
        f"(goal <= {g['goal_equal']:.0e})", rrr])


if __name__ == "__main__":
    raise SystemExit(main("designs"))
