"""Sparse polynomials (:mod:`pkm.core.modes.polynomial`): a Poly built by arithmetic evaluates to the same arithmetic
done on numbers, is kept expanded (its degree the true one), and a System evaluates stacks of points as point by
point, its Jacobian matching central differences. (Hessians and ``fix`` on a chart: ``test_equations.py``.)"""

from __future__ import annotations

import numpy as np
import pytest

from pkm.core.modes.polynomial import Poly, System, dot, fix, matvec, variables


def _expression(x, y, z):
    """The same expression for Polys and for numbers; numpy scalars on the left exercise the reflected operators."""
    return (x + 2.0) * (y - 3.0j) - np.float64(0.5) * x * x * z + 1.0 - z + (2.0 - y) * (np.complex128(1j) * z)


def test_a_poly_evaluates_to_the_same_arithmetic_done_on_numbers():
    """At random complex points the Poly of the expression equals the expression computed on the numbers (1e-13
    relative), whether numbers or numpy scalars stand on either side of an operator."""
    x, y, z = variables(3)
    p = _expression(x, y, z)
    assert isinstance(p, Poly) and isinstance(np.float64(2.0) * x, Poly) and isinstance(np.float64(2.0) - x, Poly)
    rng = np.random.default_rng(0)
    for _ in range(5):
        pt = rng.normal(size=3) + 1j * rng.normal(size=3)
        direct = _expression(*pt)
        assert abs(p(pt) - direct) <= 1e-13 * max(1.0, abs(direct))


def test_products_are_expanded_so_the_degree_is_the_true_one():
    """(x + 1)(x - 1) - x^2 cancels exactly to the constant -1 (degree 0, one term); a product's degree is the sum of
    its factors' degrees; homogeneous() tells one degree from several."""
    (x,) = variables(1)
    p = (x + 1.0) * (x - 1.0) - x * x
    assert p.degree == 0 and p.terms == {(0,): -1.0}
    a, b = variables(2)
    q = (a * a + b) * (a * b - 2.0)
    assert q.degree == 4 and not q.homogeneous() and (a * a * b + a * b * b).homogeneous()
    assert (-q + q).terms == {} and (-q + q).degree == 0


def test_cleaned_drops_only_the_terms_below_the_relative_threshold():
    """Terms below rel * scale go (the 1e-17 left by rounding), larger ones stay untouched."""
    a, b = variables(2)
    p = a * a * 2.0 + b * 1e-17 + 3.0
    kept = p.cleaned(scale=3.0)
    assert kept.terms == {(2, 0): 2.0, (0, 0): 3.0} and p.cleaned(scale=1e-6).terms == p.terms


def test_a_system_evaluates_stacks_as_point_by_point():
    """F and J on a (4, 5, n) stack of points equal F and J at each point (exactly: the same arithmetic); the Jacobian
    at a point equals central differences (1e-7)."""
    x, y, z = variables(3)
    S = System([_expression(x, y, z), x * y * z - 1.0, y * y + 0.25])
    rng = np.random.default_rng(1)
    pts = rng.normal(size=(4, 5, 3)) + 1j * rng.normal(size=(4, 5, 3))
    F, J = S(pts), S.jacobian(pts)
    assert F.shape == (4, 5, 3) and J.shape == (4, 5, 3, 3)
    for i in range(4):
        for k in range(5):
            np.testing.assert_allclose(F[i, k], S(pts[i, k]), rtol=1e-15, atol=0)
            np.testing.assert_allclose(J[i, k], S.jacobian(pts[i, k]), rtol=1e-15, atol=0)
    h, pt = 1e-6, pts[0, 0]
    fd = np.column_stack([(S(pt + h * e) - S(pt - h * e)) / (2 * h) for e in np.eye(3)])
    assert np.abs(fd - S.jacobian(pt)).max() <= 1e-7 * max(1.0, np.abs(fd).max())


def test_the_zero_polynomial_and_the_empty_system():
    """The zero Poly (no terms) evaluates to 0 with a zero Jacobian row; a System of no polynomials is a ValueError."""
    (x, y) = variables(2)
    S = System([x - x, x * y])
    assert S(np.array([2.0, 3.0]))[0] == 0 and not S.jacobian(np.array([2.0, 3.0]))[0].any()
    with pytest.raises(ValueError, match="at least one polynomial"):
        System([])


def test_dot_matvec_and_fix_agree_with_numbers():
    """dot and matvec of Polys evaluate to numpy's on the numbers; fix(p, i, v) evaluates to p with x_i = v."""
    v = variables(3)
    M = np.arange(9.0).reshape(3, 3) - 4.0
    pt = np.array([0.3, -1.2, 2.0])
    assert abs(dot(M[0], v)(pt) - M[0] @ pt) <= 1e-15 * 10
    assert np.abs(np.array([p(pt) for p in matvec(M, v)]) - M @ pt).max() <= 1e-14
    p = _expression(*v)
    assert abs(fix(p, 1, pt[1])(pt[[0, 2]]) - p(pt)) <= 1e-13 * abs(p(pt))
