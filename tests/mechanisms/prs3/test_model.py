"""pkm.mechanisms.prs3.model: the 3-PRS's generated URDF holds every name its closure spec uses, the spec survives
TOML, the actuation chooses the actuated joints, and a design other than Table 2's builds with its own lengths."""

from __future__ import annotations

import numpy as np
import pytest

from pkm.mechanisms import delta, prs3
from tests.mechanisms.model_contract import (
    check_build_of_a_design,
    check_collision_primitives,
    check_other_params_refused,
    check_spec_round_trip,
    check_urdf_holds_the_spec_names,
    frame_offset,
    joint_offset,
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


@pytest.mark.parametrize("params", [prs3.Prs3Params(), prs3.Prs3Params(l=1.1, h=0.45, g=0.95, gamma=1.2,
                                                                        link_radius=0.03, slider_size=0.08,
                                                                        platform_thickness=0.04,
                                                                        base_thickness=0.07)])
def test_collision_primitives_span_the_links_at_a_closed_configuration(params):
    """Couplers from the knee to the spherical joint closed on the platform (the cylinders' end centres at the
    joints' world positions, 1e-12 m), slider cubes centred on the knees, the platform disc's mid-plane through the
    spherical joints at its rim, the base disc's upper face through the rails' feet a_i (the slider joints'
    placements on the base) at its rim: read from the URDF's text, placed by Pinocchio's forward kinematics at the reference; each size the
    design's."""
    mech, p = prs3.build(params), params
    rods = {f"coupler_{n}": (f"knee_{n}", f"platform_ball_{n}", p.link_radius) for n in (1, 2, 3)}
    feet = [joint_offset(mech, f"slider_{n}") for n in (1, 2, 3)]  # (a_i: the rails' origins, on the base)
    plates = {"platform_link": (p.h, p.platform_thickness, [(f"platform_ball_{n}", 0.0) for n in (1, 2, 3)]),
              "base": (p.g, p.base_thickness, [(a, p.base_thickness / 2) for a in feet])}
    boxes = {f"slider_link_{n}": (f"knee_{n}", p.slider_size) for n in (1, 2, 3)}
    check_collision_primitives(mech, prs3.urdf_xml(params), rods, plates, boxes)
