"""Clearance: the Gough-Stewart's leg-leg distances at a configuration, and an interference map over its workspace.

Routes at one configuration (every pair pkm checks: the 60 leg-leg pairs of its 12 capsules and the 6
cylinder-platform pairs):

* ``minimum``: :func:`pkm.core.collision.clearance_map` on 100 nodes a call, per node (Pinocchio's geometry
  placements and coal's signed distances for the checked pairs, the requests made once): the smallest distance;
  and on one node a call (its input checks then count);
* ``clearance``: :func:`pkm.clearance`: every pair's distance, witness points and normals (the gradient not asked);
* ``segments`` (the baseline): the legs' capsules as segments from Pinocchio's forward kinematics, the clamped
  closed-form segment-to-segment distance minus the radii (Ericson), in numpy, for the 60 leg-leg pairs.

The two routes' leg-leg distances are compared (the largest difference [m]).

``map``: :func:`pkm.workspace_map` (compiled IK, configurations kept) over an x-y grid at a fixed height and a turned
platform (``--yaw``), then :func:`~pkm.core.collision.clearance_map` at every reachable node: the CPU time of the
clearance map, and the workspace within the joint limits beside its interference-free part.

Usage: ``python -m pkm.bench.clearance [--json] [--quick] [--nodes 100] [--repeat 2000] [--yaw 1.2] [--radius R]``.
"""

from __future__ import annotations

import time

import numpy as np
import pinocchio as pin

from pkm.bench import main, median_us

QUICK = {"nodes": 6, "repeat": 50}


