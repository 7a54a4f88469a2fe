"""The acceptance checks of every mechanism, run through the generic core and the uniform interface.

For each mechanism, 200 random reachable configurations on the default working mode
(task targets drawn around the reference, kept when regular):

* the closed-form configuration closes every loop to <= 1e-10;
* generic forward kinematics (loop closure from the reference) returns the task to <= 1e-9;
* generic inverse kinematics (from the reference) equals the closed-form inverse to <= 1e-9;
* the paper's forward kinematics (where it has one) returns the task to <= 1e-9;
* on a subset: the forward and inverse Jacobians against central finite differences of the
  position solvers (<= 1e-6 relative), the constraint Jacobian against finite differences of
  the residual, and the joint and task accelerations against finite differences of velocities.
"""

from __future__ import annotations

import numpy as np
import pytest

import pkm
from pkm.core import TaskMap, close_loops, diagnose, solve_ik
from pkm.core.kinematics import constraints
from pkm.errors import UnreachableError
from pkm.mechanisms import definition, module, names
from tests import fd

N_RANDOM = 200
N_DIFFERENTIAL = 15


def sample(mech, name: str, n: int, seed: int = 0):
    """n regular configurations (q, y) from the closed form, drawn around the reference."""
    mod, task = module(name), TaskMap(mech)
    rng = np.random.default_rng(seed)
    y_ref = task.value(mech.q_reference)
    scale = np.array(definition(name).tangent_scale(task.names))
    out = []
    while len(out) < n:
        y = task.retract(y_ref, scale * rng.uniform(-1.0, 1.0, task.size))
        try:
            q = mod.closed_form_configuration(mech, y)
        except UnreachableError:
            continue
        d = diagnose(mech, q)
        if d.classification == "regular" and min(d.sigma_direct, d.sigma_inverse) > 1e-3:
            out.append((q, y))
    return out


@pytest.fixture(scope="module", params=names())
def case(request, built):
    mech = built(request.param)
    return request.param, mech, sample(mech, request.param, N_RANDOM)


def test_closed_form_configurations_close_every_loop(case):
    """Every closed-form configuration closes the loops to 1e-10 and lands on the target task."""
    _name, mech, samples = case
    task = TaskMap(mech)
    worst_res = max(np.abs(constraints.residual(mech, q)).max() for q, _ in samples)
    worst_task = max(np.abs(task.error(y, task.value(q))).max() for q, y in samples)
    assert worst_res <= 1e-10
    assert worst_task <= 1e-10


def test_generic_forward_kinematics_round_trips(case):
    """Closed-form inverse then generic loop closure gives back the task to 1e-9.

    The loop closure tracks the reference's assembly mode along the inverse-kinematics path from
    the reference to the target (5 steps, each seeded with the last), as a user following a
    trajectory does: near a direct singularity (the hexapod's pose T) a straight path in actuated
    coordinates can leave the workspace, and Newton's method straight from the reference can land
    on a neighbouring assembly mode.
    """
    name, mech, samples = case
    mod, task = module(name), TaskMap(mech)
    y_ref = task.value(mech.q_reference)
    for q, y in samples:
        qq = mech.q_reference
        for s in np.linspace(0.2, 1.0, 5):
            res = close_loops(mech, mod.closed_form_ik(mech.params, task.interpolate(y_ref, y, s)), qq)
            qq = res.q
        assert res.converged and res.residual <= 1e-10
        assert np.abs(task.error(y, task.value(res.q))).max() <= 1e-9
        assert np.abs(mech.wrap(res.q) - mech.wrap(q)).max() <= 1e-8


def test_generic_inverse_kinematics_equals_closed_form(case):
    """The generic inverse kinematics from the reference equals the paper's closed form to 1e-9."""
    name, mech, samples = case
    mod = module(name)
    for _q, y in samples:
        res = solve_ik(mech, y)
        assert res.converged
        assert np.abs(mech.actuated_q(res.q) - mod.closed_form_ik(mech.params, y)).max() <= 1e-9


def test_paper_forward_kinematics_round_trips(case):
    """Where the paper has a forward-kinematics method, it returns the task of the closed-form inverse."""
    name, mech, samples = case
    mod = module(name)
    if mod.closed_form_fk is None:
        pytest.skip(f"{name} has no closed-form forward kinematics (its paper gives none, or it has no paper)")
    task = TaskMap(mech)
    for q, y in samples:
        y_fk = mod.closed_form_fk(mech.params, mech.actuated_q(q))
        assert np.abs(task.error(y, y_fk)).max() <= 1e-9


def test_jacobians_match_finite_differences(case):
    """Forward, inverse and constraint Jacobians agree with central differences (<= 1e-6 relative)."""
    name, mech, samples = case
    mod = module(name)
    for q, _ in samples[:N_DIFFERENTIAL]:
        assert fd.forward_jacobian_error(mech, q) <= 1e-6
        assert fd.inverse_jacobian_error(mech, q, lambda y: mod.closed_form_ik(mech.params, y)) <= 1e-6
        assert fd.constraint_jacobian_error(mech, q) <= 1e-6
        assert np.abs(pkm.forward_jacobian(mech, q) @ pkm.inverse_jacobian(mech, q) - np.eye(mech.n_task)).max() <= 1e-9


def test_accelerations_match_finite_differences_of_velocities(case):
    """Joint and task accelerations (drift included) are the time derivatives of the velocities."""
    _name, mech, samples = case
    rng = np.random.default_rng(1)
    for q, _ in samples[:N_DIFFERENTIAL]:
        err = fd.acceleration_errors(mech, q, rng)
        assert err["joint"] <= 1e-6 and err["task"] <= 1e-6
        assert err["closure"] <= 1e-9 and err["inverse"] <= 1e-9


@pytest.mark.parametrize("name", names())
def test_every_branch_has_a_seed_with_its_signs(name, built):
    """Each working mode declared in the spec can be reached from the reference by the generic core."""
    mech = built(name)
    for bname in mech.spec.branches:
        q = pkm.core.branch_seed(mech, bname)
        assert mech.on_branch(q, bname)
        assert np.abs(constraints.residual(mech, q)).max() <= 1e-10


@pytest.mark.parametrize("name", names())
def test_reference_design_is_regular_with_expected_mobility(name, built):
    """At the reference configuration the loops are closed and mobility equals the number of outputs."""
    mech = built(name)
    d = diagnose(mech, mech.q_reference)
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() <= 1e-10
    assert d.classification == "regular"
    assert d.mobility == mech.n_task == mech.na
