"""pkm.core.model.springs: the ``[springs.<joint>]`` tables of a closure spec, checked, written back and carried from
a model file's springs (the spec's win; a joint the spec fixes keeps none)."""

from __future__ import annotations

import dataclasses

import pytest

from pkm.core import ClosureSpec
from pkm.core.formats.base import Imported
from pkm.core.formats.imported import with_file
from pkm.core.model.springs import parse_springs
from pkm.errors import SpecError

SPEC = """format = "pkm.closures/1"
mechanism = "m"
urdf = "m.urdf"
actuated = ["a"]
[[closure]]
name = "c"
type = "point"
frame_a = "x"
frame_b = "y"
[springs.knee-spring]
stiffness = 1500
rest = -0.25
damping = 0.1
[springs.rod]
damping = 2.0
"""


def test_the_springs_table_is_read_and_written_back_exactly():
    spec = ClosureSpec.from_toml(SPEC)
    assert spec.springs == {"knee-spring": {"stiffness": 1500.0, "rest": -0.25, "damping": 0.1},
                            "rod": {"damping": 2.0}}
    assert ClosureSpec.from_toml(spec.to_toml()).springs == spec.springs


@pytest.mark.parametrize(("table", "message"), [
    ({"j": {"stiffnes": 1.0}}, "unknown keys"), ({"j": {"stiffness": -1.0}}, "is >= 0"),
    ({"j": {"damping": float("nan")}}, "finite number"), ({"j": {"rest": True}}, "must be a number"),
    ({"j": 3.0}, "must be a table"), ({"j": {"stiffness": 1e12}}, "below 1e\\+12")])
def test_a_bad_spring_is_refused_naming_it(table, message):
    with pytest.raises(SpecError, match=message):
        parse_springs(table, "t")


def test_the_file_s_springs_come_under_the_spec_s_and_a_fixed_joint_keeps_none():
    spec = dataclasses.replace(ClosureSpec.from_toml(SPEC), joint_types={"heel": "fixed"})
    imp = Imported("<robot/>", (), {}, ("a",), "m", "mjcf",
                   springs={"knee-spring": {"stiffness": 9.0, "damping": 5.0}, "heel": {"stiffness": 3.0},
                            "shin": {"stiffness": 4.0, "rest": 0.1}})
    merged = with_file(spec, imp, "t").springs
    assert merged == {"knee-spring": {"stiffness": 1500.0, "rest": -0.25, "damping": 0.1}, "rod": {"damping": 2.0},
                      "shin": {"stiffness": 4.0, "rest": 0.1}}


def test_a_spring_on_a_joint_the_model_lacks_is_refused_naming_the_valid_ones(built):
    from pkm.core.model.builder import from_strings
    from pkm.errors import SpecNameError

    delta_mech = built("delta")
    spec = dataclasses.replace(delta_mech.spec, springs={"motor_9": {"stiffness": 1.0}})
    with pytest.raises(SpecNameError, match=r"motor_9.*\[springs\.motor_9\]"):
        from_strings(delta_mech.urdf, spec)
    kept = from_strings(delta_mech.urdf, dataclasses.replace(delta_mech.spec, springs={"motor_1": {"stiffness": 1.0}}))
    assert kept.spec.springs == {"motor_1": {"stiffness": 1.0}}


def test_a_scaled_copy_scales_a_prismatic_spring_s_rest_length_only(built):
    """``scaled_mechanism(mech, 2)``: a prismatic joint's spring rest length doubles, a revolute's rest angle and every
    stiffness and damping stay (exact)."""
    from pkm.core.model.builder import from_strings, scaled_mechanism

    mech = built("prs3")
    prismatic, revolute = "slider_1", "knee_1"
    assert (mech.joints[prismatic].kind, mech.joints[revolute].kind) == ("JointModelPX", "JointModelRY")
    springs = {prismatic: {"stiffness": 300.0, "rest": 0.05, "damping": 2.0}, revolute: {"stiffness": 4.0, "rest": 0.3}}
    sprung = from_strings(mech.urdf, dataclasses.replace(mech.spec, springs=springs))
    assert scaled_mechanism(sprung, 2.0).spec.springs == {
        prismatic: {"stiffness": 300.0, "rest": 0.1, "damping": 2.0}, revolute: {"stiffness": 4.0, "rest": 0.3}}
