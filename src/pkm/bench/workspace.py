"""Planar 3-RRR workspace and condition-index maps: vectorised numpy against a per-node loop and the generic route.

Two cases, each timed vectorised (best of ``--repeat``), as a naive Python loop over a
random sample of its nodes (closed-form IK + per-pose Jacobians + SVD per node, from
``pkm.mechanisms.rrr3.workspace.naive_condition_index``), extrapolated to all nodes, and through the generic
route of any mechanism (:func:`pkm.core.analysis.maps.task_map`: the compiled twin's IK warm-started across the grid, its
inverse Jacobian, singular values; compilation not timed); the ratios are measured in the same run, and the CIs
compared between the routes:

* ``workspace_ci_3d``: the paper's Fig. 3 count, 101 x 101 positions over ``[0, H]^2`` times 361
  orientations (1 deg) = 3,682,561 nodes, reference design (a = b = 40, h = 10, H = 100 cm);
  reachability and CI of every node, area and GCI per orientation. Goal <= 5 s.
* ``gci_paper_grid``: one design (Fig. 9's) on the paper's map grid, 801 x 801 nodes every 2 mm,
  overall and area GCI. Goal <= 0.5 s.

``--coarsen K`` keeps every K-th node of both grids along each axis (positions every K cm, orientations every K deg,
the map every 2K mm); ``--quick`` takes K = 10 (4,477 and 6,561 nodes: a check that it runs, not its timings).

Usage: ``python -m pkm.bench.workspace [--json] [--quick] [--sample 2000] [--repeat 3] [--coarsen 1]``.
"""

from __future__ import annotations

import time

import numpy as np

from pkm.bench import best_time, main
from pkm.mechanisms import rrr3
from pkm.mechanisms.rrr3 import workspace as maps
from pkm.papers.rrr3 import paper_grid

QUICK = {"sample": 10, "repeat": 1, "coarsen": 10}


def _best(fn, repeat: int) -> float:
    return best_time(fn, repeat)[0]


def _naive(design, nodes: np.ndarray, settings: maps.CiSettings) -> tuple[float, np.ndarray]:
    """Seconds per node and the CIs of the per-node loop over ``nodes`` (rows ``x, y, phi``)."""
    t0 = time.perf_counter()
    out = np.array([maps.naive_condition_index(design, node, maps.CiSettings(float(node[2]), settings.branch))
                    for node in nodes])
    return (time.perf_counter() - t0) / len(nodes), out


def _generic(design, axes: dict, fixed: dict, repeat: int):
    """The generic route (:func:`pkm.core.analysis.maps.task_map` through the compiled twin) on the same grid: best time
    [s] (the compilation done beforehand, on a 2-node grid) and the map."""
    import pkm
    from pkm.core.analysis.maps import workspace_map

    mech = pkm.build("rrr3", a=design.a, b=design.b, h=design.h, H=design.H)
    length = design.h / rrr3.SQRT3
    kernels = pkm.Kernels(mech)
    workspace_map(mech, {k: v[:2] for k, v in axes.items()}, fixed, length=length, kernels=kernels)
    return best_time(lambda: workspace_map(mech, axes, fixed, length=length, kernels=kernels), repeat)


