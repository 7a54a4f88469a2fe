"""Hernández Reyna & Sandoval-Castro (2018): the Delta's base radius R chosen by the condition number.

The paper (sec. 5, Fig. 5) varies R from 100 to 200 mm in 0.1 mm steps, at the pose
(0, 0, -375) mm, with La = 110, Lb = 330, r = 50 mm (Table 1), and plots the condition number
``K = ||J|| ||J^-1||`` of ``J = dX/dth`` (eqs. 12-14, Frobenius norm). It concludes that K tends to
1 as R grows, that the workspace shrinks as R grows, and picks R = 120 mm (110-130 mm as a guideline).

What this study does, and its reading of the paper:

* The design is the paper's Table 1, given explicitly (:data:`PAPER`, with the study pose as its
  reference); its lengths equal the module's default :class:`~pkm.mechanisms.delta.DeltaParams`, but
  the study does not rely on that.
* Three condition numbers, named: ``"fro"`` (raw ``||J||_F ||J^-1||_F``, eqs. 13-14 as printed,
  >= 3 for a 3x3 matrix), ``"fro_normalized"`` (the same over 3, >= 1) and ``"2"``
  (``sigma_max / sigma_min``, >= 1). The paper's "minimum K = 1" holds only for the last two.
* Working mode: knee out (the usual Delta). Knee in has a direct singularity at
  R = r + sqrt(La^2 - (z + Lb)^2) = 150.37 mm (three vertical forearms) inside the studied range;
  only knee out gives a smooth K(R).
* Beyond 200 mm: the pose stays reachable up to R = r + sqrt((La + Lb)^2 - z^2) = 280.16 mm (arms
  stretched). K does not tend to 1: on the axis, by the three-fold symmetry, ``K_2 = sqrt(2) |b| / |a|``
  with ``(a, b)`` the forearm vector in the arm plane, which is smallest where the arm hangs
  vertically, at R = r + sqrt(Lb^2 - (|z| - La)^2) = 246.66 mm (K_2 = 1.906), and rises again.
* Workspace: every point all three arms reach, below the base, no joint limits (the paper gives
  none), on a grid of 8 mm cubes. The paper's claim that it shrinks as R grows holds.
* Choice of R: the radius in the paper's range [100, 200] mm, in 5 mm steps, with the largest
  well-conditioned workspace, the part where ``K_2 <= 3`` (errors amplified at most threefold). The
  bound is a design decision, not fitted; the figures and the row's note show how the choice moves
  with it.

Fig. 5 itself is not legible in our copy of the paper (the image is lost), so its curve values have
no published number to compare with; the rows record ours with the convention named.
"""

from __future__ import annotations

import csv
import dataclasses
import math
from functools import lru_cache
from pathlib import Path

import numpy as np

from pkm._plot import figure, save
from pkm.mechanisms.delta import DeltaParams
from pkm.mechanisms.delta import design as design
from pkm.papers import Row, cached_rows, ident_rows, opcount_rows, stiffness_rows

TITLE = "Hernández Reyna & Sandoval-Castro (2018): kinematics and base-radius reconfiguration of a Delta robot"

PAPER = DeltaParams(La=0.110, Lb=0.330, r=0.050, R=0.150, home=(0.0, 0.0, -0.375))
"""Table 1: La = 110, Lb = 330, r = 50 mm; R = 150 mm for Fig. 4; the study pose (0, 0, -375) mm."""
POSE = np.array(PAPER.home)
R_RANGE = (0.100, 0.200)
R_STEP = 1e-4  # the paper's 0.1 mm
KINDS = ("fro", "fro_normalized", "2")
LABELS = {"fro": r"raw Frobenius $\|J\|_F\,\|J^{-1}\|_F$",
          "fro_normalized": r"normalised $\frac{1}{3}\|J\|_F\,\|J^{-1}\|_F$",
          "2": r"2-norm $\sigma_{max}/\sigma_{min}$"}
K_MAX = 3.0
CHOICE_KIND = "2"
SPACING = 0.008
R_STUDY = np.round(np.concatenate([np.arange(0.040, 0.0951, 0.010), np.arange(0.100, 0.2001, 0.005),
                                    np.arange(0.210, 0.2801, 0.010)]), 6)
