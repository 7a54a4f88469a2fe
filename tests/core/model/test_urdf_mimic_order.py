"""URDF mimic joints met before their leaders in Pinocchio's traversal (:func:`pkm.core.model.urdf.mimics_first`):
Pinocchio 4.1's parser refuses them ("The parent joint of the mimic joint is not in the kinematic tree"), pkm
orders the tree itself. A gripper on a two-joint arm, written here: the mimic finger ``a_finger_left`` sorts
before its leader ``b_finger_right`` (the parser visits sibling joints in name order)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pkm.core.model.urdf import load_model
from pkm.errors import SpecError

INERTIAL = '<inertial><mass value="{m}"/><inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/></inertial>'
LIMIT = '<limit lower="{lo}" upper="{hi}" effort="10" velocity="2"/>'
GRIPPER = f"""<robot name="arm_gripper">
  <link name="base"/>
  <link name="upper">{INERTIAL.format(m=1, i=0.01)}</link>
  <link name="palm">{INERTIAL.format(m=0.5, i=0.001)}</link>
  <link name="left">{INERTIAL.format(m=0.1, i=0.0001)}</link>
  <link name="right">{INERTIAL.format(m=0.1, i=0.0001)}</link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
    {LIMIT.format(lo=-3, hi=3)}</joint>
  <joint name="wrist" type="revolute"><parent link="upper"/><child link="palm"/><origin xyz="0.3 0 0"/>
    <axis xyz="0 1 0"/>{LIMIT.format(lo=-2, hi=2)}</joint>
  <joint name="a_finger_left" type="prismatic"><parent link="palm"/><child link="left"/><origin xyz="0.05 0.02 0"/>
    <axis xyz="0 1 0"/>{LIMIT.format(lo=-0.05, hi=0.05)}<mimic joint="b_finger_right" multiplier="-2" offset="0.01"/>
  </joint>
  <joint name="b_finger_right" type="prismatic"><parent link="palm"/><child link="right"/><origin xyz="0.05 -0.02 0"/>
    <axis xyz="0 1 0"/>{LIMIT.format(lo=-0.04, hi=0.03)}</joint>
</robot>
"""


def test_pinocchio_alone_refuses_the_file():
    """The case itself: if a later Pinocchio reads it, this test says the workaround may go."""
    with pytest.raises(ValueError, match="mimic joint is not in the kinematic tree"):
        pin.buildModelFromXML(GRIPPER, mimic=True)


def test_the_mimic_before_its_leader_loads_and_the_coupling_holds():
    """Loads (the leader visited first); the left finger follows q_left = -2 q_right + 0.01 [m] in the palm's
    frame (1e-12 m), the limits stay each joint's, and the arm's joints keep theirs."""
    model = load_model(GRIPPER, "gripper.urdf")
    assert list(model.names) == ["universe", "shoulder", "wrist", "b_finger_right", "a_finger_left"]
    assert model.nq == 3 and model.joints[4].shortname() == "JointModelMimic"
    assert np.allclose(model.lowerPositionLimit, [-3, -2, -0.04]) and np.allclose(model.upperPositionLimit,
                                                                                   [3, 2, 0.03])
    data = model.createData()
    for q in ([0.1, 0.2, 0.03], [-1.0, 0.7, -0.02]):
        pin.framesForwardKinematics(model, data, np.array(q))
        palm = data.oMf[model.getFrameId("palm")]
        left = palm.actInv(data.oMf[model.getFrameId("left")]).translation
        right = palm.actInv(data.oMf[model.getFrameId("right")]).translation
        assert np.allclose(right, [0.05, -0.02 + q[2], 0], atol=1e-12)
        assert np.allclose(left, [0.05, 0.02 + (-2 * q[2] + 0.01), 0], atol=1e-12)


def test_a_mimic_below_its_leader_cannot_be_ordered_and_says_so():
    """The shoulder mimicking the wrist, a joint further down its own branch: no order visits the leader first."""
    below = GRIPPER.replace('<mimic joint="b_finger_right" multiplier="-2" offset="0.01"/>', "").replace(
        '<limit lower="-3" upper="3" effort="10" velocity="2"/></joint>',
        '<limit lower="-3" upper="3" effort="10" velocity="2"/><mimic joint="wrist"/></joint>', 1)
    with pytest.raises(SpecError, match=r"gb\.urdf: joint 'shoulder' mimics 'wrist', a joint below it in the tree"):
        load_model(below, "gb.urdf")
