"""Joint springs in the dynamics (``[springs]``, pkm.core.model.springs): a four-bar in MJCF whose three hinges carry
springs about rest angles (the coupler's with damping) checked against the derivative of its potential, its own
round trips (inverse, forward, Pinocchio's constraintDynamics), MuJoCo on the written file (the loop rigid) and the
energy of pkm.simulate released from rest; the compiled twin's model equals the Python one."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.bench.mujoco_baseline import MujocoRigid, unavailable
from pkm.core.dynamics.projection import energy
from pkm.core.formats.to_mjcf import mjcf_from_mechanism
from tests.fd import rel

FOURBAR = Path(__file__).resolve().parents[3] / "examples" / "mjcf_fourbar" / "fourbar.xml"
#: The crank (actuated), the coupler (damped) and the rocker sprung about rest angles in degrees (the MJCF's unit).
SPRUNG = {'<joint name="crank_joint" range="-180 180"/>':
          '<joint name="crank_joint" range="-180 180" stiffness="0.3" springref="5"/>',
          '<joint name="coupler_joint"/>': '<joint name="coupler_joint" stiffness="0.8" springref="10" damping="0.02"/>',
          '<joint name="rocker_joint"/>': '<joint name="rocker_joint" stiffness="0.5" springref="-20"/>'}


@pytest.fixture(scope="module")
def sprung(tmp_path_factory) -> pkm.Mechanism:
    text = FOURBAR.read_text()
    for old, new in SPRUNG.items():
        text = text.replace(old, new)
    path = tmp_path_factory.mktemp("springs") / "fourbar.xml"
    path.write_text(text)
    return pkm.load(path)


@pytest.fixture(scope="module")
def rigid(sprung) -> pkm.Mechanism:
    """The same four-bar without its springs (nor the coupler's damping)."""
    return pkm.from_strings(sprung.urdf, dataclasses.replace(sprung.spec, springs={}))


def _state(mech: pkm.Mechanism, qa: float = 0.3, qd: float = 1.0, qdd: float = 2.0):
    q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + qa).q
    v = pkm.velocities(mech, q, [qd])
    return q, v, pkm.accelerations(mech, q, v, [qdd])


def test_the_springs_are_read_as_efforts_and_the_damping_as_friction(sprung, tmp_path):
    """The stiffness and rest (degrees to rad) of the three hinges; the coupler's damping is Pinocchio's ``damping``
    there (the joint's viscous friction); the efforts ``-k (q - rest)`` on those joints alone; pkm's MJCF writer
    writes them and the file reads back as the same springs (1e-15)."""
    s = sprung.springs
    assert s.names == ("crank_joint", "coupler_joint", "rocker_joint")
    assert np.allclose(s.rest, np.deg2rad([5.0, 10.0, -20.0]), rtol=0, atol=1e-15)
    assert list(np.asarray(sprung.model.damping)) == [0.0, 0.02, 0.0]
    q = sprung.q_reference
    assert np.allclose(s.efforts(q), -np.array([0.3, 0.8, 0.5]) * (q - s.rest), rtol=0, atol=1e-15)
    (tmp_path / "written.xml").write_text(mjcf_from_mechanism(sprung))
    back = pkm.load(tmp_path / "written.xml").spec.springs
    assert back.keys() == sprung.spec.springs.keys()
    assert all(abs(back[j].get(k, 0.0) - v) <= 1e-15 for j, t in sprung.spec.springs.items() for k, v in t.items())