"""Workspace sweep [m]: 5 mm steps over the paper's range, 10 mm steps beyond, up to the pose's reach limit."""


def reach_limit() -> float:
    """Largest R [m] for which the study pose is reachable (closed form via the reach intervals)."""
    ((_, hi),) = design.reachable_radii(PAPER, POSE)
    return hi


def knee_in_singularity() -> float:
    """R [m] where knee in has three vertical forearms at the study pose (direct singularity)."""
    return PAPER.r + math.sqrt(PAPER.La**2 - (POSE[2] + PAPER.Lb) ** 2)


def arms_vertical_radius() -> float:
    """R [m] minimising every K at the study pose, where the arms hang vertically (see the module doc)."""
    return PAPER.r + math.sqrt(PAPER.Lb**2 - (abs(POSE[2]) - PAPER.La) ** 2)


@lru_cache(maxsize=2)
def fig5_sweep(branch: str = "knee_out") -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """K vs R at the study pose, 0.1 mm steps from 100 mm to just below the reach limit."""
    R = np.arange(R_RANGE[0], reach_limit(), R_STEP)
    return R, design.condition_vs_radius(PAPER, POSE, R, branch, KINDS)


@lru_cache(maxsize=1)
def radius_study() -> design.RadiusStudy:
    """Workspaces (8 mm grid, K_2 per node) for R over :data:`R_STUDY`."""
    return design.workspace_vs_radius(PAPER, R_STUDY, kind=CHOICE_KIND, spacing=SPACING)


def radius_sweep(R_values=R_STUDY, scheduler: str | None = None):
    """The study of R through :func:`pkm.sweep`: for each base radius (the other dimensions the paper's), the
    reachable volume, the volume where ``K_2 <= 3``, the integral of ``1/K_2`` (8 mm grid) and ``K_2``, ``K_F`` at
    the study pose; the same numbers as :func:`radius_study` and :func:`fig5_sweep` (tested).

    Returns:
        The :class:`pkm.sweeps.SweepResult` (columns ``volume``, ``volume_K3``, ``weighted``, ``K_2``, ``K_fro``).
    """
    import pkm
    from pkm import sweeps

    fixed = {"La": PAPER.La, "Lb": PAPER.Lb, "r": PAPER.r, "home": PAPER.home}
    spacing = f"spacing={SPACING!r}"
    return pkm.sweep("delta", sweeps.table({"R": np.asarray(R_values, dtype=float)}),
                     [f"volume=workspace_volume:{spacing}", f"volume_K3=conditioned_volume:{spacing},k_max={K_MAX!r}",
                      f"weighted=weighted_volume:{spacing}", "K_2=condition:kind=2", "K_fro=condition:kind=fro"],
                     fixed=fixed, scheduler=scheduler)


def choose_radius(k_max: float = K_MAX, R_range: tuple[float, float] = R_RANGE) -> float:
    """The R [m] in ``R_range`` with the largest workspace volume where ``K_2 <= k_max``."""
    study = radius_study()
    inside = (study.R >= R_range[0] - 1e-12) & (study.R <= R_range[1] + 1e-12)
    vol = study.conditioned_volume(k_max)[inside]
    return float(study.R[inside][int(np.argmax(vol))])


def _at(R: float) -> dict[str, float]:
    return {k: float(v[0]) for k, v in design.condition_vs_radius(PAPER, POSE, [R], "knee_out", KINDS).items()}