def segment_distance(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> float:
    """The distance between segments [p1, q1] and [p2, q2]: the clamped closed form (Ericson, Real-Time Collision
    Detection, 5.1.9)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e, f = d1 @ d1, d2 @ d2, d2 @ r
    c, b = d1 @ r, d1 @ d2
    denom = a * e - b * b
    s = min(max((b * f - c * e) / denom, 0.0), 1.0) if denom > 1e-14 * a * e else 0.0
    t = (b * s + f) / e
    if t < 0.0:
        t, s = 0.0, min(max(-c / a, 0.0), 1.0)
    elif t > 1.0:
        t, s = 1.0, min(max((b - c) / a, 0.0), 1.0)
    return float(np.linalg.norm(p1 + s * d1 - (p2 + t * d2)))


def segments(mech, q: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray, float]]:
    """Each leg's cylinder and rod as ``(end, end, radius)`` [m], world frame, as the design places them."""
    m, d, p = mech.model, mech.data, mech.params
    pin.forwardKinematics(m, d, q)
    pin.updateFramePlacements(m, d)
    half, out = p.leg_min / 2, {}
    for k in range(1, 7):
        a = d.oMi[m.getJointId(f"u{k}")].translation
        b = d.oMf[mech.frame_id(f"ball_{k}")].translation
        u = (b - a) / np.linalg.norm(b - a)
        out[f"cylinder_{k}"] = (a, a + half * u, p.cylinder_radius)
        out[f"rod_{k}"] = (b - half * u, b, p.rod_radius)
    return out


def leg_distances(mech, q: np.ndarray, pairs: list[tuple[str, str]]) -> list[float]:
    """The baseline: the leg-leg pairs' distances [m] from the segments."""
    s = segments(mech, q)
    return [segment_distance(s[a][0], s[a][1], s[b][0], s[b][1]) - s[a][2] - s[b][2] for a, b in pairs]


def add_arguments(ap) -> None:
    ap.add_argument("--nodes", type=int, default=100, help="nodes per axis of the x-y map (default 100: 10,000)")
    ap.add_argument("--repeat", type=int, default=2000, help="timed calls per single-configuration route")
    ap.add_argument("--yaw", type=float, default=1.2, help="the platform's turn about z over the map [rad]")
    ap.add_argument("--radius", type=float, default=None,
                    help="the legs' radius [m] (cylinder and rod; default: the design's)")


def run(args) -> dict:
    import pkm
    from pkm.core.collision import CollisionModel, clearance_map

    kw = {} if args.radius is None else {"cylinder_radius": args.radius, "rod_radius": args.radius}
    gs = pkm.build("gough_stewart", **kw) if kw else pkm.load("gough_stewart")
    cm = CollisionModel.of(gs)
    legs = [p for p in cm.pairs if "platform_link" not in p]
    rng = np.random.default_rng(0)
    qa0 = gs.actuated_q(gs.q_reference)
    poses = [pkm.close_loops(gs, qa0 + rng.uniform(-0.1, 0.1, gs.na)).q for _ in range(10)]
    diff = max(max(abs(pairs[p] - d) for p, d in zip(legs, leg_distances(gs, q, legs)))
               for q in poses for pairs in (pkm.clearance(gs, q).pairs,))
    args_q = [(q,) for q in poses]
    t_base = median_us(lambda q: leg_distances(gs, q, legs), args_q, repeat=args.repeat)
    batch = np.array(poses * 10)  # (100 nodes a call: the map's route, its checks once a call)
    t_min = median_us(lambda: clearance_map(gs, batch), repeat=max(1, args.repeat // 20)) / len(batch)
    t_one = median_us(lambda q: clearance_map(gs, q[None]), args_q, repeat=args.repeat)
    t_full = median_us(lambda q: pkm.clearance(gs, q), args_q, repeat=args.repeat)

    y0 = pkm.TaskMap.of(gs).named(gs.q_reference)
    quat = pin.Quaternion(pin.rpy.rpyToMatrix(0.0, 0.0, args.yaw)).coeffs()
    seed = pkm.solve_ik(gs, [y0["x"], y0["y"], y0["z"], *quat]).q
    axes = {k: y0[k] + np.linspace(-0.15, 0.15, args.nodes) for k in ("x", "y")}
    wmap = pkm.workspace_map(gs, axes, seed=seed, length=gs.characteristic_length, configurations=True)
    assert wmap.q is not None
    Q = wmap.q.reshape(-1, gs.nq)[wmap.reachable.ravel()]
    inside = np.array([not gs.outside_limits(q) for q in Q], dtype=bool)
    t0 = time.process_time()
    minima = clearance_map(gs, Q)
    t1 = time.process_time()
    free = inside & (minima > 0.0)
    return {
        "mechanism": f"gough_stewart, legs of radius {gs.params.cylinder_radius:g} m (cylinder) and "
                     f"{gs.params.rod_radius:g} m (rod); {len(cm.pairs)} pairs checked, {len(legs)} leg-leg",
        "us_per_configuration": {"segments": t_base, "minimum": t_min, "minimum_one_call": t_one,
                                 "clearance": t_full},
        "max_difference_m": diff,
        "map": {"nodes": int(wmap.reachable.size), "reachable": len(Q), "within_limits": int(inside.sum()),
                "interference_free_within_limits": int(free.sum()), "yaw_rad": args.yaw,
                "clearance_map_cpu_s": t1 - t0,
                "smallest_m": float(minima.min()) if len(minima) else None},
        "goals": {"minimum_us": 50.0, "map_10000_nodes_s": 10.0},
    }


def table(out: dict) -> str:
    t, m = out["us_per_configuration"], out["map"]
    return "\n".join([
        out["mechanism"],
        f"{'route':34s} {'time':>12s}",
        f"{'segments (numpy closed form, legs)':34s} {t['segments']:9.1f} us",
        f"{'minimum (clearance_map, 100 nodes)':34s} {t['minimum']:9.1f} us a node  (goal {out['goals']['minimum_us']:.0f} "
        "us)",
        f"{'minimum (clearance_map, one node)':34s} {t['minimum_one_call']:9.1f} us",
        f"{'pkm.clearance (every pair)':34s} {t['clearance']:9.1f} us",
        f"largest difference of the leg-leg distances: {out['max_difference_m']:.1e} m",
        f"map of {m['nodes']} nodes at yaw {m['yaw_rad']:g} rad: {m['reachable']} reachable, {m['within_limits']} "
        f"within the joint limits, {m['interference_free_within_limits']} of them interference-free; clearance map "
        f"{m['clearance_map_cpu_s']:.2f} s of CPU (goal at 10,000 nodes: {out['goals']['map_10000_nodes_s']:.0f} s)"])


if __name__ == "__main__":
    raise SystemExit(main("clearance"))
