"""The hexapod paper study (pkm.papers.hexapod): row contract, pose-T rows, figures."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from pkm import papers
from pkm.papers import hexapod as study
from tests.papers.figures import draw_checked, uncovered

IDS = ("hexapod.poseT.beta_min_reachable_deg", "hexapod.poseT.beta_opt_wrot_deg", "hexapod.poseT.beta_opt_wtras_deg",
       "hexapod.spiral.max_gap_rot_tras_deg", "hexapod.spiral.gain_after_40_wrot",
       "hexapod.opcount.mul", "hexapod.opcount.add",  # issue 15
       "hexapod.fk.modes_reference",  # issue 17
       "hexapod.ident.n_base", "hexapod.ident.n_base_tied", "hexapod.ident.routes_agree",  # issue 30
       *(f"hexapod.stiffness.{q}_beta_{b}" for q in ("force_min", "f1")  # issue 54
         for b in ("m30", "m15", "0", "p15", "p30")))


@pytest.fixture(scope="module")
def reproduced():
    return study.reproduce()


def test_rows_carry_the_ids_of_the_issue_with_notes(reproduced):
    """reproduce() returns exactly the contract ids, each with a source and a note; numbers are finite."""
    rows = reproduced
    assert tuple(r.id for r in rows) == IDS
    assert all(isinstance(r, papers.Row) and r.source and r.note for r in rows)
    assert all(math.isfinite(r.computed) for r in rows)


def test_the_homotopy_finds_the_multistarts_modes_and_no_fewer(reproduced):
    """hexapod.fk.modes_reference: every real assembly mode at the reference (complete: no path failed); the
    paper's semi-closed FK from 32 seeds finds the same ones (a mode it missed would be named in the note)."""
    pytest.importorskip("bertini")
    row = {r.id: r for r in reproduced}["hexapod.fk.modes_reference"]
    assert row.computed >= 2 and "; complete;" in row.note and "none missed" in row.note


def test_pose_t_rows_match_the_paper(reproduced):
    """Sec. 4: reachable from -60 deg (printed to the degree), both optima 'approximately -11 deg' (1 deg)."""
    rows = {r.id: r for r in reproduced}
    assert all(rows[i].matches for i in IDS[:3])
    assert abs(rows[IDS[0]].computed - (-59.50)) < 0.01
    assert abs(rows[IDS[2]].computed - (-10.98)) < 0.01


def test_spiral_rows_are_reported_honestly(reproduced):
    """The spiral's gap is computed from the pointwise optima and does not match 2 deg (see the note); the gain is
    the mean of w_rot(beta*)/w_rot(0) - 1 from pose 40 on, in percent."""
    rows = {r.id: r for r in reproduced}
    s = study.spiral()["profiles"]
    gap = np.degrees(np.abs(s["w_rot"].pointwise - s["w_tras"].pointwise)).max()
    assert math.isclose(rows[IDS[3]].computed, gap) and rows[IDS[3]].matches is False
    pr = s["w_rot"]
    assert math.isclose(rows[IDS[4]].computed, 100 * np.mean(pr.pointwise_value[40:] / pr.base_value[40:] - 1))
    assert rows[IDS[4]].published is None and "no clear gain" in rows[IDS[4]].note


def test_figures_and_series_are_written(tmp_path):
    """Figs. 7, 9 and 10 as PNG files, each passing the figure check; the numbers behind each as CSV (Fig. 7's
    curves, the spiral's profiles)."""
    paths, problems = draw_checked(study, tmp_path)
    assert len(paths) == 3 and all(p.exists() and p.stat().st_size > 10_000 for p in paths)
    assert problems == {p.stem: [] for p in paths}
    series = study.series(tmp_path)
    assert uncovered(study, paths, series) == []
    f7, spiral = series
    with f7.open() as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == ["beta_deg", "reachable", "w_rot", "w_tras_m3"] and len(rows) > 100
    with spiral.open() as fh:
        rows = list(csv.reader(fh))
    assert len(rows) == 102 and rows[0][:3] == ["k", "w_rot_base", "w_rot_pointwise"]


def test_the_stiffness_rows_are_the_forward_kinematics_jacobians(reproduced):
    """The stiffness rows (issue 54) at beta = -30 and 30 deg against the platform's displacement under small moves
    of each alpha drive (pkm.close_loops at beta held, central differences, 1e-5 rad): J = d(p, theta)/d(alpha),
    C = J J^T / k, the smallest principal stiffness under a force 1 / lambda_max(C_ff) (1e-6 relative)."""
    import pinocchio as pin

    import pkm
    from pkm.papers import DRIVE_STIFFNESS

    rows = {r.id: r for r in reproduced}
    mech = pkm.load("hexapod")
    h = 1e-5
    for b, key in ((-30, "m30"), (30, "p30")):
        q = study.stiffness_configuration(mech, b)
        qa = mech.actuated_q(q)

        def pose(qa_, seed):
            pin.framesForwardKinematics(mech.model, mech.data, pkm.close_loops(mech, qa_, seed, tol=1e-14).q)
            return mech.data.oMf[mech.ee_frame].copy()

        J = np.zeros((6, 6))
        for i in range(6):  # (alpha_1..alpha_6; beta_1, the last actuated joint, held)
            e = np.zeros(len(qa))
            e[i] = h
            a, c = pose(qa + e, q), pose(qa - e, q)
            J[:3, i] = (a.translation - c.translation) / (2 * h)
            J[3:, i] = pin.log3(a.rotation @ c.rotation.T) / (2 * h)
        C = J @ J.T / DRIVE_STIFFNESS
        k_min = 1.0 / np.linalg.eigvalsh(C[:3, :3]).max()
        assert rows[f"hexapod.stiffness.force_min_beta_{key}"].computed == pytest.approx(k_min, rel=1e-6)