@cached_rows("delta")
def reproduce() -> list[Row]:
    R, K = fig5_sweep("knee_out")
    in_range = R <= R_RANGE[1] + 1e-12
    monotone = {k: bool(np.all(np.diff(K[k][in_range]) < 0.0)) for k in KINDS}
    _, K_in = fig5_sweep("knee_in")
    k100, k120, k200 = _at(0.100), _at(0.120), _at(0.200)
    R_min, K2_min = design.radius_minimising_condition(PAPER, POSE, "knee_out", "2")
    R_lim = reach_limit()
    K2_lim = math.sqrt(2.0) * abs(POSE[2]) / (R_lim - PAPER.r)
    study = radius_study()
    R_choice = choose_radius()
    sens = ", ".join(f"K_2 <= {k:g}: {choose_radius(k) * 1e3:.0f} mm" for k in (2.5, 3.0, 3.5, 4.0, 5.0))
    vol = {r: study.volume[np.isclose(study.R, r)][0] * 1e3 for r in (0.100, 0.120, 0.200)}
    peak = int(np.argmax(study.volume))
    shrinks = bool(np.all(np.diff(study.volume[peak:]) < 0.0))
    weighted = study.best_weighted()
    unbounded = float(study.R[int(np.argmax(study.conditioned_volume(K_MAX)))])
    conv = "at (0, 0, -375) mm, knee out, paper's Table 1 dimensions"
    return [
        Row("delta.fig5.K_F_R100", None, k100["fro"], "", None, "Fig. 5, eqs. 12-14",
            f"raw Frobenius ||J||_F ||J^-1||_F {conv}; normalised {k100['fro_normalized']:.4f}, "
            f"2-norm {k100['2']:.4f}. Fig. 5's values are not legible in our copy; the raw Frobenius product "
            "is >= 3 for any 3x3 J, so the paper's 'minimum K = 1' cannot refer to it"),
        Row("delta.fig5.K_F_R200", None, k200["fro"], "", None, "Fig. 5, eqs. 12-14",
            f"raw Frobenius {conv}; normalised {k200['fro_normalized']:.4f}, 2-norm {k200['2']:.4f}"),
        Row("delta.fig5.K_2_R120", None, k120["2"], "", None, "Fig. 5; sec. 6 (R = 120 mm chosen)",
            f"2-norm sigma_max / sigma_min {conv}; raw Frobenius {k120['fro']:.4f}, "
            f"normalised {k120['fro_normalized']:.4f}"),
        Row("delta.fig5.monotone_100_200", True, all(monotone.values()), "", None, "Fig. 5; sec. 6",
            f"K strictly decreasing on 100-200 mm in 0.1 mm steps, knee out, per convention {monotone}. "
            f"Knee in is not: it has a direct singularity (three vertical forearms) at "
            f"R = {knee_in_singularity() * 1e3:.2f} mm, where K reaches {np.max(K_in['2'][in_range]):.3g} (K_2) "
            "on the 0.1 mm grid"),
        Row("delta.fig5.R_min_K2_mm", None, R_min * 1e3, "mm", None, "Fig. 5; sec. 6 ('K tends to 1 as R grows')",
            f"K_2 is smallest at R = {R_min * 1e3:.4f} mm (K_2 = {K2_min:.4f}; the same R minimises every "
            f"convention: raw Frobenius {_at(R_min)['fro']:.4f}, normalised {_at(R_min)['fro_normalized']:.4f}), "
            f"found by scan and bounded Brent; closed form (arm vertical) "
            f"r + sqrt(Lb^2 - (|z| - La)^2) = {arms_vertical_radius() * 1e3:.4f} mm. Beyond it K rises again "
            f"until the pose leaves the workspace at R = {R_lim * 1e3:.4f} mm (arms stretched; K_2 -> {K2_lim:.4f}). "
            "K never reaches 1: the paper's 'K tends to 1' holds for none of the three conventions"),
        Row("delta.choice.R_mm", 120.0, R_choice * 1e3, "mm", 10.0, "sec. 6 (110-130 mm guideline, 120 chosen)",
            f"largest workspace volume with K_2 <= {K_MAX:g} among R = 100..200 mm in 5 mm steps "
            f"({SPACING * 1e3:.0f} mm grid, no joint limits, z < 0); the choice moves with the bound: {sens}; "
            f"without the paper's range it is {unbounded * 1e3:.0f} mm. Threshold-free alternative, the largest "
            f"integral of 1/K_2 (volume x GCI): {weighted * 1e3:.0f} mm over the sweep. Reachable volume "
            f"{vol[0.100]:.1f} L at 100 mm, {vol[0.120]:.1f} L at 120 mm, {vol[0.200]:.1f} L at 200 mm: "
            f"largest at R = {study.R[peak] * 1e3:.0f} mm of the sweep (R close to r) and "
            f"{'strictly decreasing' if shrinks else 'not monotone'} from there to {study.R[-1] * 1e3:.0f} mm: "
            "it shrinks as R grows over the paper's range, as the paper says",
            why=f"the choice moves with the unstated bound on K_2 ({sens}); 120 mm is the paper's guideline, "
                "not an optimum of a stated criterion"),
    ] + opcount_rows("delta", "delta.opcount.") + ident_rows("delta", "delta.ident.") + stiffness_over_radius()


