"""The generic core on the four mechanisms: properties over random designs and configurations.

Each test runs once per mechanism (``name``) and draws a design of it (the strategies of
:mod:`tests.properties`), then a pose about its reference or an arbitrary, unassembled configuration.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

import pkm
from pkm.core import TaskMap, close_loops, dynamics, solve_ik
from pkm.core.kinematics import constraints
from pkm.mechanisms import module, names
from tests import fd
from tests.properties import (
    delta_designs,
    delta_pose,
    examples,
    generic_case,
    hexapod_designs,
    hexapod_pose,
    prs3_designs,
    prs3_pose,
    reachable,
    record,
    regular,
    round_trip_tolerance,
    rrr3_designs,
    rrr3_pose,
    unit_box,
    wrap,
)

#: name -> (design strategy, pose from unit offsets, number of offsets, characteristic length of a design)
CASES = {
    "hexapod": (hexapod_designs(layout="sector"), hexapod_pose, 7, lambda p: p.LA),
    "rrr3": (rrr3_designs(), rrr3_pose, 3, lambda p: p.H),
    "delta": (delta_designs(), delta_pose, 3, lambda p: p.La),
    "prs3": (prs3_designs(), prs3_pose, 3, lambda p: p.l),
}


def case(name: str):
    """The strategies of ``name``: its own, or :func:`generic_case` for a mechanism registered without them."""
    return CASES[name] if name in CASES else generic_case(name)


def _draw(data, name):
    """A random design of ``name``, its mechanism and a regular assembled configuration about its reference."""
    designs, pose, n, length = case(name)
    p = data.draw(designs, label="design")
    mod = module(name)
    mech = mod.build(p)
    y = pose(p, data.draw(unit_box(n), label="offset"))
    q = reachable(mod.closed_form_configuration, mech, y)
    assume(regular(mech, q, 1e-2 * length(p)))
    return mod, p, mech, y, q


def _unassembled(data, mech, spread=0.3):
    """A configuration moved from the reference by a random tangent vector (loops generally open)."""
    return pin.integrate(mech.model, mech.q_reference, spread * data.draw(unit_box(mech.nv), label="dq"))


@pytest.mark.parametrize("name", names())
@examples(48)
@given(data=st.data())
def test_solve_ik_then_close_loops_round_trips(name, data):
    """The generic inverse kinematics from the reference reaches a random pose (residual 1e-12) and equals the
    paper's closed form (1e-9); the generic loop closure, seeded with a perturbed configuration, gives back
    the whole configuration and the pose (1e-9; near a singularity, what a residual of 1e-12 allows: see
    :func:`tests.properties.round_trip_tolerance`)."""
    mod, p, mech, y, q = _draw(data, name)
    tol = round_trip_tolerance(mech, q)
    task = TaskMap(mech)
    res = solve_ik(mech, y)
    assert res.converged and res.residual <= 1e-12
    qa = mech.actuated_q(res.q)
    assert record("core solve_ik vs closed-form IK", np.abs(wrap(qa - mod.closed_form_ik(p, y))).max()) <= tol
    seed = pin.integrate(mech.model, res.q, 1e-3 * data.draw(unit_box(mech.nv), label="seed"))
    back = close_loops(mech, qa, seed)
    dq = wrap(pin.difference(mech.model, res.q, back.q))
    assert record("core solve_ik->close_loops (q)", np.abs(dq).max()) <= tol
    assert record("core solve_ik->close_loops (task)", np.abs(task.error(y, task.value(back.q))).max()) <= tol


@pytest.mark.parametrize("name", names())
@examples(60)
@given(data=st.data())
def test_constraint_jacobian_drift_and_task_bias_are_derivatives_anywhere(name, data):
    """At an arbitrary configuration (loops open), the constraint Jacobian is the derivative of the closure
    residual (point closures: exactly, 1e-7), and the drift and the task bias are the derivatives of J_c v
    and J_t v along q(t) = q (+) t v (Richardson differences, 1e-6)."""
    p = data.draw(case(name)[0], label="design")
    mech = module(name).build(p)
    q = _unassembled(data, mech)
    v = data.draw(unit_box(mech.nv), label="v")
    assert record("core constraint J vs FD, open loops (rel)", fd.constraint_jacobian_error(mech, q)) <= 1e-7
    task = TaskMap(mech)

    def diff(f):
        def step(h):
            return (f(pin.integrate(mech.model, q, h * v)) - f(pin.integrate(mech.model, q, -h * v))) / (2 * h)
        return fd.richardson(step, 1e-4)

    def err(a, b):  # relative, with a floor of 1e-4 m/s^2 (rad/s^2) above the rounding of the differences
        return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-4))

    drift = constraints.drift(mech, q, v)
    assert record("core drift vs FD (rel)", err(drift, diff(lambda qq: constraints.jacobian(mech, qq) @ v))) <= 1e-6
    assert record("core task bias vs FD (rel)", err(task.bias(q, v), diff(lambda qq: task.jacobian(qq) @ v))) <= 1e-6


@pytest.mark.parametrize("name", names())
@examples(60)
@given(data=st.data())
def test_velocity_maps_are_consistent(name, data):
    """At a regular configuration: velocities() keeps the loops closed (J_c v = 0) and the actuated rates;
    their task rates are J_fwd qd; J_inv J_fwd = I; inverse_velocities(J_fwd qd) gives them back; the mobility
    is the number of task coordinates and the rank counts add up (all 1e-9)."""
    _, _, mech, _, q = _draw(data, name)
    qd = data.draw(unit_box(mech.na), label="qd")
    v = pkm.velocities(mech, q, qd)
    Jc = constraints.jacobian(mech, q)
    assert np.abs(Jc @ v).max() <= 1e-12 * np.abs(Jc).max() * np.abs(v).max()
    assert np.abs(v[mech.act_v] - qd).max() <= 1e-15
    Jf = pkm.forward_jacobian(mech, q)
    assert fd.rel(pkm.task_velocity(mech, q, v), Jf @ qd) <= 1e-9
    assert record("core J_inv J_fwd - I", np.abs(pkm.inverse_jacobian(mech, q) @ Jf - np.eye(mech.na)).max()) <= 1e-9
    assert record("core inverse_velocities(J_fwd qd) vs velocities (rel)",
                  fd.rel(pkm.inverse_velocities(mech, q, Jf @ qd), v)) <= 1e-9
    d = pkm.diagnose(mech, q)
    assert d.mobility == mech.n_task == mech.na
    assert d.constraint_rank + d.redundant_constraints == mech.n_constraints


@pytest.mark.parametrize("name", names())
@examples(60)
@given(data=st.data())
def test_task_retract_and_error_are_inverse(name, data):
    """TaskMap.retract(y, dy) moves y by the tangent vector dy: error(retract(y, dy), y) = dy (1e-12), and
    interpolate runs from y0 (s = 0) to y1 (s = 1)."""
    p = data.draw(case(name)[0], label="design")
    mech = module(name).build(p)
    task = TaskMap(mech)
    y0 = task.value(_unassembled(data, mech))
    dy = 0.5 * data.draw(unit_box(task.size), label="dy")
    y1 = task.retract(y0, dy)
    assert record("core TaskMap error(retract(y, dy), y) - dy", np.abs(task.error(y1, y0) - dy).max()) <= 1e-12
    assert np.abs(task.error(task.interpolate(y0, y1, 0.0), y0)).max() <= 1e-12
    assert np.abs(task.error(task.interpolate(y0, y1, 1.0), y1)).max() <= 1e-12


@pytest.mark.parametrize("name", names())
@examples(40)
@given(data=st.data())
def test_energy_is_that_of_the_mass_matrix_and_the_centre_of_mass(name, data):
    """dynamics.energy at an arbitrary state: kinetic = v^T M(q) v / 2 (Pinocchio's CRBA) and potential =
    -m g . c (total mass, centre of mass), to 1e-12 relative; the hexapod's mimic joints included."""
    p = data.draw(case(name)[0], label="design")
    mech = module(name).build(p)
    q = _unassembled(data, mech)
    v = data.draw(unit_box(mech.nv), label="v")
    kinetic, potential = dynamics.energy(mech, q, v)
    M = pin.crba(mech.model, mech.data, q)
    M = np.triu(M) + np.triu(M, 1).T
    com = pin.centerOfMass(mech.model, mech.data, q)
    mass = sum(I.mass for I in mech.model.inertias)
    ke = 0.5 * v @ M @ v
    assert record("core kinetic energy vs v^T M v / 2 (rel)", abs(kinetic - ke) / max(ke, 1e-300)) <= 1e-12
    pot = -mass * float(mech.model.gravity.linear @ com)  # relative to m g times 1 mm
    err = abs(potential - pot) / max(abs(pot), mass * 9.81e-3)
    assert record("core potential energy vs -m g.c (rel)", err) <= 1e-12