def test_a_spring_s_effort_is_the_derivative_of_its_potential(sprung, rigid):
    """Joint by joint, ``τ_s = -dV_s/dq`` (central differences of ``½ k (q - rest)²``, 1e-9); on the closed
    mechanism the static efforts ``g_a`` are ``dV/dq_a`` of the whole potential (gravity's and the springs',
    :func:`energy`) along the closed motion and :func:`pkm.spring_efforts` that of the springs' alone
    (Richardson-extrapolated central differences, 1e-8 relative); the springs change ``g_a`` by their share."""
    s, q = sprung.springs, _state(sprung)[0]
    h = 1e-6
    fd = [(s.energy(q + h * e) - s.energy(q - h * e)) / (2 * h) for e in np.eye(sprung.model.nq)]
    assert rel(-s.efforts(q), fd) <= 1e-9
    qa = sprung.actuated_q(q)

    def along(f, step):
        ends = [pkm.close_loops(sprung, qa + x, q).q for x in (step, -step)]
        return (f(ends[0]) - f(ends[1])) / (2 * step)

    for f, expected in ((lambda x: energy(sprung, x, np.zeros(sprung.nv))[1], pkm.gravity_efforts(sprung, q)),
                        (s.energy, pkm.spring_efforts(sprung, q))):
        d = (4 * along(f, 5e-5) - along(f, 1e-4)) / 3
        assert rel(expected, [d]) <= 1e-8
    assert rel(pkm.gravity_efforts(sprung, q) - pkm.spring_efforts(sprung, q), pkm.gravity_efforts(rigid, q)) <= 1e-12
    assert abs(pkm.spring_efforts(sprung, q)[0]) > 0.1 * abs(pkm.gravity_efforts(rigid, q)[0])


def test_inverse_and_forward_dynamics_round_trip_with_springs(sprung, rigid):
    """Efforts to accelerations (the model; Pinocchio's constraintDynamics with the springs' efforts applied, 1e-9)
    and back (1e-10); the efforts are the spring-free mechanism's plus :func:`pkm.spring_efforts` (the damping,
    friction, stays out of the inverse dynamics as a drive's does)."""
    q, v, a = _state(sprung)
    tau = np.array([0.4])
    a_model = pkm.forward_dynamics(sprung, q, v, tau)
    assert rel(pkm.forward_dynamics(sprung, q, v, tau, method="constraint_dynamics"), a_model) <= 1e-9
    assert rel(pkm.inverse_dynamics(sprung, q, v, a_model), tau) <= 1e-10
    assert rel(pkm.inverse_dynamics(sprung, q, v, a),
               pkm.inverse_dynamics(rigid, q, v, a) + pkm.spring_efforts(sprung, q)) <= 1e-12
    model = pkm.actuator_model(sprung, q, v)
    assert rel(model.efforts(sprung.actuated_q(a)), pkm.inverse_dynamics(sprung, q, v, a)) <= 1e-10
    assert rel(model.h - pkm.actuator_model(rigid, q, v).h, model.springs) <= 1e-12


def test_khalil_s_projection_and_virtual_work_agree_on_a_sprung_delta(built):
    """A Delta with springs on a motor and on a passive knee: Khalil's projection (the legs' own Newton-Euler) and
    virtual work give the same efforts (1e-10), those of the forward dynamics (model and constraintDynamics), and
    differ from the unsprung Delta's by the springs' share."""
    delta = built("delta")
    sprung = pkm.from_strings(delta.urdf, dataclasses.replace(delta.spec, springs={
        "motor_2": {"stiffness": 3.0, "rest": 0.2}, "knee_1": {"stiffness": 5.0, "rest": -0.3}}))
    q = pkm.solve_ik(sprung, [0.02, 0.01, -0.36]).q
    v = pkm.inverse_velocities(sprung, q, [0.05, 0.0, 0.1])
    tau = np.array([0.3, -0.2, 0.5])
    a = pkm.forward_dynamics(sprung, q, v, tau)
    assert rel(pkm.forward_dynamics(sprung, q, v, tau, method="constraint_dynamics"), a) <= 1e-9
    for method in ("khalil", "virtual_work"):
        assert rel(pkm.inverse_dynamics(sprung, q, v, a, method=method), tau) <= 1e-10
    share = pkm.spring_efforts(sprung, q)
    assert rel(pkm.inverse_dynamics(delta, q, v, a) + share, tau) <= 1e-10 and np.abs(share).min() > 1e-3


