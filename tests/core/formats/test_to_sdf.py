"""pkm.core.formats.to_sdf and the SDF reader's parts it uses (``<pkm:position>``, ``<pkm:free_joint>``, SDFormat
1.11's ``<mimic>``): the file is closed at its own poses for any SDFormat reader, pkm reads its own coordinates
back, and what SDFormat (as pkm reads it) cannot hold is refused by name. The round trip of every matrix mechanism is
tests/core/formats/test_roundtrip.py's."""

from __future__ import annotations

import re

import numpy as np
import pinocchio as pin
import pytest
from lxml import etree

import pkm
from pkm.core.formats.sdf import read_sdf
from pkm.core.formats.to_sdf import sdf_from_mechanism
from pkm.core.kinematics import constraints
from pkm.errors import SpecError
from tests.core.formats.test_roundtrip import original
from tests.core.formats.test_sdf import fourbar


def _without_pkm(text: str) -> str:
    """The SDF as another reader sees it: pkm's custom elements gone."""
    return re.sub(r"\s*<pkm:position>[^<]*</pkm:position>", "", text)


def test_the_file_is_closed_at_its_poses_and_pkm_reads_its_coordinates_back(tmp_path):
    """The Delta (reference away from zero, prismatic and revolute joints) and the acceptance set's ankle (two ball
    joints): read without pkm's elements, the file's zero configuration closes every loop (1e-12: the cut joints
    are closed where SDFormat puts them) and its limits count from the reference; read by pkm, the joints' placements
    and limits are the original's (1e-15) and q_reference is the original's (1e-12)."""
    for case in ("delta", "acceptance:ankle"):
        mech = original(case)
        text, dropped = sdf_from_mechanism(mech)
        assert dropped[0].startswith("the closures' frames: read back as <closure>_parent")
        assert list(dropped[1:]) == (["collision geometry of base (on the world)"] if case == "delta" else []), dropped
        assert text.count("<pkm:position>") == mech.model.njoints - 1
        other = read_sdf(_without_pkm(text), "other.sdf")
        plain = pkm.from_strings(other.urdf, pkm.ClosureSpec(
            mechanism="other", urdf="other.sdf", end_effector=None, actuated=mech.actuated_names,
            closures=other.closures, task=pkm.core.model.spec.TaskSpec((), mech.actuated_names), reference={},
            joint_types=other.joint_types), source="other.sdf")
        assert np.abs(constraints.residual(plain, pin.neutral(plain.model))).max() <= 1e-12, case
        ref = mech.q_to_dict(mech.q_reference)
        for joint, (lo, hi) in mech.limits.items():
            assert np.allclose(plain.limits[joint], (lo - ref[joint], hi - ref[joint]), rtol=0, atol=1e-15), joint
        with pytest.warns(pkm.errors.PkmWarning, match="the closures' frames: read back as <closure>_parent"):
            back = pkm.load(pkm.save(mech, tmp_path / case.replace(":", "_") / "robot.sdf"))
        for j in range(1, mech.model.njoints):
            k = back.model.getJointId(mech.model.names[j])
            assert np.abs(mech.model.jointPlacements[j].homogeneous -
                          back.model.jointPlacements[k].homogeneous).max() <= 1e-15, case
        assert back.limits.keys() == mech.limits.keys()
        assert max(np.abs(np.subtract(back.limits[n], v)).max() for n, v in mech.limits.items()) <= 1e-15
        assert np.abs(back.q_reference - mech.q_reference).max() <= 1e-12, case


def test_an_sdformat_mimic_is_read_with_its_offset_and_reference():
    """SDFormat 1.11: follower = offset + multiplier (leader - reference), positions from the model's pose: a URDF
    mimic of multiplier m and offset ``offset - m reference``; with ``<pkm:position>`` on both, their values at the
    pose enter the offset (``p_f - m p_l``). A mimic without a multiplier, or of a cut joint, is refused."""
    mimic = ("<mimic joint='crank_joint' axis='axis'><multiplier>-0.5</multiplier><offset>0.2</offset>"
             "<reference>0.1</reference></mimic>")
    text = fourbar().replace("<axis><xyz>0 1 0</xyz></axis></joint>\n      <joint name=\"cut\"",
                             f"<axis><xyz>0 1 0</xyz>{mimic}</axis></joint>\n      <joint name=\"cut\"")
    assert mimic in text

    def coupling(sdf: str) -> tuple[str, float, float]:  # (the loop is then rigid: the URDF is what is checked)
        el = etree.fromstring(read_sdf(sdf, "fb.sdf").urdf.encode()).find("joint[@name='rocker_joint']/mimic")
        return el.get("joint"), float(el.get("multiplier")), float(el.get("offset"))

    assert coupling(text) == ("crank_joint", -0.5, 0.2 + 0.5 * 0.1)
    posed = text.replace('<sdf version="1.7">', '<sdf version="1.11" xmlns:pkm="urn:pkm:sdf">').replace(
        "<parent>world</parent><child>rocker</child>", "<parent>world</parent><child>rocker</child><pkm:position>0.3"
        "</pkm:position>").replace("<child>crank</child>", "<child>crank</child><pkm:position>-0.2</pkm:position>")
    assert coupling(posed) == ("crank_joint", -0.5, 0.2 + 0.5 * 0.1 + 0.3 - 0.5 * 0.2)
    for bad, match in ((text.replace("<multiplier>-0.5</multiplier>", ""), "needs a <multiplier>"),
                       (text.replace("<mimic joint='crank_joint'", "<mimic joint='cut'"), "two joints of the tree"),
                       (posed.replace("<pose>0 0 0.15 0 0 0</pose>",
                                      "<pose>0 0 0.15 0 0 0</pose><pkm:position>1</pkm:position>"),
                        "on a joint that cuts a loop"),
                       (posed.replace('<link name="rocker">', '<link name="rocker"><pkm:free_joint/>'),
                        "needs the free-flyer joint's name")):
        with pytest.raises(SpecError, match=match):
            read_sdf(bad, "fb.sdf")