#: The base radii of the stiffness rows [m]: the paper's range, its choice and Table 1's.
STIFFNESS_R = (0.100, 0.120, 0.150, 0.200)


def stiffness_over_radius() -> list[Row]:
    """Rows ``delta.stiffness.force_min_R<mm>`` and ``delta.stiffness.f1_R<mm>`` (issue 54): the Delta's smallest
    translational stiffness and first natural frequency at the study pose for each base radius of
    :data:`STIFFNESS_R` (:func:`pkm.papers.stiffness_rows`: the motors' servo stiffness, rigid links)."""
    from pkm.mechanisms.delta import model

    cases = []
    for R in STIFFNESS_R:
        mech = model.build(dataclasses.replace(PAPER, R=R))
        cases.append((f"R{R * 1e3:.0f}", f"R = {R * 1e3:.0f} mm, the pose (0, 0, -375) mm, knee out, Table 1's "
                                         "other dimensions", mech, mech.q_reference))
    return stiffness_rows("delta.stiffness.", cases, mech.actuated_names)


K_BOUNDS = (2.5, 3.0, 4.0, 5.0)  # the bounds on K_2 whose conditioned volumes the R study draws


@lru_cache(maxsize=1)
def _choice_against_bound() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(bounds, chosen R [mm], at an end of the paper's range)`` for bounds 2.2..8 on K_2 (0.1 steps)."""
    bounds = np.linspace(2.2, 8.0, 59)
    chosen = np.array([choose_radius(b) * 1e3 for b in bounds])
    return bounds, chosen, np.isclose(chosen, R_RANGE[0] * 1e3) | np.isclose(chosen, R_RANGE[1] * 1e3)


#: Each figure and the CSV series that hold its numbers.
SERIES = {"delta_fig5_K_vs_R": ("delta_fig5_K_vs_R",),
          "delta_workspace_vs_R": ("delta_workspace_vs_R", "delta_choice_vs_bound")}


def figures(out_dir) -> list[Path]:
    """Fig. 5 (K against R, three conventions, both knee branches) and the workspace study behind sec. 6's
    choice (volume against R for several bounds on K_2; the R chosen against the bound)."""
    out = []
    R, K = fig5_sweep("knee_out")
    R_in, K_in = fig5_sweep("knee_in")
    fig, axes = figure(ncols=3, size=(4.6, 4.0))
    for ax, kind in zip(axes[0], KINDS):
        ax.plot(R * 1e3, K[kind], label="knee out")
        ax.plot(R_in * 1e3, K_in[kind], "--", lw=0.8, label="knee in")
        lower = 3.0 if kind == "fro" else 1.0
        ax.axhline(lower, color="grey", lw=0.6, ls=":", label="least possible K (isotropic J)")
        ax.axvspan(R_RANGE[0] * 1e3, R_RANGE[1] * 1e3, color="0.92", zorder=0, label="paper's range of R")
        ax.axvline(arms_vertical_radius() * 1e3, color="C2", lw=0.8, label="least K (arms vertical)")
        ax.axvline(reach_limit() * 1e3, color="C3", lw=0.8, label="reach limit of the pose")
        ax.axvline(120.0, color="k", lw=0.6, ls="-.", label="paper's choice, 120 mm")
        top = float(np.max(K[kind])) * 1.6
        ax.set_ylim(lower * 0.9, top)
        ax.set_xlabel("base radius R [mm]")
        ax.set_ylabel("K [-]")
        ax.set_title(LABELS[kind], fontsize=9)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=7, frameon=False)
    fig.suptitle(f"Delta, La = {PAPER.La * 1e3:.0f}, Lb = {PAPER.Lb * 1e3:.0f}, r = {PAPER.r * 1e3:.0f} mm: condition "
                 f"number K at (0, 0, {POSE[2] * 1e3:.0f}) mm against R (paper's Fig. 5; its image is not legible "
                 "in our copy)", fontsize=9)
    fig.tight_layout(rect=(0, 0.1, 1, 1))
    out.append(save(fig, out_dir, "delta_fig5_K_vs_R", layout=False))

    study = radius_study()
    fig, axes = figure(ncols=2, size=(5.6, 4.0))
    ax1, ax2 = axes[0]
    ax1.plot(study.R * 1e3, study.volume * 1e3, "k", label="reachable (z < 0)")
    for k_max in K_BOUNDS:
        ax1.plot(study.R * 1e3, study.conditioned_volume(k_max) * 1e3, label=rf"$K_2 \leq {k_max:g}$")
    ax1.axvspan(R_RANGE[0] * 1e3, R_RANGE[1] * 1e3, color="0.92", zorder=0, label="paper's range of R")
    ax1.axvline(choose_radius() * 1e3, color="C1", lw=0.8, ls="--", label=rf"our choice ($K_2 \leq {K_MAX:g}$)")
    ax1.axvline(120.0, color="k", lw=0.6, ls="-.", label="paper's choice, 120 mm")
    ax1.set_xlabel("base radius R [mm]")
    ax1.set_ylabel("workspace volume [L]")
    ax1.legend(fontsize=7)
    bounds, chosen, at_end = _choice_against_bound()
    ax2.plot(bounds, chosen, "-", color="C0", lw=0.8, label="R of the largest volume")
    ax2.plot(bounds[~at_end], chosen[~at_end], ".", color="C0", label="inside the range: an optimum")
    ax2.plot(bounds[at_end], chosen[at_end], "o", mfc="none", color="C3", ms=4,
             label="at an end of the range: a bound, not an optimum")
    ax2.axhline(120.0, color="k", lw=0.6, ls="-.", label="paper's choice, 120 mm")
    ax2.set_xlabel(r"bound $k_{max}$ on $K_2$ [-]")
    ax2.set_ylabel("chosen R [mm]")
    ax2.set_title(r"R with the largest volume where $K_2 \leq k_{max}$", fontsize=9)
    ax2.legend(fontsize=7)
    fig.suptitle(f"Delta, La = {PAPER.La * 1e3:.0f}, Lb = {PAPER.Lb * 1e3:.0f}, r = {PAPER.r * 1e3:.0f} mm: workspace "
                 f"against R ({SPACING * 1e3:.0f} mm grid; the paper's sec. 6 choice, no figure)", fontsize=9)
    out.append(save(fig, out_dir, "delta_workspace_vs_R"))
    return out


