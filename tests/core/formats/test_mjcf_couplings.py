"""Linear couplings of an MJCF file (issue 51), on ``data/coupled.xml``: a waist differential (two fixed tendons,
``yaw + roll`` and ``yaw - roll``, a motor on each), two gear equalities (an elbow geared to its shoulder, the right
neck crank to the left one) and a neck whose two crank-rod loops, closed by site connects, over-constrain the head
(six rows of rank three). Checked against MuJoCo on the same file (its kinematics, tendon lengths, constraint
Jacobians and rigid-body inverse dynamics), against finite differences, and through pkm's MJCF writer and back."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.dynamics.motors import joint_efforts, motor_efforts, motor_values
from pkm.core.formats.to_mjcf import mjcf_from_mechanism, qpos_of
from pkm.core.kinematics import constraints
from pkm.errors import PkmWarning, SpecError
from tests.fd import constraint_jacobian_error, forward_jacobian_error

mujoco = pytest.importorskip("mujoco")

XML = Path(__file__).parent / "data" / "coupled.xml"
MOTORS = ("waist_left_motor", "waist_right_motor", "left_shoulder_pitch", "left_neck")


@pytest.fixture(scope="module")
def mech() -> pkm.Mechanism:
    return pkm.load(XML)


@pytest.fixture(scope="module")
def mj():
    m = mujoco.MjModel.from_xml_path(str(XML))
    m.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    return m, mujoco.MjData(m)


@pytest.fixture(scope="module")
def state(mech):
    """A closed configuration away from the reference, with consistent velocities and accelerations (base held)."""
    q = pkm.assemble(mech, mech.with_actuated(mech.q_reference, [0.3, -0.2, 0.5, 0.25]), hold=mech.actuated_names).q
    v = pkm.velocities(mech, q, [0.4, -0.7, 1.1, 0.6])
    a = pkm.accelerations(mech, q, v, [2.0, 1.5, -3.0, 4.0])
    return q, v, a


def _qpos(mech, m, q):
    """MuJoCo's qpos of ``q`` (Pinocchio's), joint by joint by name (a mimic joint's own value)."""
    qpos = np.zeros(m.nq)
    for k in range(m.njnt):
        j = mech.model.getJointId(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, k))
        seg = qpos_of(mech.model, j, q)
        qpos[m.jnt_qposadr[k]:m.jnt_qposadr[k] + len(seg)] = seg
    return qpos


def _dofs(mech, m, x):
    """MuJoCo's qvel (or qacc) of ``x`` (Pinocchio's), the base at rest (its six entries zero in both)."""
    out = np.zeros(m.nv)
    for k in range(m.njnt):
        if m.jnt_type[k] == mujoco.mjtJoint.mjJNT_FREE:
            continue
        jm = mech.model.joints[mech.model.getJointId(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, k))]
        scale = jm.extract().scaling if jm.shortname() == "JointModelMimic" else 1.0
        out[m.jnt_dofadr[k]] = scale * x[jm.idx_v]
    return out


def test_it_loads_with_a_differential_gears_and_an_over_constrained_neck(mech, state):
    assert mech.actuated_names == ("waist_yaw", "waist_roll", "left_shoulder_pitch", "left_neck")
    assert mech.motor_map.names == MOTORS
    np.testing.assert_array_equal(mech.motor_map.matrix[:2, :2], [[1.0, 1.0], [1.0, -1.0]])
    np.testing.assert_array_equal(mech.motor_map.matrix[2:], np.eye(4)[2:])
    kinds = {n: mech.model.joints[mech.model.getJointId(n)].shortname() for n in ("left_elbow", "right_neck")}
    assert set(kinds.values()) == {"JointModelMimic"}
    Jc = constraints.jacobian(mech, state[0])
    assert Jc.shape[0] == 6 and np.linalg.matrix_rank(Jc, tol=1e-9 * np.abs(Jc).max()) == 3
    assert not mech.dependent_actuators
    assert any("differential" in n and "waist_left_motor" in n for n in mech.notes)


