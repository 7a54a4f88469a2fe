"""pkm.mechanisms.hexapod.geometry: the paper's points and angles in closed form. The inverse kinematics puts every
elbow B_i at LA from A_i (eq. 3) and LB from C_i (eq. 6), in its leg's plane, at random poses and on both working
modes; the base points lie where eqs. 1-2 put them; the platform points are a rigid prism; the paper's angles and
the actuated vector convert into each other. Each check uses only the stated equations, not pkm's model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pkm.errors import InvalidInputError, UnreachableError
from pkm.mechanisms.hexapod import geometry as g
from pkm.mechanisms.hexapod import kinematics
from pkm.mechanisms.hexapod.params import HexapodParams, leg_frame
from pkm.validation import wrap_angle

PARAMS = HexapodParams()


def _rotation(w) -> np.ndarray:
    """exp of the skew matrix of w (Rodrigues)."""
    w = np.asarray(w, dtype=float)
    t = np.linalg.norm(w)
    K = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]) / t
    return np.eye(3) + math.sin(t) * K + (1 - math.cos(t)) * K @ K


def _random_poses(n: int, seed: int):
    """n reachable (R, P, beta) near the paper design's reference: tilts up to 0.1 rad, 2 cm, beta up to 0.4 rad."""
    rng = np.random.default_rng(seed)
    R0, P0, _ = kinematics.reference_pose(PARAMS)
    out = []
    while len(out) < n:
        R, P, beta = _rotation(0.1 * rng.uniform(-1, 1, 3)) @ R0, P0 + 0.02 * rng.uniform(-1, 1, 3), rng.uniform(-0.4, 0.4)
        try:
            g.inverse_kinematics(PARAMS, R, P, beta)
        except UnreachableError:
            continue
        out.append((R, P, beta))
    return out


@pytest.mark.parametrize("branch", ["elbow_out", "elbow_in", ("elbow_out", "elbow_in") * 3])
def test_inverse_kinematics_puts_each_elbow_at_la_from_a_and_lb_from_c(branch):
    """At 20 random poses: |B_i - A_i| = LA (eq. 3) and |C_i - B_i| = LB (eq. 6) to 1e-12 m, and B_i - A_i is
    perpendicular to the leg's axis u_i (the arm turns in its leg plane)."""
    for R, P, beta in _random_poses(20, seed=11):
        alphas = g.inverse_kinematics(PARAMS, R, P, beta, branch)
        A, B, C = g.base_points(PARAMS, beta), g.elbow_points(PARAMS, alphas, beta), g.platform_points(PARAMS, R, P)
        np.testing.assert_allclose(np.linalg.norm(B - A, axis=1), PARAMS.LA, atol=1e-12)
        np.testing.assert_allclose(np.linalg.norm(C - B, axis=1), PARAMS.LB, atol=1e-12)
        u = np.array([leg_frame(t)[:, 2] for t in PARAMS.theta])
        np.testing.assert_allclose(np.einsum("ij,ij->i", B - A, u), 0.0, atol=1e-13)


def test_the_two_working_modes_are_the_two_elbows_of_each_leg():
    """elbow_out and elbow_in give different alphas with the same A_i and C_i; a per-leg tuple mixes them leg by leg."""
    R, P, beta = _random_poses(1, seed=12)[0]
    out = g.inverse_kinematics(PARAMS, R, P, beta, "elbow_out")
    inn = g.inverse_kinematics(PARAMS, R, P, beta, "elbow_in")
    assert np.all(np.abs(wrap_angle(out - inn)) > 1e-6)
    mixed = g.inverse_kinematics(PARAMS, R, P, beta, ("elbow_out", "elbow_in") * 3)
    np.testing.assert_array_equal(mixed, np.where(np.arange(6) % 2 == 0, out, inn))