def series(out_dir) -> list[Path]:
    path = Path(out_dir)
    path.mkdir(parents=True, exist_ok=True)
    R, K = fig5_sweep("knee_out")
    _, K_in = fig5_sweep("knee_in")
    f1 = path / "delta_fig5_K_vs_R.csv"
    with f1.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["R_mm"] + [f"K_{k}_knee_out" for k in KINDS] + [f"K_{k}_knee_in" for k in KINDS])
        for j in range(len(R)):
            w.writerow([f"{R[j] * 1e3:.1f}"] + [f"{K[k][j]:.10g}" for k in KINDS] + [f"{K_in[k][j]:.10g}" for k in KINDS])
    study = radius_study()  # (the figure's numbers; radius_sweep gives the same through pkm.sweep, tested)
    f2 = path / "delta_workspace_vs_R.csv"
    with f2.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["R_mm", "volume_L"] + [f"volume_K2_le_{b:g}_L" for b in K_BOUNDS] + ["integral_inv_K2_L"])
        columns = [study.volume, *(study.conditioned_volume(b) for b in K_BOUNDS), study.weighted_volume()]
        for j, R_j in enumerate(study.R):
            w.writerow([f"{R_j * 1e3:.1f}"] + [f"{c[j] * 1e3:.6g}" for c in columns])
    f3 = path / "delta_choice_vs_bound.csv"
    with f3.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["k_max", "chosen_R_mm", "at_range_end"])
        w.writerows([f"{b:.1f}", f"{c:.1f}", int(e)] for b, c, e in zip(*_choice_against_bound()))
    return [f1, f2, f3]


__all__ = ["K_BOUNDS", "PAPER", "POSE", "SERIES", "TITLE", "arms_vertical_radius", "choose_radius", "fig5_sweep", "figures",
           "knee_in_singularity", "radius_study", "radius_sweep", "reach_limit", "reproduce", "series"]
