"""pkm.mechanisms.delta.params: the Delta's design dataclass holds the paper's Table 1 lengths, documents a unit for
every field, and refuses non-positive, non-finite or absurd lengths and masses naming the field; its fixed geometry
(motor azimuths, branch signs) is pinned."""

from __future__ import annotations

import math

import pytest

from pkm.mechanisms.delta import params as dp
from tests.mechanisms.params_contract import (
    NOT_POSITIVE,
    check_documented_defaults,
    check_refused,
    check_units_metadata,
)


def test_defaults_are_table_1_of_the_paper():
    """Hernandez Reyna & Sandoval-Castro 2018, Table 1: La 110 mm, Lb 330 mm, r 50 mm; R 150 mm (Fig. 4); no
    stated pose (found for the design)."""
    p = dp.DeltaParams()
    assert (p.La, p.Lb, p.r, p.R, p.home) == (0.110, 0.330, 0.050, 0.150, None)
    assert dp.Params is dp.DeltaParams and dp.NAME == "delta"


def test_the_docstring_states_the_defaults_and_the_units_of_every_field():
    """The values in the Attributes section are the defaults, and each field's [unit] is its metadata's."""
    check_documented_defaults(dp.DeltaParams, {"La", "Lb", "r", "R", "arm_radius", "rod_radius", "platform_thickness",
                                               "base_thickness"})
    check_units_metadata(dp.DeltaParams)


@pytest.mark.parametrize("field", ["La", "Lb", "r", "R", "m_arm", "m_forearm", "m_platform", "arm_radius",
                                   "rod_radius", "platform_thickness", "base_thickness"])
def test_lengths_and_masses_must_be_positive_finite_and_not_absurd(field):
    """0, negatives, NaN, +-inf and 2e6 (a value in mm given as m) are each refused naming the field."""
    for bad in NOT_POSITIVE:
        err = check_refused(dp.DeltaParams, field, bad)
        assert repr(bad) in str(err) or str(bad) in str(err)


def test_home_is_stored_as_a_tuple_of_floats():
    """A home given as a list of ints is kept as floats in a tuple (the dataclass stays hashable)."""
    p = dp.DeltaParams(home=[0, 0, -1])
    assert p.home == (0.0, 0.0, -1.0) and all(type(v) is float for v in p.home) and hash(p) == hash(p)


def test_motor_azimuths_and_branch_signs():
    """Motors at 0, 120, 240 deg about z; knee_out is negative knee angles, knee_in positive."""
    assert [math.degrees(a) for a in dp.PHI] == pytest.approx([0.0, 120.0, 240.0], abs=1e-12)
    assert dp.BRANCHES == {"knee_out": -1, "knee_in": 1}
