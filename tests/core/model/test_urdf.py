"""The URDF builder and loader: mimic joints survive, malformed or hostile files are refused quickly."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

import pkm
from pkm.core.model.builder import from_strings
from pkm.core.model.urdf import UrdfBuilder, check_urdf, limit_notes, load_model, position_limits
from pkm.errors import SpecError

GOOD = """<robot name="r"><link name="base"/><link name="a"/>
<joint name="j" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"""


def test_builder_keeps_mimic_joints_that_yourdfpy_drops():
    """A mimic joint written by the builder is honoured by Pinocchio: one coordinate drives both joints."""
    b = UrdfBuilder("m")
    b.link("base")
    b.link("a", 1.0, (0.1, 0, 0), np.eye(3) * 1e-3)
    b.link("b", 1.0, (0.1, 0, 0), np.eye(3) * 1e-3)
    b.joint("j1", "revolute", "base", "a")
    b.joint("j2", "revolute", "base", "b", xyz=(0, 1, 0), mimic=("j1", 1.0, 0.0))
    text = b.to_xml()
    assert '<mimic joint="j1"' in text
    model = load_model(text)
    assert model.nq == 1 and model.nv == 1


def test_good_urdf_loads():
    """A minimal well-formed URDF becomes a Pinocchio model."""
    assert load_model(GOOD).nq == 1


@pytest.mark.parametrize("text, message", [
    (GOOD[:120], "not well-formed"),
    (GOOD.replace('<child link="a"/>', '<child link="ghost"/>'), "child link 'ghost' does not exist"),
    (GOOD.replace('<limit lower="-1" upper="1" effort="1" velocity="1"/>', ""), "needs a <limit> element"),
    (GOOD.replace('xyz="0 0 1"', 'xyz="0 0 nan"'), "not finite"),
    (GOOD.replace('xyz="0 0 1"', 'xyz="0 0 0"'), "zero axis"),
    (GOOD.replace('lower="-1"', 'lower="1e9"'), "value 1000000000.0 is absurd for a lower limit"),
    (GOOD.replace('upper="1"', 'upper="-1e6"'), "absurd for a upper limit"),
    (GOOD.replace('velocity="1"', 'velocity="nan"'), "limit velocity: value nan is not finite"),
    (GOOD.replace('effort="1"', 'effort="-inf"'), "limit effort: value -inf is not finite"),
    (GOOD.replace('<axis xyz="0 0 1"/>', '<origin xyz="1e8 0 0"/><axis xyz="0 0 1"/>'), "absurdly large"),
    (GOOD.replace('<link name="a"/>', '<link name="a"><inertial><mass value="1e8"/><inertia ixx="1" ixy="0" ixz="0" '
                                      'iyy="1" iyz="0" izz="1"/></inertial></link>'), "mass: value 100000000.0 is not "
                                                                                       "finite or absurdly large"),
    (GOOD.replace('<link name="a"/>', '<link name="a"><inertial><mass value="1"/><inertia ixx="1e7" ixy="0" ixz="0" '
                                      'iyy="1" iyz="0" izz="1"/></inertial></link>'), "inertia .* absurdly large"),
    (GOOD.replace('lower="-1" upper="1"', 'lower="1" upper="-1"'), "lower limit"),
    (GOOD.replace('type="revolute"', 'type="spherical"'), "unknown type"),
    (GOOD.replace("</robot>", '<joint name="k" type="fixed"><parent link="base"/><child link="a"/></joint></robot>'),
     "two parents"),
    (GOOD.replace("<robot", "<robbot").replace("</robot>", "</robbot>"), "expected <robot>"),
    (GOOD.replace("</joint>", '<mimic joint="nobody"/></joint>'), "mimics unknown joint"),
])
def test_malformed_urdf_is_refused_with_a_reason(text, message):
    """Each defect gives a SpecError saying what is wrong (instead of Pinocchio's bare ValueError)."""
    with pytest.raises(SpecError, match=message):
        load_model(text)


@pytest.mark.parametrize("word", ["1", "-2.5", "+.5", "1.", "3e-7", "1E+3", "nan", "-Inf", "infinity", "1_000",
                                  "\u0661", "0x10", "1e", "--1", "1,5", "one"])
def test_a_number_is_read_as_the_pattern_reads_it(word):
    """``floats``' fast path (float() on ASCII text without "_") takes exactly the words its pattern takes."""
    from pkm.core.model.urdf import _NUMBER, floats

    if _NUMBER.fullmatch(word) and math.isfinite(float(word)):
        assert floats(word, 1, "w", "<t>") == [float(word)]
    elif _NUMBER.fullmatch(word):
        with pytest.raises(SpecError, match="is not finite"):
            floats(word, 1, "w", "<t>")
    else:
        with pytest.raises(SpecError, match="not a list of numbers"):
            floats(word, 1, "w", "<t>")


def test_a_text_checked_once_is_refused_alike_when_changed_and_loads_alike_again():
    """The checked texts are remembered by their whole text: the same text loads again to the same model (checked
    once), and a one-character change is checked anew."""
    first, again = load_model(GOOD), load_model(GOOD)
    assert first == again
    with pytest.raises(SpecError, match="zero axis"):
        load_model(GOOD.replace('xyz="0 0 1"', 'xyz="0 0 0"'))


def test_entity_expansion_bomb_is_refused_quickly():
    """A billion-laughs document is refused in bounded time, before any expansion."""
    bomb = ('<?xml version="1.0"?><!DOCTYPE lolz [<!ENTITY lol "lol">'
            + "".join(f'<!ENTITY lol{i} "{"&lol" + (str(i - 1) if i > 1 else "") + ";" * 1}' * 10 + '">'
                      for i in range(1, 10))
            + ']><robot name="&lol9;"><link name="base"/></robot>')
    t0 = time.perf_counter()
    with pytest.raises(SpecError):
        check_urdf(bomb)
    assert time.perf_counter() - t0 < 1.0


def test_external_entity_is_not_read(tmp_path):
    """An external entity pointing at a local file is refused and the file is not read into the model."""
    secret = tmp_path / "secret.txt"
    secret.write_text("TOP-SECRET")
    doc = (f'<?xml version="1.0"?><!DOCTYPE r [<!ENTITY x SYSTEM "file://{secret}">]>'
           '<robot name="&x;"><link name="base"/></robot>')
    with pytest.raises(SpecError, match=r"DOCTYPE|entity") as info:
        check_urdf(doc)
    assert "TOP-SECRET" not in str(info.value)


# ---------------------------------------------------------------------- optional position limits
def _fivebar_urdf(limit_attrs: str) -> str:
    """The toy five-bar's URDF with each ``<limit>`` rewritten as ``<limit effort="..." velocity="..." ...>`` (its
    effort and velocity kept)."""
    import re

    from tests import fivebar

    return re.sub(r'<limit effort="([^"]*)" velocity="([^"]*)" lower="[^"]*" upper="[^"]*"/>',
                  lambda m: f'<limit effort="{m[1]}" velocity="{m[2]}"{limit_attrs}/>', fivebar.urdf_xml(fivebar.Params()))


def test_joints_without_position_limits_load_and_have_none():
    """``<limit effort velocity/>`` (as onshape-to-robot writes it) loads; the mechanism states no limits and no
    solver result reports a violation."""
    from tests import fivebar

    text = _fivebar_urdf("")
    assert "lower=" not in text
    mech = from_strings(text, fivebar.closure_spec(fivebar.Params()))
    assert mech.limits == {}
    assert pkm.solve_ik(mech, pkm.TaskMap.of(mech).value(mech.q_reference) + [0.01, 0.0]).outside_limits == ()


def test_one_sided_limits_are_refused_naming_the_joint():
    with pytest.raises(SpecError, match=r"joint 'motor_1' \(revolute\) states only its lower limit"):
        check_urdf(_fivebar_urdf(' lower="-1.0"'))


def test_stated_limits_are_carried_and_violations_reported_by_the_solvers():
    """With |motor| <= 0.1 rad stated, the five-bar's reference solution (motors near 2 and 1 rad) is reported
    outside the limits, joint by joint, by solve_ik and close_loops; pkm does not enforce them."""
    from tests import fivebar

    mech = from_strings(_fivebar_urdf(' lower="-0.1" upper="0.1"'), fivebar.closure_spec(fivebar.Params()))
    assert set(mech.limits.values()) == {(-0.1, 0.1)} and set(mech.limits) == {"motor_1", "motor_2", "elbow_1",
                                                                                 "elbow_2"}
    ik = pkm.solve_ik(mech, pkm.TaskMap.of(mech).value(mech.q_reference))
    expected = tuple(n for n in mech.limits if abs(float(np.ravel(mech.q_to_dict(ik.q)[n])[0])) > 0.1)
    assert expected and ik.outside_limits == expected
    assert pkm.close_loops(mech, mech.actuated_q(ik.q)).outside_limits == expected
    inside = mech.q_reference.copy()
    inside[[mech.joints[n].idx_q for n in mech.limits]] = 0.05
    assert mech.outside_limits(inside) == ()


# ---------------------------------------------------------------------- exporters' "unlimited" limits
@pytest.mark.parametrize("attrs, limits", [
    ('lower="-1e8" upper="0.5" effort="1" velocity="1"', {"j": (-np.inf, 0.5)}),
    ('lower="-0.25" upper="1e6" effort="1" velocity="1"', {"j": (-0.25, np.inf)}),
    ('lower="-1e16" upper="1e16" effort="1" velocity="1"', {}),
    ('lower="-1" upper="1" effort="1e8" velocity="1e8"', {"j": (-1.0, 1.0)}),
    ('lower="-999999.0" upper="999999.0" effort="999999.0" velocity="999999.0"', {"j": (-999999.0, 999999.0)}),
])
def test_limits_of_a_million_or_more_are_read_as_none(attrs, limits):
    """A limit of magnitude >= 1e6 (UNLIMITED) is no limit: that side of the position range is infinite, and a joint
    with neither side bounded has no entry; just below 1e6 the limit is kept as stated."""
    text = GOOD.replace('lower="-1" upper="1" effort="1" velocity="1"', attrs)
    assert load_model(text).nq == 1
    assert position_limits(text) == limits


def test_the_limits_read_as_none_are_noted_once_per_value():
    text = GOOD.replace('effort="1" velocity="1"', 'effort="1e+30" velocity="1e8"').replace("</robot>", (
        '<link name="b"/><joint name="k" type="revolute"><parent link="a"/><child link="b"/>'
        '<limit lower="-1e8" upper="1e8" effort="2" velocity="1e8"/></joint></robot>'))
    assert limit_notes(check_urdf(text)) == (  # in the file's order
        "joint 'j': effort limit 1e+30 read as none (|x| >= 1e+06)",
        "joints 'j', 'k': velocity limit 1e8 read as none (|x| >= 1e+06)",
        "joint 'k': lower limit -1e8 read as none (|x| >= 1e+06)",
        "joint 'k': upper limit 1e8 read as none (|x| >= 1e+06)")
    assert limit_notes(check_urdf(GOOD)) == ()



def test_builder_writes_collision_primitives_with_their_placement():
    """Each primitive comes back as the <collision> element it names, sizes in m, its origin's rpy the rotation's."""
    import pinocchio as pin
    from lxml import etree
    b = UrdfBuilder("r")
    b.link("a", 1.0, inertia=np.eye(3) * 1e-3)
    R = pin.rpy.rpyToMatrix(0.1, -0.2, 0.3)
    b.collision("a", "capsule", (0.0, 0.0, 0.1), R, radius=0.01, length=0.2)
    b.collision("a", "box", x=0.1, y=0.2, z=0.3)
    els = etree.fromstring(b.to_xml().encode()).findall("link/collision")
    assert [e.find("geometry")[0].tag for e in els] == ["capsule", "box"]
    assert float(els[0].find("geometry/capsule").get("length")) == 0.2
    assert els[1].find("geometry/box").get("size") == "0.1 0.2 0.3"
    rpy = [float(v) for v in els[0].find("origin").get("rpy").split()]
    np.testing.assert_allclose(pin.rpy.rpyToMatrix(*rpy), R, atol=1e-15)
    with pytest.raises(pkm.errors.InvalidInputError, match="takes"):
        b.collision("a", "sphere", radius=0.1, length=1.0)
    with pytest.raises(pkm.errors.InvalidInputError, match="positive"):
        b.collision("a", "sphere", radius=-0.1)
