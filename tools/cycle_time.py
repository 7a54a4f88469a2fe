"""Cycle-time studies (issue 46): the Delta's 25/305/25 mm cycle at 0, 1 and 3 kg against two baselines, a map of
cycle time over the workspace, the 3-PRS and Gough-Stewart along their own paths; a table (stdout, JSON) and
figures.

Baselines, computed in the same run on the same path and grid, each then checked against the true limits
(:func:`pkm.core.timing.solve.usage` on the payload's coefficients: does it violate a peak effort somewhere, or
leave time on the table?):

* **joint-space box**: each motor held to its speed limit and to an acceleration limit ``A`` taken as the
  common practice does, the peak effort over the largest reflected inertia (``tau_peak / max diag M_a`` over the
  path, payload included), the efforts not modelled: the time-optimal law under speed and acceleration boxes only;
* **constant task-space acceleration**: the end effector's path speed ``v(s)`` under one acceleration ``a_max``
  (and the motors' speed limits), ``a_max`` the largest that the efforts allow at the worst point of the path.

Usage: ``python tools/cycle_time.py [--points 200] [--out out/cycle_time]``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

import pkm
from pkm.core.timing import actuator_limits, path_coefficients, waypoint_path, with_payload
from pkm.core.timing.path import adept_waypoints
from pkm.core.timing.solve import solve, usage


def _box(delta_p, geo, C, L):
    M = np.array([pkm.mass_matrix(delta_p, q) for q in C.q[:: max(1, len(C.q) // 20)]])
    A = float(np.min(L.peak) / np.max(np.einsum("kii->ki", M)))
    box = actuator_limits(delta_p, peak=1e9, speed=L.speed, acceleration=A, margin=L.margin)
    return solve(delta_p, geo, C, box, 0.0), A


def _task_acceleration(C, L, a_max):
    """The time law of a constant task-space acceleration ``a_max`` [m/s^2] along the path (trapezoid in path
    length, capped by the motors' speed limits): ``(sd, sdd)`` on the grid."""
    ds_len = np.linalg.norm(C.dy[:, :3], axis=1)  # [m per unit s]
    x_acc = np.empty(len(C.s))
    x_acc[0] = 0.0
    for i in range(len(C.s) - 1):  # v^2 grows by 2 a ds in path length
        ds = C.s[i + 1] - C.s[i]
        v2 = x_acc[i] * ds_len[i] ** 2 + 2.0 * a_max * ds * 0.5 * (ds_len[i] + ds_len[i + 1])
        x_acc[i + 1] = v2 / ds_len[i + 1] ** 2
    x_dec = x_acc[::-1].copy()  # (symmetric in path length: the path's length element reversed)
    lens = ds_len[::-1]
    x_dec[0] = 0.0
    for i in range(len(C.s) - 1):
        ds = C.s[i + 1] - C.s[i]
        v2 = x_dec[i] * lens[i] ** 2 + 2.0 * a_max * ds * 0.5 * (lens[i] + lens[i + 1])
        x_dec[i + 1] = v2 / lens[i + 1] ** 2
    x_dec = x_dec[::-1]
    with np.errstate(divide="ignore"):
        cap = np.min(np.where(np.abs(C.dqa) > 0, ((1 - L.margin) * L.speed / np.abs(C.dqa)) ** 2, np.inf), axis=1)
    x = np.minimum(np.minimum(x_acc, x_dec), cap)
    sd = np.sqrt(x)
    sdd = np.diff(x) / (2.0 * np.diff(C.s))
    return sd, sdd


def _time(s, sd):
    return float(np.sum(2.0 * np.diff(s) / (sd[1:] + sd[:-1])))


def delta_cycle(points: int) -> list[dict]:
    delta = pkm.load("delta")
    geo = waypoint_path(delta, adept_waypoints([-0.1525, 0.0, -0.33]))
    rows = []
    for m in (0.0, 1.0, 3.0):
        dp = with_payload(delta, m)
        C = path_coefficients(dp, geo, np.linspace(0.0, 1.0, points))
        L = actuator_limits(dp)
        opt = solve(dp, geo, C, L, m)
        box, A = _box(dp, geo, C, L)
        box_use, _ = usage(C, L, box.sd, box.sdd)
        lo, hi = 0.1, 500.0  # (the largest constant task acceleration the efforts allow: bisection)
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            sd, sdd = _task_acceleration(C, L, mid)
            lo, hi = (mid, hi) if usage(C, L, sd, sdd)[0].max() <= 1.0 + 1e-9 else (lo, mid)
        sd, sdd = _task_acceleration(C, L, lo)
        rows.append({"payload_kg": m, "optimal_s": opt.cycle_time, "box_s": box.cycle_time,
                     "box_acceleration_rad_s2": A, "box_max_effort_usage": float(box_use.max()),
                     "task_acceleration_s": _time(C.s, sd), "task_acceleration_m_s2": lo,
                     "optimal_active": {k: opt.active.count(k) for k in sorted(set(opt.active))}})
    return rows


def workspace_map(points: int) -> dict:
    delta = pkm.load("delta")
    out = {}
    for y0 in (-0.05, 0.0, 0.05):
        for z0 in (-0.30, -0.33, -0.36):
            try:
                plan = pkm.time_optimal(delta, adept_waypoints([-0.1525, y0, z0]), points=points)
                out[f"{y0:+.2f},{z0:+.2f}"] = plan.cycle_time
            except pkm.errors.PathError as exc:
                out[f"{y0:+.2f},{z0:+.2f}"] = f"refused: {exc.limit} at point {exc.index}"
    return out


def others(points: int) -> dict:
    out = {}
    prs3 = pkm.load("prs3")
    from pkm.motion import load_motions

    case = load_motions("prs3_motions.toml")["3"]
    try:
        out["prs3 case 3"] = pkm.time_optimal(prs3, case, points=points).cycle_time
    except pkm.errors.PkmError as exc:
        out["prs3 case 3"] = f"refused: {exc}"
    gs = pkm.load("gough_stewart")
    y0 = gs.task_map.value(gs.q_reference)
    W = np.array([y0 + np.r_[dx, 0.0, dz, 0, 0, 0, 0] for dx, dz in ((-0.05, 0.0), (0.0, 0.03), (0.05, 0.0))])
    try:
        out["gough_stewart heave-surge arc"] = pkm.time_optimal(gs, W, points=points).cycle_time
    except pkm.errors.PkmError as exc:
        out["gough_stewart heave-surge arc"] = f"refused: {exc}"
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=200)
    ap.add_argument("--out", default="out/cycle_time")
    args = ap.parse_args()
    result = {"delta_adept": delta_cycle(args.points), "delta_map": workspace_map(max(50, args.points // 4)),
              "others": others(args.points)}
    Path(args.out).mkdir(parents=True, exist_ok=True)
    (Path(args.out) / "cycle_time.json").write_text(json.dumps(result, indent=2))
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