def test_a_damping_on_an_actuated_joint_adds_to_its_drive_s(rigid, tmp_path):
    """A spring's damping on the driven crank is in parallel with the drive's viscous friction: Pinocchio's
    ``damping`` is their sum (exact), the drive keeps its own; the MJCF written has the sum, read back as the drive's
    viscous (the same friction)."""
    spec = dataclasses.replace(rigid.spec, springs={"crank_joint": {"stiffness": 1.0, "damping": 0.1}},
                               actuators={"crank_joint": {"viscous": 0.05}})
    mech = pkm.from_strings(rigid.urdf, spec)
    assert mech.model.damping[mech.act_v[0]] == 0.1 + 0.05 and mech.actuators[0].viscous == 0.05
    (tmp_path / "crank.xml").write_text(mjcf_from_mechanism(mech))
    back = pkm.load(tmp_path / "crank.xml")
    assert back.actuators[0].viscous == 0.1 + 0.05 and back.model.damping[back.act_v[0]] == 0.1 + 0.05


@pytest.mark.skipif(unavailable() is not None, reason="MuJoCo is a benchmark-only dependency")
def test_mujoco_on_the_written_file_has_the_same_springs_and_efforts(sprung):
    """The written MJCF (:func:`~pkm.core.formats.to_mjcf.mjcf_from_mechanism`) carries the springs: MuJoCo's
    ``qfrc_spring`` is pkm's ``τ_s`` and its ``qfrc_damper`` the coupler's ``-c v`` (1e-12), and its rigid inverse
    dynamics (the benchmarks' baseline, :class:`~pkm.bench.mujoco_baseline.MujocoRigid`: ``B τ + J_cᵀ λ = rne -
    qfrc_spring``, the loop hard) equals pkm.inverse_dynamics (1e-9)."""
    import mujoco

    mj = MujocoRigid(sprung)
    m, d = mj.model, mj.data
    for qa in (0.3, -0.8):
        q, v, a = _state(sprung, qa)
        mj._state(q, v, a)
        mujoco.mj_fwdPosition(m, d)
        mujoco.mj_comVel(m, d)
        mujoco.mj_passive(m, d)
        dof = [int(m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n)]) for n in sprung.springs.names]
        assert np.abs(d.qfrc_spring[dof] - sprung.springs.efforts(q)).max() <= 1e-12
        assert np.abs(d.qfrc_damper[dof] + np.asarray(sprung.model.damping) * v).max() <= 1e-12
        tau = pkm.inverse_dynamics(sprung, q, v, a)
        assert np.abs(mj.efforts(q, v, a) - tau).max() <= 1e-9 * max(1.0, np.abs(tau).max())  # (the baseline's)


@pytest.mark.skipif(unavailable() is not None, reason="MuJoCo is a benchmark-only dependency")
def test_mujoco_follows_pkm_simulate_on_the_released_sprung_four_bar(sprung):
    """Released at rest away from its equilibrium, no effort: MuJoCo's RK4 on the written file (its loop soft, its
    damping on) follows pkm.simulate (friction on: the coupler's damping) over 0.2 s within 1e-5 rad of the crank,
    which swings by more than 0.1 rad."""
    import mujoco

    mj = MujocoRigid(sprung)
    m, d = mj.model, mj.data
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    q0 = pkm.close_loops(sprung, sprung.actuated_q(sprung.q_reference) + 0.3).q
    zero = np.zeros(sprung.nv)
    mj._state(q0, zero, zero)
    d.qvel[:], d.ctrl[:] = 0.0, 0.0
    crank = int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "crank_joint")])
    steps = round(0.2 / m.opt.timestep)
    mujoco_crank = []
    for _ in range(steps):
        mujoco.mj_step(m, d)
        mujoco_crank.append(d.qpos[crank])
    run = pkm.simulate(sprung, q0, duration=0.2, dt=m.opt.timestep, backend="python")
    assert run.event is None and np.ptp(run.actuated[:, 0]) > 0.1
    assert np.abs(np.array(mujoco_crank) - run.actuated[1:, 0]).max() <= 1e-5


