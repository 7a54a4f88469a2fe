"""Helpers shared by the mechanism packages (pkm.mechanisms._common)."""

from __future__ import annotations

import pytest

from pkm.errors import InvalidInputError
from pkm.mechanisms import delta, hexapod, prs3, rrr3
from pkm.mechanisms._common import leg_branches, params_from_table, spec_parameters


@pytest.mark.parametrize("params", [delta.DeltaParams(R=0.12, home=(0.01, 0.0, -0.38)), rrr3.Rrr3Params(branch=3),
                                    hexapod.HexapodParams(layout="literal"), prs3.Prs3Params(actuation="R", gamma=1.2)])
def test_a_spec_parameter_table_gives_back_its_design(params):
    """spec_parameters then params_from_table is the identity (tuples, strings and integer fields included)."""
    assert params_from_table(type(params), spec_parameters(params)) == params


def test_missing_entries_keep_their_defaults():
    assert params_from_table(delta.DeltaParams, {"R": 0.12}) == delta.DeltaParams(R=0.12)


def test_leg_branches_takes_one_name_for_all_or_one_per_leg():
    valid = {"up": 1, "down": -1}
    assert leg_branches("up", valid, 3) == ("up", "up", "up")
    assert leg_branches(["up", "down"], valid, 2) == ("up", "down")
    assert leg_branches(None, valid, 2, "down") == ("down", "down")
    for bad in (None, "sideways", ("up",), 3, ("up", 1)):
        with pytest.raises(InvalidInputError, match="branch"):
            leg_branches(bad, valid, 2)