def test_what_sdformat_cannot_hold_is_refused_by_name(tmp_path):
    """A floating base (pkm's SDF reader fixes the base), a planar joint; a universal joint is written as two hinges,
    and said."""
    from tests.core.model.test_mechanism import _floating_ankle
    from tests.core.twin.test_tree import zoo

    with pytest.raises(SpecError, match=r"ankle\.sdf: .* no floating base \('pelvis'\)"):
        pkm.save(_floating_ankle()[0], tmp_path / "ankle.sdf")
    with pytest.raises(SpecError, match="SDFormat has no JointModelPlanar"):
        sdf_from_mechanism(zoo())
    with pytest.warns(pkm.errors.PkmWarning, match=r"universal joints .*<name>__1, <name>__2"):
        main = pkm.save(original("gough_stewart"), tmp_path / "gs", to="sdf")
    assert main.name == "gough_stewart.closures.toml" and (tmp_path / "gs" / "gough_stewart.sdf").is_file()


def test_every_written_file_names_each_link_joint_and_frame_once():
    """SDFormat (1.7 on) gives a model's links, joints and frames one namespace: every matrix mechanism's file names
    each once (the Gough-Stewart's closure 'ball_1' and its frame 'ball_1' were both written: libsdformat 12 refused
    the file; checked with it by hand on every case since, and here by the rule)."""
    from tests.core.formats.test_roundtrip import CASES

    for case in CASES:
        model = etree.fromstring(sdf_from_mechanism(original(case))[0].encode()).find("model")
        names = [el.get("name") for el in model if el.tag in ("link", "joint", "frame")]
        assert len(names) == len(set(names)), (case, sorted({n for n in names if names.count(n) > 1}))


def _sprung_delta() -> pkm.Mechanism:
    """The Delta with a spring on a passive knee (rest away from the reference, damped), one on a motor, and a
    damper alone."""
    import dataclasses

    d = original("delta")
    springs = {"knee_1": {"stiffness": 3.5, "rest": -2.0, "damping": 0.2}, "motor_2": {"stiffness": 7.0, "rest": 0.3},
               "knee_2_b": {"damping": 0.05}}
    return pkm.from_strings(d.urdf, dataclasses.replace(d.spec, springs=springs), d.params, "sprung delta")


def test_the_springs_are_written_as_sdformat_s_and_read_back():
    """The joint springs as ``<axis><dynamics>``: another reader sees the reference from the written pose (``rest -
    q_ref``, as the limits) and the joint's whole damping; pkm's SDF reader alone (no spec beside) gives back the
    springs' stiffness and rest (1e-12) and the damping (Pinocchio's, 1e-15)."""
    mech = _sprung_delta()
    text, _ = sdf_from_mechanism(mech)
    root = etree.fromstring(text.encode())
    ref = mech.q_to_dict(mech.q_reference)
    dyn = {j.get("name"): j.find("axis/dynamics") for j in root.iter("joint") if j.find("axis/dynamics") is not None}
    assert float(dyn["knee_1"].findtext("spring_reference")) == pytest.approx(-2.0 - ref["knee_1"], abs=1e-12)
    assert float(dyn["knee_1"].findtext("damping")) == 0.2 and dyn["knee_2_b"].find("spring_stiffness") is None
    assert float(dyn["motor_2"].findtext("spring_stiffness")) == 7.0
    alone = read_sdf(text, "delta.sdf")
    assert alone.springs.keys() == set(mech.springs.names)
    for name, k, rest in zip(mech.springs.names, mech.springs.stiffness, mech.springs.rest):
        assert alone.springs[name]["stiffness"] == k and abs(alone.springs[name]["rest"] - rest) <= 1e-12
    plain = pin.buildModelFromXML(alone.urdf)
    for name in ("knee_1", "knee_2_b", "motor_2"):
        i, j = plain.joints[plain.getJointId(name)].idx_v, mech.joints[name].idx_v
        assert abs(plain.damping[i] - mech.model.damping[j]) <= 1e-15, name