def test_positions_and_tendon_lengths_are_mujocos(mech, mj, state):
    """Every body's world pose and site's position equal MuJoCo's (1e-12 m and in each rotation entry) at the
    reference and at a moved closed configuration (the geared elbow and right crank included); the motors' coordinates are MuJoCo's tendon lengths (1e-12 rad)."""
    m, d = mj
    data = mech.model.createData()
    for q in (mech.q_reference, state[0]):
        d.qpos[:] = _qpos(mech, m, q)
        mujoco.mj_fwdPosition(m, d)
        pin.framesForwardKinematics(mech.model, data, q)
        for k in range(1, m.nbody):
            name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, k)
            X = data.oMf[mech.model.getFrameId(name, pin.FrameType.BODY)]
            assert np.abs(X.translation - d.xpos[k]).max() <= 1e-12, name
            assert np.abs(X.rotation - d.xmat[k].reshape(3, 3)).max() <= 1e-12, name
        for k in range(m.nsite):
            name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_SITE, k)
            assert np.abs(data.oMf[mech.model.getFrameId(name)].translation - d.site_xpos[k]).max() <= 1e-12, name
        np.testing.assert_allclose(motor_values(mech, q)[:2], d.ten_length, rtol=0, atol=1e-12)
        np.testing.assert_allclose(motor_values(mech, q)[2:], mech.actuated_q(q)[2:], rtol=0, atol=0)


def test_jacobians_match_finite_differences(mech, state):
    """The closures' Jacobian (with the mimic joints) and the forward Jacobian of a head site's position and the
    shoulder against Richardson differences of position-level solves (relative 1e-7; measured 1.0e-9, 3.4e-10)."""
    task = pkm.load(XML, task={"end_effector": "head_left", "components": ["x", "y", "z"],
                               "joints": ["left_shoulder_pitch"]})
    q = state[0]
    assert constraint_jacobian_error(task, q) <= 1e-7
    assert forward_jacobian_error(task, q) <= 1e-7


def test_inverse_dynamics_is_mujocos_with_its_equalities_exact(mech, mj, state):
    """pkm's motor efforts (``C^-T`` of its actuated-joint efforts) equal MuJoCo's on the same file: its rigid-body
    forces ``M a + c`` (``mj_rne``, plus the armature) balanced by its actuators' moments, the base's six forces and
    its equality rows' Jacobian (connects and joint equalities, held exactly: a least-squares solve, unique in the
    motor efforts) to 1e-9 relative (measured 1.7e-15; without the armature they would differ by 1.2e-2)."""
    m, d = mj
    q, v, a = state
    tau = pkm.inverse_dynamics(mech, q, v, a, base="fixed")
    f = motor_efforts(mech, tau)
    np.testing.assert_allclose(joint_efforts(mech, f), tau, rtol=1e-14, atol=1e-14)
    d.qpos[:], d.qvel[:], d.qacc[:] = _qpos(mech, m, q), _dofs(mech, m, v), _dofs(mech, m, a)
    mujoco.mj_fwdPosition(m, d)
    mujoco.mj_comVel(m, d)
    rne = np.zeros(m.nv)
    mujoco.mj_rne(m, d, 1, rne)
    rne += m.dof_armature * d.qacc
    rows = d.efc_type[:d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    J = d.efc_J[:d.nefc * m.nv].reshape(d.nefc, m.nv)[rows]
    assert J.shape[0] == 2 * 3 + 2  # (two connects, two joint equalities: no limit row)
    moment = np.zeros((m.nu, m.nv))
    mujoco.mju_sparse2dense(moment, d.actuator_moment, d.moment_rownnz, d.moment_rowadr, d.moment_colind)
    A = np.hstack([moment.T, np.eye(m.nv)[:, :6], J.T])
    x, *_ = np.linalg.lstsq(A, rne, rcond=None)
    assert np.abs(A @ x - rne).max() <= 1e-9 * np.abs(rne).max()  # (the balance holds: consistent state)
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_ACTUATOR, k) for k in range(m.nu)]
    mine = dict(zip(MOTORS, f))
    theirs = dict(zip(["waist_left_motor", "waist_right_motor", "left_shoulder_pitch", "left_neck"], x[:m.nu]))
    assert names == ["waist_left_motor", "waist_right_motor", "shoulder_motor", "neck_motor"]
    err = max(abs(mine[k] - theirs[k]) for k in mine)
    assert err <= 1e-9 * max(abs(t) for t in theirs.values()), (mine, theirs)


