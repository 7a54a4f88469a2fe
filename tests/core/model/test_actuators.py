"""pkm.core.model.actuators: the drive of each actuated joint, checked on construction, read from Pinocchio's fields
and a spec's ``[actuators.<joint>]`` tables, written back into the model, changed by ``pkm.with_actuators`` and
carried through ``pkm.save`` and pickling."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.model.actuators import NUMBERS, UNLIMITED, Actuator, from_model, parse_table, write_model
from pkm.core.model.spec import ClosureSpec
from pkm.errors import InvalidInputError, SpecError
from tests import fivebar

#: Two revolute joints: ``a`` with effort and velocity limits and friction, ``b`` with an exporter's "none" values.
TWO_JOINTS = """<robot name="two">
  <link name="base"/><link name="l1"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0"
  iyz="0"/></inertial></link><link name="l2"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0"
  ixz="0" iyz="0"/></inertial></link>
  <joint name="a" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="12.5" velocity="3"/><dynamics damping="0.2" friction="0.1"/></joint>
  <joint name="b" type="revolute"><parent link="l1"/><child link="l2"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="0" velocity="1e30"/></joint>
</robot>"""


@pytest.fixture(scope="module")
def five() -> pkm.Mechanism:
    return fivebar.build()


def test_an_actuator_reflects_its_rotor_and_saturates_at_its_peak():
    a = Actuator("m", rotor_inertia=2e-5, gear_ratio=50, armature=1e-3, effort_limit=4, peak_effort=12)
    assert a.reflected_inertia == pytest.approx(2e-5 * 50**2 + 1e-3, rel=1e-15)
    assert a.max_effort == 12.0 and Actuator("m", effort_limit=4).max_effort == 4.0
    assert all(type(getattr(a, f)) is float for f in NUMBERS)  # ints and numpy scalars become floats
    assert type(Actuator("m", viscous=np.float32(0.5)).viscous) is float
    free = Actuator("m")
    assert (free.reflected_inertia, free.viscous, free.coulomb) == (0.0, 0.0, 0.0)
    assert math.isinf(free.effort_limit) and math.isinf(free.max_effort) and math.isinf(free.velocity_limit)


@pytest.mark.parametrize("field, value, message", [
    ("viscous", -0.1, "must be a finite number >= 0"),
    ("armature", math.nan, "must be a finite number >= 0"),
    ("rotor_inertia", math.inf, "must be a finite number >= 0"),
    ("coulomb", True, "expected a number"),
    ("gear_ratio", "50", "expected a number"),
    ("gear_ratio", 0.0, "gear_ratio must be > 0"),
    ("effort_limit", 0.0, "effort_limit must be > 0"),
    ("velocity_limit", -1.0, "or inf: none"),
])
def test_a_bad_value_names_the_joint_the_field_and_the_value(field, value, message):
    with pytest.raises(InvalidInputError, match=message) as err:
        Actuator("motor_7", **{field: value})
    got = err.value.value
    assert err.value.name == field and "'motor_7'" in str(err.value)
    assert got == value or (got != got and value != value)  # (NaN: the value itself)


def test_a_peak_below_the_continuous_limit_is_refused():
    with pytest.raises(InvalidInputError, match="peak effort 3 is below the continuous limit 4") as err:
        Actuator("m", effort_limit=4, peak_effort=3)
    assert err.value.name == "peak_effort" and err.value.value == 3.0


def test_a_spec_table_is_read_as_floats():
    assert parse_table({"motor_1": {"gear_ratio": 50, "viscous": 0.02}}, "s.toml") == \
        {"motor_1": {"gear_ratio": 50.0, "viscous": 0.02}}
    assert parse_table({}, "s.toml") == {}


@pytest.mark.parametrize("raw, message", [
    ([1, 2], r"\[actuators\] must be a table"),
    ({"motor_1": 3.0}, r"actuators.motor_1 must be a table"),
    ({"motor_1": {"gear": 50}}, r"actuators.motor_1: unknown keys \['gear'\]"),
    ({"motor_1": {"viscous": "0.1"}}, r"actuators.motor_1.viscous must be a number, got str"),
    ({"motor_1": {"coulomb": True}}, r"actuators.motor_1.coulomb must be a number, got bool"),
    ({"motor_1": {"armature": -1e-3}}, r"actuators.motor_1: armature: actuator 'motor_1'.*-0.001"),
    ({"motor_1": {"effort_limit": math.nan}}, r"actuators.motor_1: effort_limit: .*nan"),
])
def test_a_bad_spec_table_is_a_spec_error_naming_the_joint(raw, message):
    with pytest.raises(SpecError, match=message) as err:
        parse_table(raw, "s.toml")
    assert err.value.source == "s.toml"


def test_the_model_fields_are_read_and_written_back():
    """URDF limits and dynamics through Pinocchio's fields; an effort of 0 and a velocity of 1e30 read as none; the
    overrides win per field; write_model puts the reflected inertia in ``armature``."""
    model = pin.buildModelFromXML(TWO_JOINTS)
    a = from_model(model, "a", model.joints[model.getJointId("a")].idx_v)
    assert (a.viscous, a.coulomb, a.effort_limit, a.velocity_limit) == (0.2, 0.1, 12.5, 3.0)
    assert (a.rotor_inertia, a.gear_ratio, a.armature) == (0.0, 1.0, 0.0)
    iv = model.joints[model.getJointId("b")].idx_v
    b = from_model(model, "b", iv)
    assert math.isinf(b.effort_limit) and math.isinf(b.velocity_limit) and UNLIMITED <= 1e30
    geared = from_model(model, "b", iv, {"rotor_inertia": 1e-5, "gear_ratio": 30.0, "peak_effort": 8.0,
                                         "effort_limit": 5.0})
    assert (geared.gear_ratio, geared.effort_limit, geared.peak_effort, geared.viscous) == (30.0, 5.0, 8.0, 0.0)
    write_model(model, geared, iv)
    assert model.armature[iv] == pytest.approx(9e-3, rel=1e-15) and model.rotorGearRatio[iv] == 30.0
    assert model.effortLimit[iv] == 5.0 and math.isinf(model.velocityLimit[iv])
    assert model.armature[1 - iv] == 0.0  # the other joint untouched


def test_with_actuators_changes_the_drives_in_the_model_and_leaves_the_original(five):
    base = five.actuators
    new = pkm.with_actuators(five, {"motor_1": {"rotor_inertia": 2e-5, "gear_ratio": 50.0, "viscous": 0.3},
                                    "motor_2": Actuator("ignored", coulomb=0.2, effort_limit=4.0, peak_effort=9.0)})
    m1, m2 = new.actuators
    assert (m1.joint, m1.gear_ratio, m1.viscous, m1.effort_limit) == ("motor_1", 50.0, 0.3, base[0].effort_limit)
    assert m2 == Actuator("motor_2", coulomb=0.2, effort_limit=4.0, peak_effort=9.0)  # replaced whole, renamed
    assert new.model.armature[new.act_v[0]] == pytest.approx(2e-5 * 2500, rel=1e-15)
    assert new.model.damping[new.act_v[0]] == 0.3 and new.model.friction[new.act_v[1]] == 0.2
    assert five.actuators == base and five.model.armature[five.act_v[0]] == 0.0
    again = pkm.with_actuators(new, {"motor_1": {"viscous": 0.5}})  # a table changes only its fields
    assert again.actuators[0].viscous == 0.5 and again.actuators[0].gear_ratio == 50.0


@pytest.mark.parametrize("actuators, message", [
    ({"elbow_1": {"viscous": 0.1}}, "'elbow_1' is not an actuated joint"),
    ({"motor_1": {"gear": 50.0}}, r"unknown fields \['gear'\]"),
    ({"motor_1": {"viscous": -0.1}}, "viscous must be a finite number >= 0"),
    ({"motor_1": 0.3}, "expected an Actuator or a table"),
    ([("motor_1", {})], r"expected \{joint"),
])
def test_with_actuators_refuses_bad_input(five, actuators, message):
    with pytest.raises(InvalidInputError, match=message):
        pkm.with_actuators(five, actuators)


def test_the_drives_survive_the_spec_text_save_and_pickle(five, tmp_path):
    new = pkm.with_actuators(five, {"motor_2": {"rotor_inertia": 3.3e-5, "gear_ratio": 50.0, "viscous": 0.02,
                                                "coulomb": 0.1, "effort_limit": 20.0, "peak_effort": 60.0,
                                                "velocity_limit": 6.0}})
    text = new.spec.to_toml()
    assert "[actuators.motor_2]\nrotor_inertia = 3.3e-05\ngear_ratio = 50.0\nviscous = 0.02" in text
    assert ClosureSpec.from_toml(text) == new.spec
    assert pkm.load(pkm.save(new, tmp_path / "five.closures.toml")).actuators == new.actuators
    assert pickle.loads(pickle.dumps(new)).actuators == new.actuators


def test_a_spec_table_on_a_joint_that_is_not_actuated_is_refused(five):
    text = five.spec.to_toml() + "\n[actuators.elbow_1]\nviscous = 0.1\n"
    with pytest.raises(SpecError, match=r"\[actuators.elbow_1\]: 'elbow_1' is not an actuated joint"):
        ClosureSpec.from_toml(text, "five.closures.toml")


def test_a_peak_alone_is_checked_against_the_drives_continuous_limit(five):
    assert five.actuators[0].effort_limit == 3.9  # (a PM54-040-S250-R's continuous torque)
    assert pkm.with_actuators(five, {"motor_1": {"peak_effort": 8.0}}).actuators[0].peak_effort == 8.0
    with pytest.raises(SpecError, match=r"peak effort 2 is below the continuous limit 3\.9"):
        pkm.with_actuators(five, {"motor_1": {"peak_effort": 2.0}})


def test_the_reflected_inertia_is_not_counted_twice_without_urdf_text(five):
    from pkm.core.model.builder import build

    bare = build(pin.Model(five.model), five.spec, five.params, None, "bare", ())
    geared = pkm.with_actuators(bare, {"motor_1": {"rotor_inertia": 1e-3, "gear_ratio": 10.0}})
    again = pkm.with_actuators(geared, {"motor_1": {"viscous": 0.1}})
    assert again.actuators[0].reflected_inertia == pytest.approx(0.1, rel=1e-15)


def test_a_servo_stiffness_reads_with_its_unit_and_the_joints_kind(five, tmp_path):
    """``stiffness`` in a spec: a number (SI) or a string with its unit, kept as written and converted at build with
    the joint's kind (2 kN m/rad = 2000 N m/rad; 5 N/mm = 5000 N/m on the Gough-Stewart's prismatic legs); a
    prismatic's unit on a revolute drive is refused, never converted; pkm.save writes the string back."""
    assert parse_table({"motor_1": {"stiffness": "2 kN m/rad"}}, "s.toml") == {"motor_1": {"stiffness": "2 kN m/rad"}}
    assert math.isinf(five.actuators[0].stiffness)  # (none stated: a rigid drive)
    text = five.spec.to_toml() + '\n[actuators.motor_1]\nstiffness = "2 kN m/rad"\n\n[actuators.motor_2]\nstiffness = 1500\n'
    spec = ClosureSpec.from_toml(text, "five.closures.toml")
    sprung = pkm.with_actuators(five, {"motor_1": {"stiffness": "2 kN m/rad"}, "motor_2": {"stiffness": 1500}})
    assert [a.stiffness for a in sprung.actuators] == [2000.0, 1500.0]
    assert spec.actuators["motor_1"] == {"stiffness": "2 kN m/rad"}
    assert ClosureSpec.from_toml(spec.to_toml()) == spec  # (the unit kept as written)
    from pkm.core.model.builder import from_strings

    built = from_strings(five.urdf, spec, five.params, "five")
    assert [a.stiffness for a in built.actuators] == [2000.0, 1500.0]
    again = pkm.load(pkm.save(built, tmp_path / "five.closures.toml"))
    assert 'stiffness = "2 kN m/rad"' in (tmp_path / "five.closures.toml").read_text()
    assert again.actuators == built.actuators
    wrong = ClosureSpec.from_toml(text.replace("2 kN m/rad", "5 N/mm"), "five.closures.toml")
    with pytest.raises(SpecError, match=r"'N/mm' is a translational stiffness unit but stiffness is in \[N m/rad\]"):
        from_strings(five.urdf, wrong, five.params, "five")
    gs = pkm.load("gough_stewart")
    legs = pkm.with_actuators(gs, {gs.actuated_names[0]: {"stiffness": "5 N/mm"}})
    assert legs.actuators[0].stiffness == 5000.0
    with pytest.raises(InvalidInputError, match="'N m/rad' is a rotational stiffness unit"):
        pkm.with_actuators(gs, {gs.actuated_names[0]: {"stiffness": "5 N m/rad"}})


@pytest.mark.parametrize("raw, message", [
    ({"motor_1": {"stiffness": "2 furlongs"}}, r"actuators.motor_1: .*unknown unit 'furlongs'"),
    ({"motor_1": {"stiffness": "3 N m"}}, r"'N m' is a torque unit"),
    ({"motor_1": {"viscous": "0.1 N m s/rad"}}, r"actuators.motor_1.viscous must be a number, got str"),
    ({"motor_1": {"stiffness": 0.0}}, r"stiffness must be > 0 \(a drive that yields freely"),
    ({"motor_1": {"stiffness": "1e12 N m/rad"}}, r"a servo stiffness below 1e\+12"),
])
def test_a_bad_servo_stiffness_is_a_spec_error(raw, message):
    with pytest.raises(SpecError, match=message):
        parse_table(raw, "s.toml")
