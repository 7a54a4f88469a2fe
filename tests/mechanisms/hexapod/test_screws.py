"""Screw-theory velocity and acceleration of the hexapod (paper eqs. 18-33) against the generic core and FD.

Tolerances: screw route = generic core to 1e-9 (relative, Frobenius); both = Richardson-extrapolated
central differences (tests/fd.py) to 1e-7.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.differential import screws
from pkm.mechanisms import hexapod as hx
from pkm.mechanisms.hexapod import screws as hs
from pkm.papers.hexapod import pose_T_placement
from tests.fd import forward_jacobian_error, rel, richardson

DEG = math.pi / 180.0
MIXED = ("elbow_out", "elbow_in", "elbow_out", "elbow_in", "elbow_in", "elbow_out")
CASES = [(-40 * DEG, "elbow_out"), (-11 * DEG, "elbow_out"), (30 * DEG, "elbow_in"), (10 * DEG, MIXED)]


@pytest.fixture(scope="module")
def mech():
    return hx.build()


def pose(params, k=0):
    rng = np.random.default_rng(10 + k)
    R0, P0 = pose_T_placement()
    return pin.exp3(0.05 * rng.uniform(-1, 1, 3)) @ R0, P0 + 0.02 * rng.uniform(-1, 1, 3)


def core_config(mech, R, P, beta, branch):
    return hx.closed_form_configuration(mech, hx.task_vector(R, P, beta), branch)


def core_reduced_acceleration(mech, q, qd, qdd, P):
    """[w_dot; a_O - w x v_O] from the generic core's task acceleration [a_P; w_dot] (classical, at P)."""
    v = pkm.velocities(mech, q, qd)
    a = pkm.accelerations(mech, q, v, qdd)
    yd, ydd = pkm.task_velocity(mech, q, v), pkm.task_acceleration(mech, q, v, a)
    w, vP, aP, wd = yd[3:6], yd[:3], ydd[:3], ydd[3:6]
    vO = vP + np.cross(w, -P)
    aO = aP + np.cross(wd, -P) + np.cross(w, np.cross(w, -P))
    return np.concatenate([wd, aO - np.cross(w, vO)])


@pytest.mark.parametrize("beta, branch", CASES)
def test_screw_twist_jacobian_equals_the_generic_core(mech, beta, branch):
    """(J_x^T DELTA)^-1 [J_q, J'_q (1,1,1,0,0,0)] = the core's twist Jacobian, at P and at O (1e-9)."""
    R, P = pose(mech.params)
    q = core_config(mech, R, P, beta, branch)
    Jt = pkm.twist_jacobian(mech, q)  # [v_P; w] per actuated rate
    J = hs.jacobians(mech.params, R, P, beta, branch)
    assert rel(J.twist_jacobian("P"), np.vstack([Jt[3:], Jt[:3]])) < 1e-9
    Jo = np.vstack([Jt[3:], Jt[:3] + pin.skew(P) @ Jt[3:]])  # v_O = v_P + P x w
    assert rel(J.twist_jacobian("O"), Jo) < 1e-9


@pytest.mark.parametrize("beta, branch", CASES)
def test_screw_acceleration_equals_the_generic_core(mech, beta, branch):
    """Eq. (33) with C from the Lie screws (eqs. 29-30) = the core's accelerations, drift included (1e-9)."""
    R, P = pose(mech.params, 1)
    q = core_config(mech, R, P, beta, branch)
    rng = np.random.default_rng(2)
    for _ in range(3):
        qd, qdd = rng.normal(size=7), rng.normal(size=7)
        A = hs.acceleration(mech.params, R, P, beta, qd, qdd, branch)
        assert rel(A, core_reduced_acceleration(mech, q, qd, qdd, P)) < 1e-9


def test_screw_jacobian_equals_differences_of_the_semi_closed_forward_kinematics(mech):
    """The twist Jacobian = differences of the pose by the paper's FK (eqs. 4-13), 1e-7; so does the core's."""
    params = mech.params
    R, P = pose(params, 2)
    beta = -0.2
    qa = hx.closed_form_ik(params, hx.task_vector(R, P, beta))
    y0 = hx.task_vector(R, P, beta)

    def diff(h):
        cols = []
        for e in h * np.eye(7):
            yp, ym = hx.closed_form_fk(params, qa + e, seed=y0), hx.closed_form_fk(params, qa - e, seed=y0)
            Rp, Rm = (pin.Quaternion(y[6], *y[3:6]).toRotationMatrix() for y in (yp, ym))
            cols.append(np.concatenate([pin.log3(Rp @ Rm.T), yp[:3] - ym[:3]]) / (2 * h))
        return np.column_stack(cols)

    J_fd = richardson(diff, 1e-5)
    assert rel(hs.jacobians(params, R, P, beta).twist_jacobian("P"), J_fd) < 1e-7
    assert forward_jacobian_error(mech, core_config(mech, R, P, beta, "elbow_out")) < 1e-7


