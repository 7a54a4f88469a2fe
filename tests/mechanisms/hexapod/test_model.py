"""pkm.mechanisms.hexapod.model: the hexapod's generated URDF holds every name its closure spec uses (mimic
reconfiguration joints included), the spec survives TOML, a design other than the paper's builds with its own
lengths in the tree, and its collision primitives span the links' joint and closure points."""

from __future__ import annotations

import numpy as np
import pytest

from pkm.mechanisms import delta, hexapod
from pkm.mechanisms.hexapod.geometry import base_points, platform_local_points
from tests.mechanisms.model_contract import (
    check_build_of_a_design,
    check_collision_primitives,
    check_other_params_refused,
    check_spec_round_trip,
    check_urdf_holds_the_spec_names,
    frame_offset,
    joint_offset,
    urdf_names,
)

DESIGN = hexapod.HexapodParams(LA=0.22, LB=0.42, Rr=0.14, R2=0.46, layout="literal")


@pytest.mark.parametrize("params", [hexapod.HexapodParams(), DESIGN])
def test_urdf_and_spec_agree_and_the_spec_survives_toml(params):
    """Tree, names and TOML round trip, for the paper's design and another (literal layout)."""
    check_urdf_holds_the_spec_names(hexapod, params)
    check_spec_round_trip(hexapod, params)


def test_beta_2_and_beta_3_mimic_beta_1_in_the_urdf():
    """The gear train is written as URDF mimic joints of beta_1, multiplier 1, offset 0."""
    from pkm.core.model.urdf import parse_xml

    root = parse_xml(hexapod.urdf_xml(hexapod.HexapodParams()))
    mimics = {j.get("name"): dict(j.find("mimic").attrib) for j in root.iter("joint") if j.find("mimic") is not None}
    assert mimics == {f"beta_{n}": {"joint": "beta_1", "multiplier": "1.0", "offset": "0.0"} for n in (2, 3)}
    assert {"recon_1", "recon_2", "recon_3"} <= urdf_names(hexapod.urdf_xml(DESIGN))[0]


def test_a_design_builds_with_its_lengths_in_the_tree():
    """Legs 1-3: alpha at Rr along the reconfiguration link; legs 4-6: alpha at A_i (beta = 0); knees at LA, leg
    tips at LB; platform points where the layout puts them (1e-15 m)."""
    mech = check_build_of_a_design(hexapod, DESIGN)
    A = base_points(DESIGN, 0.0)
    C = platform_local_points(DESIGN)
    for n in range(1, 7):
        expected = [DESIGN.Rr, 0.0, 0.0] if n <= 3 else A[n - 1]
        np.testing.assert_allclose(joint_offset(mech, f"alpha_{n}"), expected, atol=1e-15)
        np.testing.assert_allclose(joint_offset(mech, f"knee_{n}"), [DESIGN.LA, 0.0, 0.0], atol=1e-15)
        np.testing.assert_allclose(frame_offset(mech, f"leg_{n}_tip"), [DESIGN.LB, 0.0, 0.0], atol=1e-15)
        np.testing.assert_allclose(frame_offset(mech, f"platform_c_{n}"), C[n - 1], atol=1e-15)
    assert mech.spec.task.joints == ("beta_1",) and len(mech.spec.closures) == 6


def test_another_mechanisms_params_are_refused():
    """The Delta's design (or None) is not a hexapod's."""
    check_other_params_refused(hexapod, delta.DeltaParams())


@pytest.mark.parametrize("params", [hexapod.HexapodParams(), hexapod.HexapodParams(LA=0.22, LB=0.42, Rr=0.14,
                                                                                  link_radius=0.006)])
def test_collision_primitives_span_the_links_at_a_closed_configuration(params):
    """Reconfiguration links from F_i to A_i, arms from A_i to B_i, rods from B_i to the spherical joint closed on the
    platform (the cylinders' end centres at the joints' world positions, 1e-12 m); the platform prism's cylinder
    of radius r and height h with C_1..C_3 on its upper rim and C_4..C_6 on its lower one: read from the URDF's
    text, placed by Pinocchio's forward kinematics at the reference; each size the design's."""
    mech, p = hexapod.build(params), params
    rods = {f"recon_{n}": (f"beta_{n}", f"alpha_{n}", p.link_radius) for n in (1, 2, 3)}
    rods |= {f"arm_{n}": (f"alpha_{n}", f"knee_{n}", p.link_radius) for n in range(1, 7)}
    rods |= {f"rod_{n}": (f"knee_{n}_b", f"platform_c_{n}", p.link_radius) for n in range(1, 7)}
    rim = [(f"platform_c_{n}", p.h / 2 if n <= 3 else -p.h / 2) for n in range(1, 7)]
    check_collision_primitives(mech, hexapod.urdf_xml(params), rods, {"platform_body": (p.r, p.h, rim)})
