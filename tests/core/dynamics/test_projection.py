"""Khalil's projection over the generic core, against independent routes.

Each check has its own source of truth: the whole-tree virtual-work route ``G^T rnea``,
Pinocchio's constrained forward dynamics (``constraintDynamics``: the efforts must give back the
prescribed accelerations) and the energy balance of the bodies along a motion.
"""

import dataclasses
import warnings

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core import Configuration, dynamics
from pkm.errors import SingularityError, SpecError
from pkm.mechanisms import delta, prs3
from tests.fd import richardson

# (mechanism builder, closed-form configuration, nominal task point, task scale)
CASES = {
    "prs3_P": (lambda: prs3.build(), prs3.configuration, np.array([0.8, 0.08, -0.06]), np.array([0.02, 0.05, 0.05])),
    "prs3_R": (lambda: prs3.build(prs3.Prs3Params(actuation="R", gamma=1.2)), prs3.configuration,
               np.array([0.8, 0.08, -0.06]), np.array([0.02, 0.05, 0.05])),
    "delta": (lambda: delta.build(), delta.configuration, np.array([0.03, -0.02, -0.37]), np.full(3, 0.02)),
}


@pytest.fixture(scope="module", params=list(CASES))
def case(request):
    make, conf, y0, scale = CASES[request.param]
    return request.param, make(), conf, y0, scale


def _state(mech, conf, y, yd, ydd):
    q = conf(mech, y)
    v = pkm.inverse_velocities(mech, q, yd)
    return q, v, pkm.inverse_accelerations(mech, q, v, ydd)


def test_partition_finds_the_platform_and_one_leg_per_closure(case):
    """Each leg is one closure's subtree and carries one actuated joint; every joint is in exactly one part."""
    _, mech, *_ = case
    part = dynamics.partition(mech)
    assert len(part.legs) == 3
    assert sorted(k for leg in part.legs for k in leg.actuated_index) == [0, 1, 2]
    joints = np.concatenate([part.platform_v, *(leg.v for leg in part.legs)])
    assert sorted(joints) == list(range(mech.nv))


def test_projection_equals_virtual_work_and_constraint_dynamics(case):
    """Over random states: Khalil = G^T rnea to 1e-10 relative, and constraintDynamics(tau) = a to 1e-8."""
    name, mech, conf, y0, scale = case
    rng = np.random.default_rng(7)
    proj = dynamics.KhalilProjection(mech)
    for _ in range(10):
        y = y0 + scale * rng.uniform(-1, 1, 3)
        q, v, a = _state(mech, conf, y, rng.normal(size=3), rng.normal(size=3))
        tau = proj.inverse_dynamics(q, v, a)
        ref = dynamics.virtual_work_dynamics(mech, q, v, a)
        assert np.linalg.norm(tau - ref) <= 1e-10 * np.linalg.norm(ref), name
        a_back = dynamics.forward_dynamics(mech, q, v, tau)
        assert np.linalg.norm(a_back - a) <= 1e-8 * max(1.0, np.linalg.norm(a)), name


def test_external_wrench_enters_through_the_platform_jacobian(case):
    """A wrench w on the platform changes tau by -J_k^T P_e^T w: checked against G^T (rnea - J_ee^T w)."""
    _, mech, conf, y0, _ = case
    rng = np.random.default_rng(3)
    q, v, a = _state(mech, conf, y0, rng.normal(size=3), rng.normal(size=3))
    w = rng.normal(size=6)
    tau = dynamics.inverse_dynamics(mech, q, v, a, wrench=w)
    import pinocchio as pin
    pin.computeJointJacobians(mech.model, mech.data, q)
    pin.updateFramePlacements(mech.model, mech.data)
    Je = pin.getFrameJacobian(mech.model, mech.data, mech.ee_frame, pin.LOCAL_WORLD_ALIGNED)
    G = pkm.passive_map(mech, q)
    ref = G.T @ (pin.rnea(mech.model, mech.data, q, v, a) - Je.T @ w)
    assert np.allclose(tau, ref, rtol=1e-10, atol=1e-10)