def test_screw_acceleration_equals_differences_of_the_screw_twist_along_a_motion(mech):
    """A = dV/dt (pole fixed) along alpha(t) = alpha + t qd + t^2/2 qdd, poses from the paper's FK (1e-7)."""
    params = mech.params
    R, P = pose(params, 3)
    beta = 0.15
    y0 = hx.task_vector(R, P, beta)
    qa = hx.closed_form_ik(params, y0)
    rng = np.random.default_rng(4)
    qd, qdd = rng.normal(size=7), rng.normal(size=7)

    def V(t):
        y = hx.closed_form_fk(params, qa + t * qd + 0.5 * t * t * qdd, seed=y0)
        Rt = pin.Quaternion(y[6], *y[3:6]).toRotationMatrix()
        return hs.twist(params, Rt, y[:3], y[7], qd + t * qdd)

    A_fd = richardson(lambda h: (V(h) - V(-h)) / (2 * h), 1e-5)
    assert rel(hs.acceleration(params, R, P, beta, qd, qdd), A_fd) < 1e-7


def test_rod_screw_is_reciprocal_to_every_passive_joint_and_the_virtual_rate_is_zero(mech):
    """{$6; $n} = 0 for n = 2..6 but not for $1 (and $r); the passive rates give back the platform twist."""
    params = mech.params
    R, P = pose(params, 4)
    S = hs.leg_screws(params, R, P, 0.3)
    for i in range(6):
        k = screws.klein(S[i, 6], S[i])
        assert np.abs(k[2:7]).max() < 1e-15 and abs(k[1]) > 1e-3
    qd = np.random.default_rng(5).normal(size=7)
    rates = hs.leg_rates(params, R, P, 0.3, qd)
    assert np.abs(rates[:, 7]).max() < 1e-13  # omega_f = 0
    V = hs.twist(params, R, P, 0.3, qd)
    assert np.abs(screws.chain_twist(S, rates) - V).max() < 1e-13


def test_reconfiguration_klein_form_is_not_one_as_printed(mech):
    """Eqs. (22)-(24) say {$r; $6} = 1 (collinear screws); it equals Rr u.(c x w) + LA u.(a x w) instead."""
    params = mech.params
    R, P = pose(params, 5)
    beta = 0.4
    J = hs.jacobians(params, R, P, beta)
    alphas = hx.inverse_kinematics(params, R, P, beta)
    B, C = hx.elbow_points(params, alphas, beta), hx.platform_points(params, R, P)
    for i in range(3):
        L = hx.leg_frame(params.theta[i])
        u, c = L[:, 2], math.cos(beta) * L[:, 0] + math.sin(beta) * L[:, 1]
        a = math.cos(alphas[i]) * L[:, 0] + math.sin(alphas[i]) * L[:, 1]
        w = (C[i] - B[i]) / params.LB
        ref = params.Rr * u @ np.cross(c, w) + params.LA * u @ np.cross(a, w)
        assert abs(J.Jq_prime[i, i] - ref) < 1e-15 and abs(ref - 1.0) > 0.1
    assert np.allclose(np.diag(J.Jq_prime)[3:], 1.0)


def test_inverse_velocity_equals_the_generic_inverse_jacobian(mech):
    """alpha rates = J_q^-1 (J_x^T DELTA V - J'_q qd_beta) equal the core's inverse Jacobian (1e-9)."""
    R, P = pose(mech.params, 6)
    beta = -0.3
    q = core_config(mech, R, P, beta, "elbow_out")
    Jinv = pkm.inverse_jacobian(mech, q)  # (x y z wx wy wz beta) -> actuated
    J = hs.jacobians(mech.params, R, P, beta)
    rng = np.random.default_rng(8)
    yd = rng.normal(size=7)
    V = np.concatenate([yd[3:6], yd[:3] + np.cross(yd[3:6], -P)])  # [w; v_O]
    qd_beta = np.r_[np.full(3, yd[6]), np.zeros(3)]
    qd_alpha = np.linalg.solve(J.Jq, J.JxT_delta @ V - J.Jq_prime @ qd_beta)
    assert rel(np.r_[qd_alpha, yd[6]], Jinv @ yd) < 1e-9
