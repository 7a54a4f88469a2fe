"""Smale's alpha test and the polishing Newton (:mod:`pkm.core.modes.certify`) on systems whose roots and alpha
quantities are known in closed form. (A simple root certified and a double one not: ``test_equations.py``.)"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pkm.core.modes.certify import ALPHA0, alpha_test, polish
from pkm.core.modes.polynomial import System, variables

ROOT = np.array([math.sqrt(2.0), math.sqrt(2.0)])


def _circle_and_diagonal() -> System:
    x, y = variables(2)
    return System([x * x + y * y - 4.0, x - y])


@pytest.mark.parametrize("x0", [1.5, -0.9, 3.0 + 1.0j])
def test_alpha_beta_gamma_of_a_quadratic_are_the_closed_forms(x0):
    """For f = x^2 - 2: beta = |f / f'| = |x0^2 - 2| / |2 x0|, gamma = |f'' / (2 f')| = 1 / |2 x0|, alpha their
    product, the radius 2 beta (1e-15 relative); certified exactly when alpha < ALPHA0 = (13 - 3 sqrt 17) / 4."""
    (x,) = variables(1)
    c = alpha_test(System([x * x - 2.0]), np.array([x0]))
    beta, gamma = abs(x0 * x0 - 2.0) / abs(2 * x0), 1.0 / abs(2 * x0)
    for got, want in ((c.beta, beta), (c.gamma, gamma), (c.alpha, beta * gamma), (c.radius, 2 * beta)):
        assert abs(got - want) <= 1e-15 * want
    assert c.certified == (beta * gamma < ALPHA0) and abs(ALPHA0 - 0.157670780786754) <= 1e-15


def test_a_certified_point_has_the_true_root_within_its_radius():
    """Points 1e-3 off the root (sqrt 2, sqrt 2) of the circle x^2 + y^2 = 4 and the line x = y are certified and the
    closed-form root lies within 2 beta of each; a point far away is not certified."""
    S = _circle_and_diagonal()
    rng = np.random.default_rng(2)
    for _ in range(4):
        x = ROOT + 1e-3 * (rng.normal(size=2) + 1j * rng.normal(size=2))
        c = alpha_test(S, x)
        assert c.certified and np.linalg.norm(x - ROOT) <= c.radius
    assert not alpha_test(S, np.array([5.0, -3.0])).certified


def test_what_cannot_be_tested_is_not_certified():
    """A singular Jacobian (x^2 at 0) and a non-square system give inf quantities, not certified (no exception)."""
    x, y = variables(2)
    for system, point in ((System([x * x, y]), np.zeros(2)), (System([x - 1.0]), np.ones(2))):
        c = alpha_test(system, point)
        assert not c.certified and math.isinf(c.alpha) and math.isinf(c.radius)


def test_polish_converges_quadratically_to_the_root():
    """From 1e-2 off the root one Newton step leaves an error of order its square (<= 10 e^2), eight reach it to
    1e-15; the polished point is then certified with a radius under 1e-14."""
    S = _circle_and_diagonal()
    x0 = ROOT + np.array([1e-2, -0.7e-2])
    e0 = np.linalg.norm(x0 - ROOT)
    e1 = np.linalg.norm(polish(S, x0, iterations=1) - ROOT)
    assert 0 < e1 <= 10 * e0 ** 2
    x = polish(S, x0)
    assert np.linalg.norm(x - ROOT) <= 1e-15 * 4
    c = alpha_test(S, x)
    assert c.certified and c.radius <= 1e-14


def test_polish_stops_at_a_singular_jacobian_and_does_not_touch_its_input():
    """At a point where the Jacobian is singular the point comes back unchanged (no LinAlgError); the caller's array
    is never written."""
    x, y = variables(2)
    start = np.zeros(2)
    out = polish(System([x * x, y * y]), start)
    assert np.array_equal(out, start) and out is not start
    x0 = ROOT + 0.1
    polish(_circle_and_diagonal(), x0)
    assert np.array_equal(x0, ROOT + 0.1)