def test_power_balance_along_a_smooth_motion(case):
    """sum tau_i qd_i = dE/dt (kinetic + potential, every body) to 1e-8 relative along a smooth motion.

    dE/dt comes from Richardson-extrapolated central differences of the energy along the motion,
    the state rebuilt at each time by the closed-form IK and the core's inverse velocities.
    """
    _, mech, conf, y0, scale = case
    amp, om, ph = scale, np.array([1.3, 2.1, 0.7]), np.array([0.3, 1.1, 2.0])

    def motion(t):
        return (y0 + amp * np.sin(om * t + ph), amp * om * np.cos(om * t + ph), -amp * om**2 * np.sin(om * t + ph))

    def energy(t):
        y, yd, _ = motion(t)
        q = conf(mech, y)
        return sum(dynamics.energy(mech, q, pkm.inverse_velocities(mech, q, yd)))

    for t in (0.0, 0.4, 1.7):
        q, v, a = _state(mech, conf, *motion(t))
        power = dynamics.inverse_dynamics(mech, q, v, a) @ v[mech.act_v]
        dE = richardson(lambda h, t=t: np.array([(energy(t + h) - energy(t - h)) / (2 * h)]), 1e-3)[0]
        scale_p = np.abs(dynamics.inverse_dynamics(mech, q, v, a)).max() * np.abs(v[mech.act_v]).max()
        assert abs(power - dE) <= 1e-8 * max(scale_p, 1e-12), (t, power, dE)


def test_a_leg_at_its_rank_loss_is_reported_as_an_inverse_singularity():
    """3-PRS leg 1 with its coupler perpendicular to the rail (eq. 10's double root) cannot be projected."""
    mech = prs3.build()
    q = mech.q_reference.copy()
    q[mech.joint("knee_1").idx_q] = 0.0
    with pytest.raises(SingularityError) as err:
        dynamics.KhalilProjection(mech).projection(q)
    assert err.value.kind == "inverse" and "ball_1" in str(err.value)


def test_the_projection_s_measures_scale_with_the_mechanism_and_its_maps_are_joint_rates():
    """Gough-Stewart (prismatic legs, a free-flying platform) scaled by 10: its legs' homogenised singular values
    are 10 times larger and those of M the same (1e-9 relative: the rank decisions are the same at any size), and at
    both sizes the projection's efforts (at rest, gravity) equal the virtual-work route's (1e-9): its maps are given
    back in joint rates."""
    from pkm.core.model.builder import scaled_mechanism
    from pkm.core.model.scale import scale_configuration

    mech = pkm.load("gough_stewart")
    big = scaled_mechanism(mech, 10.0)
    q = mech.q_reference
    p, pb = dynamics.KhalilProjection(mech).projection(q), dynamics.KhalilProjection(big).projection(
        scale_configuration(mech, q, 10.0))
    assert np.isclose(pb.sigma_direct, p.sigma_direct, rtol=1e-9)  # (M = [A; K] homogenised is unit-free)
    assert np.allclose(pb.sigma_leg, 10.0 * np.array(p.sigma_leg), rtol=1e-9)
    zero = np.zeros(mech.nv)
    for m in (mech, big):
        qm = m.q_reference
        assert np.allclose(dynamics.inverse_dynamics(m, qm, zero, zero, method="khalil"),
                           dynamics.inverse_dynamics(m, qm, zero, zero, method="virtual_work"), rtol=1e-9, atol=1e-9)


def test_knee_actuation_with_vertical_rails_is_a_direct_singularity():
    """With vertical rails and the knees driven, the platform rises with every knee locked: M loses rank (the load
    warns that the knees fall short of the mobility)."""
    from pkm.errors import PkmWarning

    with pytest.warns(PkmWarning, match="move the task with every actuator locked"):
        mech = prs3.build(prs3.Prs3Params(actuation="R", reference=(0.81, 0.0, 0.0)))
    with pytest.raises(SingularityError) as err:
        dynamics.KhalilProjection(mech).projection(mech.q_reference)
    assert err.value.kind == "direct"


def test_structures_the_projection_cannot_cut_are_refused(built):
    """The 3-RRR's platform closes on two legs through one chain; the hexapod has mimic joints."""
    for name in ("rrr3", "hexapod"):
        with pytest.raises(SpecError):
            dynamics.partition(built(name))


# ---------------------------------------------------------------------- one call for every mechanism
def _actuated_motion(mech, seed: int):
    """A state function ``t -> (q, v, a)`` along the actuated parabola ``qa0 + t qd + t^2 qdd / 2`` from the
    reference, by the generic core (loop closure, velocities, accelerations)."""
    rng = np.random.default_rng(seed)
    qa0 = mech.actuated_q(mech.q_reference)
    qd, qdd = 0.2 * rng.uniform(-1, 1, mech.na), 0.2 * rng.uniform(-1, 1, mech.na)

    def state(t):
        q = pkm.close_loops(mech, qa0 + t * qd + 0.5 * t * t * qdd, mech.q_reference).q
        v = pkm.velocities(mech, q, qd + t * qdd)
        return q, v, pkm.accelerations(mech, q, v, qdd)
    return state


