"""pkm.core.formats.gepetto and pkm.core.model.joints: models in Gepetto's URDF + robot.yaml convention, with ball joints the
URDF writes as revolutes, loaded with no hand edits and given every generic answer.

The two models in ``examples/`` were written for pkm in that convention (limits as onshape-to-robot
writes them: effort and velocity only): a planar five-bar (``gepetto_fivebar``) and a spatial RSSR four-bar whose
coupler hangs between two ball joints (``gepetto_rssr``: one is a URDF revolute made ``SPHERICAL`` by the YAML,
the other the 3-D closure), so that the coupler's spin about its own axis is an idle motion.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core import dynamics
from pkm.core.formats import spec_from_gepetto
from pkm.core.kinematics import constraints
from pkm.core.model.compare import mechanism_differences
from pkm.errors import SpecError, SpecNameError
from tests import fd

DATA = Path(__file__).resolve().parents[3] / "examples"
MODELS = {"gepetto_fivebar": DATA / "gepetto_fivebar", "gepetto_rssr": DATA / "gepetto_rssr" / "robot.yaml"}


@pytest.fixture(scope="module", params=sorted(MODELS))
def model(request):
    return request.param, pkm.load(MODELS[request.param])


def test_loaded_assembled_and_typed_as_the_yaml_says(model):
    name, mech = model
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() <= 1e-10
    assert mech.limits == {} and mech.spec.end_effector is None
    d = pkm.diagnose(mech, mech.q_reference)
    assert d.classification == "regular"
    if name == "gepetto_rssr":
        assert mech.joints["ball_b"].kind == "JointModelSpherical" and mech.actuated_names == ("motor",)
        assert (d.idle_motions, d.idle_joints, d.mobility) == (1, ("ball_b",), 2)
    else:
        assert mech.actuated_names == ("mot1", "mot2") and d.idle_motions == 0


def test_forward_and_inverse_kinematics_round_trip_and_the_jacobian_matches_differences(model):
    _, mech = model
    rng = np.random.default_rng(1)
    for _ in range(3):
        qa = mech.actuated_q(mech.q_reference) + 0.1 * rng.uniform(-1, 1, mech.na)
        fk = pkm.close_loops(mech, qa)
        assert fk.residual <= 1e-10
        ik = pkm.solve_ik(mech, pkm.TaskMap.of(mech).value(fk.q))
        assert np.abs(mech.actuated_q(ik.q) - qa).max() <= 1e-9
        assert fd.forward_jacobian_error(mech, fk.q) <= 1e-6


def test_inverse_dynamics_balances_the_power(model):
    """sum tau qd = dE/dt to 1e-8 relative along an actuated motion (the virtual-work route: no platform to cut).

    The RSSR's coupler spin (an idle motion) included: its rate is the one of least kinetic energy
    (docs/conventions.md), so that it takes no power (with the Euclidean minimum-norm rate that pkm.velocities gave
    before, the balance failed).
    """
    _, mech = model
    qa0 = mech.actuated_q(mech.q_reference)
    qd, qdd = np.full(mech.na, 0.3), np.full(mech.na, -0.2)

    def state(t):
        q = pkm.close_loops(mech, qa0 + t * qd + 0.5 * t * t * qdd, mech.q_reference).q
        v = pkm.velocities(mech, q, qd + t * qdd)
        return q, v, pkm.accelerations(mech, q, v, qdd)

    q, v, a = state(0.0)
    tau = pkm.inverse_dynamics(mech, q, v, a)
    dE = fd.richardson(lambda h: np.array([(sum(dynamics.energy(mech, *state(h)[:2]))
                                            - sum(dynamics.energy(mech, *state(-h)[:2]))) / (2 * h)]), 1e-3)[0]
    assert abs(tau @ qd - dE) <= 1e-8 * max(np.abs(tau).max() * np.abs(qd).max(), 1e-12)


def test_saved_as_a_pkm_spec_it_loads_back_with_its_ball_joint(tmp_path):
    mech = pkm.load(MODELS["gepetto_rssr"])
    path = pkm.save(mech, tmp_path / "rssr.closures.toml")
    assert '[joint_types]\nball_b = "spherical"' in path.read_text()
    assert mechanism_differences(pkm.load(path), mech) == []


def test_the_cli_takes_the_folder():
    from tests.cli.helpers import run

    proc = run("fk", str(MODELS["gepetto_fivebar"]), "--joints", "mot1=100deg")
    assert proc.returncode == 0, proc.stderr


JOINTS = ["mot1", "free1", "mot2", "free2"]


@pytest.mark.parametrize("text, message", [
    ("closed_loop: [[a, b]\n", "not valid YAML"),
    ("- 1\n- 2\n", "a mapping"),
    ("type: ['3d']\nname_mot: ['mot']\n", "missing key 'closed_loop'"),
    ("closed_loop: [['a', 'b']]\ntype: ['3d', '6d']\nname_mot: ['mot']\n", "1 closed_loop pairs but 2 types"),
    ("closed_loop: [['a', 'b']]\ntype: ['4d']\nname_mot: ['mot']\n", "use '3d'"),
    ("closed_loop: [['a']]\ntype: ['3d']\nname_mot: ['mot']\n", "pair of frame names"),
    ("closed_loop: [['a', 'b']]\ntype: ['3d']\nname_mot: ['motor_knee']\n", "neither a joint name nor a part of one"),
    ("closed_loop: [['a', 'b']]\ntype: ['3d']\nname_mot: ['mot']\njoint_name: ['free1']\njoint_type: ['BALL']\n",
     "use one of"),
    ("closed_loop: [['a', 'b']]\ntype: ['3d']\nname_mot: ['mot']\njoint_name: ['free1']\njoint_type: ['UJOINT_ZZ']\n",
     "use one of .*'UJOINT_ZY'"),
    ("closed_loop: [['a', 'b']]\ntype: ['3d']\nname_mot: ['mot']\njoint_name: ['free1']\njoint_type: ['UJOINT-ZY']\n",
     r"did you mean 'UJOINT_ZY'\?"),
    ("closed_loop: [['a', 'b']]\ntype: ['3d']\nname_mot: ['mot']\njoint_name: ['free9']\njoint_type: ['FIXED']\n",
     r"joint 'free9' does not exist in five \(joint_name\)"),
    ("closed_loop: [['a', 'b']]\ntype: ['3d']\nname_mot: ['mot']\njoint_name: [free1, free1]\n"
     "joint_type: [FIXED, SPHERICAL]\n", "lists 'free1' twice"),
    ("closed_loop: [['a', 'b']]\ntype: ['3d']\nname_mot: ['mot']\njoint_name: ['free1']\n", "1 joint_name entries"),
])
def test_a_malformed_yaml_is_a_spec_error_saying_what(text, message):
    with pytest.raises(SpecError, match=message):
        spec_from_gepetto(text, "robot.urdf", JOINTS, "five", "five")


@pytest.mark.parametrize("toolbox, pkm_type", [("CARDAN", "universal"), ("UJOINT_XY", "universal_xy"),
                                               ("UJOINT_XZ", "universal_xz"), ("UJOINT_YX", "universal_yx"),
                                               ("UJOINT_YZ", "universal_yz"), ("UJOINT_ZX", "universal_zx"),
                                               ("ujoint_zy", "universal_zy"), ("SPHERICAL", "spherical"),
                                               ("FIXED", "fixed")])
def test_every_joint_type_of_the_toolbox_is_read(toolbox, pkm_type):
    spec = spec_from_gepetto("closed_loop: [['a', 'b']]\ntype: ['6d']\nname_mot: ['mot1']\njoint_name: ['free1']\n"
                             f"joint_type: ['{toolbox}']\n", "robot.urdf", JOINTS, "f")
    assert spec.joint_types == {"free1": pkm_type}


# A spatial RUSR four-bar written for these tests in the toolbox's convention: a crank (the motor, about z), a
# coupler hung from it by a universal joint about z then y (a URDF revolute made UJOINT_ZY by the YAML), whose tip
# meets the tip of a rocker (about x) at a ball joint (the 3-D closure). One degree of freedom, no idle motion.
RUSR_LENGTH = float(np.sqrt(0.2 ** 2 + 0.15 ** 2 + 0.1 ** 2))  # the coupler: the tips meet at every crank angle
RUSR_YAML = """closed_loop: [['closedloop1_A', 'closedloop1_B']]
type: ['3d']
name_mot: ['motor']
joint_name: ['ujoint_b']
joint_type: ['UJOINT_ZY']
"""


def rusr_urdf(motor: str = "motor", velocity: str = "20", effort: str = "1") -> str:
    """The RUSR's URDF (SI units), its joints' ``<limit>`` as onshape-to-robot writes them (effort, velocity)."""
    def inertial(x: float, y: float) -> str:
        return (f'<inertial><origin xyz="{x!r} {y!r} 0"/><mass value="0.2"/>'
                '<inertia ixx="1e-4" ixy="0" ixz="0" iyy="2e-4" iyz="0" izz="3e-4"/></inertial>')

    lim = f'<limit effort="{effort}" velocity="{velocity}"/>'
    return f"""<?xml version="1.0"?>
