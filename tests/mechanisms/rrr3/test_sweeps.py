"""pkm.mechanisms.rrr3.sweeps: the 3-RRR's closed-form sweep objectives, called directly on designs of the
registered family: the five share one map, an empty workspace gives nulls (not failures), an area scales as the
square of the design's size and the condition indices not at all. (The route against the serial paper loop is
``tests/sweeps/test_objectives.py``.)"""

from __future__ import annotations

import pytest

from pkm import sweeps
from pkm.mechanisms.rrr3.sweeps import CLOSED_FORMS, OPTIONS
from pkm.sweeps.family import RegisteredFamily

NAMES = ("gci", "gci_area", "coverage", "min_area_ci", "workspace_volume")


def values(candidate, step: str = "4cm", side: str = "30cm") -> dict:
    out = {}
    for name in NAMES:
        o = sweeps.objective(f"{name}:step={step},side={side}")
        out[name] = CLOSED_FORMS[name].function(candidate, o.options)
    return out


def test_declared_forms_units_and_options():
    """Five closed forms; workspace_volume is an area (m^2); they read the grid step (by default the library's,
    relative to the design's size: a fixed 1 cm made a 5 % design's GCI 0.370 from 10 nodes against 0.421) and the
    side of the area of interest (30 cm)."""
    from pkm.mechanisms.rrr3 import workspace as ws

    assert set(CLOSED_FORMS) == set(NAMES)
    assert {k: f.unit for k, f in CLOSED_FORMS.items()} == {**dict.fromkeys(NAMES, ""), "workspace_volume": "m^2"}
    assert (OPTIONS["step"][:2], OPTIONS["side"][:2]) == (("length", None), ("length", 0.30))
    c = RegisteredFamily("rrr3").candidate({})
    d = ws.Design.of(c.params)
    expected = ws.ci_map(d, ws.workspace_grid(d), ws.CiSettings(branch=c.params.branch)).gci().value
    assert CLOSED_FORMS["gci"].function(c, sweeps.objective("gci").options) == expected


def test_the_paper_design_shares_one_map_and_its_values_are_consistent():
    """One cached map; indices in (0, 1]; the smallest CI of the area is at most its mean; coverage is a
    fraction; the area is a whole number of cells."""
    c = RegisteredFamily("rrr3").candidate({})
    v = values(c)
    assert [k[0] for k in c._cache if isinstance(k, tuple)] == ["rrr3_map"]
    assert 0.0 < v["min_area_ci"] <= v["gci_area"] <= 1.0 and 0.0 < v["gci"] <= 1.0
    assert 0.0 <= v["coverage"] <= 1.0
    cells = v["workspace_volume"] / 0.04**2
    assert cells > 0 and cells == pytest.approx(round(cells), abs=1e-9)


def test_an_empty_workspace_gives_nulls_and_zeros():
    """Links too short to reach the platform anywhere: no GCI and no smallest CI (None: a null in the results),
    coverage and area 0."""
    c = RegisteredFamily("rrr3").candidate({"a": 0.1, "b": 0.1})
    assert values(c) == {"gci": None, "gci_area": None, "coverage": 0.0, "min_area_ci": None, "workspace_volume": 0.0}


def test_a_design_twice_as_large_has_four_times_the_area_and_the_same_indices():
    """Lengths, step and side doubled: the same nodes; the area is 4 times, the dimensionless indices equal (1e-12)."""
    paper = values(RegisteredFamily("rrr3").candidate({}))
    double = values(RegisteredFamily("rrr3").candidate({"a": 0.8, "b": 0.8, "h": 0.2, "H": 2.0}), "8cm", "60cm")
    assert double["workspace_volume"] == pytest.approx(4 * paper["workspace_volume"], rel=1e-12)
    for name in ("gci", "gci_area", "coverage", "min_area_ci"):
        assert double[name] == pytest.approx(paper[name], rel=1e-12), name


def test_a_sweep_of_the_former_mode_is_a_sweep_of_branch():
    """sweeps.grid(mode=...) and fixed={"mode": ...} warn naming branch and sweep branch: the same values, under
    the new name."""
    import numpy as np

    import pkm

    new = pkm.sweep("rrr3", sweeps.grid(branch=[1, 2]), ["gci:step=8cm"], fixed={"a": 0.45}, scheduler="serial",
                    progress=False)
    with pytest.warns(DeprecationWarning, match="'mode' is now 'branch'"):
        old = pkm.sweep("rrr3", sweeps.grid(mode=[1, 2]), ["gci:step=8cm"], fixed={"a": 0.45}, scheduler="serial",
                        progress=False)
    np.testing.assert_array_equal(old.column("gci:step=8cm"), new.column("gci:step=8cm"))
    np.testing.assert_array_equal(old.column("branch"), [1, 2])
    with pytest.warns(DeprecationWarning, match="'mode' is now 'branch'"):
        fixed = pkm.sweep("rrr3", sweeps.grid(a=[0.45]), ["gci:step=8cm"], fixed={"mode": 2}, scheduler="serial",
                          progress=False)
    assert fixed.column("gci:step=8cm")[0] == new.column("gci:step=8cm")[1]
