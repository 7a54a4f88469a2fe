"""The 3-PRS study: the contract rows, the CSV series and the figures."""

import csv

import numpy as np
import pytest

from pkm.papers import prs3 as study
from tests.papers.figures import draw_checked, uncovered

CONTRACT = ["prs3.opcount.mul", "prs3.opcount.add", "prs3.opcount.generic_mul", "prs3.opcount.generic_add",
            "prs3.case2.power_spread_W", "prs3.case3.p1_peak_ratio",
            "prs3.case3.p2p3_opposite"] + [f"prs3.case{c}.F{i}_{k}_N" for c in (2, 3) for k in ("t0", "t1", "t2p5")
                                           for i in (1, 2, 3)]


@pytest.fixture(scope="module")
def rows():
    return {r.id: r for r in study.reproduce()}


def test_every_contract_row_is_there_and_every_comparable_one_matches(rows):
    assert set(CONTRACT) <= set(rows)
    for r in rows.values():
        assert r.matches in (True, None), r
        assert r.source and r.note


def test_the_forward_kinematics_has_eight_real_modes_at_the_reference(rows):
    """prs3.fk.modes_reference: 8 real of the family's 16, and the note states the 8 working modes too."""
    pytest.importorskip("bertini")
    row = rows["prs3.fk.modes_reference"]
    assert row.computed == 8 and "; complete;" in row.note and "8 working modes" in row.note


def test_the_generic_count_is_within_1_5_times_the_hand_written_one(rows):
    """Issue 15: the generic inverse dynamics of the Pinocchio model, counted at its boundary, within 1.5x the
    hand-written twin's count (both its numeric and its inertial-symbolic modes)."""
    numeric = study.counts()["numeric"]
    for kind, hand in (("mul", rows["prs3.opcount.mul"].computed), ("add", rows["prs3.opcount.add"].computed)):
        generic = rows[f"prs3.opcount.generic_{kind}"].computed
        assert generic <= 1.5 * min(hand, getattr(numeric, kind)), (kind, generic, hand)


def test_case2_force_rows_equal_the_translating_closed_form(rows):
    """Each case-2 force row equals (m_p/3 + m1 + m2)(g + z'') printed in its own note, to 1e-9 N."""
    for i in (1, 2, 3):
        for k in ("t0", "t1", "t2p5"):
            r = rows[f"prs3.case2.F{i}_{k}_N"]
            closed = float(r.note.rsplit("= ", 1)[1].split()[0])
            assert abs(r.computed - closed) < 1e-9


def test_series_are_written_every_10_ms_with_forces_and_powers(tmp_path):
    paths = {p.name: p for p in study.series(tmp_path)}
    with paths["prs3_case3.csv"].open() as fh:
        data = list(csv.reader(fh))
    assert data[0] == ["t_s", "d1_m", "d2_m", "d3_m", "F1_N", "F2_N", "F3_N", "P1_W", "P2_W", "P3_W"]
    assert len(data) == 502 and data[-1][0] == "5.00"
    values = np.array(data[1:], dtype=float)
    _t, _, r = study.simulate("3")
    assert np.allclose(values[:, 4:7], r.tau, rtol=1e-9) and np.allclose(values[:, 7:], r.power, atol=1e-9)


def test_figures_are_written(tmp_path):
    """Figs. 3, 4 and the forces pass the figure check, and the series hold the numbers behind each."""
    paths, problems = draw_checked(study, tmp_path)
    assert problems == {p.stem: [] for p in paths}
    assert uncovered(study, paths, study.series(tmp_path)) == []
    assert {p.name for p in paths} == {"prs3_fig3_power_case2.png", "prs3_fig4_power_case3.png", "prs3_forces.png"}
    assert all(p.stat().st_size > 10_000 for p in paths)
