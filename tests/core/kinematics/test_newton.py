"""The shared Gauss-Newton (:mod:`pkm.core.kinematics.newton`) on small systems whose roots are known in closed form:
its convergence rate, its bounds (iterations, step cap, stall), its backtracking and its least-squares step."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from pkm.core.kinematics.newton import gauss_newton, least_squares

ROOT = np.array([math.sqrt(2.0), math.sqrt(2.0)])


def circle_and_diagonal(x):
    """``x^2 + y^2 = 4`` and ``x = y``: the root (sqrt 2, sqrt 2) from the right half-plane."""
    return np.array([x[0] ** 2 + x[1] ** 2 - 4.0, x[0] - x[1]]), np.array([[2 * x[0], 2 * x[1]], [1.0, -1.0]])


def test_converges_quadratically_to_the_known_root():
    """The error to the closed-form root (sqrt 2, sqrt 2) is squared at each step near it (e_{k+1} <= 2 e_k^2), and
    the returned residual is the system's own at the returned point."""
    iterates = []

    def fun(x):
        iterates.append(np.array(x))
        return circle_and_diagonal(x)

    x, res, it = gauss_newton(fun, np.array([3.0, 0.5]), tol=1e-14, max_iter=20)
    assert np.abs(x - ROOT).max() <= 1e-15 * 4 and res <= 1e-14 and it <= 7
    assert res == np.abs(circle_and_diagonal(x)[0]).max()
    errors = [float(np.abs(p - ROOT).max()) for p in iterates]
    close = [(a, b) for a, b in itertools.pairwise(errors) if 1e-7 < a < 0.1]
    assert len(close) >= 2 and all(b <= 2.0 * a * a for a, b in close), errors


def test_a_separate_jacobian_gives_the_same_iterates_made_at_the_kept_points_only():
    """With ``jacobian=`` (fun the residual alone), the iterates equal those of fun returning both, bit for bit, and
    the Jacobian is made once per iteration, at the points kept (never at a backtracking trial: atan from 2
    backtracks)."""
    for fun, x0 in ((circle_and_diagonal, np.array([3.0, 0.5])),
                    (lambda x: (np.arctan(x), np.array([[1.0 / (1.0 + x[0] ** 2)]])), np.array([2.0]))):
        made, trials = [], []

        def residual(x, fun=fun, trials=trials):
            trials.append(np.array(x))
            return fun(x)[0]

        def jacobian(x, r, fun=fun, made=made):
            made.append(np.array(x))
            assert np.array_equal(r, fun(x)[0])
            return fun(x)[1]

        eager = gauss_newton(fun, x0, tol=1e-14, max_iter=30)
        lazy = gauss_newton(residual, x0, tol=1e-14, max_iter=30, jacobian=jacobian)
        assert np.array_equal(eager[0], lazy[0]) and eager[1:] == lazy[1:]
        assert len(made) == lazy[2] < len(trials)


def test_stops_at_max_iter_and_makes_no_step_with_zero():
    """With max_iter=2 from a far start it makes exactly 2 iterations and reports the residual still above tol; with
    max_iter=0 it returns the start untouched and its residual."""
    x0 = np.array([30.0, -7.0])
    x, res, it = gauss_newton(circle_and_diagonal, x0, tol=1e-12, max_iter=2)
    assert it == 2 and res > 1e-12 and res == np.abs(circle_and_diagonal(x)[0]).max()
    x, res, it = gauss_newton(circle_and_diagonal, x0, tol=1e-12, max_iter=0)
    assert it == 0 and np.array_equal(x, x0) and res == np.abs(circle_and_diagonal(x0)[0]).max()


def test_the_step_cap_limits_every_step():
    """max_step=0.1: each of 3 iterations moves the point by at most 0.1 in every coordinate (the uncapped first step
    from (3, 0.5) is longer than 1)."""
    x, _, it = gauss_newton(circle_and_diagonal, np.array([3.0, 0.5]), tol=1e-14, max_iter=1)
    assert np.abs(x - [3.0, 0.5]).max() > 1.0 and it == 1
    points = [np.array([3.0, 0.5])]
    for _ in range(3):
        x, _, it = gauss_newton(circle_and_diagonal, points[-1], tol=1e-14, max_iter=1, max_step=0.1)
        points.append(x)
    steps = [np.abs(b - a).max() for a, b in itertools.pairwise(points)]
    assert all(0.0 < s <= 0.1 + 1e-15 for s in steps), steps


def test_backtracking_converges_where_plain_newton_diverges():
    """``atan(x) = 0`` from x = 2: Newton's full steps overshoot and grow (|x| > 1.39 diverges, a textbook case), so
    with no halving the residual never drops below its start; with the default backtracking it reaches the root 0."""
    fun = lambda x: (np.arctan(x), np.array([[1.0 / (1.0 + x[0] ** 2)]]))
    x0 = np.array([2.0])
    _, res_plain, _ = gauss_newton(fun, x0, tol=1e-12, max_iter=30, halvings=1)
    assert res_plain >= math.atan(2.0)
    x, res, _ = gauss_newton(fun, x0, tol=1e-12, max_iter=30)
    assert res <= 1e-12 and abs(x[0]) <= 1e-12


