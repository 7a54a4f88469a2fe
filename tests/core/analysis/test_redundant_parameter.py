"""Tests of the sequential-QP choice of a scalar reconfiguration parameter (pkm.core.analysis.redundant_parameter)."""

from __future__ import annotations

import numpy as np
import proxsuite
import pytest

from pkm.core.analysis import redundant_parameter as rc
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


# ---------------------------------------------------------------------- several parameters
A = np.array([[2.0, 0.6], [0.6, 1.0]])  # a coupled (non-diagonal) curvature
CENTRES = np.column_stack([np.linspace(-0.5, 0.5, 9), np.linspace(0.3, -0.3, 9)])


def coupled(k, x):
    """``3 - (x - c_k)^T A (x - c_k) + 0.05 sin(3 x_0)``: two parameters, one row of ``x`` per pose index."""
    d = x - CENTRES[k]
    return 3.0 - np.einsum("ni,ij,nj->n", d, A, d) + 0.05 * np.sin(3.0 * x[:, 0])


def _scipy_maximum(k, lo, hi):
    from scipy.optimize import minimize

    best = None
    for start in (lo, hi, 0.5 * (lo + hi)):
        r = minimize(lambda x: -coupled(np.array([k]), x[None])[0], start, bounds=list(zip(lo, hi)),
                     method="L-BFGS-B", options={"ftol": 1e-15, "gtol": 1e-12})
        best = r if best is None or r.fun < best.fun else best
    return best.x


def test_several_parameters_pointwise_equal_a_bounded_quasi_newton():
    """Two coupled parameters per pose, boxes that cut some optima: maximise() equals scipy's L-BFGS-B (1e-6), and
    a single parameter given as (n, 1) boxes equals the scalar call."""
    lo = np.column_stack([np.full(9, -0.3), np.full(9, -1.0)])
    hi = np.column_stack([np.full(9, 0.4), np.full(9, 0.1)])
    res = rc.maximise(coupled, lo, hi)
    assert res.converged and res.x.shape == (9, 2)
    for k in range(9):
        assert np.abs(res.x[k] - _scipy_maximum(k, lo[k], hi[k])).max() <= 1e-6, k
    one = rc.maximise(lambda k, x: quadratic(k, x[:, 0]), np.full((41, 1), -1.5), np.full((41, 1), 0.8))
    scalar = rc.maximise(quadratic, np.full(41, -1.5), np.full(41, 0.8))
    assert np.array_equal(one.x[:, 0], scalar.x) and np.array_equal(one.value, scalar.value)


def test_several_parameters_profile_is_the_optimum_of_the_smoothed_problem():
    """The profile of two parameters with per-parameter rate limits respects both and equals SLSQP on the whole
    problem (sum f_k / s - mu/2 sum ||x_{k+1} - x_k||^2 with the boxes and the rate rows), to 1e-5."""
    from scipy.optimize import minimize

    n = 9
    lo, hi = np.full((n, 2), -1.0), np.full((n, 2), 1.0)
    rate = np.array([0.05, 0.03])
    res = rc.optimise_profile(coupled, lo, hi, rate_limit=rate, smoothness=2.0, baseline=(0.0, 0.0))
    assert res.converged and res.x.shape == (n, 2)
    assert np.all(np.abs(np.diff(res.x, axis=0)) <= rate + 1e-9)
    k = np.arange(n)

    def negative(flat):
        x = flat.reshape(n, 2)
        return -(np.sum(coupled(k, x)) / res.scale - 1.0 * np.sum(np.diff(x, axis=0) ** 2))

    rows = [{"type": "ineq", "fun": (lambda flat, j=j, i=i, s=s: rate[i] - s * (flat[2 * (j + 1) + i] - flat[2 * j + i]))}
            for j in range(n - 1) for i in range(2) for s in (1, -1)]
    ref = minimize(negative, res.start.ravel(), method="SLSQP", bounds=[(-1.0, 1.0)] * (2 * n), constraints=rows,
                   options={"ftol": 1e-14, "maxiter": 500})
    assert np.abs(res.x.ravel() - ref.x).max() <= 1e-5
    assert res.objective >= -ref.fun - 1e-9 and np.all(np.isfinite(res.relative_gain[res.baseline_ok]))


def test_several_parameters_feasible_bounds_and_clipping_work_per_parameter():
    lo = np.column_stack([np.zeros(5), np.array([0.0, 0.0, 0.5, 0.5, 0.5])])
    hi = np.column_stack([np.ones(5), np.array([0.2, 0.2, 1.0, 1.0, 1.0])])
    L, U = rc.feasible_bounds(lo, hi, [0.5, 0.35])
    for i, r in enumerate((0.5, 0.35)):
        Li, Ui = rc.feasible_bounds(lo[:, i], hi[:, i], r)
        assert np.array_equal(L[:, i], Li) and np.array_equal(U[:, i], Ui)
    x = rc.clip_to_rate(np.full((5, 2), 0.9), lo, hi, [0.5, 0.35])
    assert np.all(np.abs(np.diff(x, axis=0)) <= np.array([0.5, 0.35]) + 1e-15)
    with pytest.raises(InvalidInputError, match="parameter 1"):
        rc.feasible_bounds(lo, hi, [0.5, 0.05])
    with pytest.raises(InvalidInputError, match="rate limit"):
        rc.feasible_bounds(lo, hi, [0.5, 0.2, 0.1])