<robot name="rusr">
  <link name="base_link"/>
  <link name="crank">{inertial(0.05, 0.0)}</link>
  <link name="coupler">{inertial(RUSR_LENGTH / 2, 0.0)}</link>
  <link name="rocker">{inertial(0.0, 0.075)}</link>
  <link name="closedloop1_A"/>
  <link name="closedloop1_B"/>
  <joint name="{motor}" type="revolute"><parent link="base_link"/><child link="crank"/><axis xyz="0 0 1"/>{lim}</joint>
  <joint name="ujoint_b" type="revolute"><origin xyz="0.1 0 0"/><parent link="crank"/><child link="coupler"/>
    <axis xyz="0 0 1"/>{lim}</joint>
  <joint name="tip_a" type="fixed"><origin xyz="{RUSR_LENGTH!r} 0 0"/><parent link="coupler"/>
    <child link="closedloop1_A"/></joint>
  <joint name="rocker_joint" type="revolute"><origin xyz="0.3 0 0.1"/><parent link="base_link"/><child link="rocker"/>
    <axis xyz="1 0 0"/>{lim}</joint>
  <joint name="tip_b" type="fixed"><origin xyz="0 0.15 0"/><parent link="rocker"/><child link="closedloop1_B"/></joint>
</robot>
"""


def test_a_ujoint_robot_loads_assembled_and_gives_every_generic_answer(tmp_path):
    """The RUSR with its UJOINT_ZY: assembled (1e-10), closed from a perturbed seed, its forward Jacobian equal to
    finite differences (1e-6 relative), its inverse dynamics given back by constraintDynamics (1e-8), saved as a pkm
    spec and loaded back the same."""
    (tmp_path / "robot.urdf").write_text(rusr_urdf())
    (tmp_path / "robot.yaml").write_text(RUSR_YAML)
    mech = pkm.load(tmp_path)
    u = mech.model.joints[mech.model.getJointId("ujoint_b")].extract()
    assert mech.joints["ujoint_b"].kind == "JointModelUniversal"
    assert (tuple(u.axis1), tuple(u.axis2)) == ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0))
    assert mech.spec.joint_types == {"ujoint_b": "universal_zy"} and any("ujoint_b" in n for n in mech.notes)
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() <= 1e-10
    d = pkm.diagnose(mech, mech.q_reference)
    assert (d.classification, d.mobility, d.idle_motions) == ("regular", 1, 0)

    qa = mech.actuated_q(mech.q_reference)
    seed = pin.integrate(mech.model, mech.q_reference, 0.1 * np.random.default_rng(2).uniform(-1, 1, mech.nv))
    fk = pkm.close_loops(mech, qa, seed)
    assert fk.residual <= 1e-10 and np.abs(mech.actuated_q(fk.q) - qa).max() <= 1e-12

    q = pkm.close_loops(mech, qa + 0.3, mech.q_reference, tol=1e-12).q
    assert fd.forward_jacobian_error(mech, q) <= 1e-6
    qd, qdd = np.array([0.7]), np.array([-1.3])
    v = pkm.velocities(mech, q, qd)
    tau = pkm.inverse_dynamics(mech, q, v, pkm.accelerations(mech, q, v, qdd))
    assert np.abs(dynamics.forward_dynamics(mech, q, v, tau)[mech.act_v] - qdd).max() <= 1e-8

    path = pkm.save(mech, tmp_path / "saved" / "rusr.closures.toml")
    assert '[joint_types]\nujoint_b = "universal_zy"' in path.read_text()
    assert mechanism_differences(pkm.load(path), mech) == []


def test_name_mot_patterns_match_as_the_toolbox_reads_them():
    spec = spec_from_gepetto("closed_loop: [['a', 'b']]\ntype: ['6d']\nname_mot: ['mot']\n", "robot.urdf", JOINTS, "f")
    assert spec.actuated == ("mot1", "mot2") and spec.closures[0].type == "frame"


def test_retyping_an_unknown_joint_names_the_valid_ones():
    from pkm.core.model.joints import retype_joints

    model = pkm.load(MODELS["gepetto_fivebar"]).model
    with pytest.raises(SpecNameError, match="free3"):
        retype_joints(model, {"free3": "spherical"})
    assert retype_joints(model, {"free1": "fixed"}).nq == model.nq - 1
    universal = retype_joints(model, {"free1": "universal"})
    assert universal.nq == model.nq + 1 and pin.neutral(universal).shape == (model.nq + 1,)