def test_rank_deficient_jacobians_take_the_minimum_norm_step():
    """One equation x + y = 2 in two unknowns (1 x 2 Jacobian) and the same equation written twice (singular 2 x 2):
    from the origin one step lands on the minimum-norm root (1, 1), the closed form of the pseudo-inverse (1e-14)."""
    under = lambda x: (np.array([x[0] + x[1] - 2.0]), np.array([[1.0, 1.0]]))
    twice = lambda x: (np.array([x[0] + x[1] - 2.0, 2 * x[0] + 2 * x[1] - 4.0]),
                       np.array([[1.0, 1.0], [2.0, 2.0]]))
    for fun in (under, twice):
        x, res, it = gauss_newton(fun, np.zeros(2), tol=1e-12, max_iter=5)
        assert it == 1 and res <= 1e-14 and np.abs(x - 1.0).max() <= 1e-14  # (a few rounding units)


def test_a_system_without_a_root_stops_at_its_least_squares_point():
    """x = 0 and x = 1 together: no root; it stops after `stall` iterations that do not lower the residual, long
    before max_iter, at the least-squares point 0.5 (closed form) with residual 0.5."""
    fun = lambda x: (np.array([x[0], x[0] - 1.0]), np.array([[1.0], [1.0]]))
    x, res, it = gauss_newton(fun, np.array([7.0]), tol=1e-12, max_iter=100, stall=3)
    assert it == 4 and abs(x[0] - 0.5) <= 1e-15 and abs(res - 0.5) <= 1e-15


def test_a_retraction_keeps_the_iterates_on_their_manifold():
    """A unit vector (cos t, sin t) with one tangent coordinate, retracted by a rotation: it reaches sin t = 0.6 with
    the iterate still a unit vector (1e-15) and t = asin(0.6) (1e-12)."""

    def rotate(x, dt):
        c, s = math.cos(dt[0]), math.sin(dt[0])
        return np.array([c * x[0] - s * x[1], s * x[0] + c * x[1]])

    fun = lambda x: (np.array([x[1] - 0.6]), np.array([[x[0]]]))
    x, res, _ = gauss_newton(fun, np.array([1.0, 0.0]), tol=1e-14, max_iter=20, retract=rotate)
    assert res <= 1e-14 and abs(np.linalg.norm(x) - 1.0) <= 1e-15
    assert abs(math.atan2(x[1], x[0]) - math.asin(0.6)) <= 1e-12


def test_it_stops_before_a_step_that_makes_the_residual_non_finite():
    """A residual that is NaN everywhere but at the start: the first step is refused (every halving too), the start
    and its residual are returned after one iteration; an empty system is solved at once."""
    x0 = np.array([1.0])
    fun = lambda x: ((np.array([1.0]) if x[0] == 1.0 else np.array([np.nan])), np.array([[1.0]]))
    x, res, it = gauss_newton(fun, x0, tol=1e-12, max_iter=10)
    assert np.array_equal(x, x0) and res == 1.0 and it == 1
    x, res, it = gauss_newton(lambda x: (np.zeros(0), np.zeros((0, 3))), np.ones(3), tol=0.0, max_iter=10)
    assert res == 0.0 and it == 0


def test_least_squares_is_the_solve_the_pseudo_inverse_or_no_step():
    """A regular square system: numpy's solve (1e-15); singular or tall: the pseudo-inverse's minimum-norm solution
    (1e-14); a non-finite entry in A or b: the zero step."""
    rng = np.random.default_rng(3)
    A = rng.normal(size=(4, 4)) + 4 * np.eye(4)
    b = rng.normal(size=4)
    assert np.abs(least_squares(A, b) - np.linalg.solve(A, b)).max() <= 1e-15 * 10
    S = np.outer(rng.normal(size=4), rng.normal(size=4))
    T = rng.normal(size=(6, 3))
    for M, c in ((S, b), (T, rng.normal(size=6))):
        assert np.abs(least_squares(M, c) - np.linalg.pinv(M) @ c).max() <= 1e-14 * max(1.0, np.abs(c).max())
    for bad_A, bad_b in ((np.where(np.eye(4) > 0, np.nan, A), b), (A, np.full(4, np.inf))):
        out = least_squares(bad_A, bad_b)
        assert out.shape == (4,) and not out.any()


@pytest.mark.parametrize("tol", [1e-6, 1e-10])
def test_the_tolerance_is_where_it_stops(tol):
    """It stops at the first iterate whose residual is at most tol: that residual is below tol, the one before was
    not (the iterates recorded on the side)."""
    seen = []

    def fun(x):
        r, J = circle_and_diagonal(x)
        seen.append(float(np.abs(r).max()))
        return r, J

    _, res, it = gauss_newton(fun, np.array([3.0, 0.5]), tol=tol, max_iter=20)
    assert res <= tol and res == seen[-1] and min(seen[:-1]) > tol and it >= 1
