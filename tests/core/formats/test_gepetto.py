"""pkm.core.formats.gepetto and pkm.core.joints: models in Gepetto's URDF + robot.yaml convention, with ball joints the
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
from pkm.core import constraints, dynamics
from pkm.core.compare import mechanism_differences
from pkm.core.formats import spec_from_gepetto
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
        ik = pkm.solve_ik(mech, mech.task_map.value(fk.q))
        assert np.abs(mech.actuated_q(ik.q) - qa).max() <= 1e-9
        assert fd.forward_jacobian_error(mech, fk.q) <= 1e-6


def test_inverse_dynamics_balances_the_power(model):
    """sum tau qd = dE/dt to 1e-8 relative along an actuated motion (the virtual-work route: no platform to cut).

    With an idle motion (the RSSR's coupler spin) the efforts let the dynamics choose the spin's acceleration, which
    a motion built from the kinematics alone does not follow: there ``constraintDynamics`` under the efforts gives
    back the actuated accelerations instead (1e-8).
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
    if pkm.diagnose(mech, q).idle_motions:
        a_back = dynamics.forward_dynamics(mech, q, v, tau)
        assert np.abs(a_back[mech.act_v] - qdd).max() <= 1e-8
        return
    dE = fd.richardson(lambda h: np.array([(sum(dynamics.energy(mech, *state(h)[:2]))
                                            - sum(dynamics.energy(mech, *state(-h)[:2]))) / (2 * h)]), 1e-3)[0]
    assert abs(tau @ qd - dE) <= 1e-8 * max(np.abs(tau).max() * np.abs(qd).max(), 1e-12)


def test_saved_as_a_pkm_spec_it_loads_back_with_its_ball_joint(tmp_path):
    mech = pkm.load(MODELS["gepetto_rssr"])
    path = pkm.save(mech, tmp_path / "rssr.closures.toml")
    assert '[joint_types]\nball_b = "spherical"' in path.read_text()
    assert mechanism_differences(pkm.load(path), mech) == []


def test_the_cli_takes_the_folder():
    from tests.test_cli import run

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
    ("closed_loop: [['a', 'b']]\ntype: ['3d']\nname_mot: ['motor_knee']\n", "matches no joint"),
    ("closed_loop: [['a', 'b']]\ntype: ['3d']\nname_mot: ['mot']\njoint_name: ['free1']\njoint_type: ['BALL']\n",
     "use one of"),
    ("closed_loop: [['a', 'b']]\ntype: ['3d']\nname_mot: ['mot']\njoint_name: ['free1']\n", "1 joint_name entries"),
])
def test_a_malformed_yaml_is_a_spec_error_saying_what(text, message):
    with pytest.raises(SpecError, match=message):
        spec_from_gepetto(text, "robot.urdf", JOINTS, "five")


def test_name_mot_patterns_match_as_the_toolbox_reads_them():
    spec = spec_from_gepetto("closed_loop: [['a', 'b']]\ntype: ['6d']\nname_mot: ['mot']\n", "robot.urdf", JOINTS, "f")
    assert spec.actuated == ("mot1", "mot2") and spec.closures[0].type == "frame"


def test_retyping_an_unknown_joint_names_the_valid_ones():
    from pkm.core.joints import retype_joints

    model = pkm.load(MODELS["gepetto_fivebar"]).model
    with pytest.raises(SpecNameError, match="free3"):
        retype_joints(model, {"free3": "spherical"})
    assert retype_joints(model, {"free1": "fixed"}).nq == model.nq - 1
    universal = retype_joints(model, {"free1": "universal"})
    assert universal.nq == model.nq + 1 and pin.neutral(universal).shape == (model.nq + 1,)
