"""Choice of the reconfiguration angle beta (paper sec. 4) by proxqp sequential QPs.

Independent routes: the reachable interval against bisection on the closed-form inverse
kinematics; beta* against a dense 0.01-deg sweep; the profile's constraints checked pose by pose
with the closed-form inverse kinematics.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pkm.core.analysis import redundant_parameter
from pkm.errors import InvalidInputError, UnreachableError
from pkm.mechanisms import hexapod as hx
from pkm.mechanisms.hexapod import indices as hi
from pkm.mechanisms.hexapod import reconfiguration as hr
from pkm.papers.hexapod import POSE_T_ROTATION, pose_T_placement, spiral_poses
from tests.mechanisms.hexapod.test_kinematics import bisect_beta_limit

DEG = math.pi / 180.0


@pytest.fixture(scope="module")
def params():
    return hx.Params()


def pose_t(p):
    return pose_T_placement()


def test_reachable_interval_of_pose_t_matches_bisection_on_the_inverse_kinematics(params):
    """Closed form: pose T is reachable on [-59.5017, 90] deg; bisection on the IK finds the same edge (1e-9 rad)."""
    R, P = pose_t(params)
    spans = hr.reachable_intervals(params, R, P)
    assert len(spans) == 1 and spans[0][1] == 90 * DEG
    assert abs(spans[0][0] - bisect_beta_limit(params, R, P, -90 * DEG, 0.0)) < 1e-9


def test_reachable_intervals_along_the_spiral_match_bisection(params):
    """For every 10th pose of the spiral, the lower edge equals the IK bisection (1e-9 rad)."""
    for R, P in spiral_poses()[::10]:
        (a, c), = hr.reachable_intervals(params, R, P)
        assert abs(a - bisect_beta_limit(params, R, P, -90 * DEG, a + 1 * DEG)) < 1e-9 and c == 90 * DEG


@pytest.mark.parametrize("index", hi.INDICES)
def test_optimal_beta_at_pose_t_matches_a_dense_sweep(params, index):
    """beta* by SQP = argmax of a 0.01-deg sweep refined by a parabola through its 3 best nodes (0.01 deg)."""
    R, P = pose_t(params)
    choice = hr.optimal_beta(params, R, P, index)
    grid = np.arange(-59.5, 90.0, 0.01) * DEG
    v = hi.PoseIndex(params, [(R, P)], index)(np.zeros(grid.size, int), grid)
    i = int(np.argmax(v))
    ref = grid[i] + 0.5 * (grid[1] - grid[0]) * (v[i - 1] - v[i + 1]) / (v[i - 1] - 2 * v[i] + v[i + 1])
    assert choice.optimum.converged and abs(choice.beta - ref) < 0.01 * DEG
    assert choice.value >= v.max()
    assert choice.interval == hr.reachable_intervals(params, R, P)[0]


def test_pose_unreachable_for_every_beta_says_so(params):
    """A pose no beta in [-90, 90] deg reaches raises UnreachableError naming the leg and the limits."""
    R = pose_T_placement()[0]
    with pytest.raises(UnreachableError, match=r"unreachable for every beta in \[-90, 90\] deg") as exc:
        hr.optimal_beta(params, R, (0.0, -0.9, 0.0))
    assert exc.value.excess > 0
    with pytest.raises(UnreachableError, match="legs 4-6 do not depend on beta"):
        hr.optimal_beta(params, R, (0.3, -0.35, 0.0))
    with pytest.raises(UnreachableError, match="pose 2: "):
        hr.beta_profile(params, [pose_t(params)] * 2 + [(R, (0.0, -0.9, 0.0))])


def test_non_orthonormal_rotation_is_rejected_with_its_defect(params):
    """A 'rotation' 3 % off orthonormal is refused with max|R^T R - I| in the message; 4-digit matrices pass."""
    R, P = pose_t(params)
    with pytest.raises(InvalidInputError, match=r"max\|R\^T R - I\| = 0.0609"):
        hr.optimal_beta(params, 1.03 * R, P)
    printed = np.reshape(POSE_T_ROTATION, (3, 3))
    assert abs(hr.optimal_beta(params, printed, P).beta - hr.optimal_beta(params, R, P).beta) < 1e-6


def test_spiral_profile_respects_the_rate_limit_and_reachability_and_beats_the_clipped_optimum(params):
    """Along the 101-pose spiral with delta = 0.05 deg/pose (binding): |d beta| <= delta + 1e-9, every pose reachable
    by the closed-form IK at its beta, objective >= the pointwise optimum clipped to the rate limit; base = beta 0."""
    poses = spiral_poses()
    delta = 0.05 * DEG
    prof = hr.beta_profile(params, poses, "w_rot", rate_limit=delta, smoothness=1.0)
    res = prof.result
    assert res.converged and set(res.qp_status) == {"PROXQP_SOLVED"}
    assert np.abs(np.diff(prof.beta)).max() <= delta + 1e-9
    for (R, P), b in zip(poses, prof.beta):
        hx.inverse_kinematics(params, R, P, b)
    clipped = redundant_parameter.clip_to_rate(prof.pointwise, prof.lower, prof.upper, delta)
    f = hi.PoseIndex(params, poses, "w_rot")
    k = np.arange(len(poses))

    def objective(x):
        return np.sum(f(k, x)) / res.scale - 0.5 * np.sum(np.diff(x) ** 2)

    assert np.abs(np.diff(prof.pointwise)).max() > delta  # the limit binds
    assert abs(objective(prof.beta) - res.objective) < 1e-12
    assert objective(prof.beta) >= objective(clipped)
    assert np.allclose(prof.base_value, f(k, np.zeros(k.size)), rtol=1e-12)
    assert np.allclose(prof.relative_gain, prof.value / prof.base_value - 1.0, rtol=1e-12)


def test_split_reachable_set_agrees_with_the_inverse_kinematics_and_the_best_piece_is_chosen(params):
    """At P = (100, -460, 0) mm the pose is reachable on two intervals of [-90, 90] deg: the closed-form
    intervals agree with the IK on a 0.1-deg grid, and beta* lies in the piece holding the larger maximum."""
    R, P = pose_T_placement()[0], (0.1, -0.46, 0.0)
    spans = hr.reachable_intervals(params, R, P)
    assert len(spans) == 2
    for b in np.arange(-90.0, 90.0, 0.1) * DEG:
        inside = any(a <= b <= c for a, c in spans)
        if min(abs(b - e) for s in spans for e in s) < 1e-6:
            continue
        try:
            hx.inverse_kinematics(params, R, P, b)
            reached = True
        except UnreachableError:
            reached = False
        assert reached == inside
    choice = hr.optimal_beta(params, R, P, "w_tras")
    f = hi.PoseIndex(params, [(R, P)], "w_tras")
    best = [max(f(np.zeros(200, int), np.linspace(a + 1e-6, c - 1e-6, 200))) for a, c in spans]
    assert choice.interval == spans[int(np.argmax(best))]
    assert choice.value >= max(best)
