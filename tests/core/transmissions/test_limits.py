"""pkm.core.transmissions.limits (and the closure at given outputs): a prismatic output's search reaches its limits
on a transmission of any size (its reach in characteristic lengths, its tolerance relative); the closure's default
tolerance is relative to the sub-mechanism's size."""

from __future__ import annotations

import functools

import numpy as np

import pkm
from pkm.core.kinematics import constraints
from pkm.core.transmissions.coordinates import CLOSURE_RTOL, close_at_outputs, closure_tol
from pkm.core.transmissions.limits import output_limits
from tests.core.transmissions.robots import robot


@functools.cache
def _slider(scale: float) -> pkm.Transmission:
    (t,) = pkm.transmissions(pkm.scaled_mechanism(robot("slider_crank"), scale))
    return t


def test_a_prismatic_outputs_search_reaches_its_limits_at_any_size():
    """The slider-crank ten times larger (its rail travels 1.47 m from the reference to its inverse singularity, 1.07
    characteristic lengths): the default reach, in characteristic lengths, finds both ends, each the inverse
    singularity, where a reach of 1 m stopped the search short and reported 'reach'."""
    t = _slider(10.0)
    limits = output_limits(t, steps=4, tol=1e-3)  # (a coarse bisection: the ends, not their digits)
    assert limits.binding == ("inverse singularity", "inverse singularity")
    assert t.q_reference[t.out_q][0] - limits.lower[0] > 1.4


def test_the_closure_at_given_outputs_is_closed_relative_to_the_size():
    """Closed from the reference with the rail moved by 1 % of the size: within CLOSURE_RTOL times the characteristic
    length, at the same angles on the transmission a thousand times larger."""
    angles = []
    for scale in (1.0, 1000.0):
        t = _slider(scale)
        sub = t.mechanism
        assert closure_tol(sub) == CLOSURE_RTOL * sub.characteristic_length
        q = close_at_outputs(sub, t.q_reference[t.out_q] - 0.01 * scale, t.q_reference, t.out_q, t.out_v)
        assert np.abs(constraints.residual(sub, q)).max() <= closure_tol(sub)
        angles.append(sub.actuated_q(q))
    np.testing.assert_allclose(angles[1], angles[0], rtol=0.0, atol=1e-9)
