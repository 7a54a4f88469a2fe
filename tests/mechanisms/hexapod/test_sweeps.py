"""pkm.mechanisms.hexapod.sweeps: the hexapod's closed-form sweep objectives, called directly on designs of the
registered family: the reachable interval of beta equals a scan of the closed-form inverse kinematics, the gain of
the best beta is positive and vanishes for a design whose reference beta is that best one, and a pose option is
refused. (The exact intervals against the generic map are ``tests/sweeps/test_objectives.py``.)"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pkm import sweeps
from pkm.errors import InvalidInputError, UnreachableError
from pkm.mechanisms.hexapod import geometry, kinematics
from pkm.mechanisms.hexapod.reconfiguration import LIMITS, optimal_beta
from pkm.mechanisms.hexapod.sweeps import CLOSED_FORMS
from pkm.sweeps.family import RegisteredFamily


def value(spec: str, candidate):
    o = sweeps.objective(spec)
    return CLOSED_FORMS[o.definition.name].function(candidate, o.options)


def test_declared_forms_and_units():
    """Two closed forms: the interval in rad, the gain unitless."""
    assert {k: f.unit for k, f in CLOSED_FORMS.items()} == {"reachable_interval": "rad", "beta_gain": ""}


def test_the_reachable_interval_is_the_measure_of_the_betas_the_inverse_kinematics_reaches():
    """At the paper design's reference pose, a 0.5-degree scan of beta over the reconfiguration's range
    (reconfiguration.LIMITS, [-90, 90] deg) with the closed-form inverse kinematics finds the same reachable length
    within two steps."""
    c = RegisteredFamily("hexapod").candidate({})
    exact = value("reachable_interval", c)
    R, P, _ = kinematics.reference_pose(c.params)
    step = math.radians(0.5)
    reached = 0
    lo, hi = LIMITS
    for beta in np.arange(lo + step / 2, hi, step):
        try:
            geometry.inverse_kinematics(c.params, R, P, beta)
            reached += 1
        except UnreachableError:
            pass
    assert 0.0 < exact <= hi - lo and abs(reached * step - exact) <= 2 * step


def test_the_gain_is_positive_and_zero_when_the_reference_beta_is_the_best():
    """beta_gain > 0 for both indices at the paper design (its beta = 0 is not the best); the same pose with its
    beta set to beta* (w_rot) has no gain (1e-9)."""
    c = RegisteredFamily("hexapod").candidate({})
    assert value("beta_gain", c) > 0.0 and value("beta_gain:index=w_tras", c) > 0.0
    R, P, _ = kinematics.reference_pose(c.params)
    best = optimal_beta(c.params, R, P, "w_rot").beta
    fixed = {"home_rotation": tuple(np.ravel(R)), "home_position": tuple(P), "home_beta": float(best)}
    assert value("beta_gain", RegisteredFamily("hexapod", fixed).candidate({})) == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("name", ["reachable_interval", "beta_gain"])
def test_a_pose_option_is_refused_pointing_to_the_generic_route(name):
    """The closed forms score the reference pose only: a pose is an InvalidInputError naming route=generic."""
    with pytest.raises(InvalidInputError, match="route=generic"):
        value(f"{name}:pose=x=1cm", RegisteredFamily("hexapod").candidate({}))
