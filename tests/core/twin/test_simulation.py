"""pkm.core.twin.simulation's expressions on CasADi's virtual machine (no compiler): Pinocchio's integrate and
difference on every joint kind the twin handles (the C route's stage seeds and its step test), the quaternion of a
rotation as pin.Quaternion gives it (every branch of Eigen's algorithm), the task values as TaskMap.value. (The
compiled runs against the Python route: ``tests/core/dynamics/test_simulate_c.py``.)"""

from __future__ import annotations

import casadi as cs
import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.model.scale import JacobianScales
from pkm.core.twin import Twin
from pkm.core.twin.simulation import difference, integrate, quaternion, task_value
from tests.core.twin.test_tree import FILES, zoo


def _mechanism(name: str) -> pkm.Mechanism:
    return zoo() if name == "zoo" else pkm.load(FILES[name]) if name in FILES else pkm.load(name)


@pytest.mark.parametrize("name", ["zoo", "prs3", "ankle", "gough_stewart", "hexapod"])
def test_integrate_and_difference_are_pinocchio(name):
    """Planar, unbounded revolute, unaligned and mimic joints (the zoo), free flyers, spherical and universal joints:
    steps of 1e-7 to 1 (rad or m) from a moved configuration, 1e-12."""
    mech = _mechanism(name)
    tw = Twin(mech)
    dv, q1 = cs.SX.sym("dv", mech.nv), cs.SX.sym("q1", mech.model.nq)
    f = cs.Function("f", [tw.q, dv, q1], [integrate(tw, tw.q, dv), difference(tw, tw.q, q1)])
    rng = np.random.default_rng(5)
    q = pin.integrate(mech.model, mech.q_reference, 0.3 * rng.standard_normal(mech.nv))
    for scale in (1e-7, 1e-3, 0.3, 1.0):
        step = scale * rng.standard_normal(mech.nv)
        moved = pin.integrate(mech.model, q, step)
        got, back = (np.array(x).ravel() for x in f(q, step, moved))
        assert np.abs(got - moved).max() <= 1e-12, scale
        assert np.abs(back - pin.difference(mech.model, q, moved)).max() <= 1e-12, scale


def test_the_quaternion_of_a_rotation_is_pinocchio_s():
    """Random rotations (positive trace) and turns near pi about each axis (each of the other three branches)."""
    R = cs.SX.sym("R", 3, 3)
    f = cs.Function("quat", [R], [cs.vertcat(*quaternion(R))])
    rng = np.random.default_rng(6)
    rotations = [pin.exp3(rng.standard_normal(3)) for _ in range(20)]
    rotations += [pin.exp3((np.pi - 0.1) * axis + 0.05 * rng.standard_normal(3)) for axis in np.eye(3)]
    for M in rotations:
        assert np.abs(np.array(f(M)).ravel() - pin.Quaternion(M).coeffs()).max() <= 1e-14


@pytest.mark.parametrize("name", ["gough_stewart", "prs3", "ankle"])
def test_the_task_values_are_task_map_values(name):
    """A pose (position and quaternion), positions and Z-Y-X angles, joint coordinates: TaskMap.value's, 1e-14."""
    mech = _mechanism(name)
    tw = Twin(mech)
    f = cs.Function("task", [tw.q], [task_value(tw)])
    qa = mech.actuated_q(mech.q_reference) + 0.02
    q = pkm.close_loops(mech, qa).q
    assert np.abs(np.array(f(q)).ravel() - pkm.TaskMap.of(mech).value(q)).max() <= 1e-14


def test_the_compiled_singularity_check_reads_the_homogenised_passive_jacobian():
    """The C route's ``J_p`` (the singular values it compares with ``singular_tol``) is the passive columns of the
    constraint Jacobian homogenised by the characteristic length, as the Python route's check (issue 41: the raw one
    made the event depend on the mechanism's size); the PRS's prismatic sliders and free-flying platform make the
    homogenisation more than the identity. 1e-12."""
    from pkm.core.kinematics import constraints
    from pkm.core.twin import Kernels
    from pkm.core.twin.simulation import Simulator

    mech = _mechanism("prs3")
    assert not JacobianScales.of(mech).trivial
    rates = Simulator(Kernels(mech, compiled=False)).functions[1]
    q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + 0.02).q
    got = np.array(rates(q, np.zeros(mech.na), [1.0, 1e-3])[5])
    want = JacobianScales.of(mech).constraint(constraints.jacobian(mech, q))[:, mech.passive_v]
    assert np.abs(got - want).max() <= 1e-12 * np.abs(want).max()
