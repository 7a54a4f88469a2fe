"""pkm.mechanisms.prs3.model: the 3-PRS's generated URDF holds every name its closure spec uses, the spec survives
TOML, the actuation chooses the actuated joints, and a design other than Table 2's builds with its own lengths."""

from __future__ import annotations

import numpy as np
import pytest

from pkm.mechanisms import delta, prs3
from tests.mechanisms.model_contract import (
    check_build_of_a_design,
    check_other_params_refused,
    check_spec_round_trip,
    check_urdf_holds_the_spec_names,
    frame_offset,
)

DESIGN = prs3.Prs3Params(l=1.1, h=0.45, g=0.95)


@pytest.mark.parametrize("params", [prs3.Prs3Params(), DESIGN, prs3.Prs3Params(actuation="R", gamma=1.2)])
def test_urdf_and_spec_agree_and_the_spec_survives_toml(params):
    """Tree, names and TOML round trip, for Table 2's design, another, and knee actuation on inclined rails."""
    check_urdf_holds_the_spec_names(prs3, params)
    check_spec_round_trip(prs3, params)


def test_the_actuation_chooses_the_actuated_joints():
    """'P' drives slider_1..3, 'R' knee_1..3; the spec's description says which."""
    for actuation, joint in (("P", "slider"), ("R", "knee")):
        spec = prs3.closure_spec(prs3.Prs3Params(actuation=actuation, gamma=1.2))
        assert spec.actuated == tuple(f"{joint}_{n}" for n in (1, 2, 3))
        assert f"actuated in the {actuation} joints" in spec.description


def test_a_design_builds_with_its_lengths_in_the_tree():
    """Coupler tips at l along the coupler, spherical joints at h from the platform centre (1e-15 m); the platform
    link carries the design's mass and inertia."""
    mech = check_build_of_a_design(prs3, DESIGN)
    for n in (1, 2, 3):
        np.testing.assert_allclose(frame_offset(mech, f"coupler_{n}_tip"), [0.0, 0.0, DESIGN.l], atol=1e-15)
        assert np.linalg.norm(frame_offset(mech, f"platform_ball_{n}")) == pytest.approx(DESIGN.h, abs=1e-15)
    inertia = mech.model.inertias[mech.model.getJointId("platform")]
    assert inertia.mass == DESIGN.m_platform
    np.testing.assert_allclose(inertia.inertia, DESIGN.platform_inertia, atol=1e-15)


def test_another_mechanisms_params_are_refused():
    """The Delta's design (or None) is not a 3-PRS's."""
    check_other_params_refused(prs3, delta.DeltaParams())
