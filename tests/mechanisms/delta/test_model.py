"""pkm.mechanisms.delta.model: the Delta's generated URDF holds every name its closure spec uses, the spec survives
TOML, a design other than the paper's builds with its own lengths in the tree, and its collision primitives span the
links' joint and closure points."""

from __future__ import annotations

import numpy as np
import pytest

from pkm.mechanisms import delta, rrr3
from tests.mechanisms.model_contract import (
    check_build_of_a_design,
    check_collision_primitives,
    check_other_params_refused,
    check_spec_round_trip,
    check_urdf_holds_the_spec_names,
    frame_offset,
    joint_offset,
)

DESIGN = delta.DeltaParams(La=0.12, Lb=0.31, r=0.04, R=0.12)


@pytest.mark.parametrize("params", [delta.DeltaParams(), DESIGN])
def test_urdf_and_spec_agree_and_the_spec_survives_toml(params):
    """Tree, names and TOML round trip, for the paper's design and another."""
    check_urdf_holds_the_spec_names(delta, params)
    check_spec_round_trip(delta, params)


def test_a_design_builds_with_its_lengths_in_the_tree():
    """Motor axes at R from the base centre, knees at La along the arm, forearm tips at Lb, balls at r from the
    platform centre (1e-15 m); three point closures, one per forearm."""
    mech = check_build_of_a_design(delta, DESIGN)
    for n in (1, 2, 3):
        assert np.linalg.norm(joint_offset(mech, f"motor_{n}")) == pytest.approx(DESIGN.R, abs=1e-15)
        np.testing.assert_allclose(joint_offset(mech, f"knee_{n}"), [0.0, DESIGN.La, 0.0], atol=1e-15)
        np.testing.assert_allclose(frame_offset(mech, f"forearm_{n}_tip"), [0.0, DESIGN.Lb, 0.0], atol=1e-15)
        assert np.linalg.norm(frame_offset(mech, f"platform_ball_{n}")) == pytest.approx(DESIGN.r, abs=1e-15)
    assert [c.type for c in mech.spec.closures] == ["point"] * 3 and mech.spec.task.components == ("x", "y", "z")


def test_another_mechanisms_params_are_refused():
    """The 3-RRR's design (or None) is not a Delta's."""
    check_other_params_refused(delta, rrr3.Rrr3Params())


@pytest.mark.parametrize("params", [delta.DeltaParams(), delta.DeltaParams(La=0.12, Lb=0.31, r=0.04, R=0.12,
                                                                        arm_radius=0.012, rod_radius=0.003,
                                                                        platform_thickness=0.006,
                                                                        base_thickness=0.02)])
def test_collision_primitives_span_the_links_at_a_closed_configuration(params):
    """Arms from the motor axis to the elbow, forearms from the elbow to the ball closed on the platform (the
    cylinders' end centres at the joints' world positions, 1e-12 m), the platform disc's mid-plane through the balls
    at its rim, the base disc's lower face through the motor axes at its rim: read from the URDF's text, placed by
    Pinocchio's forward kinematics at the reference; each size the design's."""
    mech = delta.build(params)
    p = params
    rods = {f"arm_{n}": (f"motor_{n}", f"knee_{n}", p.arm_radius) for n in (1, 2, 3)}
    rods |= {f"forearm_{n}": (f"knee_{n}_b", f"platform_ball_{n}", p.rod_radius) for n in (1, 2, 3)}
    plates = {"platform": (p.r, p.platform_thickness, [(f"platform_ball_{n}", 0.0) for n in (1, 2, 3)]),
              "base": (p.R, p.base_thickness, [(f"motor_{n}", -p.base_thickness / 2) for n in (1, 2, 3)])}
    check_collision_primitives(mech, delta.urdf_xml(params), rods, plates)
