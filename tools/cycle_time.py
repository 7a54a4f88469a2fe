"""Cycle-time studies (issue 46): the Delta's 25/305/25 mm cycle at 0, 1 and 3 kg against two baselines, a map of
cycle time over the workspace, the 3-PRS and the Gough-Stewart along their own paths; a table (stdout and JSON) and
figures.

Every law is checked by :func:`pkm.verify_time_optimal` (efforts by :func:`pkm.inverse_dynamics` at 10x the planning
resolution against the TRUE limits; the optimal law's tracking simulated with a PD). Baselines, computed in the same
run on the same path and grid:

* **joint-space box** (the common practice): each motor held to its speed limit and to one acceleration limit
  ``A = tau_peak / max diag M_a`` (the peak effort over the largest inertia the motor sees on the path, payload
  included; gravity and coupling not modelled): the fastest law under those boxes only. Does it violate the true
  limits somewhere, or leave time on the table?
* **constant task-space acceleration**: the end effector's speed along the path grows and falls at one acceleration
  ``a_max`` [m/s^2] (capped by the motors' speed limits), ``a_max`` the largest for which the efforts hold at
  every grid point (bisection): safe by construction, slower.

Two drive settings: the Delta's own drives (3.9 N m, 2.97 rad/s: speed-bound) and faster ones (a motor line
``omega0 = 15 rad/s``, speed limit 10 rad/s: effort-bound), to show both regimes.

Usage: ``python tools/cycle_time.py [--points 200] [--out out/cycle_time] [--quick]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from pathlib import Path

import numpy as np

import pkm
from pkm.core.timing import actuator_limits, motion_path, path_coefficients, waypoint_path, with_payload
from pkm.core.timing.path import adept_waypoints
from pkm.core.timing.solve import TimeOptimal, _between, _times, solve, usage
from pkm.motion import load_motions

SETTINGS = {"own drives": {}, "fast drives": {"omega0": 15.0, "speed": 10.0}}
START = (-0.1525, 0.0, -0.33)  # [m]: the cycle from x = -152.5 mm to +152.5 mm at y = 0, z = -0.33 m


def _law(plan: TimeOptimal, sd: np.ndarray, sdd: np.ndarray) -> TimeOptimal:
    """``plan`` with another law on the same grid (its motors' motion and efforts recomputed from the
    coefficients)."""
    C = plan.coefficients
    t = _times(C.s, sd)
    u = np.append(sdd, sdd[-1])
    return dataclasses.replace(plan, sd=sd, sdd=sdd, time=t, cycle_time=float(t[-1]), qa_rate=C.dqa * sd[:, None],
                               qa_acceleration=C.dqa * u[:, None] + C.ddqa * (sd ** 2)[:, None],
                               efforts=C.efforts(u, sd))


def box_law(plan: TimeOptimal, mid) -> tuple[TimeOptimal, float]:
    """The joint-space box baseline (module doc) on ``plan``'s path: ``(law, A [rad/s^2])``."""
    C, L = plan.coefficients, plan.limits
    M = np.array([pkm.mass_matrix(plan.mech, q) for q in C.q[:: max(1, len(C.q) // 25)]])
    A = float(np.min(L.peak) / np.max(np.einsum("kii->ki", M)))
    box = actuator_limits(plan.mech, peak=1e9, speed=L.speed, acceleration=A, margin=L.margin)
    law = solve(plan.mech, plan.path, C, box, plan.payload, mid)
    return _law(plan, law.sd, law.sdd), A


def _task_speed(C, L, a_max: float, mid) -> tuple[np.ndarray, np.ndarray]:
    """``(sd, sdd)`` of a constant task acceleration ``a_max`` along the path (module doc), the motors' speed caps
    held at the grid points and at the midpoints ``mid`` of the two segments around each."""
    g = np.linalg.norm(C.dy[:, :3], axis=1)  # [m per unit s]
    ds = np.diff(C.s)
    length = np.concatenate([[0.0], np.cumsum(0.5 * (g[1:] + g[:-1]) * ds)])  # [m]
    with np.errstate(divide="ignore"):
        cap = np.min(np.where(np.abs(C.dqa) > 0, ((1 - L.margin) * L.speed / np.abs(C.dqa)) ** 2, np.inf), axis=1)
        inner = np.min(np.where(np.abs(mid.dqa) > 0, ((1 - L.margin) * L.speed / np.abs(mid.dqa)) ** 2, np.inf),
                       axis=1)
    cap[:-1] = np.minimum(cap[:-1], inner)  # (x is linear in s on a segment: held at both its ends, held inside)
    cap[1:] = np.minimum(cap[1:], inner)
    w = np.minimum(cap * g ** 2, 1e12)  # (speed^2 [m^2/s^2]: the motors' caps, then a_max up and down)
    w[0] = w[-1] = 0.0
    dl = np.diff(length)
    for i in range(len(w) - 1):
        w[i + 1] = min(w[i + 1], w[i] + 2.0 * a_max * dl[i])
    for i in range(len(w) - 1, 0, -1):
        w[i - 1] = min(w[i - 1], w[i] + 2.0 * a_max * dl[i - 1])
    x = w / g ** 2
    sd = np.sqrt(np.maximum(x, 0.0))
    return sd, np.diff(x) / (2.0 * ds)


def task_acceleration_law(plan: TimeOptimal, mid) -> tuple[TimeOptimal, float]:
    """The constant task-acceleration baseline: ``(law, a_max [m/s^2])``, ``a_max`` the largest (bisection in
    [0.01, 1000] m/s^2: 1000 means the motors' speed caps bind everywhere) whose efforts hold at the grid points
    and inside every segment (:func:`pkm.core.timing.solve._between`; the speeds are capped by construction)."""
    C, L = plan.coefficients, plan.limits
    lo, hi = 0.01, 1000.0
    for _ in range(50):
        a = np.sqrt(lo * hi)
        sd, sdd = _task_speed(C, L, a, mid)
        ok = usage(C, L, sd, sdd)[0].max() <= 1.0 + 1e-9 and _between(mid, C, L, sd, sdd)[:, 0].max() <= 1.0 + 1e-9
        lo, hi = (a, hi) if ok else (lo, a)
    sd, sdd = _task_speed(C, L, lo, mid)
    return _law(plan, sd, sdd), lo


def delta_cycle(points: int, simulate: bool) -> list[dict]:
    delta = pkm.load("delta")
    geo = waypoint_path(delta, adept_waypoints(START))
    rows = []
    for setting, given in SETTINGS.items():
        for m in (0.0, 1.0, 3.0):
            dp = with_payload(delta, m)
            s = np.linspace(0.0, 1.0, points)
            C = path_coefficients(dp, geo, s)
            mid = path_coefficients(dp, geo, 0.5 * (s[1:] + s[:-1]), q0=C.q[0])  # (the limits held between points)
            opt = solve(dp, geo, C, actuator_limits(dp, **given), m, mid)
            check = pkm.verify_time_optimal(opt, simulate=simulate)
            box, A = box_law(opt, mid)
            box_check = pkm.verify_time_optimal(box, simulate=False)
            task, a_max = task_acceleration_law(opt, mid)
            task_check = pkm.verify_time_optimal(task, simulate=False)
            rows.append({
                "drives": setting, "payload_kg": m, "optimal_s": opt.cycle_time,
                "optimal_effort_usage": check.effort_usage, "optimal_speed_usage": check.speed_usage,
                "optimal_holds": check.holds, "optimal_inactive_segments": len(check.inactive),
                "optimal_tracking_error_mrad": None if check.tracking_error is None else
                float(check.tracking_error.max() * 1e3),
                "optimal_task_error_mm": None if check.task_error is None else check.task_error * 1e3,
                "optimal_active": {k: opt.active.count(k) for k in sorted(set(opt.active))},
                "box_s": box.cycle_time, "box_acceleration_rad_s2": A, "box_effort_usage": box_check.effort_usage,
                "box_holds": box_check.holds,
                "task_s": task.cycle_time, "task_acceleration_m_s2": a_max,
                "task_effort_usage": task_check.effort_usage, "task_holds": task_check.holds,
                "_laws": (opt, box, task)})
    return rows


def workspace_map(points: int, n: int) -> dict:
    delta = pkm.load("delta")
    ys, zs = np.linspace(-0.06, 0.06, n), np.linspace(-0.38, -0.28, n)
    grid = np.full((n, n), np.nan)
    refused = {}
    for i, z0 in enumerate(zs):
        for j, y0 in enumerate(ys):
            try:
                grid[i, j] = pkm.time_optimal(delta, adept_waypoints([START[0], y0, z0]), points=points,
                                              kernels=True).cycle_time
            except pkm.errors.PathError as exc:
                refused[f"y={y0:+.3f},z={z0:+.3f}"] = f"{exc.limit} at point {exc.index}"
    return {"y_m": ys.tolist(), "z_m": zs.tolist(), "cycle_s": grid.tolist(), "refused": refused}


def others(points: int) -> dict:
    out = {}
    prs3 = pkm.load("prs3")
    cases = load_motions("prs3_motions.toml")
    for case, T, what in (("1", 5.0, "10 mm rise"), ("2", 3.0, "10 mm harmonic rise (half period)"),
                          ("3", 3.0, "0.175 rad roll (half period)"), ("4", 3.0, "0.175 rad pitch (half period)")):
        geo = motion_path(prs3, dataclasses.replace(cases[case], duration=T), ("z", "pitch", "roll"))
        plan = pkm.time_optimal(prs3, geo, points=points)
        check = pkm.verify_time_optimal(plan, simulate=False)
        out[f"prs3 case {case}: {what}"] = {"optimal_s": plan.cycle_time, "paper_s": T,
                                            "effort_usage": check.effort_usage, "holds": check.holds,
                                            "active": {k: plan.active.count(k) for k in sorted(set(plan.active))}}
    gs = pkm.load("gough_stewart")
    y0 = pkm.TaskMap.of(gs).value(gs.q_reference)
    th = np.linspace(0.0, np.pi, 25)
    W = np.array([y0 + np.r_[-0.05 * np.cos(a), 0.0, 0.03 * np.sin(a), 0, 0, 0, 0] for a in th])
    plan = pkm.time_optimal(gs, W, points=points)
    check = pkm.verify_time_optimal(plan, simulate=False)
    out["gough_stewart: 100 mm surge, 30 mm heave arc"] = {
        "optimal_s": plan.cycle_time, "effort_usage": check.effort_usage, "holds": check.holds,
        "active": {k: plan.active.count(k) for k in sorted(set(plan.active))}}
    return out


def figures(rows: list[dict], grid: dict, out: Path) -> list[str]:
    from pkm._plot import figure, save

    written = []
    for setting in SETTINGS:
        fig, ax = figure(size=(7.0, 4.0))
        row = next(r for r in rows if r["drives"] == setting and r["payload_kg"] == 1.0)
        for law, name in zip(row["_laws"], ("time-optimal", "joint box", "constant task acceleration")):
            ax.plot(law.time, law.sd * np.linalg.norm(law.coefficients.dy[:, :3], axis=1), label=
                    f"{name}: {law.cycle_time * 1e3:.1f} ms")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("end-effector speed [m/s]")
        ax.set_title(f"Delta 25/305/25 mm cycle, 1 kg, {setting}")
        ax.legend(fontsize=8)
        written.append(str(save(fig, out, f"delta_speed_{setting.replace(' ', '_')}")))
    fig, ax = figure(size=(5.5, 4.5))
    c = np.array(grid["cycle_s"], dtype=float) * 1e3
    im = ax.pcolormesh(np.array(grid["y_m"]) * 1e3, np.array(grid["z_m"]) * 1e3, c, shading="nearest")
    fig.colorbar(im, ax=ax, label="cycle time [ms]")
    ax.set_xlabel("path's y [mm]")
    ax.set_ylabel("path's z [mm]")
    ax.set_title("Delta cycle time over the workspace (own drives)")
    written.append(str(save(fig, out, "delta_cycle_map")))
    return written


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=200)
    ap.add_argument("--out", default="out/cycle_time")
    ap.add_argument("--quick", action="store_true", help="coarser grids and map, no tracking simulation")
    args = ap.parse_args()
    t0 = time.perf_counter()
    points = 60 if args.quick else args.points
    rows = delta_cycle(points, simulate=not args.quick)
    grid = workspace_map(max(50, points // 2), 3 if args.quick else 7)
    result = {"delta_adept": [{k: v for k, v in r.items() if k != "_laws"} for r in rows], "delta_map": grid,
              "others": others(points)}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    try:
        result["figures"] = figures(rows, grid, out)
    except pkm.errors.MissingDependencyError as exc:
        result["figures"] = str(exc)
    result["seconds"] = time.perf_counter() - t0
    (out / "cycle_time.json").write_text(json.dumps(result, indent=2))
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