def test_the_mjcf_writer_round_trips_the_differential_and_the_gears(mech, tmp_path):
    """pkm's MJCF writes the differential as fixed tendons under motors, the gears as joint equalities: read back, the
    same motors, map, mimic couplings and reference (1e-12); MuJoCo loads it with two tendons and four actuators."""
    text = mjcf_from_mechanism(mech)
    m = mujoco.MjModel.from_xml_string(text)
    assert (m.ntendon, m.nu) == (2, 4)
    path = tmp_path / "coupled.xml"
    path.write_text(text, encoding="utf-8")
    back = pkm.load(path)
    assert back.actuated_names == mech.actuated_names and back.motor_map.names == mech.motor_map.names
    np.testing.assert_array_equal(back.motor_map.matrix, mech.motor_map.matrix)
    assert np.abs(back.q_reference - mech.q_reference).max() <= 1e-12
    spec = pkm.load(pkm.save(mech, tmp_path / "coupled.closures.toml"))
    assert spec.spec.motors == mech.spec.motors


def test_redundant_motor_values_of_a_key_are_released_not_refused(tmp_path):
    """Two neck motors and no gear equality: the loops make the second depend on the first. A ``home`` key whose
    two crank values differ by 1e-4 rad (as MuJoCo's soft equalities leave them) over-determines the loops: the load
    holds the independent motors and moves the redundant one (a note and a warning say by how much) instead of failing
    with ``[reference] lacks joints``."""
    text = XML.read_text().replace('<joint name="neck_gear" joint1="right_neck" joint2="left_neck" '
                                   'polycoef="0 1 0 0 0"/>', "")
    text = text.replace('<motor name="neck_motor" joint="left_neck" ctrlrange="-5 5"/>',
                        '<motor name="neck_motor" joint="left_neck"/><motor name="neck_motor_r" joint="right_neck"/>')
    text = text.replace("</mujoco>", '<keyframe><key name="home" qpos="0 0 1 1 0 0 0  0.1 0.05 0.3 0 0 0.2 0 0.2001 0"/>'
                                     "</keyframe></mujoco>")
    path = tmp_path / "neck.xml"
    path.write_text(text, encoding="utf-8")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mech = pkm.load(path)
    said = [str(w.message) for w in caught if issubclass(w.category, PkmWarning) and "over-determine" in str(w.message)]
    assert len(said) == 1 and "moved ['right_neck'] by 0.0001" in said[0]
    values = mech.q_to_dict(mech.q_reference)
    assert (values["waist_yaw"], values["waist_roll"], values["left_neck"]) == pytest.approx((0.1, 0.05, 0.2), abs=1e-12)
    assert values["right_neck"] == pytest.approx(0.2, abs=1e-9)
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() <= 1e-12
    assert mech.dependent_actuators == ("right_neck",)


def test_loops_that_cannot_close_under_a_floating_base_are_said_so_not_blamed_on_the_reference(tmp_path):
    """The file states only its floating base's pose (pkm's generated [reference]): a rod too long for its loop to
    close is "the loops cannot be closed", not a "[reference] lacks joints" the user cannot mend; the redundant rows
    of its planar loop are said (an over-constrained loop whose sites disagree by a rounding error fails alike)."""
    path = tmp_path / "long.xml"
    path.write_text("""<mujoco><compiler angle="radian"/><worldbody><body name="base"><freejoint name="root"/>
      <geom type="sphere" size="0.05"/><site name="anchor" pos="0.1 0 0"/>
      <body name="crank"><joint name="crank" axis="0 1 0"/><geom type="sphere" size="0.01" pos="0.02 0 0"/>
        <body name="rod" pos="0.02 0 0"><joint name="rod" axis="0 1 0"/><geom type="sphere" size="0.01"/>
          <site name="tip" pos="0 0 0.5"/></body></body></body></worldbody>
      <equality><connect site1="tip" site2="anchor"/></equality><actuator><motor joint="crank"/></actuator></mujoco>""",
                    encoding="utf-8")
    with pytest.raises(SpecError, match="the loops cannot be closed") as info:
        pkm.load(path)
    assert "[reference]" not in str(info.value)
    assert "the closures' 3 equations have rank 2 there: redundant" in str(info.value)  # (a planar loop)
