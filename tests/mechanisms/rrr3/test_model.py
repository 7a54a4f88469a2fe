"""pkm.mechanisms.rrr3.model: the 3-RRR's generated URDF holds every name its closure spec uses, the spec survives
TOML (its eight working modes included), and a design other than the paper's builds with its own lengths."""

from __future__ import annotations

import numpy as np
import pytest

from pkm.mechanisms import delta, rrr3
from pkm.mechanisms.rrr3.params import base_vertices
from tests.mechanisms.model_contract import (
    check_build_of_a_design,
    check_other_params_refused,
    check_spec_round_trip,
    check_urdf_holds_the_spec_names,
    frame_offset,
    joint_offset,
)

DESIGN = rrr3.Rrr3Params(a=0.45, b=0.35, h=0.12, H=0.9, branch=3)


@pytest.mark.parametrize("params", [rrr3.Rrr3Params(), DESIGN])
def test_urdf_and_spec_agree_and_the_spec_survives_toml(params):
    """Tree, names and TOML round trip, for the paper's design and another (working mode 3)."""
    check_urdf_holds_the_spec_names(rrr3, params)
    check_spec_round_trip(rrr3, params)


def test_a_design_builds_with_its_lengths_in_the_tree():
    """Motors on the base vertices, elbows at a, leg tips at b, platform vertices B and C at h from A (1e-15 m);
    two point closures (leg 1 carries the platform); the default branch is the design's branch."""
    mech = check_build_of_a_design(rrr3, DESIGN)
    for n, vertex in enumerate(base_vertices(DESIGN), 1):
        np.testing.assert_allclose(joint_offset(mech, f"motor_{n}"), [*vertex, 0.0], atol=1e-15)
        np.testing.assert_allclose(joint_offset(mech, f"elbow_{n}"), [DESIGN.a, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(joint_offset(mech, "wrist_1"), [DESIGN.b, 0.0, 0.0], atol=1e-15)
    for n in (2, 3):
        np.testing.assert_allclose(frame_offset(mech, f"leg{n}_tip"), [DESIGN.b, 0.0, 0.0], atol=1e-15)
    for v in "BC":
        assert np.linalg.norm(frame_offset(mech, f"platform_{v}")) == pytest.approx(DESIGN.h, abs=1e-15)
    assert [c.name for c in mech.spec.closures] == ["wrist_2", "wrist_3"]
    assert mech.spec.default_branch == "mode3" and len(mech.spec.branches) == 8


def test_another_mechanisms_params_are_refused():
    """The Delta's design (or None) is not a 3-RRR's."""
    check_other_params_refused(rrr3, delta.DeltaParams())
