"""The sparse LU with pivots chosen once (:mod:`pkm.core.twin.linear`): on random sparse well-conditioned parametric
matrices it solves ``A x = b`` and ``A^T y = b`` away from the reference (checked by the residual and against numpy),
it reports a fixed pivot that vanishes while the matrix stays regular, and it refuses what it cannot factor."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from pkm.core.differential.velocity import homogenised_pinv
from pkm.core.twin.linear import HomogenisedPinv, PivotedLU


def _parametric(n: int, seed: int):
    """A random sparse n x n SX matrix of 3 parameters, diagonally dominated (well conditioned for |p| <~ 1)."""
    rng = np.random.default_rng(seed)
    p = cs.SX.sym("p", 3)
    pattern = (rng.random((n, n)) < 0.4) | np.eye(n, dtype=bool)
    C0, C1, C2 = (rng.normal(size=(n, n)) for _ in range(3))
    A = cs.SX(n, n)
    for i, j in zip(*np.nonzero(pattern)):
        A[i, j] = C0[i, j] + (2.0 * n if i == j else 0.0) + 0.3 * C1[i, j] * cs.sin(p[0]) + 0.3 * C2[i, j] * p[1] * p[2]
    return p, A, cs.Function("A", [p], [A])


def _solver(p, A, lu: PivotedLU):
    b = cs.SX.sym("b", A.shape[0])
    bt = cs.SX.sym("bt", A.shape[1])
    return cs.Function("s", [p, b, bt], [lu.solve(b), lu.solve_transposed(bt), lu.smallest_relative_pivot()])


@pytest.mark.parametrize("n, seed", [(3, 0), (6, 1), (9, 2)])
def test_it_solves_random_well_conditioned_systems_away_from_the_reference(n, seed):
    """Pivots chosen at p = 0, systems solved at 4 random p: A x = b and A^T y = b to 1e-13 relative residual, the
    same x and y as numpy's dense solve (1e-12); at the reference every pivot is its own reference value (ratio 1)."""
    p, A, Af = _parametric(n, seed)
    lu = PivotedLU(A, np.array(Af(np.zeros(3))))
    assert sorted(c for _, c in lu.order) == list(range(n)) and sorted(r for r, _ in lu.order) == list(range(n))
    solve = _solver(p, A, lu)
    rng = np.random.default_rng(seed + 10)
    assert abs(float(solve(np.zeros(3), np.ones(n), np.ones(n))[2]) - 1.0) <= 1e-15
    for _ in range(4):
        pp, b, bt = rng.uniform(-1, 1, size=3), rng.normal(size=n), rng.normal(size=n)
        M = np.array(Af(pp))
        x, y, pivot = (np.array(v).ravel() for v in solve(pp, b, bt))
        assert np.abs(M @ x - b).max() <= 1e-13 * np.abs(b).max() and np.abs(M.T @ y - bt).max() <= 1e-13 * np.abs(bt).max()
        assert np.abs(x - np.linalg.solve(M, b)).max() <= 1e-12 and np.abs(y - np.linalg.solve(M.T, bt)).max() <= 1e-12
        assert pivot[0] > 0.1


def test_a_fixed_pivot_that_vanishes_is_reported():
    """[[p, 1], [1, 2]] factored at p = 3 pivots on p (the largest of its column, ties to the first); at p = 0 the
    matrix is regular (det -1) but that pivot is 0: the smallest relative pivot is 0 and the fixed-order solution
    is not finite, which is what the kernels' callers test before falling back."""
    p = cs.SX.sym("p")
    A = cs.vertcat(cs.horzcat(p, 1.0), cs.horzcat(1.0, 2.0))
    lu = PivotedLU(A, np.array([[3.0, 1.0], [1.0, 2.0]]))
    assert lu.order[0] == (0, 0) and np.array_equal(lu.reference_pivots[:1], [3.0])
    solve = _solver(p, A, lu)
    x, _, pivot = (np.array(v).ravel() for v in solve(0.0, [1.0, 1.0], [1.0, 1.0]))
    assert pivot[0] == 0.0 and not np.all(np.isfinite(x))
    x, _, pivot = (np.array(v).ravel() for v in solve(1.5, [1.0, 1.0], [1.0, 1.0]))
    assert abs(pivot[0] - 0.5) <= 1e-15 and np.abs(np.array([[1.5, 1.0], [1.0, 2.0]]) @ x - 1.0).max() <= 1e-15


def test_a_tall_matrix_is_factored_on_its_independent_rows():
    """A 3 x 2 matrix whose third row is the sum of the first two: x solves a consistent system exactly (1e-14), and
    the transposed solution is zero on the one row left without a pivot."""
    A = cs.SX(np.array([[2.0, 1.0], [1.0, 3.0], [3.0, 4.0]]))
    lu = PivotedLU(A, np.array(cs.DM(A)))
    free = ({0, 1, 2} - {r for r, _ in lu.order}).pop()
    M = np.array(cs.DM(A))
    x_true = np.array([0.7, -1.3])
    x = np.array(cs.evalf(lu.solve(cs.DM(M @ x_true)))).ravel()
    y = np.array(cs.evalf(lu.solve_transposed(cs.DM([1.0, 2.0])))).ravel()
    assert np.abs(x - x_true).max() <= 1e-14 and y[free] == 0.0 and np.abs(M.T @ y - [1.0, 2.0]).max() <= 1e-14


def test_what_cannot_be_factored_is_refused():
    """More columns than rows, or a reference of rank 1 < 2: ValueError saying which."""
    with pytest.raises(ValueError, match="a 1 x 2 matrix: PivotedLU needs at least as many rows as columns"):
        PivotedLU(cs.SX(np.ones((1, 2))), np.ones((1, 2)))
    with pytest.raises(ValueError, match=r"rank 1 < 2 at the reference: no pivot for columns \[\d\]"):
        PivotedLU(cs.SX(np.array([[1.0, 2.0], [2.0, 4.0]])), np.array([[1.0, 2.0], [2.0, 4.0]]))


def test_the_homogenised_pseudo_inverse_equals_the_cores_away_from_the_reference():
    """A tall 7 x 3 matrix of full column rank, rows and columns weighted (a rotation row by L, a length column by L):
    the solves by the normal equations (factored at the reference, evaluated elsewhere) equal the core's SVD route
    (homogenised_pinv) to 1e-12: least squares for a right-hand side outside the range, the transposed solve's
    multipliers of least weighted norm (and they solve A^T y = b)."""
    rng = np.random.default_rng(3)
    rows, cols = np.array([1.0, 1.0, 1.0, 0.2, 0.2, 0.2, 1.0]), np.array([1.0, 0.2, 1.0])
    A_ref = rng.standard_normal((7, 3))
    x = cs.SX.sym("x", 7, 3)
    P = HomogenisedPinv(x, A_ref, rows, cols)
    b, c = cs.SX.sym("b", 7), cs.SX.sym("c", 3)
    f = cs.Function("f", [x, b, c], [P.solve(b), P.solve_transposed(c)])
    A = A_ref + 0.3 * rng.standard_normal((7, 3))
    bv, cv = rng.standard_normal(7), rng.standard_normal(3)
    xs, ys = (np.array(o).ravel() for o in f(A, bv, cv))
    pinv = homogenised_pinv(A, rows, cols, 1e-12)[0]
    assert np.abs(xs - pinv @ bv).max() <= 1e-12 and np.abs(ys - pinv.T @ cv).max() <= 1e-12
    assert np.abs(A.T @ ys - cv).max() <= 1e-12
