"""Tests of the sequential-QP choice of a scalar reconfiguration parameter (pkm.core.redundant_parameter)."""

from __future__ import annotations

import numpy as np
import proxsuite
import pytest

from pkm.core import redundant_parameter as rc
from pkm.errors import InvalidInputError

C = np.linspace(-1.0, 1.0, 41)


def bumpy(k, x):
    """Concave trend with ripples: several local maxima per pose."""
    return 2.0 - (x - C[k]) ** 2 + 0.1 * np.cos(5.0 * x)


def quadratic(k, x):
    return 3.0 - (1.0 + 0.5 * np.sin(k)) * (x - C[k]) ** 2


def test_pointwise_maxima_match_a_dense_grid_and_stay_in_their_intervals():
    """maximise() finds the global maximum of each pose (dense grid of 1e-5, tolerance 2e-5), bounds included."""
    lo, hi = np.full(C.size, -1.5), np.full(C.size, 0.8)
    res = rc.maximise(bumpy, lo, hi)
    grid = np.linspace(-1.5, 0.8, 230001)
    ref = np.array([grid[np.argmax(bumpy(np.full(grid.size, k), grid))] for k in range(C.size)])
    assert res.converged and np.abs(res.x - ref).max() < 2e-5
    assert np.all(res.x >= lo) and np.all(res.x <= hi)
    assert np.any(res.x == hi)  # poses whose optimum lies beyond 0.8 stop on the bound


def test_profile_respects_rate_limit_and_intervals_and_beats_the_clipped_pointwise_optima():
    """The QP profile stays in [lower, upper], changes by at most delta (+1e-9) and its objective >= the start's."""
    lo = np.full(C.size, -0.9) + 0.05 * np.sin(np.arange(C.size))
    hi = lo + 1.2
    delta = 0.02
    res = rc.optimise_profile(bumpy, lo, hi, rate_limit=delta, smoothness=5.0)
    assert res.converged
    assert np.all(res.x >= lo - 1e-12) and np.all(res.x <= hi + 1e-12)
    assert np.abs(np.diff(res.x)).max() <= delta + 1e-9
    start = rc.clip_to_rate(res.pointwise.x, lo, hi, delta)
    assert np.allclose(res.start, start)
    assert res.objective >= res.start_objective
    assert res.objective > res.start_objective + 1e-3  # the rate limit binds: the SQP really improves


def test_profile_of_concave_quadratics_is_a_local_hence_global_optimum():
    """For concave quadratic indices the problem is convex: no feasible perturbation improves the result.

    Independent check: 2000 random feasible directions (perturbation, then clipping to the rate
    limit and the intervals) never raise the objective by more than 1e-12.
    """
    lo, hi, delta, mu = np.full(C.size, -0.6), np.full(C.size, 0.7), 0.03, 2.0
    res = rc.optimise_profile(quadratic, lo, hi, rate_limit=delta, smoothness=mu)
    k = np.arange(C.size)

    def objective(x):
        return np.sum(quadratic(k, x)) / res.scale - 0.5 * mu * np.sum(np.diff(x) ** 2)

    assert abs(objective(res.x) - res.objective) < 1e-12
    rng = np.random.default_rng(1)
    best = max(objective(rc.clip_to_rate(res.x + eps * rng.normal(size=C.size), lo, hi, delta))
               for eps in (1e-3, 1e-2) for _ in range(1000))
    assert best <= res.objective + 1e-12


def test_without_rate_limit_or_smoothing_the_profile_is_the_pointwise_optimum():
    """A loose rate limit and mu = 0 give back the pointwise maxima (1e-7)."""
    lo, hi = np.full(C.size, -2.0), np.full(C.size, 2.0)
    res = rc.optimise_profile(quadratic, lo, hi, rate_limit=10.0, smoothness=0.0)
    assert np.abs(res.x - C).max() < 1e-7


def test_gain_over_the_baseline():
    """relative_gain = f(x_k) / f(baseline) - 1 where the baseline lies in the interval, nan elsewhere."""
    lo, hi = np.full(C.size, -0.5), np.full(C.size, 0.5)
    lo[0] = 0.1  # baseline 0 outside pose 0's interval
    res = rc.optimise_profile(quadratic, lo, hi, rate_limit=1.0, smoothness=0.0, baseline=0.0)
    k = np.arange(1, C.size)
    assert not res.baseline_ok[0] and np.isnan(res.relative_gain[0])
    assert np.allclose(res.relative_gain[1:], quadratic(k, res.x[1:]) / quadratic(k, np.zeros(k.size)) - 1, rtol=1e-12)
    assert res.mean_gain() > 0


def test_an_unreachable_rate_limit_and_bad_intervals_are_refused():
    """No profile fits: InvalidInputError naming the pose; empty or non-finite intervals too."""
    lo, hi = np.array([0.0, 1.0]), np.array([0.1, 1.1])
    with pytest.raises(InvalidInputError, match="pose 1"):
        rc.feasible_bounds(lo, hi, 0.5)
    with pytest.raises(InvalidInputError, match="empty interval"):
        rc.maximise(quadratic, [1.0], [0.0])
    with pytest.raises(InvalidInputError, match="not finite"):
        rc.maximise(lambda k, x: np.where(x > 0, 1.0, np.nan), [-1.0], [1.0])


def test_warm_qp_solves_before_updating_and_matches_cold_solves_near_active_bounds():
    """WarmQP: init+solve first, then update+solve warm-started with the duality-gap check on.

    A sequence of box-constrained QPs whose active bound moves (the case where a warm start without
    the duality-gap check may report a wrong 'solved'): every warm answer equals a cold proxqp solve (1e-8).
    """
    n = 6
    D = np.diff(np.eye(n), axis=0)
    H = np.eye(n) * 0.1 + D.T @ D
    qp = rc.WarmQP(n, D, np.full(n - 1, -0.05), np.full(n - 1, 0.05))
    rng = np.random.default_rng(3)
    for it in range(12):
        g = rng.normal(size=n) * (1 + it)
        lb, ub = np.full(n, -0.2 + 0.01 * it), np.full(n, 0.1 + 0.01 * it)
        x = qp.solve(H, g, lb, ub)
        cold = proxsuite.proxqp.dense.QP(n, 0, n - 1, True)
        cold.settings.eps_abs = 1e-12
        cold.init(H, g, None, None, D, np.full(n - 1, -0.05), np.full(n - 1, 0.05), lb, ub)
        cold.solve()
        assert np.abs(x - cold.results.x).max() < 1e-8
    assert qp.solves == 12 and set(qp.statuses) == {"PROXQP_SOLVED"}
