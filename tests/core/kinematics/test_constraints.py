"""pkm.core.kinematics.constraints on the tests' five-bar and the shipped mechanisms: residual, Jacobian, drift."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pkm.core.kinematics import constraints
from pkm.mechanisms import names
from tests import fd


@pytest.mark.parametrize("name", names())
def test_the_reference_closes_and_the_jacobian_is_the_derivative_of_the_residual(name, built):
    """Residual 0 (1e-10) at the reference; J = d residual / dq by Richardson differences away from it (1e-6)."""
    mech = built(name)
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() <= 1e-10
    rng = np.random.default_rng(3)
    q = pin.integrate(mech.model, mech.q_reference, 0.1 * rng.standard_normal(mech.nv))
    assert fd.constraint_jacobian_error(mech, q) <= 1e-6
    r, J = constraints.residual_and_jacobian(mech, q)
    np.testing.assert_allclose(r, constraints.residual(mech, q), rtol=0, atol=1e-14)
    np.testing.assert_allclose(J, constraints.jacobian(mech, q), rtol=0, atol=1e-14)


def test_the_drift_is_the_time_derivative_of_the_closure_velocity(built):
    """gamma(q, v) = d/dt (J(q(t)) v) along q(t) = q + t v (Richardson, 1e-7 relative) on the five-bar."""
    mech = built("fivebar")
    rng = np.random.default_rng(4)
    q, v = mech.q_reference, rng.standard_normal(mech.nv)

    def diff(h):
        qp, qm = (pin.integrate(mech.model, q, s * h * v) for s in (1.0, -1.0))
        return (constraints.jacobian(mech, qp) @ v - constraints.jacobian(mech, qm) @ v) / (2 * h)

    assert fd.rel(constraints.drift(mech, q, v), fd.richardson(diff, 1e-4)) <= 1e-7