def test_a_released_sprung_mechanism_keeps_its_energy(sprung):
    """Released at rest away from equilibrium: without friction kinetic + gravity + spring energy stays within 1e-7 of
    the largest kinetic energy (RK4, 1 ms); with the coupler's damping it falls, and with the energy dissipated it
    balances (1e-4 of the dissipated, the trapezoidal rule's); the potential is gravity's plus ``½ k (q - rest)²``."""
    q0 = pkm.close_loops(sprung, sprung.actuated_q(sprung.q_reference) + 0.3).q
    free = pkm.simulate(sprung, q0, duration=0.1, dt=1e-3, friction=False, backend="python")
    assert free.event is None and free.kinetic.max() > 1e-3
    assert np.abs(free.energy - free.energy[0]).max() <= 1e-7 * free.kinetic.max()
    q = free.q[-1]
    gravity = pin.computePotentialEnergy(sprung.model, sprung.model.createData(), q)
    assert free.potential[-1] == pytest.approx(gravity + sprung.springs.energy(q), rel=1e-14)
    assert sprung.springs.energy(q) > 0.1 * free.kinetic.max()
    damped = pkm.simulate(sprung, q0, duration=0.1, dt=1e-3, backend="python")
    assert np.all(np.diff(damped.dissipated) > 0.0)
    balance = damped.energy - damped.energy[0] + damped.dissipated
    assert np.abs(balance).max() <= 1e-4 * damped.dissipated[-1]


def test_the_twin_s_model_equals_the_python_model_with_springs(sprung):
    """The twin (pkm.Kernels, numpy route: the expressions the C, JAX and Warp targets are generated from): ``M_a``,
    ``h_a``, ``g_a`` and the forward dynamics with and without friction equal pkm.actuator_model's (1e-10), springs
    and damping in."""
    from pkm.core.twin.kernels import Kernels

    K = Kernels(sprung, compiled=False)
    rng = np.random.default_rng(0)
    Q = np.array([_state(sprung, x)[0] for x in (0.3, -0.6)])
    QD, TAU = rng.standard_normal((2, 1)), rng.standard_normal((2, 1))
    M, h = K.mass_and_bias(Q, QD)
    g, free, rubbing = K.gravity(Q), K.forward_dynamics(Q, QD, TAU), K.forward_dynamics(Q, QD, TAU, friction=True)
    for k in range(2):
        model = pkm.actuator_model(sprung, Q[k], QD[k])
        for got, ref in ((M[k], model.M), (h[k], model.h), (g[k], model.g), (free[k], model.accelerations(TAU[k],
                         friction=False)), (rubbing[k], model.accelerations(TAU[k]))):
            assert rel(np.ravel(got), np.ravel(ref)) <= 1e-10
        assert abs(model.springs[0]) > 1e-2 * abs(model.g[0])


def test_a_free_base_carries_the_springs_internal_efforts():
    """The four-bar under a free pelvis, springs on its coupler and rocker: the forward dynamics (the model, and
    Pinocchio's constraintDynamics with the springs' efforts, 1e-8) asks no wrench of the base in
    pkm.base_inverse_dynamics, which gives the efforts back (1e-9); released spinning, no effort and no friction, the
    energy (kinetic, gravity, springs) stays within 1e-7 of the kinetic energy over 20 ms."""
    from tests.core.dynamics.floating import floating

    base = floating("fourbar")
    mech = pkm.from_strings(base.urdf, dataclasses.replace(base.spec, springs={
        "coupler_joint": {"stiffness": 0.8, "rest": 0.4}, "rocker_joint": {"stiffness": 0.5, "rest": -0.3}}))
    q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + 0.05, mech.q_reference).q
    v = np.zeros(mech.nv)
    v[mech.base_v], v[mech.act_v] = [0.3, -0.2, 0.5, 1.0, -0.5, 2.0], 0.4
    v = pkm.actuator_model(mech, q, v).v  # (the joint rates of the base's twist and the actuated rate)
    tau = np.array([0.05])
    a = pkm.forward_dynamics(mech, q, v, tau)
    assert rel(pkm.forward_dynamics(mech, q, v, tau, method="constraint_dynamics"), a) <= 1e-8
    out = pkm.base_inverse_dynamics(mech, q, v, a)
    assert not out.needs_base_wrench and rel(out.efforts, tau) <= 1e-9
    run = pkm.simulate(mech, q, v, duration=0.02, dt=1e-3, friction=False, limits=False, backend="python")
    assert run.event is None and abs(mech.springs.energy(q)) > 1e-3 * run.kinetic.max()
    assert np.abs(run.energy - run.energy[0]).max() <= 1e-7 * run.kinetic.max()
