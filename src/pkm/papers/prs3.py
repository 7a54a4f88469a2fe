"""Díaz-Rodríguez et al. (2016), 3-PRS kinematics and inverse dynamics: sec. 4's operation count and
sec. 5's simulations (Table 2, motion cases of ``dynamics/prs3_motions.toml``) reproduced.

The paper prints no force or power values, only Figs. 3-4 (powers of cases 2 and 3) and
qualitative statements; the force rows therefore carry ``published = None`` and give, for case 2,
the closed form of a translating robot in their note. Row ids for t = 2.5 s spell it ``t2p5``.
"""

from __future__ import annotations

import csv
import functools
from pathlib import Path

import numpy as np

from pkm._plot import figure, save
from pkm.mechanisms.prs3 import Prs3Params
from pkm.mechanisms.prs3.dynamics import BOUNDARY, G, Prs3Dynamics, operation_count
from pkm.motion import load_motions
from pkm.papers import Row, cached_rows, generic_count, ident_rows, modes_row, opcount_rows

TITLE = "Díaz-Rodríguez, Carretero, Bautista-Quintero & Chacón (2016): 3-PRS kinematics and inverse dynamics"
PUBLISHED_COUNTS = {"this paper": (860, 680), "Díaz-Rodríguez et al. 2013": (1163, 735),
                    "Tsai & Yuan 2010": (1352, 778)}
FORCE_TIMES = {"t0": 0.0, "t1": 1.0, "t2p5": 2.5}
MOTIONS = "prs3_motions.toml"


@functools.cache
def motions():
    """The sec. 5 motion cases (``dynamics/prs3_motions.toml``), read once."""
    return load_motions(MOTIONS)


@functools.cache
def simulate(case: str):
    """``(t, Ydd, result)`` of a sec. 5 motion case on the Table 2 design (P-actuated, slider below)."""
    t, Y, Yd, Ydd = motions()[case].sample()
    return t, Ydd, Prs3Dynamics(Prs3Params()).batch(Y, Yd, Ydd, t=t)


@functools.cache
def counts():
    """Our operation counts, per mode (see :func:`pkm.mechanisms.prs3.dynamics.operation_count`)."""
    return {mode: operation_count(Prs3Params(), mode=mode) for mode in ("symbolic", "inertial", "numeric")}


def _at(t: np.ndarray, time: float) -> int:
    k = int(np.argmin(np.abs(t - time)))
    if abs(t[k] - time) > 1e-9:
        raise ValueError(f"no sample at t = {time} s")
    return k


def _working_modes_too(mech, modes) -> str:
    """The 3-PRS has no closed-form FK to compare with: the generic core's Newton from the reference, and the
    working modes at the reference pose."""
    import pkm

    ws = pkm.working_modes(mech, pkm.TaskMap.of(mech).value(mech.q_reference))
    return (f"The 3-PRS family has 16 generic solutions (the 16 paths: a parameter homotopy from them). At the "
            f"reference pose the inverse kinematics has {len(ws)} working modes (pkm.working_modes: each leg's two "
            "slider positions of eq. (10)). The paper gives no forward kinematics.")


@cached_rows("prs3")
def reproduce() -> list[Row]:
    """The paper's numbers and claims next to ours."""
    c = counts()
    ours = c["inertial"]
    note = (f"ours with symbolic inertial parameters and Table 2 geometry; fully symbolic {c['symbolic'].mul}/"
            f"{c['symbolic'].add}, all numeric {c['numeric'].mul}/{c['numeric'].add} (mult/add); also "
            f"{ours.functions['sin']} sin, {ours.functions['cos']} cos, {ours.functions['sqrt']} sqrt, "
            f"{ours.functions['atan2']} atan2. Earlier: Díaz-Rodríguez et al. 2013 1163/735, Tsai & Yuan 2010 "
            f"1352/778. Boundary: {BOUNDARY}")
    rows = [Row("prs3.opcount.mul", 860, ours.mul, "", None, "sec. 4, after eq. (40)", note, "<="),
            Row("prs3.opcount.add", 680, ours.add, "", None, "sec. 4, after eq. (40)", note, "<=")]
    num, g = c["numeric"], generic_count("prs3")
    rows += opcount_rows("prs3", "prs3.opcount.generic_", (
        f"{g.mul / num.mul:.2f}x / {g.add / num.add:.2f}x the hand-written twin with the same numeric parameters "
        f"({num.mul}/{num.add}), {g.mul / ours.mul:.2f}x / {g.add / ours.add:.2f}x its count with symbolic inertial "
        f"parameters (prs3.opcount.mul/add, {ours.mul}/{ours.add}); the hand-written count also includes the "
        "closed-form leg inverse kinematics from the task pose, which the generic route takes as its input q. "))

    rows.append(modes_row("prs3", "prs3.fk.modes_reference", _working_modes_too))
    p = Prs3Params()
    t2, Ydd2, r2 = simulate("2")
    spread = float(np.ptp(r2.power, axis=1).max())
    rows.append(Row("prs3.case2.power_spread_W", 0.0, spread, "W", 1e-6, "sec. 5, Fig. 3",
                    "largest difference between the three actuator powers over the 5 s (the paper: all equal)"))
    t3, _, r3 = simulate("3")
    peaks = np.abs(r3.power).max(axis=0)
    ratio = float(peaks[0] / min(peaks[1], peaks[2]))
    rows.append(Row("prs3.case3.p1_peak_ratio", 0.1, ratio, "", None, "sec. 5, Fig. 4",
                    f"peak |P1| / smaller of peak |P2|, |P3| (peaks {peaks[0]:.4g}, {peaks[1]:.4g}, {peaks[2]:.4g} W); "
                    "the paper: the third actuator needs less than 10 % of the other two", "<="))
    moving = np.abs(r3.power[:, 1]) > 1e-3 * peaks[1]
    opposite = bool(np.all(r3.power[moving, 1] * r3.power[moving, 2] < 0) and 0.5 < peaks[1] / peaks[2] < 2)
    rows.append(Row("prs3.case3.p2p3_opposite", True, opposite, "", None, "sec. 5, Fig. 4",
                    f"P2 and P3 of opposite sign at every sample where they are not ~0, peaks within a factor 2 "
                    f"(ratio {peaks[1] / peaks[2]:.4f})"))
    m_leg = p.m_platform / 3 + p.m_slider + p.m_coupler
    for case, (t, r) in (("2", (t2, r2)), ("3", (t3, r3))):
        for key, time in FORCE_TIMES.items():
            k = _at(t, time)
            extra = f"; closed form (m_p/3 + m1 + m2)(g + z'') = {m_leg * (G + Ydd2[k, 0]):.13g} N" if case == "2" \
                else ""
            for i in range(3):
                rows.append(Row(f"prs3.case{case}.F{i + 1}_{key}_N", None, float(r.tau[k, i]), "N", None,
                                f"sec. 5, case {case}", f"slider force at t = {time} s; the paper prints no "
                                                        f"force values{extra}"))
    return rows + ident_rows("prs3", "prs3.ident.")


