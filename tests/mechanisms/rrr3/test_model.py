"""pkm.mechanisms.rrr3.model: the 3-RRR's generated URDF holds every name its closure spec uses, the spec survives
TOML (its eight working modes included), and a design other than the paper's builds with its own lengths."""

from __future__ import annotations

import numpy as np
import pytest

from pkm.mechanisms import delta, rrr3
from pkm.mechanisms.rrr3.params import base_vertices
from tests.mechanisms.model_contract import (
    check_build_of_a_design,
    check_collision_primitives,
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


@pytest.mark.parametrize("params", [rrr3.Rrr3Params(), rrr3.Rrr3Params(a=0.45, b=0.35, h=0.12, H=0.9, branch=3,
                                                                        link_radius=0.02, platform_thickness=0.01)])
def test_collision_primitives_span_the_links_at_a_closed_configuration(params):
    """Proximal links from the base vertex to the elbow, distal links from the elbow to the platform vertex (A on
    leg 1's wrist, B and C closed on the platform) (the cylinders' end centres at the joints' world positions,
    1e-12 m); the platform disc through A, B, C in its mid-plane: read from the URDF's text, placed by Pinocchio's
    forward kinematics at the reference; each size the design's."""
    mech, p = rrr3.build(params), params
    rods = {f"proximal_{n}": (f"motor_{n}", f"elbow_{n}", p.link_radius) for n in (1, 2, 3)}
    rods |= {f"distal_{n}": (f"elbow_{n}", end, p.link_radius)
             for n, end in ((1, "wrist_1"), (2, "platform_B"), (3, "platform_C"))}
    rim = [(f, 0.0) for f in ("platform_A", "platform_B", "platform_C")]
    check_collision_primitives(mech, rrr3.urdf_xml(params), rods,
                               {"platform": (p.h / np.sqrt(3.0), p.platform_thickness, rim)})
