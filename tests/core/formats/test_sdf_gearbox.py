"""pkm.core.formats.sdf: SDFormat ``gearbox`` joints (Cassie's motor rotors) read as Pinocchio mimic joints, and the
Pinocchio 4.1 restrictions the reader and :func:`pkm.core.model.joints.retype_joints` work around."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.dynamics.projection import energy
from pkm.core.formats.sdf import read_sdf
from pkm.core.model.spec import TaskSpec
from pkm.core.model.urdf import load_model
from pkm.errors import SpecError

I_ROTOR, I_OUT = 2e-5, 3e-3  # kg m^2 about z (each body's centre of mass on its axis)


def inertial(izz: float) -> str:
    return (f"<inertial><mass>0.5</mass><inertia><ixx>1e-4</ixx><iyy>1e-4</iyy><izz>{izz!r}</izz><ixy>0</ixy>"
            "<ixz>0</ixz><iyz>0</iyz></inertia></inertial>")


def geared(ratio: float = 0.1, rotor: str = "motor_ip", output: str = "motor_op", axis: str = "0 0 1",
           axis2: str = "0 0 1", rotor_parent: str = "base", extra: str = "") -> str:
    """A motor rotor and an output link, each on a revolute about z from ``base``, geared by ``ratio``
    (SDFormat: theta_output = -ratio theta_rotor); the rotor offset 0.05 m in x (a spur pair)."""
    return f"""<sdf version="1.6"><model name="gear">
      <link name="base">{inertial(1e-3)}</link>
      <link name="rotor"><pose>0.05 0 0 0 0 0</pose>{inertial(I_ROTOR)}</link>
      <link name="out"><pose>0 0 0 0 0 1.2</pose>{inertial(I_OUT)}</link>
      <joint name="{rotor}" type="revolute"><parent>{rotor_parent}</parent><child>rotor</child>
        <axis><xyz>0 0 1</xyz></axis></joint>
      <joint name="{output}" type="revolute"><parent>base</parent><child>out</child>
        <axis><xyz>0 0 1</xyz><limit><lower>-1</lower><upper>1</upper></limit></axis></joint>
      <joint name="gear" type="gearbox"><parent>rotor</parent><child>out</child>
        <gearbox_reference_body>base</gearbox_reference_body><gearbox_ratio>{ratio!r}</gearbox_ratio>
        <axis><xyz>{axis}</xyz><use_parent_model_frame>1</use_parent_model_frame></axis>
        <axis2><xyz>{axis2}</xyz><use_parent_model_frame>1</use_parent_model_frame></axis2></joint>
      {extra}
    </model></sdf>"""


def rotation_z(model: pin.Model, q: np.ndarray, joint: str) -> float:
    """How far joint ``joint``'s body has turned about z (its axis) from the model's pose, from the kinematics."""
    d = model.createData()
    angles = []
    for qq in (pin.neutral(model), q):
        pin.forwardKinematics(model, d, qq)
        R = d.oMi[model.getJointId(joint)].rotation
        angles.append(np.arctan2(R[1, 0], R[0, 0]))
    return float(angles[1] - angles[0])


@pytest.mark.parametrize("ratio, axis2, rotor, output", [
    (0.1, "0 0 1", "motor_ip", "motor_op"),  # Cassie's: the rotor's joint name sorts first (a mount link)
    (0.1, "0 0 -1", "z_rotor", "a_output"),  # the output's axis2 against its joint's axis: s2 = -1
    (8.0, "0 0 1", "motor_ip", "motor_op"),  # |ratio| > 1: the parent (here "rotor") is the slower, it leads
])
def test_a_gearbox_is_a_mimic_whose_rotor_inertia_counts(ratio, axis2, rotor, output):
    """SDFormat: theta_2 = -ratio theta_1, theta_1 the parent's (rotor's) angle about <axis>, theta_2 the
    child's about <axis2>. The slower side keeps the coordinate; at its rate omega the mass matrix and the
    kinetic energy are those of I_lead + I_follower (omega_follower / omega)^2 (1e-12 relative)."""
    model = load_model(read_sdf(geared(ratio, rotor, output, axis2=axis2), "gear.sdf").urdf, "gear.sdf")
    assert model.nq == model.nv == 1
    s2 = 1.0 if axis2 == "0 0 1" else -1.0
    follower, i_lead, i_follower = (rotor, I_OUT, I_ROTOR) if ratio <= 1 else (output, I_ROTOR, I_OUT)
    assert model.joints[model.getJointId(follower)].shortname() == "JointModelMimic"
    q = np.array([0.03])
    theta_rotor, theta_out = rotation_z(model, q, rotor), s2 * rotation_z(model, q, output)
    assert theta_out == pytest.approx(-ratio * theta_rotor, rel=1e-12)  # the SDFormat relation, from the poses
    gain = -s2 / ratio if ratio <= 1 else -s2 * ratio  # d q_follower / d q_lead
    mass = i_lead + i_follower * gain**2
    d = model.createData()
    assert pin.crba(model, d, q)[0, 0] == pytest.approx(mass, rel=1e-12)
    omega = 2.0  # rad/s
    pin.forwardKinematics(model, d, q, np.array([omega]))
    kinetic = sum(0.5 * model.inertias[i].vtiv(d.v[i]) for i in range(1, model.njoints))
    assert kinetic == pytest.approx(0.5 * mass * omega**2, rel=1e-12)


def _pair(mimic_on: str) -> str:
    """Two revolutes on one base, ``a`` and ``b``; joint ``mimic_on`` mimics the other."""
    joints = "".join(
        f'<joint name="{n}" type="revolute"><parent link="base"/><child link="{n}_link"/><axis xyz="0 0 1"/>'
        '<limit effort="0" velocity="0"/>'
        + (f'<mimic joint="{"b" if n == "a" else "a"}" multiplier="-10" offset="0"/>' if n == mimic_on else "")
        + "</joint>" for n in "ab")
    return f'<robot name="t"><link name="base"/><link name="a_link"/><link name="b_link"/>{joints}</robot>'


def test_pinocchio_adds_a_mimic_only_after_its_leader():
    """The upstream restrictions worked around (module docs of pkm.core.formats.sdf and pkm.core.model.joints):
    Pinocchio 4.1 visits a link's child joints in name order and refuses a mimic joint met before its leader,
    and it cannot reduce a model with mimic joints. When these start to pass, the workarounds can go."""
    assert pin.buildModelFromXML(_pair("b"), mimic=True).nq == 1
    with pytest.raises(Exception, match="mimic"):
        pin.buildModelFromXML(_pair("a"), mimic=True)
    model = pin.buildModelFromXML(_pair("b"), mimic=True)
    with pytest.raises(Exception, match=r"[Mm]imic"):
        pin.buildReducedModel(model, [model.getJointId("a")], pin.neutral(model))
    urdf = read_sdf(geared(), "gear.sdf").urdf  # rotor joint motor_ip sorts before motor_op: the reader mounts it
    assert '<joint name="motor_op__gear" type="fixed">' in urdf and 'link="gear__rotor_mount"' in urdf
    assert '<link name="gear__rotor_mount"/>' not in read_sdf(geared(rotor="z_ip"), "gear.sdf").urdf  # (no need)


@pytest.mark.parametrize("change, match", [
    ({"rotor_parent": "out"}, "its parent link 'rotor' must hang on a revolute joint from its gearbox_reference_body"),
    ({"axis": "1 0 0"}, "is not the axis"),
    ({"ratio": 0.0}, "must be finite and nonzero"),
])
def test_a_gearbox_that_is_no_gear_pair_on_its_reference_body_is_refused(change, match):
    with pytest.raises(SpecError, match=f"gearbox 'gear'.*{match}"):
        read_sdf(geared(**change), "gear.sdf")
    with pytest.raises(SpecError, match="gearbox 'gear' needs a <gearbox_reference_body>"):
        read_sdf(geared().replace("<gearbox_reference_body>base</gearbox_reference_body>", ""), "gear.sdf")


def fourbar_geared(types=None, gear: bool = True) -> pkm.Mechanism:
    """The spatial four-bar of test_sdf, its crank geared 1:20 to a rotor on the world, and a pendulum on a ball
    joint of the coupler (a tree joint [joint_types] retypes, with a mimic joint in the model); without ``gear``
    the rotor turns freely."""
    from tests.core.formats.test_sdf import INERTIA, fourbar

    gearbox = """<joint name="crank_gear" type="gearbox"><parent>crank_rotor</parent><child>crank</child>
        <gearbox_reference_body>world</gearbox_reference_body><gearbox_ratio>0.05</gearbox_ratio>
        <axis><xyz>0 1 0</xyz></axis><axis2><xyz>0 1 0</xyz></axis2></joint>"""
    extra = f"""<link name="crank_rotor">{INERTIA}</link>
      <joint name="crank_ip" type="revolute"><parent>world</parent><child>crank_rotor</child>
        <axis><xyz>0 1 0</xyz></axis></joint>{gearbox if gear else ""}
      <link name="pendulum"><pose relative_to="coupler">0 0 0.05 0 0 0</pose>{INERTIA}</link>
      <joint name="pendulum_ball" type="ball"><parent>coupler</parent><child>pendulum</child></joint>"""
    imp = read_sdf(fourbar(extra=extra), "fb.sdf")
    spec = pkm.ClosureSpec(mechanism="fb", urdf="fb.sdf", end_effector=None, actuated=("crank_joint",),
                           closures=imp.closures, task=TaskSpec((), ("crank_joint",)), reference={},
                           joint_types={**imp.joint_types, **(types or {})})
    return pkm.from_strings(imp.urdf, spec, source="fb.sdf")


def test_a_geared_crank_drives_a_loop_and_joints_can_be_retyped_beside_it():
    """retype_joints keeps the mimic (Pinocchio 4.1 cannot reduce a model with one: rebuilt, then re-mimicked);
    the rotor turns -20 times the crank (1e-12 rad); the rotor's inertia is in the dynamics (400 I_rotor)."""
    mech = fourbar_geared()
    assert mech.joints["pendulum_ball"].kind == "JointModelSpherical"
    assert mech.joints["crank_ip"].kind == "JointModelMimic" and mech.nv == 6
    q = pkm.close_loops(mech, [0.1], mech.q_reference).q
    d = mech.data
    pin.framesForwardKinematics(mech.model, d, q)
    R = d.oMf[mech.frame_id("crank_rotor")].rotation
    assert np.arctan2(R[0, 2], R[0, 0]) == pytest.approx(-20 * 0.1, abs=1e-12)  # about y
    assert pkm.diagnose(mech, q).mobility == 4  # the crank and the pendulum's ball
    free = fourbar_geared(gear=False)
    assert free.joints["crank_ip"].kind == "JointModelRY" and free.nv == 7
    kinetic = []
    for m in (mech, free):  # 1 rad/s of the crank alone: the gear adds the rotor's 1/2 (1/0.05)^2 I_rotor
        v = np.zeros(m.nv)
        v[m.joints["crank_joint"].idx_v] = 1.0
        kinetic.append(energy(m, m.q_reference, v)[0])
    assert kinetic[0] - kinetic[1] == pytest.approx(0.5 * 400 * 1e-4, rel=1e-12)
    with pytest.raises(SpecError, match="joint 'crank_ip' mimics 'crank_joint'; neither can be retyped"):
        fourbar_geared(types={"crank_ip": "fixed"})
