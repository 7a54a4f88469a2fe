"""The reference pose apart from the geometry: given and checked, or found for the design (every registered mechanism)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import pkm
from pkm.core.kinematics import constraints
from pkm.errors import InvalidParameterError, UnreachableError
from pkm.mechanisms import names
from pkm.mechanisms._common import best_reference


@pytest.mark.parametrize("name", names())
def test_default_designs_state_no_pose_and_get_a_regular_assembled_reference(name):
    """Every registered default design leaves its reference pose to be found; the reference configuration built at
    that pose closes every loop (1e-12) and is regular for the generic core."""
    mod = pkm.mechanisms.module(name)
    params = mod.Params()
    pose_fields = [f.name for f in dataclasses.fields(params) if f.default is None]
    assert pose_fields and all(getattr(params, f) is None for f in pose_fields)
    mech = mod.build(params)
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() < 1e-12
    assert pkm.diagnose(mech, mech.q_reference).classification == "regular"


@pytest.mark.parametrize("name, lengths", [
    ("delta", {"La": 0.524, "Lb": 1.244}),  # unreachable from the old fixed home (0, 0, -0.375) m
    ("rrr3", {"a": 0.9, "b": 0.3, "H": 2.0}),
    ("prs3", {"l": 2.0, "g": 1.5}),
    ("hexapod", {"LA": 0.5, "LB": 0.9}),
])
def test_a_design_with_other_lengths_builds_without_a_pose(name, lengths):
    """Changing the lengths alone gives a mechanism: its reference pose is found for the new design."""
    mech = pkm.build(name, **lengths)
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() < 1e-12
    assert pkm.diagnose(mech, mech.q_reference).classification == "regular"


def test_the_delta_reference_is_the_best_conditioned_pose_of_the_axis_grid():
    """On the axis grid no candidate has a larger inverse condition number than the found pose; 2 cm off the axis
    either way none has either (the search on the axis misses no better pose nearby)."""
    from pkm.core.differential.indices import inverse_condition
    from pkm.mechanisms import delta as D

    P = D.Params()
    z_found = D.reference_pose(P)[2]
    n = D.kinematics.REFERENCE_DEPTHS
    zs = -(P.La + P.Lb) * np.arange(1, n + 1) / n
    scores = []
    for z in zs:
        try:
            p = (0.0, 0.0, z)
            scores.append(float(inverse_condition(D.jacobian(P, D.inverse_kinematics(P, p), p))))
        except UnreachableError:
            scores.append(-1.0)
    scores = np.array(scores)
    k = int(np.flatnonzero(np.isclose(zs, z_found, rtol=0, atol=1e-15))[0])
    assert scores[k] == scores.max() > 0.5
    for dx in (-0.02, 0.02):
        p = (dx, 0.0, z_found)
        assert inverse_condition(D.jacobian(P, D.inverse_kinematics(P, p), p)) < scores[k]


@pytest.mark.parametrize("name, field, pose, lengths", [
    ("delta", "home", (0.0, 0.0, -2.0), {}),
    ("rrr3", "home", (0.5, 0.0, 0.0), {}),
    ("prs3", "reference", (0.81, 0.0, 0.0), {"l": 0.4}),  # vertical rails: every height reachable with l = 1 m
    ("hexapod", "home_position", (0.0, -1.2, 0.0), {}),
])
def test_a_given_unreachable_pose_is_refused_with_the_leg_when_building(name, field, pose, lengths):
    """A stated pose is checked where it is used: building names the field, the leg and the miss."""
    params = pkm.mechanisms.module(name).Params(**{field: pose}, **lengths)  # the geometry alone is valid
    with pytest.raises(InvalidParameterError, match=r"leg \d misses by") as exc:
        pkm.mechanisms.module(name).build(params)
    assert exc.value.name == field


def test_best_reference_takes_the_best_the_first_of_equals_and_skips_candidates_that_raise():
    def score(c):
        if c == 0:
            raise UnreachableError(1, 0.1, "m")
        return {1: 0.5, 2: 1.0, 3: 1.0 - 1e-12, 4: 0.9}[c]

    assert best_reference("home", [0, 1, 2, 3, 4], score, minimum=1e-3) == 2
    assert best_reference("home", [0, 4, 3, 2, 1], score, minimum=1e-3) == 3


def test_best_reference_refuses_when_nothing_assembles_or_everything_is_singular():
    with pytest.raises(InvalidParameterError, match=r"among 2 candidates \(none of them assembles; the first: .*"
                                                    r"leg 1 misses by 0\.1 m"):
        best_reference("home", [0, 1], lambda c: (_ for _ in ()).throw(UnreachableError(1, 0.1, "m")), minimum=1e-3)
    with pytest.raises(InvalidParameterError, match=r"the best is 1e-05 from singular"):
        best_reference("home", [0, 1], lambda c: 1e-5, minimum=1e-3)
