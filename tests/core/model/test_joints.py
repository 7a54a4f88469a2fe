"""pkm.core.model.joints: the joints a URDF writes as revolutes that ``[joint_types]`` retypes, above all the universal
joints about any two distinct axes of the joint frame (``universal_ab``, the toolbox's ``UJOINT_AB``), checked against
the product of the two rotations and carried through a spec's TOML and ``pkm.save``."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest

from pkm.core import ClosureSpec
from pkm.core.model import joints
from pkm.core.model.joints import JOINT_TYPES, UNIVERSAL_AXES, has_mimic, reduced_model, retype_joints
from pkm.core.model.urdf import load_model
from pkm.errors import SpecError

#: A revolute placeholder ``u`` at a turned, offset placement, between two bodies, and a joint after it.
URDF = """<robot name="u"><link name="base"/>
<link name="a"><inertial><mass value="0.3"/><inertia ixx="1e-3" ixy="0" ixz="0" iyy="2e-3" iyz="0" izz="3e-3"/>
</inertial></link><link name="b"/>
<joint name="u" type="revolute"><origin xyz="0.1 -0.2 0.3" rpy="0.4 -0.5 0.6"/><parent link="base"/>
<child link="a"/><axis xyz="0 0 1"/><limit effort="1" velocity="20"/></joint>
<joint name="after" type="revolute"><origin xyz="0.2 0 0"/><parent link="a"/><child link="b"/><axis xyz="0 1 0"/>
<limit effort="1" velocity="20"/></joint></robot>"""
AXES = {"x": np.array([1.0, 0.0, 0.0]), "y": np.array([0.0, 1.0, 0.0]), "z": np.array([0.0, 0.0, 1.0])}


def test_the_universal_types_are_the_six_ordered_pairs_of_distinct_axes_and_universal_is_xy():
    assert sorted(k for k in UNIVERSAL_AXES if k != "universal") == sorted(
        f"universal_{a}{b}" for a in "xyz" for b in "xyz" if a != b)
    assert UNIVERSAL_AXES["universal"] == ("x", "y")
    assert set(JOINT_TYPES) == {"spherical", "fixed", *UNIVERSAL_AXES}


@pytest.mark.parametrize("kind", sorted(UNIVERSAL_AXES))
def test_a_retyped_universal_joint_turns_about_its_first_axis_then_its_second(kind):
    """The child's placement is ``placement * exp(q1 [a]) exp(q2 [b])`` (1e-14) at random coordinates, and its
    Jacobian columns are axis ``a`` turned back by the second rotation, then axis ``b`` (joint frame, 1e-14)."""
    model = retype_joints(load_model(URDF), {"u": kind})
    assert model.joints[1].shortname() == "JointModelUniversal" and (model.nq, model.nv) == (3, 3)
    assert model.names[2] == "after" and model.inertias[1].mass == pytest.approx(0.3, abs=0.0)
    a, b = (AXES[c] for c in UNIVERSAL_AXES[kind])
    data = model.createData()
    for q in np.random.default_rng(7).uniform(-2.0, 2.0, (4, 3)):
        pin.forwardKinematics(model, data, q)
        expected = model.jointPlacements[1] * pin.SE3(pin.exp3(q[0] * a) @ pin.exp3(q[1] * b), np.zeros(3))
        assert np.abs(data.oMi[1].homogeneous - expected.homogeneous).max() <= 1e-14
        J = pin.computeJointJacobian(model, data, q, 1)[:, :2]  # in the joint's frame
        assert np.abs(J[3:, 0] - pin.exp3(q[1] * b).T @ a).max() <= 1e-14
        assert np.abs(J[3:, 1] - b).max() <= 1e-14 and np.abs(J[:3]).max() <= 1e-14


def test_an_unknown_type_is_refused_naming_the_closest():
    model = load_model(URDF)
    with pytest.raises(SpecError, match=r"joint_types.u = 'universal_ZY': did you mean 'universal_zy'\? use one of"):
        retype_joints(model, {"u": "universal_ZY"})
    with pytest.raises(SpecError, match="use one of"):
        retype_joints(model, {"u": "universal_zz"})  # four types are as close: none is named


def test_the_new_types_go_through_a_spec_s_toml_and_back():
    spec = ClosureSpec.from_toml('format = "pkm.closures/1"\nmechanism = "u"\nurdf = "u.urdf"\nactuated = ["after"]\n'
                                 '[task]\ncomponents = []\njoints = ["after"]\n'
                                 '[joint_types]\nu = "universal_zy"\n')
    assert spec.joint_types == {"u": "universal_zy"}
    again = ClosureSpec.from_toml(spec.to_toml())
    assert again == spec and '[joint_types]\nu = "universal_zy"' in spec.to_toml()
    assert dataclasses.replace(spec, joint_types={"u": "universal_xz"}).to_toml().count("universal_xz") == 1


#: A link and a joint named alike (``a``), as MJCF bodies and joints often are (MuJoCo Menagerie's Cassie).
SHARED = URDF.replace('name="a"', 'name="u"').replace('link="a"', 'link="u"')


def test_a_model_whose_link_and_joint_share_a_name_is_reduced_keeping_every_frame():
    """Pinocchio's own reduction raises on such a model (its frames looked up by name alone); :func:`reduced_model`
    keeps every frame's name and type, and the kept frames' placements at the locked value (1e-14)."""
    model = load_model(SHARED)
    assert [str(f.type) for f in model.frames if f.name == "u"] == ["JOINT", "BODY"]
    q = np.array([0.3, -0.7])
    with pytest.raises(ValueError, match="Several frames match"):
        pin.buildReducedModel(model, [model.getJointId("u")], q)
    reduced = reduced_model(model, [model.getJointId("u")], q)
    assert sorted((f.name, str(f.type)) for f in reduced.frames) == sorted(
        (f.name, "FIXED_JOINT" if f.name == "u" and f.type == pin.FrameType.JOINT else str(f.type))
        for f in model.frames)
    full, red = model.createData(), reduced.createData()
    pin.framesForwardKinematics(model, full, q)
    pin.framesForwardKinematics(reduced, red, q[1:])
    for name in ("b", "u"):
        a, b = (m.getFrameId(name, pin.FrameType.BODY) for m in (model, reduced))
        assert np.abs((full.oMf[a].inverse() * red.oMf[b]).toActionMatrix() - np.eye(6)).max() < 1e-14


def test_has_mimic_remembers_a_model_while_it_lives_and_asks_again_after_a_joint_is_added():
    """has_mimic's answer, remembered by the model's id, is the scan's: False for two revolutes, True for the model
    that turns the second into a mimic, False again for the first; a joint added since is scanned; a freed model's
    entry is gone (no later model takes its answer with its id)."""
    model = pin.Model()
    a = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "a")
    b = model.addJoint(a, pin.JointModelRZ(), pin.SE3.Identity(), "b")
    assert not has_mimic(model) and not has_mimic(model)
    mimic = pin.transformJointIntoMimic(model, a, b, 2.0, 0.0)
    assert has_mimic(mimic) and has_mimic(mimic) and not has_mimic(model)
    model.addJoint(b, pin.JointModelRX(), pin.SE3.Identity(), "c")
    assert not has_mimic(model) and joints._MIMIC[id(model)] == (4, False)  # (its joint count changed: scanned again)
    key = id(mimic)
    del mimic
    assert key not in joints._MIMIC
