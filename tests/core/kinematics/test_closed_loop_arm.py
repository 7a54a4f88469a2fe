"""The generic core on a robot it was not written for: a UR5 from example-robot-data whose tool
is welded (6-D frame closure) to the carriage of an XYZ gantry.

The loop leaves 3 degrees of freedom: the shoulder pan, shoulder lift and elbow are actuated; the
wrist and the gantry follow, so that the tool keeps its orientation and the gantry tracks it.
Forward kinematics is then a numerical orientation-locked IK of the arm, solved by the same loop
closure as the parallel robots; the task is the tool position.
"""

from __future__ import annotations

from importlib.metadata import distribution

import numpy as np
import pinocchio as pin
import pytest
from lxml import etree

import pkm
from pkm.core import ClosureSpec, Mechanism, TaskMap, close_loops, diagnose, solve_ik
from pkm.core.kinematics import constraints
from pkm.core.model.builder import from_strings
from pkm.core.model.spec import Closure, TaskSpec
from tests import fd

UR5 = "cmeel.prefix/share/example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"
Q_ARM = {"shoulder_pan_joint": 0.3, "shoulder_lift_joint": -1.1, "elbow_joint": 1.4,
         "wrist_1_joint": -1.6, "wrist_2_joint": -1.4, "wrist_3_joint": 0.5}


def _gantry_ur5() -> Mechanism:
    text = distribution("example-robot-data").locate_file(UR5).read_text()
    arm = pin.buildModelFromXML(text)
    data = arm.createData()
    q_arm = pin.neutral(arm)
    for n, v in Q_ARM.items():
        q_arm[arm.joints[arm.getJointId(n)].idx_q] = v
    pin.framesForwardKinematics(arm, data, q_arm)
    tool = data.oMf[arm.getFrameId("tool0")]

    root = etree.fromstring(text.encode())
    world = next(el.get("name") for el in root.findall("link")
             if el.get("name") not in {j.find("child").get("link") for j in root.findall("joint")})
    rpy = " ".join(repr(float(a)) for a in pin.rpy.matrixToRpy(tool.rotation))
    for _k, (axis, parent) in enumerate(zip("xyz", (world, "gantry_x", "gantry_y"))):
        etree.SubElement(root, "link", name=f"gantry_{axis}")
        j = etree.SubElement(root, "joint", name=f"gantry_{axis}_joint", type="prismatic")
        etree.SubElement(j, "parent", link=parent)
        etree.SubElement(j, "child", link=f"gantry_{axis}")
        etree.SubElement(j, "axis", xyz=" ".join("1" if a == axis else "0" for a in "xyz"))
        etree.SubElement(j, "limit", lower="-3", upper="3", effort="1", velocity="1")
    etree.SubElement(root, "link", name="gantry_tool")
    j = etree.SubElement(root, "joint", name="gantry_tool_fixed", type="fixed")
    etree.SubElement(j, "parent", link="gantry_z")
    etree.SubElement(j, "child", link="gantry_tool")
    etree.SubElement(j, "origin", xyz="0 0 0", rpy=rpy)
    urdf = etree.tostring(root).decode()

    reference = {n: (v,) for n, v in Q_ARM.items()}
    reference.update({f"gantry_{a}_joint": (float(tool.translation[k]),) for k, a in enumerate("xyz")})
    spec = ClosureSpec(mechanism="ur5_gantry", urdf="<memory>", end_effector="tool0",
                       actuated=("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint"),
                       closures=(Closure("weld", "frame", "tool0", "gantry_tool"),),
                       task=TaskSpec(("x", "y", "z")), reference=reference)
    return from_strings(urdf, spec, source="ur5+gantry")


@pytest.fixture(scope="module")
def mech():
    return _gantry_ur5()


def test_reference_is_assembled_and_has_three_degrees_of_freedom(mech):
    """The welded arm keeps 3 of its 9 degrees of freedom, the weld's 6 equations being independent."""
    d = diagnose(mech, mech.q_reference)
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() < 1e-12
    assert (d.constraint_rank, d.mobility, d.classification) == (6, 3, "regular")


def test_loop_closure_keeps_the_tool_orientation_and_tracks_it_with_the_gantry(mech):
    """Moving the three actuated joints, loop closure converges and the tool stays parallel to itself."""
    rng = np.random.default_rng(3)
    fid = mech.frame_id("tool0")
    pin.framesForwardKinematics(mech.model, mech.data, mech.q_reference)
    R0 = mech.data.oMf[fid].rotation.copy()
    for _ in range(20):
        qa = mech.actuated_q(mech.q_reference) + rng.uniform(-0.2, 0.2, 3)
        res = close_loops(mech, qa)
        assert res.converged and res.residual <= 1e-10
        pin.framesForwardKinematics(mech.model, mech.data, res.q)
        assert np.abs(mech.data.oMf[fid].rotation - R0).max() <= 1e-10
        gantry = [res.q[mech.joint(f"gantry_{a}_joint").idx_q] for a in "xyz"]
        assert np.abs(mech.data.oMf[fid].translation - gantry).max() <= 1e-10


def test_inverse_kinematics_round_trip(mech):
    """Generic IK of the tool position, then generic loop closure, returns the same position."""
    task = TaskMap(mech)
    y0 = task.value(mech.q_reference)
    for dy in ([0.03, -0.02, 0.01], [-0.05, 0.0, 0.04]):
        ik = solve_ik(mech, y0 + dy)
        fk = close_loops(mech, mech.actuated_q(ik.q))
        assert np.abs(task.value(fk.q) - (y0 + dy)).max() <= 1e-9


def test_jacobians_and_accelerations_match_finite_differences(mech):
    """The 6-D closure's Jacobian, drift, and the derived Jacobians and accelerations match differences."""
    q = close_loops(mech, mech.actuated_q(mech.q_reference) + [0.05, -0.04, 0.03]).q
    ik = lambda y: mech.actuated_q(solve_ik(mech, y, q).q)
    assert fd.constraint_jacobian_error(mech, q) <= 1e-6
    assert fd.forward_jacobian_error(mech, q) <= 1e-6
    assert fd.inverse_jacobian_error(mech, q, ik) <= 1e-6
    err = fd.acceleration_errors(mech, q, np.random.default_rng(0))
    assert err["joint"] <= 1e-6 and err["task"] <= 1e-6 and err["closure"] <= 1e-9


def test_constraint_jacobian_equals_pinocchios(mech, built):
    """The frame-Jacobian construction equals ``pin.getConstraintsJacobian`` (6-D here, 3-D on the
    mechanisms without mimic joints)."""
    for m in (mech, built("delta"), built("rrr3"), built("prs3")):
        q = m.q_reference
        assert np.abs(constraints.jacobian(m, q) - constraints.pinocchio_jacobian(m, q)).max() <= 1e-14


def test_top_level_api_exports_the_core():
    """``pkm`` re-exports the core entry points used above."""
    assert pkm.close_loops is close_loops and pkm.solve_ik is solve_ik
