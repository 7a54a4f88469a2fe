"""The time-optimal law: a closed-form bang-bang, Pontryagin's structure, speed-dependent limits, bad input."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import pkm
from pkm.core.timing import actuator_limits, waypoint_path
from pkm.core.timing.solve import solve
from pkm.errors import InvalidInputError, ModeChangeWarning, PathError

from .conftest import ARC, PITCH


def test_bang_bang_in_closed_form(delta, arc):
    """Constant inertia, no bias, a peak effort: s'' = +-tau/a switching half way, T = 2 sqrt(a / tau)."""
    path, C = arc
    n = len(C.s)
    one = np.ones((n, delta.na))
    a = 0.02 * one
    flat = dataclasses.replace(C, a=a, b=0 * one, c=0 * one, d=0 * one, gravity=0 * one, dqa=0.1 * one,
                               ddqa=0 * one)
    L = actuator_limits(delta, peak=2.0, speed=np.inf, margin=0.0)
    plan = solve(delta, path, flat, L, 0.0)
    assert plan.cycle_time == pytest.approx(2.0 * np.sqrt(0.02 / 2.0), abs=1e-9)
    assert np.allclose(np.abs(plan.sdd), 100.0, rtol=1e-8)


def test_effort_limited_law_is_bang_bang_and_holds(delta, arc):
    path, C = arc
    L = actuator_limits(delta, speed=50.0)
    plan = solve(delta, path, C, L, 0.0)
    assert np.all(plan.usage <= 1.0 + 1e-9)
    assert int(np.sum(plan.usage < 1.0 - 1e-6)) <= 2  # (the switching segments)
    assert {a.split()[0] for a in plan.active} == {"effort"}
    assert plan.time[-1] == plan.cycle_time and np.all(np.diff(plan.time) > 0.0)


def test_torque_speed_line_is_held_exactly_at_the_fixed_point(delta, arc):
    path, C = arc
    const = solve(delta, path, C, actuator_limits(delta, speed=20.0), 0.0)
    line = solve(delta, path, C, actuator_limits(delta, speed=20.0, omega0=8.0), 0.0)
    assert line.passes > 1 and line.cycle_time > const.cycle_time
    omega = line.qa_rate
    usage = np.abs(line.efforts) / (line.limits.effort_limit(omega) * (1.0 - line.limits.margin))
    assert usage.max() <= 1.0 + 1e-6
    assert int(np.sum(line.usage < 1.0 - 1e-6)) <= 2


def test_refused_paths_name_the_point_and_the_limit(delta):
    corner = np.array([[-0.1, 0.0, -0.36], [0.0, 0.0, -0.36], [0.0, 0.1, -0.36]])
    with pytest.raises(PathError) as err:
        waypoint_path(delta, corner)
    assert (err.value.index, err.value.limit) == (1, "smoothness")
    with pytest.raises(PathError) as err:
        pkm.time_optimal(delta, [[0.0, 0.0, -0.36], [0.0, 0.0, -2.0]], points=5)
    assert err.value.limit == "workspace" and err.value.index > 0
    with pytest.raises(PathError) as err:
        pkm.time_optimal(delta, ARC, points=5, payload=3.0, limits={"peak": 0.5})
    assert err.value.limit.startswith("peak effort of motor_") and "cannot hold" in str(err.value)
    with pytest.raises(PathError) as err, pytest.warns(ModeChangeWarning):  # (the motors raised until the knees
        # fold through: pkm's follow says so too)
        pkm.time_optimal(delta, [[-0.9] * 3, [1.5] * 3], space="actuated", points=20)
    assert err.value.limit == "singularity" and 0 < err.value.index < 19
    with pytest.raises(InvalidInputError):
        actuator_limits(delta, table=[[0.0, 1.0], [1.0, 0.9], [2.0, 0.1], [3.0, 0.05]])  # (convex: refused)


def test_same_cycle_time_as_toppra_on_its_own_constraints(delta, arc):
    """toppra assembling its own rows (SecondOrderConstraint from pkm.inverse_dynamics, JointVelocityConstraint) on
    the actuated path equals the plan built from a, b, c, to 1e-6 s."""
    import toppra
    from toppra.constraint import DiscretizationType, JointVelocityConstraint, SecondOrderConstraint

    path, C = arc
    L = actuator_limits(delta, margin=0.0, speed=20.0)
    plan = solve(delta, path, C, L, 0.0)
    assert {a.split()[0] for a in plan.active} == {"effort", "speed"}  # (both kinds of rows at work)

    class Actuated(toppra.interpolator.AbstractGeometricPath):  # (the grid's q_a, q_a', q_a'')
        path_interval = np.array([0.0, 1.0])
        dof = delta.na

        def __call__(self, s, order=0):
            k = np.searchsorted(C.s, np.atleast_1d(s) - 1e-12)
            return (C.qa, C.dqa, C.ddqa)[order][k]

    def inv_dyn(qa, qd, qdd):
        k = int(np.argmin(np.abs(C.qa - qa).sum(axis=1)))
        v = pkm.velocities(delta, C.q[k], qd)
        return pkm.inverse_dynamics(delta, C.q[k], v, pkm.accelerations(delta, C.q[k], v, qdd))

    F = np.vstack([np.eye(delta.na), -np.eye(delta.na)])
    torque = SecondOrderConstraint(inv_dyn, lambda q: F, lambda q: np.full(2 * delta.na, 3.9), delta.na,
                                   discretization_scheme=DiscretizationType.Interpolation)
    speed = JointVelocityConstraint(np.tile([-20.0, 20.0], (delta.na, 1)))
    algo = toppra.algorithm.TOPPRA([torque, speed], Actuated(), gridpoints=C.s, solver_wrapper="seidel")
    _, sd, _ = algo.compute_parameterization(0.0, 0.0)
    T = float(np.sum(2.0 * np.diff(C.s) / (sd[1:] + sd[:-1])))
    assert abs(T - plan.cycle_time) <= 1e-6


def test_limits_are_held_between_the_grid_points(delta, arc):
    """From rest, sqrt(x) grows fastest just after a grid point, where a torque-speed line falls fastest: the grid
    alone lets the efforts cross the line inside the first segment; checked inside and tightened, they do not."""
    from pkm.core.timing import path_coefficients
    from pkm.core.timing.solve import _between

    path, C = arc
    mid = path_coefficients(delta, path, 0.5 * (C.s[1:] + C.s[:-1]), q0=C.q[0])
    L = actuator_limits(delta, speed=20.0, omega0=8.0)
    plain, held = solve(delta, path, C, L, 0.0), solve(delta, path, C, L, 0.0, mid)
    assert _between(mid, C, L, plain.sd, plain.sdd).max() > 1.0 + L.margin
    assert _between(mid, C, L, held.sd, held.sdd).max() <= 1.0 + 0.5 * L.margin
    assert held.cycle_time > plain.cycle_time


def test_a_path_across_position_limits_is_refused_naming_point_joint_value_and_limit(ankle):
    """Pitch 0 -> 0.8 rad on the ankle (range +-0.6): refused at the first check point outside (a straight line: the
    pitch at s is 0.8 s exactly), never timed; with the motors' limits alone (+-1 rad), at the first point where a
    motor is outside, its value that of the inverse kinematics there (another route)."""
    import copy

    with pytest.raises(PathError) as e:
        pkm.time_optimal(ankle, PITCH, points=12)
    err = e.value
    assert (err.joint, err.bound, err.index) == ("ankle_pitch", (-0.6, 0.6), 8)  # (segment 8: s = 8.5/11)
    assert err.s == pytest.approx(8.5 / 11, abs=1e-12) and err.value == pytest.approx(0.8 * 8.5 / 11, abs=1e-9)
    assert "ankle_pitch = 0.618182 rad" in str(err) and "[-0.6, 0.6]" in str(err)
    motors = copy.copy(ankle)
    motors.limits = {k: v for k, v in ankle.limits.items() if k.startswith("motor")}
    with pytest.raises(PathError) as e:
        pkm.time_optimal(motors, PITCH, points=12)
    err = e.value
    assert err.joint == "motor_left" and err.bound == (-1.0, 1.0) and err.value > 1.0
    ik = pkm.solve_ik(ankle, [0.8 * err.s, 0.0]).q
    assert err.value == pytest.approx(ik[ankle.joints["motor_left"].idx_q], abs=1e-9)
    before = pkm.solve_ik(ankle, [0.8 * (err.s - 0.5 / 11), 0.0]).q  # (the check point before: inside)
    assert not motors.outside_limits(before)
