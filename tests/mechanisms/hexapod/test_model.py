"""pkm.mechanisms.hexapod.model: the hexapod's generated URDF holds every name its closure spec uses (mimic
reconfiguration joints included), the spec survives TOML, and a design other than the paper's builds with its own
lengths in the tree."""

from __future__ import annotations

import numpy as np
import pytest

from pkm.mechanisms import delta, hexapod
from pkm.mechanisms.hexapod.geometry import base_points, platform_local_points
from tests.mechanisms.model_contract import (
    check_build_of_a_design,
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
