"""Planar 3-RRR: properties over random designs, poses, the eight working modes and motions.

Designs from :func:`tests.properties.rrr3_designs` (base side 0.5-2 m, links 0.35-0.6 of it, platform
0.05-0.25 of it, random masses, regular centred reference in a random mode); poses within 5 % of the
base side and 0.2 rad of it.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import assume, given
from hypothesis import strategies as st
from scipy.optimize import brentq

import pkm
from pkm.core import TaskMap, close_loops
from pkm.core.dynamics.projection import virtual_work_dynamics
from pkm.core.kinematics import constraints
from pkm.mechanisms import rrr3
from tests import fd
from tests.properties import (
    DECADES,
    assert_vanishes,
    examples,
    floats,
    forward_acceleration_errors,
    path_derivative_errors,
    path_state,
    power_balance_error,
    reachable,
    record,
    regular,
    rrr3_designs,
    rrr3_pose,
    seed_fraction,
    sines,
    unit_box,
    wrap,
)

modes = st.sampled_from(sorted(rrr3.MODES))


def _case(p, u, mode, margin=1e-2):
    """Mechanism, pose, motor angles and closed-form configuration in ``mode``; regular (the paper's measures
    above 1e-2, the core's above ``margin`` base sides) or rejected."""
    mech = rrr3.build(p)
    y = rrr3_pose(p, u)
    th = reachable(rrr3.closed_form_ik, p, y, mode)
    assume(min(rrr3.singularity_measures(p, y, mode)) > 1e-2)
    q = rrr3.closed_form_configuration(mech, y, mode)
    assume(regular(mech, q, margin * p.H))
    return mech, y, th, q


def _task_error(y1, y0):
    return np.abs(np.r_[y1[:2] - y0[:2], wrap(y1[2] - y0[2])]).max()


@examples(100)
@given(rrr3_designs(), unit_box(3), unit_box(3), modes)
def test_inverse_then_forward_kinematics_gives_the_pose_back(p, u, du, mode):
    """Closed-form IK in any of the eight modes, then the forward kinematics (all assembly modes): the pose
    is among the solutions (1e-9), labelled with its mode; on the design's mode, closed_form_fk seeded with
    the pose returns it; the core's loop closure from a nearby assembly (closer near a direct singularity:
    :func:`seed_fraction`) returns it too (1e-9)."""
    mech, y, th, q = _case(p, u, mode, margin=1e-3)
    sols = rrr3.forward_kinematics(p, th)
    err = [_task_error(s.y, y) for s in sols]
    k = int(np.argmin(err))
    assert record("rrr3 IK->FK (closed form, all modes)", err[k]) <= 1e-9
    assert sols[k].branch == mode
    if mode == f"mode{p.branch}":
        assert _task_error(rrr3.closed_form_fk(p, th, seed=y), y) <= 1e-9
    offset = np.array([0.005 * p.H, 0.005 * p.H, 0.02]) * seed_fraction(mech, q, p.H) * du
    seed = reachable(rrr3.closed_form_configuration, mech, y + offset, mode)
    res = close_loops(mech, th, seed)
    assert record("rrr3 IK->close_loops", _task_error(TaskMap(mech).value(res.q), y)) <= 1e-9


@examples(80)
@given(rrr3_designs(), unit_box(3), modes)
def test_jacobians_match_finite_differences(p, u, mode):
    """J_q^-1 J_x (eqs. 19-20) equals Richardson differences of the closed-form IK and the core's inverse
    Jacobian; the core's forward and inverse Jacobians equal differences of its loop closure and of the IK."""
    mech, y, th, q = _case(p, u, mode)
    Jx, Jq = rrr3.jacobians(p, y, mode)
    J = np.linalg.solve(Jq, Jx)

    def ik(yy):
        return th + wrap(rrr3.closed_form_ik(p, yy, mode) - th)

    def diff(h):
        return np.column_stack([(ik(y + e) - ik(y - e)) / (2 * h) for e in h * np.eye(3)])

    assert record("rrr3 closed-form J vs FD (rel)", fd.rel(J, fd.richardson(diff, 1e-5))) <= 1e-6
    assert record("rrr3 closed-form J vs core (rel)", fd.rel(J, pkm.inverse_jacobian(mech, q))) <= 1e-9
    assert record("rrr3 core forward J vs FD (rel)", fd.forward_jacobian_error(mech, q)) <= 1e-6
    assert record("rrr3 core inverse J vs FD (rel)", fd.inverse_jacobian_error(mech, q, ik)) <= 1e-6


@examples(60)
@given(rrr3_designs(), unit_box(3), modes, sines(3), st.integers(0, 2**32 - 1))
def test_accelerations_match_differences_of_velocities(p, u, mode, motion, seed):
    """Along a random sum of sines, the core's inverse velocities and accelerations are the derivatives of the
    closed-form configuration and of the velocities; along an actuated parabola, its forward accelerations
    are those of its loop closure (1e-6 relative)."""
    mech, y, _, q = _case(p, u, mode)
    motion_at = motion.through(y, np.array([0.02 * p.H, 0.02 * p.H, 0.05]))

    def state(t):
        return path_state(mech, lambda yy: rrr3.closed_form_configuration(mech, yy, mode), motion_at, t)

    ev, ea = path_derivative_errors(mech, state, motion.t)
    assert record("rrr3 inverse velocities vs FD (rel)", ev) <= 1e-6
    assert record("rrr3 inverse accelerations vs FD (rel)", ea) <= 1e-6
    err = forward_acceleration_errors(mech, q, seed)
    assert record("rrr3 forward accelerations vs FD (rel)", err["joint"]) <= 1e-6
    assert record("rrr3 task accelerations vs FD (rel)", err["task"]) <= 1e-6


@examples(40)
@given(rrr3_designs(), floats(math.radians(15), math.radians(45)), floats(-0.2, 0.2), st.sampled_from([1, -1]),
       st.tuples(st.sampled_from([1, -1]), st.sampled_from([1, -1])), floats(0.2, 0.5))
def test_a_stretching_leg_is_approached_as_an_inverse_singularity(p, direction, phi, sign, others, s_max):
    """Leg 1 with its elbow at psi_1 = s (platform vertex A at distance ~ a + b from the base vertex), s -> 0:
    the closed form's J_q[0, 0] / a (eq. 20) equals sin s (1e-9, down to s = 1e-4 s_max: below, the pose
    fixes psi only to sqrt(eps)) and falls monotonically and linearly; the core's sigma_inverse, on the exact
    configuration, to 1e-8 of its start; regular at s_max, inverse at s = 1e-8 s_max (closed form with tol
    1e-6, and core)."""
    mech = rrr3.build(p)
    mode = next(k for k, v in rrr3.MODES.items() if v == (sign, *others))
    index_cf, index_core = [], []
    for k, s in enumerate(sign * s_max * DECADES):
        theta1 = direction - math.atan2(p.b * math.sin(s), p.a + p.b * math.cos(s))
        A = p.a * np.array([math.cos(theta1), math.sin(theta1)]) + p.b * np.array([math.cos(theta1 + s),
                                                                                   math.sin(theta1 + s)])
        y = np.r_[rrr3.centroid_from_a(p, A, phi), phi]
        values = reachable(rrr3.joint_values, p, y, mode)
        values |= {"motor_1": [theta1], "elbow_1": [s], "wrist_1": [float(wrap(phi - theta1 - s))]}
        q = mech.q_from_dict(values)
        assert np.abs(constraints.residual(mech, q)).max() <= 1e-12 * p.H
        assume(rrr3.singularity_measures(p, y, mode)[1] > 1e-2)
        leg1 = rrr3.jacobians(p, y, mode)[1][0, 0] / p.a  # sin psi_1
        if k <= 4:
            assert abs(leg1 - math.sin(s)) <= 1e-9
        index_cf.append(abs(leg1))
        index_core.append(pkm.diagnose(mech, q).sigma_inverse)
        if k == 0:
            assert rrr3.classify_singularity(p, y, mode, tol=1e-6) == "regular"
            assert pkm.diagnose(mech, q).classification == "regular"
    assert rrr3.classify_singularity(p, y, mode, tol=1e-6) == "inverse"
    assert pkm.diagnose(mech, q).classification == "inverse"
    assert_vanishes(index_cf[:5], "rrr3 stretched leg, closed form (to s = 1e-4 s_max)", final=2e-4)
    assert_vanishes(index_core, "rrr3 stretched leg, core sigma_inverse")


def _concurrency(p, y, mode) -> float:
    """How far the three distal-link lines are from meeting in a point (or being parallel), relative to H:
    the distance of line 3 from the intersection of lines 1 and 2 times the sine of the angle of 1 and 2."""
    A = rrr3.a_from_centroid(p, y[:2], y[2])
    V = rrr3.platform_vertices(p, A, y[2])
    Jx, _ = rrr3.jacobians(p, y, mode)
    u = Jx[:, :2]  # distal-link directions
    cross12 = u[0, 0] * u[1, 1] - u[0, 1] * u[1, 0]
    # intersection X = V1 + t u1 of lines 1 and 2, scaled by cross12 to stay finite when they are parallel
    d = V[1] - V[0]
    t_num = d[0] * u[1, 1] - d[1] * u[1, 0]
    Xs = cross12 * V[0] + t_num * u[0]  # = cross12 * X
    r = Xs - cross12 * V[2]
    return abs(r[0] * u[2, 1] - r[1] * u[2, 0]) / p.H


@examples(40)
@given(rrr3_designs(), unit_box(2), floats(0.3, 1.0))
def test_concurrent_distal_links_are_approached_as_a_direct_singularity(p, u, frac):
    """Turning the platform about a fixed centroid until det J_x changes sign (brentq to 1e-15 rad) finds a
    configuration whose distal-link lines are concurrent or parallel (1e-9); approaching it along Phi,
    |det J_x| (closed form) and the core's sigma_direct fall monotonically and linearly to 1e-8 of their start,
    with the class regular at s_max and direct at s = 1e-8 s_max (closed form and core)."""
    mech = rrr3.build(p)
    mode = f"mode{p.branch}"
    xy = rrr3.reference_pose(p)[:2] + 0.03 * p.H * u

    def det(phi):
        return np.linalg.det(rrr3.homogenized_jacobians(p, np.r_[xy, phi], mode)[0])

    grid = np.linspace(-1.2, 1.2, 49)
    vals = []
    for phi in grid:
        try:
            vals.append(det(phi) if rrr3.singularity_measures(p, np.r_[xy, phi], mode)[0] > 1e-2 else np.nan)
        except pkm.PkmError:
            vals.append(np.nan)
    brackets = [k for k in range(len(grid) - 1) if vals[k] * vals[k + 1] < 0]
    assume(brackets)
    k = min(brackets, key=lambda k: abs(grid[k]))
    phi_s = brentq(det, grid[k], grid[k + 1], xtol=1e-15)
    concurrency = _concurrency(p, np.r_[xy, phi_s], mode)
    assert record("rrr3 distal lines concurrency at det J_x = 0 (rel. H)", concurrency) <= 1e-9
    side = 1.0 if grid[k + 1] - phi_s > phi_s - grid[k] else -1.0
    s_max = frac * max(grid[k + 1] - phi_s, phi_s - grid[k])
    index_cf, index_core = [], []
    for j, s in enumerate(s_max * DECADES):
        y = np.r_[xy, phi_s + side * s]
        q = rrr3.closed_form_configuration(mech, y, mode)
        diag = pkm.diagnose(mech, q)
        index_cf.append(rrr3.singularity_measures(p, y, mode)[1])
        index_core.append(diag.sigma_direct)
        if j == 0:
            assume(rrr3.classify_singularity(p, y, mode, tol=1e-6) == "regular" == diag.classification)
    assert rrr3.classify_singularity(p, y, mode) == "direct"
    assert diag.classification == "direct"
    assert_vanishes(index_cf, "rrr3 concurrent distal links, closed form |det J_x|")
    assert_vanishes(index_core, "rrr3 concurrent distal links, core sigma_direct")


@examples(60)
@given(rrr3_designs(), unit_box(3), modes, sines(3))
def test_power_balance_along_random_motions(p, u, mode, motion):
    """Along a random sum of sines, the virtual-work efforts G^T rnea have the power sum tau_i qd_i equal to
    the rate of change of the bodies' energy (1e-8 of the gross power). (Khalil's projection does not cut
    the 3-RRR: its platform closes on two legs through leg 1's chain.)"""
    mech, y, _, _ = _case(p, u, mode)
    motion_at = motion.through(y, np.array([0.02 * p.H, 0.02 * p.H, 0.05]))

    def state(t):
        return path_state(mech, lambda yy: rrr3.closed_form_configuration(mech, yy, mode), motion_at, t)

    efforts = lambda q, v, a: virtual_work_dynamics(mech, q, v, a)
    err = power_balance_error(mech, state, efforts, motion.t)
    assert record("rrr3 power balance (rel. to gross power)", err) <= 1e-8
