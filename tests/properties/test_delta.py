"""Delta: properties over random designs, poses, working modes and motions.

Designs from :func:`tests.properties.delta_designs` (arm 5-30 cm, forearm 2.2-3.5 arms, random
radii and masses, reference pose on the axis); poses within a quarter arm length of it; each arm
on either knee branch.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

import pkm
from pkm.core import TaskMap, close_loops
from pkm.core.dynamics.projection import KhalilProjection, virtual_work_dynamics
from pkm.core.kinematics import constraints
from pkm.errors import SingularityError
from pkm.mechanisms import delta as D
from tests import fd
from tests.properties import (
    DECADES,
    assert_vanishes,
    delta_designs,
    delta_pose,
    examples,
    floats,
    forward_acceleration_errors,
    path_derivative_errors,
    path_state,
    power_balance_error,
    reachable,
    record,
    regular,
    seed_fraction,
    sines,
    two_link_reach,
    unit_box,
    wrap,
)

branch_sets = st.tuples(*[st.sampled_from(sorted(D.BRANCHES))] * 3)


def _case(p, u, branches, margin=1e-2):
    """The mechanism, pose, motor angles and closed-form configuration; regular (both singularity measures above
    ``margin`` arm lengths) or rejected."""
    mech = D.build(p)
    y = delta_pose(p, u)
    th = reachable(D.inverse_kinematics, p, y, branches)
    q = D.configuration(mech, y, branches)
    assume(regular(mech, q, margin * p.La))
    return mech, y, th, q


@examples(120)
@given(delta_designs(), unit_box(3), unit_box(3), branch_sets)
def test_inverse_then_forward_kinematics_gives_the_pose_back(p, u, du, branches):
    """Closed-form IK then the sphere intersection returns the pose (1e-9 m), as the lower root exactly when the
    pose is below the plane of the sphere centres; the core's loop closure, seeded with a nearby assembly on
    the same branches (0.02 La away, less near a direct singularity: :func:`seed_fraction`), returns it too
    (1e-9 m)."""
    mech, y, th, q = _case(p, u, branches, margin=1e-3)
    roots = D.forward_kinematics(p, th, both=True)
    err = np.abs(roots - y).max(axis=1)
    assert record("delta IK->FK (closed form) [m]", err.min()) <= 1e-9
    c = D.sphere_centres(p, th)
    n = np.cross(c[1] - c[0], c[2] - c[0])
    below = (y - c[0]) @ (n if n[2] > 0 else -n) < 0
    assert int(np.argmin(err)) == (0 if below else 1)
    seed = reachable(D.configuration, mech, y + 0.02 * p.La * seed_fraction(mech, q, p.La) * du, branches)
    res = close_loops(mech, th, seed)
    assert record("delta IK->close_loops [m]", np.abs(TaskMap(mech).value(res.q) - y).max()) <= 1e-9


@examples(80)
@given(delta_designs(), unit_box(3), branch_sets)
def test_jacobians_match_finite_differences(p, u, branches):
    """The closed-form J = A^-1 diag(d) equals Richardson differences of the sphere intersection and the core's
    forward Jacobian; the core's forward and inverse Jacobians equal differences of its loop closure and of the
    closed-form IK (all 1e-6 relative)."""
    mech, y, th, q = _case(p, u, branches)
    root = int(np.argmin(np.abs(D.forward_kinematics(p, th, both=True) - y).max(axis=1)))
    J = D.jacobian(p, th, y)

    def diff(h):
        return np.column_stack([(D.forward_kinematics(p, th + e, both=True)[root]
                                 - D.forward_kinematics(p, th - e, both=True)[root]) / (2 * h) for e in h * np.eye(3)])

    assert record("delta closed-form J vs FD (rel)", fd.rel(J, fd.richardson(diff, 1e-5))) <= 1e-6
    assert record("delta closed-form J vs core (rel)", fd.rel(J, pkm.forward_jacobian(mech, q))) <= 1e-9
    assert record("delta core forward J vs FD (rel)", fd.forward_jacobian_error(mech, q)) <= 1e-6
    ik = lambda yy: th + wrap(D.inverse_kinematics(p, yy, branches) - th)
    assert record("delta core inverse J vs FD (rel)", fd.inverse_jacobian_error(mech, q, ik)) <= 1e-6


@examples(60)
@given(delta_designs(), unit_box(3), branch_sets, sines(3), st.integers(0, 2**32 - 1))
def test_accelerations_match_differences_of_velocities(p, u, branches, motion, seed):
    """Along a random sum of sines in task space, the core's inverse velocities and accelerations are the time
    derivatives of the closed-form configuration and of the velocities; along an actuated parabola, its
    forward accelerations (drift included) are those of its loop closure (all 1e-6 relative)."""
    mech, y, _, q0 = _case(p, u, branches)
    scale = np.full(3, 0.05 * p.La)
    motion_at = motion.through(y, scale)

    def state(t):
        return path_state(mech, lambda y: D.configuration(mech, y, branches), motion_at, t)

    ev, ea = path_derivative_errors(mech, state, motion.t)
    assert record("delta inverse velocities vs FD (rel)", ev) <= 1e-6
    assert record("delta inverse accelerations vs FD (rel)", ea) <= 1e-6
    err = forward_acceleration_errors(mech, q0, seed)
    assert record("delta forward accelerations vs FD (rel)", err["joint"]) <= 1e-6
    assert record("delta task accelerations vs FD (rel)", err["task"]) <= 1e-6


def _axis_configuration(mech, p, theta, knee, z):
    """The three arms at motor angle ``theta`` with the forearm turned by ``knee`` in the arm plane, platform on
    the axis at height ``z`` (exact: no inverse kinematics, so a knee of 1e-9 rad stays 1e-9 rad)."""
    values = {"platform_x": [0.0], "platform_y": [0.0], "platform_z": [z]}
    for n in (1, 2, 3):
        values |= {f"motor_{n}": [theta], f"knee_{n}": [float(wrap(knee))], f"knee_{n}_b": [0.0]}
    q = mech.q_from_dict(values)
    assert np.abs(constraints.residual(mech, q)).max() <= 1e-12 * (p.La + p.Lb)
    return q


@examples(40)
@given(delta_designs(), st.sampled_from(sorted(D.BRANCHES)), floats(0.2, 0.6))
def test_stretched_arms_are_approached_as_an_inverse_singularity(p, branch, s_max):
    """Platform on the axis with every forearm turned by s from its arm (towards the branch's side), s -> 0:
    the closed-form index min|d_i| / (La Lb) equals |sin s| (1e-9), it and the core's sigma_inverse fall
    monotonically and linearly to 1e-8 of their start, and the core classifies regular at s_max, inverse at
    s = 1e-8 s_max and at s = 0."""
    mech = D.build(p)
    sign = D.BRANCHES[branch]  # knee_out: knee < 0
    index_cf, index_core = [], []
    for s in [*(sign * s_max * DECADES), 0.0]:
        theta, z = two_link_reach(p.La, p.Lb, s, p.r - p.R)
        q = _axis_configuration(mech, p, theta, s, z)
        _, d = D.jacobian_factors(p, np.array([0.0, 0.0, z]), np.full(3, theta))
        assert abs(np.abs(d).min() / (p.La * p.Lb) - abs(math.sin(s))) <= 1e-9
        diag = pkm.diagnose(mech, q)
        index_cf.append(np.abs(d).min() / (p.La * p.Lb))
        index_core.append(diag.sigma_inverse)
        expected = "regular" if abs(s) == s_max else "inverse" if abs(s) <= 1e-8 * s_max else None
        if expected:
            assert diag.classification == expected, (s, diag)
    assert_vanishes(index_cf[:-1], "delta stretched arms, closed form")
    assert_vanishes(index_core[:-1], "delta stretched arms, core sigma_inverse")


@examples(40)
@given(delta_designs(offset=(0.3, 0.8)), floats(0.01, 0.03))
def test_vertical_forearms_are_approached_as_a_direct_singularity(p, s_max):
    """Knee in, platform on the axis, every forearm tilted by s from the vertical in its arm plane, s -> 0:
    the smallest singular value of A / Lb equals sqrt(3/2) |sin s| (1e-9), it and the core's sigma_direct
    fall monotonically and linearly to 1e-8 of their start, the core classifies regular at s_max, direct
    at s = 1e-8 s_max and at s = 0, where the closed-form Jacobian raises SingularityError('direct')."""
    mech = D.build(p)
    index_cf, index_core = [], []
    for s in [*(-s_max * DECADES), 0.0]:
        theta = -math.acos((p.r - p.R - p.Lb * math.sin(s)) / p.La)  # arm down and inwards
        z = p.La * math.sin(theta) - p.Lb * math.cos(s)
        q = _axis_configuration(mech, p, theta, -math.pi / 2 + s - theta, z)
        assert mech.on_branch(q, "knee_in")
        A, _ = D.jacobian_factors(p, np.array([0.0, 0.0, z]), np.full(3, theta))
        smin = np.linalg.svd(A / p.Lb, compute_uv=False)[-1]
        assert abs(smin - math.sqrt(1.5) * abs(math.sin(s))) <= 1e-9
        diag = pkm.diagnose(mech, q)
        index_cf.append(smin)
        index_core.append(diag.sigma_direct)
        expected = "regular" if abs(s) == s_max else "direct" if abs(s) <= 1e-8 * s_max else None
        if expected:
            assert diag.classification == expected, (s, diag)
    with pytest.raises(SingularityError) as err:
        D.jacobian(p, np.full(3, theta), [0.0, 0.0, z])
    assert err.value.kind == "direct"
    assert_vanishes(index_cf[:-1], "delta vertical forearms, closed form")
    assert_vanishes(index_core[:-1], "delta vertical forearms, core sigma_direct")


@examples(60)
@given(delta_designs(), unit_box(3), branch_sets, sines(3))
def test_power_balance_along_random_motions(p, u, branches, motion):
    """Along a random sum of sines, Khalil's projection (= G^T rnea, 1e-9) gives efforts whose power
    sum tau_i qd_i equals the rate of change of the bodies' energy (1e-8 of the gross power)."""
    mech, y, _, _ = _case(p, u, branches)
    proj = KhalilProjection(mech)
    scale = np.full(3, 0.05 * p.La)
    motion_at = motion.through(y, scale)

    def state(t):
        return path_state(mech, lambda y: D.configuration(mech, y, branches), motion_at, t)

    q, v, a = state(motion.t)
    tau = proj.inverse_dynamics(q, v, a)
    assert record("delta Khalil vs G^T rnea (rel)", fd.rel(tau, virtual_work_dynamics(mech, q, v, a))) <= 1e-9
    err = power_balance_error(mech, state, proj.inverse_dynamics, motion.t)
    assert record("delta power balance (rel. to gross power)", err) <= 1e-8
