"""SDFormat ``gearbox`` joints anywhere in the tree (:mod:`pkm.core.formats.sdf`): the reference body a moving link
of an arm, the rotor in a housing fixed to it (a fixed joint between the rotor's revolute and the reference body),
the rotor's joint met before the output's in Pinocchio's traversal (ordered by
:func:`pkm.core.model.urdf.mimics_first`). The coupling checked from the poses: theta_out = -ratio theta_rotor,
both relative to the reference body."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pkm.core.formats.sdf import read_sdf
from pkm.core.model.urdf import load_model
from pkm.errors import SpecError
from tests.core.formats.test_sdf_gearbox import inertial

RATIO = 0.1


def arm(housing_joint: str = "fixed") -> str:
    """base -shoulder (about y)-> upper -> the gear pair on ``upper``: rotor on a housing fixed to it (offset and
    turned), output on ``upper`` itself; both about the upper arm's z."""
    return f"""<sdf version="1.7"><model name="geared_arm">
      <link name="base">{inertial(1e-3)}</link>
      <link name="upper"><pose>0 0 0.3 0 0 0</pose>{inertial(1e-3)}</link>
      <link name="housing"><pose>0.05 0 0.3 0 0 0.4</pose>{inertial(1e-4)}</link>
      <link name="rotor"><pose>0.05 0 0.3 0 0 0.4</pose>{inertial(2e-5)}</link>
      <link name="out"><pose>0 0 0.3 0 0 0</pose>{inertial(3e-3)}</link>
      <joint name="shoulder" type="revolute"><parent>base</parent><child>upper</child>
        <axis><xyz>0 1 0</xyz></axis></joint>
      <joint name="a_housing" type="{housing_joint}"><parent>upper</parent><child>housing</child>
        <axis><xyz>0 0 1</xyz></axis></joint>
      <joint name="a_rotor" type="revolute"><parent>housing</parent><child>rotor</child>
        <axis><xyz>0 0 1</xyz></axis></joint>
      <joint name="b_output" type="revolute"><parent>upper</parent><child>out</child>
        <axis><xyz>0 0 1</xyz></axis></joint>
      <joint name="gear" type="gearbox"><parent>rotor</parent><child>out</child>
        <gearbox_reference_body>upper</gearbox_reference_body><gearbox_ratio>{RATIO!r}</gearbox_ratio>
        <axis><xyz>0 0 1</xyz><use_parent_model_frame>1</use_parent_model_frame></axis>
        <axis2><xyz>0 0 1</xyz><use_parent_model_frame>1</use_parent_model_frame></axis2></joint>
    </model></sdf>"""


def test_a_gearbox_on_a_moving_link_through_a_fixed_housing():
    """Loads; at any shoulder and output angles, the rotor's turn relative to the upper arm is -1/ratio the
    output's (1e-12 rad), the shoulder free of the gear."""
    model = load_model(read_sdf(arm(), "arm.sdf").urdf, "arm.sdf")
    assert model.nq == 2 and model.joints[model.getJointId("a_rotor")].shortname() == "JointModelMimic"
    d = model.createData()

    def turn(q: np.ndarray, frame: str) -> float:  # about the upper arm's z, relative to the upper arm
        pin.framesForwardKinematics(model, d, q)
        R = d.oMf[model.getFrameId("upper")].rotation.T @ d.oMf[model.getFrameId(frame)].rotation
        return float(np.arctan2(R[1, 0], R[0, 0]))

    q0 = np.zeros(2)
    for shoulder, output in ((0.3, 0.02), (-1.1, -0.05)):
        q = np.zeros(2)
        q[model.joints[model.getJointId("shoulder")].idx_q] = shoulder
        q[model.joints[model.getJointId("b_output")].idx_q] = output
        theta_out = turn(q, "out") - turn(q0, "out")
        theta_rotor = np.angle(np.exp(1j * (turn(q, "rotor") - turn(q0, "rotor"))))
        assert theta_out == pytest.approx(output, abs=1e-12)
        assert theta_out == pytest.approx(-RATIO * theta_rotor, abs=1e-12)


def test_a_second_moving_joint_between_the_rotor_and_the_reference_body_is_refused():
    with pytest.raises(SpecError, match=r"arm.sdf: gearbox 'gear': its parent link 'rotor' must hang on a revolute "
                                        r"joint from its gearbox_reference_body 'upper' \(with fixed joints only"):
        read_sdf(arm("revolute"), "arm.sdf")
