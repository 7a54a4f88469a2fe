"""A :class:`~pkm.core.kinematics.configuration.Configuration` is the kinematics at one ``q``, computed once: each
field equals the separate call that computes it alone, it does not change when other configurations are computed,
and ``q`` is checked and copied. The 3-PRS is used: it has a free-flyer (a quaternion in ``q``) and an end effector."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.kinematics import constraints
from pkm.core.kinematics.configuration import Configuration
from pkm.errors import InvalidInputError


@pytest.mark.parametrize("where", ["reference", "random"])
def test_each_field_equals_its_separate_call(built, where):
    """Residual, closure Jacobian, task value and Jacobian, end-effector Jacobian: the functions that compute each
    alone (constraints.residual/jacobian, TaskMap.value/jacobian, pin.computeFrameJacobian), to 1e-14 relative, at
    the reference and at a random (open) configuration; closure_and_task_jacobian stacks the two."""
    mech = built("prs3")
    pin.seed(7)
    q = mech.q_reference if where == "reference" else pin.randomConfiguration(mech.model, -np.ones(mech.nq),
                                                                              np.ones(mech.nq))
    c = Configuration.at(mech, q)
    data = mech.model.createData()
    expected = {
        "residual": constraints.residual(mech, q),
        "constraint_jacobian": constraints.jacobian(mech, q),
        "task_value": pkm.TaskMap.of(mech).value(q),
        "task_jacobian": pkm.TaskMap.of(mech).jacobian(q),
        "ee_jacobian": pin.computeFrameJacobian(mech.model, data, q, mech.ee_frame, pin.LOCAL_WORLD_ALIGNED),
    }
    for name, value in expected.items():
        got = getattr(c, name)
        assert got.shape == value.shape and np.abs(got - value).max() <= 1e-14 * max(1.0, np.abs(value).max()), name
    assert c.residual.shape == (mech.n_constraints,) and c.constraint_jacobian.shape == (mech.n_constraints, mech.nv)
    np.testing.assert_array_equal(c.closure_and_task_jacobian, np.vstack([c.constraint_jacobian, c.task_jacobian]))
    assert (np.abs(c.residual).max() <= 1e-9) == (where == "reference")  # (the reference closes its loops, a random q does not)


def test_a_configuration_is_a_snapshot_independent_of_later_computations(built):
    """Computing another configuration, or anything else that fills the mechanism's data, leaves an earlier one's
    arrays exactly as they were (copies taken before, compared after); q is a copy of the caller's array."""
    mech = built("prs3")
    q = mech.q_reference.copy()
    c = Configuration.at(mech, q)
    before = {f.name: np.array(getattr(c, f.name)) for f in dataclasses.fields(c) if f.name != "mech"}
    q[2] += 0.3  # (the platform's z: a task coordinate)
    other = Configuration.at(mech, q)
    constraints.jacobian(mech, q)
    assert np.abs(other.task_value - c.task_value).max() > 0.0  # (a different configuration was computed)
    for name, value in before.items():
        np.testing.assert_array_equal(getattr(c, name), value, err_msg=name)
    np.testing.assert_array_equal(c.q, mech.q_reference)
    assert not np.shares_memory(c.q, q) and c.q.dtype == float


def test_fields_cannot_be_reassigned(built):
    """Frozen: assigning a field raises (dataclasses.FrozenInstanceError), so a configuration keeps its q."""
    c = Configuration.at(built("prs3"), built("prs3").q_reference)
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.q = np.zeros(3)  # type: ignore[misc]


def test_the_arrays_are_read_only(built):
    """Writing into a Configuration's q or residual raises, as its docstring's "immutable snapshot" promises."""
    c = Configuration.at(built("prs3"), built("prs3").q_reference)
    for array in (c.q, c.residual, c.task_value, c.constraint_jacobian):
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 1.0


@pytest.mark.parametrize("edit, message", [
    (lambda q: q[:-1], r"expected shape \(13,\)"),
    (lambda q: np.where(np.arange(q.size) == 2, np.nan, q), r"non-finite values at \[2\]"),
    (lambda q: q * np.where(np.arange(q.size) >= 3, 2.0, 1.0), "quaternion of joint .* has norm 2"),
    (lambda q: "0 0 0", "q: "),
])
def test_bad_q_is_refused_naming_what_is_wrong(built, edit, message):
    """Wrong size, NaN, a non-unit quaternion (the free-flyer's, scaled by 2), text: InvalidInputError naming q; the
    unchecked compute does not check (it is for the solvers' own iterates)."""
    mech = built("prs3")
    assert mech.joints[mech.model.names[1]].kind == "JointModelFreeFlyer" and mech.nq == 13
    with pytest.raises(InvalidInputError, match=message) as info:
        Configuration.at(mech, edit(mech.q_reference.copy()))
    assert info.value.name == "q"
    with pytest.raises(InvalidInputError, match=r"expected a pkm\.Mechanism"):
        Configuration.at(mech.model, mech.q_reference)