@pytest.mark.parametrize("beta", [-1.2, 0.0, 0.7])
def test_base_points_follow_eqs_1_and_2(beta):
    """Legs 1-3: A_i at Rr from the pivot F_i = Rf e_r, at Rf + Rr cos(beta) along e_r and Rr sin(beta) along Y; legs
    4-6: A_i on the circle of radius R2 of the plane y = -H0, at theta_i (1e-15 m)."""
    A = g.base_points(PARAMS, beta)
    for i, th in enumerate(PARAMS.theta):
        e_r = np.array([math.cos(th), 0.0, math.sin(th)])
        if i < 3:
            assert np.linalg.norm(A[i] - PARAMS.Rf * e_r) == pytest.approx(PARAMS.Rr, abs=1e-15)
            np.testing.assert_allclose(A[i], (PARAMS.Rf + PARAMS.Rr * math.cos(beta)) * e_r
                                       + [0.0, PARAMS.Rr * math.sin(beta), 0.0], atol=1e-15)
        else:
            np.testing.assert_allclose(A[i], PARAMS.R2 * e_r + [0.0, -PARAMS.H0, 0.0], atol=1e-15)


@pytest.mark.parametrize("layout", ["sector", "literal"])
def test_platform_points_are_two_equilateral_triangles_moved_rigidly(layout):
    """C*_1..3 lie h above C*_4..6 (along Y), each triple on the circle of radius r, 120 deg apart; platform_points
    is R C* + P (every distance kept, 1e-15 m)."""
    p = HexapodParams(layout=layout)
    Cl = g.platform_local_points(p)
    np.testing.assert_allclose(Cl[:3] - Cl[3:], np.tile([0.0, p.h, 0.0], (3, 1)), atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(Cl[3:][:, [0, 2]], axis=1), p.r, rtol=1e-15)
    sides = [np.linalg.norm(Cl[3 + k] - Cl[3 + (k + 1) % 3]) for k in range(3)]
    np.testing.assert_allclose(sides, math.sqrt(3.0) * p.r, rtol=1e-14)
    R, P = _rotation([0.2, -0.1, 0.3]), np.array([0.01, -0.3, 0.02])
    C = g.platform_points(p, R, P)
    np.testing.assert_allclose(C, Cl @ R.T + P, atol=1e-15)
    d = np.linalg.norm(C[:, None] - C[None], axis=2)
    np.testing.assert_allclose(d, np.linalg.norm(Cl[:, None] - Cl[None], axis=2), atol=1e-15)


def test_paper_alphas_and_actuated_from_paper_are_inverse():
    """For random angles: the paper's alphas -> the actuated vector -> back gives the same angles modulo 2 pi
    (1e-12); legs 1-3 differ by beta (alpha_joint = alpha_paper - beta), 4-6 not; the actuated angles are wrapped."""
    rng = np.random.default_rng(13)
    for _ in range(20):
        alphas, beta = rng.uniform(-6.0, 6.0, 6), rng.uniform(-1.5, 1.5)
        qa = g.actuated_from_paper(alphas, beta)
        assert qa.shape == (7,) and qa[6] == beta and np.all(np.abs(qa[:6]) <= math.pi)
        np.testing.assert_allclose(wrap_angle(qa[:3] - (alphas[:3] - beta)), 0.0, atol=1e-12)
        np.testing.assert_allclose(wrap_angle(g.paper_alphas(qa) - alphas), 0.0, atol=1e-12)


@pytest.mark.parametrize("call, name", [
    (lambda: g.paper_alphas(np.zeros(6)), "q_actuated"),
    (lambda: g.actuated_from_paper(np.zeros(5), 0.0), "alphas"),
    (lambda: g.actuated_from_paper(np.zeros(6), math.nan), "beta"),
    (lambda: g.elbow_points(PARAMS, [0.0] * 6 + [math.inf], 0.0), "alphas"),
    (lambda: g.inverse_kinematics(PARAMS, np.eye(3), [0.0, -0.35], 0.0), "P"),
    (lambda: g.inverse_kinematics(PARAMS, np.eye(3), [0.0, -0.35, 0.0], "0"), "beta"),
    (lambda: g.branch_names(("elbow_out",) * 5), "branch"),
])
def test_bad_arguments_are_refused_naming_them(call, name):
    """Wrong lengths, non-finite numbers, text for a number and a wrong number of branches: InvalidInputError."""
    with pytest.raises(InvalidInputError) as info:
        call()
    assert info.value.name == name