def series(out_dir) -> list[Path]:
    """CSV time series of every case: ``t, d1..d3, F1..F3, P1..P3`` every 0.01 s (SI)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for case in sorted(motions()):
        t, _, r = simulate(case)
        path = out / f"prs3_case{case}.csv"
        with path.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["t_s", "d1_m", "d2_m", "d3_m", "F1_N", "F2_N", "F3_N", "P1_W", "P2_W", "P3_W"])
            for k in range(len(t)):
                w.writerow([f"{t[k]:.2f}", *(f"{x:.10g}" for x in (*r.q_actuated[k], *r.tau[k], *r.power[k]))])
        paths.append(path)
    return paths


#: Each figure and the CSV series that hold its numbers.
SERIES = {"prs3_fig3_power_case2": ("prs3_case2",), "prs3_fig4_power_case3": ("prs3_case3",),
          "prs3_forces": ("prs3_case1", "prs3_case2", "prs3_case3", "prs3_case4")}


def _design() -> str:
    p = Prs3Params()
    return (f"3-PRS of Table 2 (l = {p.l:g} m, h = {p.h:g} m, g = {p.g:g} m, m_p = {p.m_platform:g} kg, "
            "P-actuated)")


def _legs(ax, t, values, symbol: str) -> None:
    """One curve per leg, labelled ``symbol_i``; a leg whose curve lies on an earlier one (1e-9 of the range) says
    so in its label, since the eye cannot tell them apart."""
    scale = max(float(np.ptp(values)), float(np.abs(values).max()), 1e-300)
    for i in range(3):
        same = [j for j in range(i) if np.abs(values[:, i] - values[:, j]).max() <= 1e-9 * scale]
        label = f"${symbol}_{i + 1}$" + (f" (= ${symbol}_{same[0] + 1}$)" if same else "")
        ax.plot(t, values[:, i], label=label, linestyle=("-", "--", ":")[i])


def figures(out_dir) -> list[Path]:
    """Figs. 3 and 4 (actuator powers, cases 2 and 3), and the forces of every case (no figure in the paper)."""
    paths = []
    for case, number in (("2", 3), ("3", 4)):
        t, _, r = simulate(case)
        fig, ax = figure()
        _legs(ax, t, r.power, "P")
        ax.set(xlabel="t [s]", ylabel="actuator power [W]",
               title=f"{_design()}\ncase {case}, {motions()[case].description}: actuator powers (paper's Fig. {number})")
        ax.title.set_fontsize(9)
        ax.grid(True, alpha=0.3)
        ax.legend()
        paths.append(save(fig, out_dir, f"prs3_fig{number}_power_case{case}"))
    fig, axes = figure(ncols=2, nrows=2)
    for ax, case in zip(axes.ravel(), sorted(motions())):
        t, _, r = simulate(case)
        _legs(ax, t, r.tau, "F")
        ax.set(xlabel="t [s]", ylabel="slider force [N]", title=f"case {case}: {motions()[case].description}")
        ax.grid(True, alpha=0.3)
        ax.legend()
    fig.suptitle(f"{_design()}: slider forces of the four motion cases of sec. 5 (no figure in the paper, which "
                 "prints no force)", fontsize=10)
    paths.append(save(fig, out_dir, "prs3_forces"))
    return paths


__all__ = ["FORCE_TIMES", "PUBLISHED_COUNTS", "SERIES", "TITLE", "counts", "figures", "motions", "reproduce", "series",
           "simulate"]