@pytest.mark.parametrize("name", pkm.mechanisms.names())
def test_every_mechanism_gets_efforts_that_balance_the_power(name, built):
    """pkm.inverse_dynamics on every registered mechanism (the hexapod's mimic joints and the 3-RRR's platform chain
    included): sum tau_i qd_i = dE/dt to 1e-8 relative along an actuated motion, dE/dt by Richardson differences of
    the energy of every body."""
    mech = built(name)
    state = _actuated_motion(mech, 11)

    def energy(t):
        q, v, _ = state(t)
        return sum(dynamics.energy(mech, q, v))

    q, v, a = state(0.0)
    tau = pkm.inverse_dynamics(mech, q, v, a)
    power = tau @ v[mech.act_v]
    dE = richardson(lambda h: np.array([(energy(h) - energy(-h)) / (2 * h)]), 1e-3)[0]
    assert abs(power - dE) <= 1e-8 * max(np.abs(tau).max() * np.abs(v[mech.act_v]).max(), 1e-12), (power, dE)


@pytest.mark.parametrize("name", ["delta", "prs3"])
def test_khalil_and_virtual_work_agree_where_both_apply_with_wrenches_on_any_frame(name, built):
    """On the mechanisms Khalil's projection cuts, both methods give the same efforts (1e-10 relative), with an
    external wrench at the end effector and another on a leg's frame; the wrench's share balances its power."""
    mech = built(name)
    q, v, a = _actuated_motion(mech, 12)(0.0)
    leg_frame = "forearm_1_tip" if name == "delta" else "coupler_1_tip"
    w_ee, w_leg = np.array([1.0, -2.0, 3.0, 0.1, 0.2, -0.3]), np.array([-0.5, 0.4, 0.3, 0.02, -0.01, 0.05])
    kw = {"wrench": w_ee, "wrenches": {leg_frame: w_leg}}
    t_k = pkm.inverse_dynamics(mech, q, v, a, method="khalil", **kw)
    t_v = pkm.inverse_dynamics(mech, q, v, a, method="virtual_work", **kw)
    assert np.abs(t_k - t_v).max() <= 1e-10 * np.abs(t_v).max()
    share = t_k - pkm.inverse_dynamics(mech, q, v, a, method="khalil")
    c = Configuration.at(mech, q)
    data = mech.model.createData()
    pin.computeJointJacobians(mech.model, data, q)
    pin.updateFramePlacements(mech.model, data)
    leg_twist = pin.getFrameJacobian(mech.model, data, mech.model.getFrameId(leg_frame), pin.LOCAL_WORLD_ALIGNED) @ v
    external = w_ee @ (c.ee_jacobian @ v) + w_leg @ leg_twist  # the wrenches' power on the mechanism
    assert abs(share @ v[mech.act_v] + external) <= 1e-10 * max(abs(external), 1.0)  # the actuators take it back


def test_an_idle_motion_changes_no_effort():
    """The five-bar with a massless-about-its-axis spinning rod needs the efforts of the plain five-bar (1e-12)."""
    from tests.core.differential.test_velocity import _fivebar_with_spinning_rod
    from tests.fivebar import inverse_kinematics

    spin, plain = _fivebar_with_spinning_rod()
    y = pkm.TaskMap.of(plain).value(plain.q_reference) + np.array([0.01, -0.02])
    q0 = plain.q_from_dict(inverse_kinematics(plain.params, y))
    q1 = spin.q_from_dict({**inverse_kinematics(plain.params, y), "spin_1": [0.7]})
    qd, qdd = np.array([0.3, -0.2]), np.array([1.0, 0.5])
    v0, v1 = pkm.velocities(plain, q0, qd), pkm.velocities(spin, q1, qd)
    a0, a1 = pkm.accelerations(plain, q0, v0, qdd), pkm.accelerations(spin, q1, v1, qdd)
    np.testing.assert_allclose(pkm.inverse_dynamics(spin, q1, v1, a1), pkm.inverse_dynamics(plain, q0, v0, a0),
                               rtol=0, atol=1e-12)


def test_bad_methods_frames_and_refused_structures_say_so(built):
    from pkm.errors import InvalidInputError, UnknownNameError

    mech = built("delta")
    q, v = mech.q_reference, np.zeros(mech.nv)
    with pytest.raises(InvalidInputError, match="method"):
        pkm.inverse_dynamics(mech, q, v, v, method="newton")
    with pytest.raises(UnknownNameError, match="no_such_frame"):
        pkm.inverse_dynamics(mech, q, v, v, wrenches={"no_such_frame": np.zeros(6)})
    with pytest.raises(InvalidInputError):
        pkm.inverse_dynamics(mech, q, v, v, wrenches={"platform": np.zeros(5)})
    with pytest.raises(SpecError, match="drives the platform directly"):
        pkm.inverse_dynamics(built("rrr3"), built("rrr3").q_reference, np.zeros(built("rrr3").nv),
                             np.zeros(built("rrr3").nv), method="khalil")


