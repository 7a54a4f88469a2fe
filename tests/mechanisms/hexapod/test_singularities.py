"""The paper's singular configurations (sec. 3.3, Figs. 4-6) constructed exactly and classified.

Each example is built from the geometry (not searched), classified by
``hexapod_singularities.classify`` (threshold 1e-6 on dimensionless distances) and cross-checked
with the generic core's ``diagnose`` (its smallest singular values below 1e-9, the regular
reference above 1e-3).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import pkm
from pkm.core.differential import screws
from pkm.mechanisms import hexapod as hx
from pkm.mechanisms._common import rot_y
from pkm.mechanisms.hexapod import screws as hs
from pkm.mechanisms.hexapod import singularities as hsg
from pkm.papers.hexapod import pose_T_placement

DEG = math.pi / 180.0
COINCIDENT = tuple(a * DEG for a in (35.0, 155.0, 275.0, 35.0, 155.0, 275.0))  # theta_i = theta_{i+3}


@pytest.fixture(scope="module")
def params():
    return hx.Params()


def in_plane_rotation(theta_deg):
    """Platform turned about Y so that C_1 (and C_4) face the leg at theta: C_i lie in their leg planes."""
    return rot_y(-theta_deg * DEG)


def stretched_depth(p):
    """Depth of P at which legs 1-3 are fully extended (beta = 0, platform in their planes): |C - A| = LA + LB."""
    return -math.sqrt((p.LA + p.LB) ** 2 - (p.Rf + p.Rr - p.r) ** 2) - p.h


def core_diagnosis(p, R, P, beta, branch="elbow_out"):
    mech = hx.build(p)
    return pkm.diagnose(mech, hx.configuration(mech, hx.task_vector(R, P, beta), branch))


def test_pose_t_is_regular(params):
    """Pose T at beta = 0: every distance well above the threshold; the core agrees."""
    rep = hsg.classify(params, *pose_T_placement(), 0.0)
    assert rep.kind == "regular" and rep.type == 0
    assert rep.transmission.min() > 0.5 and rep.sigma_direct > 0.05
    assert core_diagnosis(params, *pose_T_placement(), 0.0).classification == "regular"


def test_fully_extended_legs_of_m1_are_an_inverse_singularity(params):
    """Fig. 4a: LA and LB of legs 1-3 aligned (platform lowered until they stretch): type 1, det J_q = 0."""
    R, P = in_plane_rotation(35.0), (0.0, stretched_depth(params), 0.0)
    rep = hsg.classify(params, R, P, 0.0)
    assert rep.kind == "inverse" and rep.inverse_legs == (1, 2, 3) and rep.reconfiguration_legs == ()
    assert rep.transmission[:3].max() < 1e-7 and rep.transmission[3:].min() > 0.1 and rep.sigma_direct > 0.05
    assert abs(rep.det_Jq) < 1e-12
    diag = core_diagnosis(params, R, P, 0.0)
    assert diag.classification == "inverse" and diag.sigma_inverse < 1e-9


def test_reconfiguration_link_collinear_with_the_rod_is_singular_for_j_q_prime_and_j_q(params):
    """Fig. 4b case (iii): beta = 90 deg, LA and LB extended down from A, folded over Rr: det J'_q = det J_q = 0."""
    R, P = in_plane_rotation(35.0), (0.0, params.Rr - params.LA - params.LB - params.h, 0.0)
    rep = hsg.classify(params, R, P, 90 * DEG)
    assert rep.kind == "inverse" and rep.reconfiguration_legs == (1, 2, 3) and rep.inverse_legs == (1, 2, 3)
    assert abs(rep.det_Jq_prime) < 1e-12 and abs(rep.det_Jq) < 1e-12  # det J'_q = 0 => det J_q = 0
    assert core_diagnosis(params, R, P, 90 * DEG).classification == "inverse"


def test_coplanar_rods_of_m2_converging_to_a_point_are_a_direct_singularity(params):
    """Fig. 5: rods of legs 4-6 horizontal, in the plane of C4C5C6 and radial (they meet at P): type 2.

    With the platform turned so that C4..C6 face their legs and P at the depth of the arms'
    tips (B_i = A_i - LA e_y), the rods lie along the radii of the platform triangle.
    """
    R, P = in_plane_rotation(25.0), (0.0, -params.H0 - params.LA, 0.0)
    alphas = hx.inverse_kinematics(params, R, P, 0.0)
    assert np.allclose(alphas[3:], -90 * DEG, atol=1e-9)
    rep = hsg.classify(params, R, P, 0.0)
    assert rep.kind == "direct" and rep.sigma_direct < 1e-12 and rep.sigma_m2 < 1e-12 and rep.sigma_m1 > 0.5
    assert rep.inverse_legs == ()
    diag = core_diagnosis(params, R, P, 0.0)
    assert diag.classification == "direct" and diag.sigma_direct < 1e-9


def test_coincident_triangles_along_minus_y_let_the_platform_spin_about_y():
    """Sec. 3.3: theta_i = theta_{i+3} and every triangle concentric and aligned: each $6_i has a zero second
    dual component, so [e_y; 0] is reciprocal to all of them: type 2 anywhere along -Y. Table 1's thetas avoid it."""
    p = hx.Params(theta=COINCIDENT)
    R = in_plane_rotation(35.0)
    for depth in (-0.30, -0.35, -0.45):
        P = (0.0, depth, 0.0)
        J = hs.jacobians(p, R, P, 0.0)
        assert np.abs(J.Jx[4]).max() < 1e-15  # second component of every dual part
        assert np.abs(J.JxT_delta @ np.r_[0.0, 1.0, 0.0, 0.0, 0.0, 0.0]).max() < 1e-15
        assert hsg.classify(p, R, P, 0.0).kind == "direct"
    assert core_diagnosis(p, R, (0.0, -0.35, 0.0), 0.0).classification == "direct"
    assert hsg.classify(hx.Params(), R, (0.0, -0.35, 0.0), 0.0).kind == "regular"


def test_extended_legs_with_coincident_triangles_are_a_combined_singularity():
    """Type 3 case (i): legs 1-3 stretched (type 1) while the coincident triangles make J_x singular (type 2)."""
    p = hx.Params(theta=COINCIDENT)
    R, P = in_plane_rotation(35.0), (0.0, stretched_depth(p), 0.0)
    rep = hsg.classify(p, R, P, 0.0)
    assert rep.kind == "combined" and rep.type == 3 and rep.inverse_legs == (1, 2, 3)
    assert core_diagnosis(p, R, P, 0.0).classification == "combined"


def test_distances_shrink_continuously_towards_a_singularity(params):
    """Approaching the stretched configuration, the transmission of legs 1-3 falls like sqrt(distance)."""
    R = in_plane_rotation(35.0)
    y0 = stretched_depth(params)
    t = [hsg.classify(params, R, (0.0, y0 + e, 0.0), 0.0).transmission[0] for e in (1e-2, 1e-4, 1e-6)]
    assert t[0] > t[1] > t[2] and 5 < t[0] / t[1] < 20 and 5 < t[1] / t[2] < 20


def test_klein_form_of_the_rod_with_a_spin_about_y_is_its_dual_y_component(params):
    """{[e_y; 0]; $6_i} = (C_i x w_i)_y: the reason the coincident case is singular (exact)."""
    S = hs.leg_screws(params, *pose_T_placement(), 0.0)[:, 6]
    assert np.allclose(screws.klein(np.r_[0.0, 1.0, 0.0, 0.0, 0.0, 0.0], S), S[:, 4], atol=0)
