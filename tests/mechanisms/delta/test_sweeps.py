"""pkm.mechanisms.delta.sweeps: the Delta's closed-form sweep objectives, called directly on one design of the
registered family: the three workspace volumes share one grid and bound each other, a volume scales as the cube of
the design's size and the condition number not at all, and a pose option naming no task coordinate is refused.
(The closed-form condition against the generic route is ``tests/sweeps/test_objectives.py``.)"""

from __future__ import annotations

import pytest

from pkm import sweeps
from pkm.errors import UnknownNameError
from pkm.mechanisms.delta.sweeps import CLOSED_FORMS, OPTIONS
from pkm.sweeps.family import RegisteredFamily

DOUBLE = {"La": 0.22, "Lb": 0.66, "r": 0.10, "R": 0.30}  # the paper's design, twice as large


def value(spec: str, candidate):
    o = sweeps.objective(spec)
    return CLOSED_FORMS[o.definition.name].function(candidate, o.options)


def test_declared_forms_and_units():
    """Four closed forms; the volumes are in m^3 and read the grid spacing (by default (La + Lb) / 55: 8 mm at the
    paper's design, twice that at a design twice as large, where a fixed 8 mm made a small design's volume 6 %
    off); condition is unitless."""
    from pkm.mechanisms.delta.sweeps import _spacing

    assert set(CLOSED_FORMS) == {"workspace_volume", "conditioned_volume", "weighted_volume", "condition"}
    assert {k: f.unit for k, f in CLOSED_FORMS.items()} == {"workspace_volume": "m^3", "conditioned_volume": "m^3",
                                                           "weighted_volume": "m^3", "condition": ""}
    assert OPTIONS["spacing"][:2] == ("length", None)
    default = sweeps.objective("workspace_volume").options
    paper, double = RegisteredFamily("delta").candidate({}), RegisteredFamily("delta").candidate(DOUBLE)
    assert _spacing(paper, default) == pytest.approx(0.008, rel=1e-12)
    assert _spacing(double, default) == pytest.approx(0.016, rel=1e-12)
    family = RegisteredFamily("delta")
    assert sweeps.objective("workspace_volume").describe(family)["unit"] == "m^3"


def test_the_volumes_share_one_grid_and_bound_each_other():
    """On a 2 cm grid: one cached grid serves the three volumes; 0 < weighted <= workspace (1/K <= 1), conditioned
    <= workspace, weighted >= conditioned / k_max, and an unbounded k_max conditions the whole workspace. The volume
    alone makes a grid without condition numbers (no SVD a node), of the same volume."""
    c = RegisteredFamily("delta").candidate({})
    cond = value("conditioned_volume:spacing=2cm,k_max=3", c)
    v = value("workspace_volume:spacing=2cm", c)
    weighted = value("weighted_volume:spacing=2cm", c)
    assert [k for k in c._cache if isinstance(k, tuple) and k[0] == "delta_grid"] == [("delta_grid", 0.02, "2", "")]
    alone = RegisteredFamily("delta").candidate({})
    assert value("workspace_volume:spacing=2cm", alone) == v
    (grid,) = (g for k, g in alone._cache.items() if isinstance(k, tuple) and k[0] == "delta_grid")
    assert grid.K == {}
    assert 0.0 < cond <= v and 0.0 < weighted <= v and weighted >= cond / 3.0
    assert value("conditioned_volume:spacing=2cm,k_max=1e12", c) == v
    assert 0.03 < v < 0.06  # (the paper design's reachable volume is about 0.045 m^3)


def test_a_design_twice_as_large_has_eight_times_the_volume_and_the_same_condition():
    """Lengths and grid spacing doubled: the same nodes, so the volume is 8 times (1e-12 relative); the inverse
    Jacobian of a translational robot scales as 1/length, so kappa at the doubled pose is unchanged (1e-12)."""
    paper, double = RegisteredFamily("delta").candidate({}), RegisteredFamily("delta").candidate(DOUBLE)
    assert value("workspace_volume:spacing=4cm", double) == pytest.approx(
        8 * value("workspace_volume:spacing=2cm", paper), rel=1e-12)
    k1 = value("condition:pose=x=2cm/y=-1cm/z=-36cm", paper)
    k2 = value("condition:pose=x=4cm/y=-2cm/z=-72cm", double)
    assert k1 >= 1.0 and k2 == pytest.approx(k1, rel=1e-12)


def test_the_pose_overrides_the_reference_coordinates_it_names_and_refuses_others():
    """condition at the reference differs from condition at x = 2 cm; a pose naming 'w' lists x, y, z."""
    c = RegisteredFamily("delta").candidate({})
    assert value("condition", c) != value("condition:pose=x=2cm", c)
    o = sweeps.objective("condition:pose=w=1")
    with pytest.raises(UnknownNameError, match=r"task coordinate 'w' does not exist in delta; valid .*'x', 'y', 'z'"):
        CLOSED_FORMS["condition"].function(c, o.options)
