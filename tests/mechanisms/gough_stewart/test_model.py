"""pkm.mechanisms.gough_stewart.model: the Gough-Stewart's generated URDF holds every name its closure spec uses
(universal joints written as revolutes, typed by the spec), the spec survives TOML, and a design other than the
default builds with its own points and stroke."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from pkm.core.model.urdf import parse_xml
from pkm.mechanisms import delta, gough_stewart
from tests.mechanisms.model_contract import (
    check_build_of_a_design,
    check_other_params_refused,
    check_spec_round_trip,
    check_urdf_holds_the_spec_names,
    frame_offset,
    joint_offset,
)

DESIGN = gough_stewart.GoughStewartParams(platform=tuple(map(tuple, 1.15 * np.asarray(gough_stewart.PLATFORM))),
                                          leg_min=0.55, leg_max=1.1)


@pytest.mark.parametrize("params", [gough_stewart.GoughStewartParams(), DESIGN])
def test_urdf_and_spec_agree_and_the_spec_survives_toml(params):
    """Tree, names and TOML round trip, for the default design and another."""
    check_urdf_holds_the_spec_names(gough_stewart, params)
    check_spec_round_trip(gough_stewart, params)


def test_a_design_builds_with_its_points_and_stroke():
    """Universal joints at the base points, sockets at the platform points (1e-15 m), universal joints typed by
    the spec (two coordinates each), the URDF's leg limits the stroke; regular at the reference (no warning)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mech = check_build_of_a_design(gough_stewart, DESIGN)
    model = mech.model
    limits = {j.get("name"): j.find("limit").attrib for j in parse_xml(gough_stewart.urdf_xml(DESIGN)).iter("joint")
              if j.get("type") == "prismatic"}
    for n in range(1, 7):
        np.testing.assert_allclose(joint_offset(mech, f"u{n}"), DESIGN.base[n - 1], atol=1e-15)
        np.testing.assert_allclose(frame_offset(mech, f"socket_{n}"), DESIGN.platform[n - 1], atol=1e-15)
        assert model.joints[model.getJointId(f"u{n}")].nq == 2
        assert (float(limits[f"leg{n}"]["lower"]), float(limits[f"leg{n}"]["upper"])) == (0.55, 1.1)
    assert mech.spec.joint_types == {f"u{n}": "universal" for n in range(1, 7)}


def test_another_mechanisms_params_are_refused():
    """The Delta's design (or None) is not a Gough-Stewart's."""
    check_other_params_refused(gough_stewart, delta.DeltaParams())
