"""Each joint model as SX (:mod:`pkm.core.twin.joint`) against Pinocchio's own ``calc`` at random q and v: transform,
motion subspace, velocity and bias; its tangent map against central differences of ``pin.integrate`` and its
retraction agreeing with ``integrate`` to second order; a mimic joint with its multiplier and offset; refusals."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pinocchio as pin
import pytest

from pkm.core.twin.joint import Joint
from pkm.errors import SpecError

JOINTS = {
    "RX": pin.JointModelRX(), "RY": pin.JointModelRY(), "RZ": pin.JointModelRZ(),
    "RevoluteUnaligned": pin.JointModelRevoluteUnaligned(np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)),
    "PX": pin.JointModelPX(), "PY": pin.JointModelPY(), "PZ": pin.JointModelPZ(),
    "PrismaticUnaligned": pin.JointModelPrismaticUnaligned(np.array([0.0, 0.6, 0.8])),
    "RUBX": pin.JointModelRUBX(), "RUBY": pin.JointModelRUBY(), "RUBZ": pin.JointModelRUBZ(),
    "Spherical": pin.JointModelSpherical(), "FreeFlyer": pin.JointModelFreeFlyer(), "Planar": pin.JointModelPlanar(),
    "Universal": pin.JointModelUniversal(np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.6, 0.8])),
}


@pytest.fixture(scope="module")
def zoo():
    """One joint of each kind, each on the universe at a random placement; random (q, v) (seeded)."""
    pin.seed(3)
    model = pin.Model()
    for name, jm in JOINTS.items():
        model.addJoint(0, jm, pin.SE3.Random(), name)
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    v = np.random.default_rng(3).normal(size=model.nv)
    return model, q, v


def _pinocchio(model, jid, q, v):
    jm = model.joints[jid]
    jd = jm.createData()
    jm.calc(jd, q, v)
    return jd


@pytest.mark.parametrize("name", list(JOINTS))
def test_a_joint_as_sx_equals_pinocchios_calc(zoo, name):
    """M(q), S(q), S v and the bias dS/dt v of the SX joint, evaluated at random (q, v): jdata.M, S, v and c of
    Pinocchio's calc (1e-14 relative); the placement is the model's."""
    model, q, v = zoo
    jid = model.getJointId(name)
    joint = Joint(model, jid, "zoo")
    assert joint.kind == name and joint.parent == 0
    Q, V = cs.SX.sym("q", model.nq), cs.SX.sym("v", model.nv)
    M = joint.motion(Q)
    f = cs.Function("f", [Q, V], [M.R, M.p, joint.subspace(Q), joint.velocity(Q, V), joint.bias(Q, V)])
    R, p, S, vel, bias = (np.array(x) for x in f(q, v))
    jd = _pinocchio(model, jid, q, v)
    for got, want in ((R, jd.M.rotation), (p.ravel(), jd.M.translation), (S, np.asarray(jd.S).reshape(6, -1)),
                      (vel.ravel(), jd.v.vector), (bias.ravel(), jd.c.vector)):
        assert got.shape == want.shape and np.abs(got - want).max() <= 1e-14 * max(1.0, np.abs(want).max())
    assert np.abs(np.array(joint.placement.R) - model.jointPlacements[jid].rotation).max() == 0.0
    if name == "Universal":
        assert np.abs(jd.c.vector).max() > 1e-3  # (the one joint with a bias: the check is not of zeros)


@pytest.mark.parametrize("name", list(JOINTS))
def test_the_tangent_map_and_retraction_follow_pin_integrate(zoo, name):
    """tangent(q) equals central differences of the joint's block of pin.integrate(q, dq) at dq = 0 (1e-8); the
    retraction agrees with integrate to second order (a step 1e-3: within 1e-5; halved: a quarter of that, 10 %)
    and keeps unit blocks unit (1e-15)."""
    model, q, _ = zoo
    jid = model.getJointId(name)
    joint, jm = Joint(model, jid, "zoo"), model.joints[jid]
    rows, cols = slice(jm.idx_q, jm.idx_q + jm.nq), slice(jm.idx_v, jm.idx_v + jm.nv)
    Q = cs.SX.sym("q", model.nq)
    T = np.array(cs.Function("t", [Q], [joint.tangent(Q)])(q))
    h = 1e-6
    fd = np.column_stack([(pin.integrate(model, q, h * e) - pin.integrate(model, q, -h * e))[rows] / (2 * h)
                          for e in np.eye(model.nv)[cols]])
    assert T.shape == (jm.nq, jm.nv) and np.abs(T - fd).max() <= 1e-8
    DQ = cs.SX.sym("dq", model.nv)
    pairs = joint.retract(Q, DQ)
    assert [i for i, _ in pairs] == list(range(jm.idx_q, jm.idx_q + jm.nq))
    moved = cs.Function("r", [Q, DQ], [cs.vertcat(*[e for _, e in pairs])])
    direction = np.zeros(model.nv)
    direction[cols] = np.linspace(1.0, -0.5, jm.nv)
    gaps = []
    for step in (1e-3, 5e-4):
        got = np.array(moved(q, step * direction)).ravel()
        gaps.append(np.abs(got - pin.integrate(model, q, step * direction)[rows]).max())
        unit = {"RUBX": (0, 2), "RUBY": (0, 2), "RUBZ": (0, 2), "Spherical": (0, 4), "FreeFlyer": (3, 7),
                "Planar": (2, 4)}.get(name)
        if unit is not None:
            assert abs(np.linalg.norm(got[unit[0]:unit[1]]) - 1.0) <= 1e-15 * 2
    assert gaps[0] <= 1e-5 and (gaps[1] <= 0.275 * gaps[0] or gaps[0] <= 1e-15)


def test_a_mimic_joint_moves_as_its_leader_scaled_and_offset():
    """A revolute mimicking another with multiplier 2 and offset 0.3: the SX transform and velocity equal Pinocchio's
    (1e-14), it takes its leader's velocity coordinate and has no coordinates of its own; multiplier 0 is refused as
    a fixed joint."""
    pin.seed(4)
    model = pin.Model()
    lead = model.addJoint(0, pin.JointModelRX(), pin.SE3.Random(), "lead")
    follow = model.addJoint(lead, pin.JointModelRevoluteUnaligned(np.array([0.0, 0.6, 0.8])), pin.SE3.Random(),
                            "follow")
    mimic = pin.transformJointIntoMimic(model, lead, follow, 2.0, 0.3)
    joint = Joint(mimic, follow, "m")
    Q, V = cs.SX.sym("q", mimic.nq), cs.SX.sym("v", mimic.nv)
    M = joint.motion(Q)
    R, vel = (np.array(x) for x in cs.Function("f", [Q, V], [M.R, joint.velocity(Q, V)])([0.7], [0.3]))
    jd = _pinocchio(mimic, follow, np.array([0.7]), np.array([0.3]))
    assert np.abs(R - jd.M.rotation).max() <= 1e-14 and np.abs(vel.ravel() - jd.v.vector).max() <= 1e-14
    assert joint.kind == "mimic" and joint.cols == [0] and joint.tangent(Q) is None and joint.retract(Q, V) == []
    with pytest.raises(SpecError, match="joint 'follow': a mimic joint with multiplier 0 is a fixed joint"):
        Joint(pin.transformJointIntoMimic(model, lead, follow, 0.0, 0.3), follow, "m")


def test_a_joint_the_twin_does_not_handle_is_refused_by_name():
    """A SphericalZYX joint: SpecError naming the joint and its Pinocchio type."""
    model = pin.Model()
    jid = model.addJoint(0, pin.JointModelSphericalZYX(), pin.SE3.Identity(), "zyx")
    with pytest.raises(SpecError, match="joint 'zyx': the symbolic twin does not handle a Pinocchio "
                                        "JointModelSphericalZYX"):
        Joint(model, jid, "src")
