"""Stiffness: the Gough-Stewart's Cartesian stiffness at a configuration, and a stiffness map over its workspace.

Routes, with one axial spring per leg and every other joint free:

* ``pkm``: :func:`pkm.stiffness` (the generic virtual-joint model: the closures' null space, homogenised);
* ``gosselin`` (the baseline): Gosselin's ``J^T diag(k) J`` from the legs' anchors (Pinocchio's forward kinematics,
  then one row ``(u_i, (p_i - P) x u_i)`` a leg): the closed form for axial legs;
* ``map``: :func:`pkm.workspace_map` (compiled IK, configurations kept) over an x-y grid, then
  :func:`pkm.core.compliance.maps.stiffness_map` at every node: the time of each and their sum.

The two single-configuration routes' matrices are compared (the largest relative difference).

Usage: ``python -m pkm.bench.stiffness [--json] [--quick] [--nodes 100] [--repeat 2000]``.
"""

from __future__ import annotations

import time

import numpy as np
import pinocchio as pin

from pkm.bench import main, median_us

QUICK = {"nodes": 6, "repeat": 50}
K_LEG = 1.0e6  # N/m


def gosselin(mech, q: np.ndarray) -> np.ndarray:
    """``sum k r_i r_i^T`` from the anchors: each leg's universal joint (base) and ball point (platform)."""
    m, d = mech.model, mech.data
    pin.forwardKinematics(m, d, q)
    pin.updateFramePlacements(m, d)
    P = d.oMf[mech.ee_frame].translation
    rows = []
    for cm in mech.constraint_models:
        b = d.oMi[m.parents[cm.joint1_id]].translation  # (the leg's universal joint)
        p = (d.oMi[cm.joint2_id] * cm.joint2_placement).translation
        u = (p - b) / np.linalg.norm(p - b)
        rows.append(np.concatenate([u, np.cross(p - P, u)]))
    r = np.array(rows)
    return K_LEG * r.T @ r


def add_arguments(ap) -> None:
    ap.add_argument("--nodes", type=int, default=100, help="nodes per axis of the x-y map (default 100: 10,000)")
    ap.add_argument("--repeat", type=int, default=2000, help="timed calls per single-configuration route")


def run(args) -> dict:
    import pkm
    from pkm.core.compliance.maps import stiffness_map

    gs = pkm.load("gough_stewart")
    legs = {j: K_LEG for j in gs.actuated_names}
    rng = np.random.default_rng(0)
    qa0 = gs.actuated_q(gs.q_reference)
    poses = [pkm.close_loops(gs, qa0 + rng.uniform(-0.03, 0.03, gs.na)).q for _ in range(10)]
    diff = max(float(np.abs(pkm.stiffness(gs, q, joints=legs).matrix - gosselin(gs, q)).max()
                     / np.abs(gosselin(gs, q)).max()) for q in poses)
    args_q = [(q,) for q in poses]
    t_base = median_us(lambda q: gosselin(gs, q), args_q, repeat=args.repeat)
    t_pkm = median_us(lambda q: pkm.stiffness(gs, q, joints=legs), args_q, repeat=args.repeat)
    y0 = pkm.TaskMap.of(gs).named(gs.q_reference)
    axes = {k: y0[k] + np.linspace(-0.05, 0.05, args.nodes) for k in ("x", "y")}
    t0 = time.process_time()
    wmap = pkm.workspace_map(gs, axes, length=gs.characteristic_length, configurations=True)
    t1 = time.process_time()
    smap = stiffness_map(gs, wmap, joints=legs)
    t2 = time.process_time()
    return {
        "mechanism": "gough_stewart, one axial spring of 1e6 N/m a leg, other joints free",
        "us_per_call": {"gosselin": t_base, "pkm": t_pkm},
        "ratio_pkm_to_gosselin": t_pkm / t_base,
        "max_relative_difference": diff,
        "map": {"nodes": int(wmap.reachable.size), "with_stiffness": int(smap.reachable.sum()),
                "workspace_map_cpu_s": t1 - t0, "stiffness_map_cpu_s": t2 - t1, "total_cpu_s": t2 - t0,
                "force_min_N_per_m": smap.summary().get("force_min_N_per_m")},
        "goals": {"pkm_ms": 1.0, "map_10000_nodes_s": 10.0},
    }


def table(out: dict) -> str:
    t, m = out["us_per_call"], out["map"]
    return "\n".join([
        f"{'route':28s} {'time':>12s}",
        f"{'gosselin (closed form)':28s} {t['gosselin']:9.1f} us",
        f"{'pkm.stiffness':28s} {t['pkm']:9.1f} us  ({out['ratio_pkm_to_gosselin']:.1f} x the closed form; goal "
        f"{out['goals']['pkm_ms'] * 1e3:.0f} us)",
        f"largest relative difference of the matrices: {out['max_relative_difference']:.1e}",
        f"map of {m['nodes']} nodes ({m['with_stiffness']} with a stiffness): workspace {m['workspace_map_cpu_s']:.2f} s"
        f" + stiffness {m['stiffness_map_cpu_s']:.2f} s = {m['total_cpu_s']:.2f} s of CPU (goal at 10,000 nodes: "
        f"{out['goals']['map_10000_nodes_s']:.0f} s)"])


if __name__ == "__main__":
    raise SystemExit(main("stiffness"))
