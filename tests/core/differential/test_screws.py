"""Tests of the screw algebra (pkm.core.differential.screws) against Pinocchio and finite differences."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pkm.core.differential import screws
from pkm.errors import InvalidInputError

RNG = np.random.default_rng(7)


def random_screws(n):
    return RNG.normal(size=(n, 6))


def test_klein_form_is_symmetric_and_gives_the_power_of_a_wrench_on_a_twist():
    """{V; W} = {W; V} = w . m_O + v_O . f for a twist [w; v_O] and a wrench [f; m_O] (exact to 1e-15)."""
    V, W = random_screws(2)
    assert abs(screws.klein(V, W) - screws.klein(W, V)) < 1e-15
    assert abs(screws.klein(V, W) - (V[:3] @ W[3:] + V[3:] @ W[:3])) < 1e-15
    assert abs(screws.klein(V, W) - V @ screws.DELTA @ W) < 1e-15


def test_two_lines_are_reciprocal_exactly_when_they_intersect_or_are_parallel():
    """Klein form of two lines = -d sin(angle) (d the common normal's length): 0 for intersecting lines."""
    p, s1, s2 = RNG.normal(size=(3, 3))
    assert abs(screws.klein(screws.line(s1, p), screws.line(s2, p))) < 1e-14
    assert abs(screws.klein(screws.line(s1, p), screws.line(s1, p + s2))) < 1e-14
    # skew lines along x through the origin and along y through (0, 0, 1): distance 1, right angle
    assert abs(abs(screws.klein(screws.line([1, 0, 0], [0, 0, 0]), screws.line([0, 1, 0], [0, 0, 1]))) - 1.0) < 1e-15


def test_lie_product_is_antisymmetric_and_satisfies_jacobi():
    """[a, b] = -[b, a] and [a, [b, c]] + [b, [c, a]] + [c, [a, b]] = 0 (1e-14)."""
    a, b, c = random_screws(3)
    assert np.allclose(screws.lie(a, b), -screws.lie(b, a), atol=1e-15)
    jac = screws.lie(a, screws.lie(b, c)) + screws.lie(b, screws.lie(c, a)) + screws.lie(c, screws.lie(a, b))
    assert np.abs(jac).max() < 1e-14


def test_lie_product_equals_pinocchio_motion_cross_with_halves_swapped():
    """[a, b] = DELTA (a^ x b^) with a^ = DELTA a in Pinocchio's [v; w] layout (1e-14)."""
    a, b = random_screws(2)
    ref = pin.Motion(screws.DELTA @ a).cross(pin.Motion(screws.DELTA @ b)).vector
    assert np.allclose(screws.lie(a, b), screws.DELTA @ ref, atol=1e-14)


def test_transform_is_pinocchios_adjoint_and_shift_moves_the_pole():
    """transform = Ad(M) (Pinocchio action matrix, halves swapped); shift gives v_Q = v_O + w x Q (1e-14)."""
    M = pin.SE3.Random()
    s = random_screws(4)
    ref = (screws.DELTA @ M.toActionMatrix() @ screws.DELTA @ s.T).T
    assert np.allclose(screws.transform(s, M.rotation, M.translation), ref, atol=1e-14)
    Q = RNG.normal(size=3)
    V = s[0]
    assert np.allclose(screws.shift(V, Q)[3:], V[3:] + np.cross(V[:3], Q), atol=1e-15)


def test_pitch_and_axis_of_a_screw_built_from_them():
    """screw(s, r, h) has pitch h, passes through r, and prismatic screws have infinite pitch."""
    s, r = RNG.normal(size=(2, 3))
    S = screws.screw(s, r, 0.3)
    assert abs(screws.pitch(S) - 0.3) < 1e-14
    c = screws.axis_point(S)
    assert np.linalg.norm(np.cross(c - r, s)) < 1e-14 and abs(c @ s) < 1e-14
    assert screws.pitch(screws.prismatic(s)) == np.inf


def test_chain_acceleration_equals_finite_differences_of_the_chain_twist():
    """A serial chain of 4 screws: sum qdd_j $_j + sum_{j<k} [qd_j $_j, qd_k $_k] = d/dt of the twist.

    The placement is the product of exponentials of the home screws (Pinocchio exp6); the twist is
    dM/dt M^-1 (world axes, pole O), its derivative by central differences (step 1e-5, rel. 1e-8).
    """
    S0 = np.array([screws.screw(RNG.normal(size=3), RNG.normal(size=3), h) for h in (0.0, 0.1, 0.0, -0.2)])
    q0, qd, qdd = RNG.normal(size=(3, 4))

    def placement(q):
        M = pin.SE3.Identity()
        for s, x in zip(S0, q):
            M = M * pin.exp6(pin.Motion(screws.DELTA @ s * x))
        return M

    def current(q):  # screws at q: each home screw moved by the joints before it
        out, M = [], pin.SE3.Identity()
        for s, x in zip(S0, q):
            out.append(screws.transform(s, M.rotation, M.translation))
            M = M * pin.exp6(pin.Motion(screws.DELTA @ s * x))
        return np.array(out)

    def twist(t):
        q = q0 + t * qd + 0.5 * t * t * qdd
        return screws.chain_twist(current(q), qd + t * qdd)

    h = 1e-5
    # the twist itself against differences of the placement
    Mp, Mm = placement(q0 + h * qd), placement(q0 - h * qd)
    V_fd = screws.DELTA @ pin.log6(Mp * Mm.inverse()).vector / (2 * h)
    assert np.allclose(twist(0.0), V_fd, rtol=1e-8, atol=1e-8)
    A_fd = (twist(h) - twist(-h)) / (2 * h)
    A = screws.chain_twist(current(q0), qdd) + screws.chain_lie_term(current(q0), qd)
    assert np.linalg.norm(A - A_fd) < 1e-8 * np.linalg.norm(A_fd)


@pytest.mark.parametrize("call", [
    lambda: screws.klein(np.zeros(5), np.zeros(6)),
    lambda: screws.line([0, 0, 0], [1, 2, 3]),
    lambda: screws.prismatic([np.nan, 0, 1]),
    lambda: screws.transform(np.zeros(6), np.diag([1.0, 1.0, -1.0]), np.zeros(3)),
    lambda: screws.axis_point(screws.prismatic([0, 0, 1])),
])
def test_bad_screws_raise_invalid_input_error(call):
    """Wrong shapes, zero or non-finite directions, reflections and axis-less screws are refused."""
    with pytest.raises(InvalidInputError):
        call()