def test_a_floating_base_reports_the_wrench_the_motion_asks_of_it():
    """At rest, the base held: the holder's wrench is the robot's weight carried at the base, world-aligned
    ``(-m g, -(c - p) x m g)`` (c the centre of mass, p the base's origin; 1e-10), and the base-frame wrench is the
    same turned into the base's axes. The base free, a motion the free robot cannot make (pkm.accelerations keeps
    the base still: gravity would need a wrench) warns and says so; the held base does not warn."""
    import warnings

    from pkm.errors import InvalidInputError, PkmWarning
    from tests.core.dynamics.floating import floating

    mech = floating("delta")
    q0 = mech.q_reference.copy()
    at = mech.base.idx_q
    R = pin.rpy.rpyToMatrix(0.4, -0.3, 0.8)
    q0[at:at + 7] = np.r_[[0.2, -0.1, 0.7], pin.Quaternion(R).coeffs()]
    q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + 0.05, q0).q
    rest = np.zeros(mech.nv)
    held = pkm.base_inverse_dynamics(mech, q, rest, rest, base="fixed")
    m, g = pin.computeTotalMass(mech.model), mech.model.gravity.linear
    c = pin.centerOfMass(mech.model, mech.data, q)
    weight = np.r_[-m * g, -np.cross(c - q0[at:at + 3], m * g)]
    assert np.abs(held.base_wrench_world - weight).max() <= 1e-10 * m * 9.81
    assert np.abs(held.base_wrench - np.r_[R.T @ weight[:3], R.T @ weight[3:]]).max() <= 1e-10 * m * 9.81
    assert held.base == "fixed" and not held.needs_base_wrench
    v = pkm.velocities(mech, q, [0.2, -0.1, 0.3])
    a = pkm.accelerations(mech, q, v, [1.0, 0.0, -1.0])
    with pytest.warns(PkmWarning, match="asks a wrench of the free floating base"):
        tau = pkm.inverse_dynamics(mech, q, v, a)
    free = pkm.base_inverse_dynamics(mech, q, v, a)
    assert free.needs_base_wrench and np.array_equal(free.efforts, tau)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.array_equal(pkm.inverse_dynamics(mech, q, v, a, base="fixed"), tau)
    with pytest.raises(InvalidInputError, match="no floating base"):
        delta_fixed = pkm.load("delta")
        pkm.base_inverse_dynamics(delta_fixed, delta_fixed.q_reference, np.zeros(delta_fixed.nv),
                                  np.zeros(delta_fixed.nv))


def test_redundant_actuation_auto_takes_the_virtual_work_convention_the_other_routes_share():
    """The Delta with a knee actuated too (the efforts not unique, Khalil's projection applies): "auto" took
    Khalil's least-squares distribution (0.08 N m from the virtual work's, which pkm.actuator_model and the
    Kernels give); now the virtual work's, equal to the actuator-space model's to 1e-12; Khalil's stays another valid
    one: each does the Delta's own efforts' work through the knee's rate map (T^T tau, an independent route)."""
    d = pkm.load("delta")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pkm.errors.PkmWarning)  # (knee_1 depends on the motors)
        mech = pkm.from_strings(d.urdf, dataclasses.replace(d.spec, actuated=d.actuated_names + ("knee_1",)))
    assert mech.dependent_actuators == ("knee_1",)
    q = pkm.solve_ik(d, [0.02, 0.01, -0.36]).q
    T = pkm.passive_map(d, q)[mech.act_v]  # (the four actuated rates of the three motors')
    v = pkm.velocities(d, q, [0.3, -0.2, 0.1])
    a = pkm.accelerations(d, q, v, [1.0, -0.5, 0.2])
    tau = pkm.inverse_dynamics(mech, q, v, a)
    scale = np.abs(tau).max()
    assert np.abs(tau - pkm.inverse_dynamics(mech, q, v, a, method="virtual_work")).max() <= 1e-12 * scale
    assert np.abs(tau - pkm.actuator_model(mech, q, v[mech.act_v]).efforts(a[mech.act_v])).max() <= 1e-12 * scale
    khalil = pkm.inverse_dynamics(mech, q, v, a, method="khalil")
    assert np.abs(khalil - tau).max() > 1e-3 * scale
    for t in (tau, khalil):
        assert np.abs(T.T @ t - pkm.inverse_dynamics(d, q, v, a)).max() <= 1e-12 * scale