def bench_3d(sample: int, repeat: int, rng: np.random.Generator, coarsen: int = 1) -> dict:
    p = rrr3.Rrr3Params()
    xs = np.linspace(0.0, p.H, 100 // coarsen + 1)
    phis = np.radians(np.linspace(-180.0, 180.0, 360 // coarsen + 1))
    phi0 = int(np.argmin(np.abs(phis)))
    settings = maps.CiSettings()
    result = {}

    def run():
        result["sweep"] = maps.orientation_sweep(p, xs, xs, phis, settings)

    t_vec = _best(run, repeat)
    sw = result["sweep"]
    nodes = np.column_stack([rng.choice(xs, sample), rng.choice(xs, sample), rng.choice(phis, sample)])
    per_node, naive = _naive(p, nodes, settings)
    vec, _ = maps.condition_index_phi(p, nodes[:, 0], nodes[:, 1], nodes[:, 2], settings)
    both = np.isfinite(naive)
    t_gen, gen = _generic(maps.Design.of(p), {"x": xs, "y": xs, "yaw": phis}, {}, repeat)
    X, Y, P = np.meshgrid(xs, xs, phis, indexing="ij")  # the generic map's layout is (phi, y, x)
    ci_vec, reach_vec = maps.condition_index_phi(p, X.T, Y.T, P.T, settings)
    same = reach_vec & gen.reachable
    return {
        "case": "workspace_ci_3d", "nodes": sw.nodes, "reachable_nodes": int(sw.reachable_nodes.sum()),
        "vectorised_s": t_vec, "goal_s": 5.0,
        "generic_s": t_gen, "ratio_generic_over_vectorised": t_gen / t_vec, "generic_goal_ratio": 5.0,
        "generic_reach_agrees": bool(np.array_equal(reach_vec, gen.reachable)),
        "generic_max_ci_difference": float(np.max(np.abs(gen.condition_index("2")[same] - ci_vec[same]))),
        "naive_sample_nodes": sample, "naive_per_node_us": per_node * 1e6,
        "naive_extrapolated_s": per_node * sw.nodes, "ratio_naive_over_vectorised": per_node * sw.nodes / t_vec,
        "sample_reach_agrees": bool(np.array_equal(both, np.isfinite(vec))),
        "sample_max_ci_difference": float(np.max(np.abs(vec[both] - naive[both]))) if both.any() else 0.0,
        "area_phi0_cm2": float(sw.areas[phi0] * 1e4), "gci_phi0": float(sw.gci[phi0]),
    }


def bench_gci(sample: int, repeat: int, rng: np.random.Generator, coarsen: int = 1) -> dict:
    d = maps.Design.similarity_law(2.0)
    grid = paper_grid(d)
    grid = maps.Grid(grid.centre, grid.n // coarsen, grid.step * coarsen)
    settings = maps.CiSettings()
    result = {}

    def run():
        m = maps.ci_map(d, grid, settings)
        result["gci"], result["area"] = m.gci(), m.area_gci()

    t_vec = _best(run, repeat)
    nodes = np.column_stack([rng.choice(grid.xs, sample), rng.choice(grid.ys, sample), np.zeros(sample)])
    per_node, naive = _naive(d, nodes, settings)
    vec, _ = maps.condition_index(d, nodes[:, 0], nodes[:, 1], settings)
    both = np.isfinite(naive)
    t_gen, gen = _generic(d, {"x": grid.xs, "y": grid.ys}, {"yaw": 0.0}, repeat)
    return {
        "case": "gci_paper_grid", "design_cm": [d.a * 100, d.b * 100, d.h * 100, d.H * 100], "nodes": grid.size,
        "vectorised_s": t_vec, "goal_s": 0.5,
        "generic_s": t_gen, "ratio_generic_over_vectorised": t_gen / t_vec, "generic_goal_s": 1.0,
        "generic_gci_difference": abs(gen.gci() - result["gci"].value),
        "naive_sample_nodes": sample, "naive_per_node_us": per_node * 1e6,
        "naive_extrapolated_s": per_node * grid.size, "ratio_naive_over_vectorised": per_node * grid.size / t_vec,
        "sample_reach_agrees": bool(np.array_equal(both, np.isfinite(vec))),
        "sample_max_ci_difference": float(np.max(np.abs(vec[both] - naive[both]))) if both.any() else 0.0,
        "gci": result["gci"].value, "gci_area": result["area"].value,
    }


def add_arguments(ap) -> None:
    ap.add_argument("--sample", type=int, default=2000, help="nodes timed in the naive loop, per case")
    ap.add_argument("--repeat", type=int, default=3, help="vectorised runs per case (best is kept)")
    ap.add_argument("--coarsen", type=int, default=1, help="every K-th node of each grid along each axis (default 1)")


def run(args) -> list[dict]:
    rng = np.random.default_rng(0)
    return [bench_3d(args.sample, args.repeat, rng, args.coarsen), bench_gci(args.sample, args.repeat, rng, args.coarsen)]


def table(results: list[dict]) -> str:
    lines = [(f"{'case':16} {'nodes':>10} {'vector s':>9} {'goal s':>7} {'naive us/node':>14} "
              f"{'naive s (extr.)':>16} {'ratio':>7} {'max |dCI|':>10} {'generic s':>10} {'generic/vector':>15}")]
    for r in results:
        lines.append(f"{r['case']:16} {r['nodes']:10d} {r['vectorised_s']:9.3f} {r['goal_s']:7.1f} "
                     f"{r['naive_per_node_us']:14.1f} {r['naive_extrapolated_s']:16.1f} "
                     f"{r['ratio_naive_over_vectorised']:7.0f} {r['sample_max_ci_difference']:10.1e} "
                     f"{r['generic_s']:10.3f} {r['ratio_generic_over_vectorised']:15.2f}")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main("workspace"))
