"""Sec. 4 of Sanchez-Alonso et al. (RIAI 2016): the reconfiguration angle that maximises manipulability.

Model: :mod:`pkm.mechanisms.hexapod` with its defaults (Table 1, sector layout, ``elbow_out``);
indices ``w_rot``, ``w_tras`` of eqs. (35)-(37) with the twist referred to O
(:mod:`pkm.mechanisms.hexapod.indices`); ``beta*`` and the profiles by proxqp sequential QPs
(:mod:`pkm.mechanisms.hexapod.reconfiguration`); the base model is ``beta = 0`` at every pose.

* Pose T (Figs. 7-8): the printed matrix (rotation rounded to 4 digits, projected on SO(3)),
  ``P = (0, -350, 0) mm``; reachable interval within ``[-90, 90] deg``; ``beta*`` of each index.
* The descending spiral (Figs. 9-10): ``T(s)`` as printed for ``s = 0, 0.01, ..., 1`` (101 poses);
  pointwise ``beta*`` of each index (the paper's strategy), the base model, and the rate-limited
  profile (2 deg per pose, smoothness 1/rad^2) for comparison.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import numpy as np

from pkm._plot import figure, save
from pkm.core.kinematics.task import TaskMap, as_rotation
from pkm.mechanisms import hexapod as hx
from pkm.mechanisms.hexapod import indices as hi
from pkm.mechanisms.hexapod import reconfiguration as hr
from pkm.papers import Row, cached_rows, ident_rows, modes_row, opcount_rows, stiffness_rows

TITLE = "Sanchez-Alonso et al. (2016), Kinematic analysis of a novel reconfigurable parallel robot, RIAI 13:247-257"

#: Pose T (sec. 4) as printed: rotation rows (4 digits) and position [m].
POSE_T_ROTATION = (0.9623, -0.1306, -0.2388, 0.0842, 0.9771, -0.1952, 0.2588, 0.1677, 0.9513)
POSE_T_POSITION = (0.0, -0.350, 0.0)
#: The spiral's rotation as printed (sec. 4) and its position [m] for path parameter s.
SPIRAL_ROTATION = ((0.9811, -0.0558, 0.1855), (0.0858, 0.9837, -0.1581), (-0.1736, 0.1710, 0.9698))
#: First pose of the spiral from which the paper sees a clear gain (Fig. 9).
GAIN_FROM = 40
RATE_LIMIT = math.radians(2.0)


def pose_T_placement() -> tuple[np.ndarray, np.ndarray]:
    """Pose T: the rotation as printed projected on SO(3) (its defect is 1e-4), and the position [m]."""
    return as_rotation(POSE_T_ROTATION, "POSE_T_ROTATION", hx.HOME_ROTATION_TOL), np.array(POSE_T_POSITION)


def spiral_poses(n: int = 101) -> list[tuple[np.ndarray, np.ndarray]]:
    """The poses ``T(s)``, ``s = 0 .. 1`` in ``n`` steps: rotation as printed (projected), position [m]."""
    R = as_rotation(SPIRAL_ROTATION)
    return [(R, np.array([0.025 * math.cos(2 * math.pi * s), -0.250 - 0.100 * s, 0.025 * math.sin(2 * math.pi * s)]))
            for s in np.linspace(0.0, 1.0, n)]


@functools.lru_cache(maxsize=1)
def pose_t() -> dict:
    """Pose T: reachable interval, ``beta*`` of both indices and the curves of Fig. 7 (0.1 deg grid)."""
    p = hx.Params()
    R, P = pose_T_placement()
    spans = hr.reachable_intervals(p, R, P)
    choice = {idx: hr.optimal_beta(p, R, P, idx) for idx in hi.INDICES}
    grid = np.radians(np.arange(-90.0, 90.05, 0.1))
    curves = {idx: hi.PoseIndex(p, [(R, P)], idx)(np.zeros(grid.size, int), grid) for idx in hi.INDICES}
    reach = np.array([any(a <= b <= c for a, c in spans) for b in grid])
    return {"spans": spans, "choice": choice, "grid": grid, "curves": curves, "reach": reach}


@functools.lru_cache(maxsize=1)
def spiral() -> dict:
    """The spiral: pointwise optima, base model and rate-limited profiles of both indices (and w_tras at P)."""
    p = hx.Params()
    poses = spiral_poses()
    prof = {idx: hr.beta_profile(p, poses, idx, rate_limit=RATE_LIMIT) for idx in hi.INDICES}
    at_p = hr.beta_profile(p, poses, "w_tras", rate_limit=RATE_LIMIT, point="P")
    return {"profiles": prof, "w_tras_P": at_p}


@cached_rows("hexapod")
def reproduce() -> list[Row]:
    """The published numbers of sec. 4 next to ours."""
    t = pose_t()
    s = spiral()
    lo = math.degrees(t["spans"][0][0])
    b_rot, b_tras = (t["choice"][i].beta_deg for i in hi.INDICES)
    pr, pt = s["profiles"]["w_rot"], s["profiles"]["w_tras"]
    gap = np.degrees(np.abs(pr.pointwise - pt.pointwise))
    gap_p = np.degrees(np.abs(pr.pointwise - s["w_tras_P"].pointwise))
    gain_pw = pr.pointwise_value / pr.base_value - 1.0
    gain40 = 100.0 * float(np.mean(gain_pw[GAIN_FROM:]))
    gain_before = 100.0 * float(np.mean(gain_pw[:GAIN_FROM]))
    w, grid = t["curves"]["w_rot"], np.degrees(t["grid"])
    flat = grid[w >= 0.999 * w.max()]
    coarse = np.arange(-59.0, 91.0)
    on_1deg = coarse[int(np.argmax(np.interp(coarse, grid, w)))]
    return [
        Row("hexapod.poseT.beta_min_reachable_deg", -60.0, lo, "deg", 0.5, "sec. 4, Fig. 7",
            f"Closed-form lower end of the reachable interval within [-90, 90] deg: leg 1 folds (|C1 - A1| < "
            f"LB - LA) below it; the pose is reachable up to 90 deg. Printed as '-60'; ours {lo:.2f}."),
        Row("hexapod.poseT.beta_opt_wrot_deg", -11.0, b_rot, "deg", 1.0, "sec. 4, Figs. 7a, 8",
            f"argmax of w_rot (eq. 35, J of eq. 37), by proxqp SQP; {b_rot:.2f} deg (argmax on a 1-deg grid: "
            f"{on_1deg:.0f}). The paper says 'approximately -11 deg' for both indices, read from Fig. 7 whose curves "
            f"are flat near the top (w_rot is within 0.1 % of its peak over {flat.min():.1f}..{flat.max():.1f} deg); "
            "tolerance 1 deg."),
        Row("hexapod.poseT.beta_opt_wtras_deg", -11.0, b_tras, "deg", 1.0, "sec. 4, Figs. 7b, 8",
            f"argmax of w_tras (eq. 36, twist referred to O as in the paper's screws); {b_tras:.2f} deg."),
        Row("hexapod.spiral.max_gap_rot_tras_deg", 2.0, float(gap.max()), "deg", 1.0, "sec. 4, Fig. 10",
            f"max over the 101 poses of |beta*_rot - beta*_tras| (pointwise optima). Not reproduced: the model "
            f"that reproduces pose T gives {gap.max():.2f} deg (at s = {np.argmax(gap) / 100:.2f}; "
            f"{gap.min():.2f} deg at best); beta*_rot runs from {math.degrees(pr.pointwise[0]):.1f} to "
            f"{math.degrees(pr.pointwise[-1]):.1f} deg, beta*_tras from {math.degrees(pt.pointwise[0]):.1f} to "
            f"{math.degrees(pt.pointwise[-1]):.1f} deg. With w_tras at P instead of O the gap is "
            f"{gap_p.max():.2f} deg. Independent re-derivations reported the same mismatch (shared notes); "
            "the printed spiral may differ from the one computed (4-digit rotation, unstated conventions).",
            why=f"the model that reproduces pose T gives {gap.max():.1f} deg along the spiral; independent "
                "re-derivations agree (the printed spiral's conventions are not stated)"),
        Row("hexapod.spiral.gain_after_40_wrot", None, gain40, "%", None, "sec. 4, Fig. 9a",
            f"Mean of w_rot(beta*_k) / w_rot(0) - 1 over poses 40..100 (base model: beta = 0 throughout). "
            f"The paper prints no number, only 'from about point 40 the improvement is very clear'. Ours: "
            f"{gain40:.2f} % after point 40 against {gain_before:.2f} % before it, i.e. no clear gain: beta* "
            f"approaches 0 along the spiral ({math.degrees(pr.pointwise[-1]):.2f} deg at the end). The rate-limited "
            f"QP profile gives {100 * pr.mean_gain(GAIN_FROM):.2f} %."),
    ] + opcount_rows("hexapod", "hexapod.opcount.") + [
        modes_row("hexapod", "hexapod.fk.modes_reference", _against_multistart)] + ident_rows("hexapod", "hexapod.ident.") \
        + stiffness_over_beta()


#: The reconfiguration angles of the stiffness rows [deg].
STIFFNESS_BETA = (-30, -15, 0, 15, 30)


def stiffness_configuration(mech, beta_deg: float) -> np.ndarray:
    """The closed configuration at the model's reference pose of the platform with the reconfiguration angle
    ``beta_deg`` [deg] (:func:`pkm.solve_ik` from the reference)."""
    import pkm

    task = TaskMap.of(mech).named(mech.q_reference)
    return pkm.solve_ik(mech, {**task, "beta_1": math.radians(beta_deg)}).q


def stiffness_over_beta() -> list[Row]:
    """Rows ``hexapod.stiffness.force_min_beta_<m|p><deg>`` and ``hexapod.stiffness.f1_beta_...`` (issue 54): the
    platform's smallest translational stiffness and first natural frequency at the reference pose for each
    reconfiguration angle of :data:`STIFFNESS_BETA` (:func:`pkm.papers.stiffness_rows`: the six alpha drives' servo
    stiffness, the reconfiguration drive beta_1 held rigid, rigid links)."""
    import pkm

    mech = pkm.load("hexapod")
    pose = ", ".join(f"{k} {v:.6g}" for k, v in TaskMap.of(mech).named(mech.q_reference).items() if k != "beta_1")
    cases = [(f"beta_{'m' if b < 0 else 'p' if b > 0 else ''}{abs(b)}",
              f"beta = {b} deg, the model's reference pose of the platform ({pose} [m, rad]), Table 1's dimensions",
              mech, stiffness_configuration(mech, b)) for b in STIFFNESS_BETA]
    return stiffness_rows("hexapod.stiffness.", cases, [j for j in mech.actuated_names if j.startswith("alpha")])


def _against_multistart(mech, modes) -> str:
    """The homotopy's modes against the semi-closed FK's multistart (eqs. 4-13 from 32 seeds)."""
    from pkm.mechanisms.hexapod.kinematics import assembly_modes as multistart

    qa = mech.actuated_q(mech.q_reference)
    found = multistart(mech, qa, n_starts=32)
    task = TaskMap.of(mech)
    poses = [task.value(m.q) for m in modes]
    missed = [k for k, y in enumerate(poses)
              if not any(np.abs(task.error(y, task.value(f.q))).max() < 1e-7 for f in found)]
    extra = len(found) - (len(poses) - len(missed))
    text = (f"The paper's semi-closed FK (eqs. 4-13) from 32 seeds (hexapod.kinematics.assembly_modes) finds "
            f"{len(found)}; ")
    text += (f"it misses mode(s) {missed} (a finding: the multistart is not complete)" if missed
             else "the same modes, none missed") + (f", and {extra} the homotopy does not have" if extra > 0 else "")
    return text + "."


UNITS = {"w_rot": "[-]", "w_tras": "[m$^3$]"}  # w = sqrt(det(X X^T)) of the angular (1/1) or linear (m) rows
NAMES = {"w_rot": "$w_{rot}$", "w_tras": "$w_{tras}$"}
CAPTION = ("Hexapod of two 3-RUS, Table 1 design (R_f = 50, R_r = 150, R_2 = 450, H_o = 200, LA = 200, LB = 400, "
           "h = 34, r = 50 mm)")
PAPER = "0.5"  # grey: what the paper states, drawn beside our curves
#: Each figure and the CSV series that hold its numbers.
SERIES = {"hexapod_fig7_indices_vs_beta": ("hexapod_fig7_indices_vs_beta",),
          "hexapod_fig9_manipulability_spiral": ("hexapod_spiral_profiles",),
          "hexapod_fig10_beta_profiles": ("hexapod_spiral_profiles",)}


def figures(out_dir) -> list[Path]:
    """Fig. 7 (indices vs beta at pose T), Fig. 9 (base vs reconfigured along the spiral, and the gain, which the
    curves alone do not show), Fig. 10 (beta profiles)."""
    t, s = pose_t(), spiral()
    out = []
    fig, axes = figure(ncols=2)
    for ax, idx in zip(axes[0], hi.INDICES):
        v = np.where(t["reach"], t["curves"][idx], np.nan)
        ax.plot(np.degrees(t["grid"]), v, label=f"{NAMES[idx]} at pose T")
        ax.axvline(t["choice"][idx].beta_deg, ls="--", c="k", lw=0.8,
                   label=rf"$\beta^*$ = {t['choice'][idx].beta_deg:.2f} deg")
        ax.axvline(math.degrees(t["spans"][0][0]), ls=":", c="r", lw=0.8, label="reachability limit")
        ax.axvline(-11.0, ls="-.", c=PAPER, lw=1.0, label=r"paper: $\beta^*$ about -11 deg")
        ax.axvline(-60.0, ls=(0, (1, 3)), c=PAPER, lw=1.5, label="paper: reachable from -60 deg")
        ax.set(xlabel=r"reconfiguration angle $\beta$ [deg]", ylabel=f"{NAMES[idx]} {UNITS[idx]}",
               title=f"{NAMES[idx]} against $\\beta$")
        ax.legend(fontsize=8)
    fig.suptitle(f"{CAPTION}\nat pose T (paper's Fig. 7)", fontsize=10)
    out.append(save(fig, out_dir, "hexapod_fig7_indices_vs_beta"))
    fig, axes = figure(ncols=2, nrows=2, size=(6.4, 3.4))
    k = np.arange(len(s["profiles"]["w_rot"].base_value))
    for col, idx in enumerate(hi.INDICES):
        pr = s["profiles"][idx]
        top, low = axes[0, col], axes[1, col]
        top.plot(k, pr.base_value, label=r"base model ($\beta$ = 0)")
        top.plot(k, pr.pointwise_value, label=r"reconfigured (pointwise $\beta^*$)")
        top.plot(k, pr.value, ls="--", label="reconfigured (QP profile, 2 deg/pose)")
        top.set(xlabel="pose along the spiral, k [-]", ylabel=f"{NAMES[idx]} {UNITS[idx]}",
                title=f"{NAMES[idx]} along the spiral")
        top.legend(fontsize=7)
        low.plot(k, 100.0 * (pr.pointwise_value / pr.base_value - 1.0), c="C1", label=r"pointwise $\beta^*$")
        low.plot(k, 100.0 * (pr.value / pr.base_value - 1.0), c="C2", ls="--", label="QP profile")
        low.axhline(0.0, c="C0", lw=0.8, label=r"base model ($\beta$ = 0)")
        low.axvline(GAIN_FROM, c=PAPER, ls="-.", lw=1.0, label=f"paper: 'a clear gain from pose {GAIN_FROM} on'")
        low.set(xlabel="pose along the spiral, k [-]", ylabel="gain over the base model [%]",
                title=f"what reconfiguring gains in {NAMES[idx]}")
        low.legend(fontsize=7)
    fig.suptitle(f"{CAPTION}\nalong the spiral of sec. 4 (paper's Fig. 9)", fontsize=10)
    out.append(save(fig, out_dir, "hexapod_fig9_manipulability_spiral"))
    fig, axes = figure(ncols=2)
    ax, gap = axes[0]
    for idx in hi.INDICES:
        pr = s["profiles"][idx]
        ax.plot(k, np.degrees(pr.pointwise), label=rf"$\beta^*$ of {NAMES[idx]}, pointwise")
        ax.plot(k, np.degrees(pr.beta), ls="--", label=f"QP profile of {NAMES[idx]} (2 deg/pose)")
    ax.set(xlabel="pose along the spiral, k [-]", ylabel=r"$\beta$ [deg]", title="reconfiguration angle")
    ax.legend(fontsize=8)
    pr, pt = s["profiles"]["w_rot"], s["profiles"]["w_tras"]
    gap.plot(k, np.degrees(np.abs(pr.pointwise - pt.pointwise)), label=r"ours, pointwise $\beta^*$")
    gap.axhline(2.0, c=PAPER, ls="-.", label="paper: 'about two degrees at most'")
    gap.set(xlabel="pose along the spiral, k [-]", ylabel=r"$|\beta^*_{rot} - \beta^*_{tras}|$ [deg]",
            title=r"how far the two indices' $\beta^*$ lie apart", ylim=(0.0, None))
    gap.legend(fontsize=8)
    fig.suptitle(f"{CAPTION}\nalong the spiral of sec. 4 (paper's Fig. 10)", fontsize=10)
    out.append(save(fig, out_dir, "hexapod_fig10_beta_profiles"))
    return out


def series(out_dir) -> list[Path]:
    """CSV: Fig. 7's curves at pose T, and along the spiral each index's base, pointwise and QP values and angles."""
    import csv

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    t, s = pose_t(), spiral()
    f1 = out_dir / "hexapod_fig7_indices_vs_beta.csv"
    with f1.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["beta_deg", "reachable", "w_rot", "w_tras_m3"])
        for b, r, wr, wt in zip(np.degrees(t["grid"]), t["reach"], t["curves"]["w_rot"], t["curves"]["w_tras"]):
            w.writerow([f"{b:.4f}", int(bool(r)), f"{wr:.10g}" if r else "", f"{wt:.10g}" if r else ""])
    f2 = out_dir / "hexapod_spiral_profiles.csv"
    with f2.open("w", newline="") as fh:
        w = csv.writer(fh)
        head = ["k"]
        for idx in hi.INDICES:
            head += [f"{idx}_base", f"{idx}_pointwise", f"{idx}_qp", f"beta_star_{idx}_deg", f"beta_qp_{idx}_deg"]
        w.writerow(head)
        pr = [s["profiles"][idx] for idx in hi.INDICES]
        for j in range(len(pr[0].base_value)):
            row: list = [j]
            for p in pr:
                row += [f"{p.base_value[j]:.10g}", f"{p.pointwise_value[j]:.10g}", f"{p.value[j]:.10g}",
                        f"{math.degrees(p.pointwise[j]):.6f}", f"{math.degrees(p.beta[j]):.6f}"]
            w.writerow(row)
    return [f1, f2]


__all__ = ["POSE_T_POSITION", "POSE_T_ROTATION", "SERIES", "TITLE", "figures", "pose_T_placement", "pose_t", "reproduce", "series", "spiral",
           "spiral_poses"]
