"""Tests specific to the reconfigurable hexapod (Sanchez-Alonso et al., RIAI 2016).

The generic harness (tests/test_mechanisms_generic.py) checks closures, Jacobians and
accelerations; these tests check the paper: its equations (corrected where printed wrong),
its semi-closed forward kinematics, the reconfiguration coupling, the working modes, the
layouts and the claims of its sec. 4 about pose T.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core import TaskMap, solve_ik
from pkm.core.kinematics import constraints
from pkm.errors import AssemblyError, ConvergenceError, InvalidInputError, InvalidParameterError, UnreachableError
from pkm.mechanisms import hexapod as hx
from pkm.papers.hexapod import POSE_T_POSITION, POSE_T_ROTATION, pose_T_placement

DEG = math.pi / 180.0
#: Lower end of the interval of beta where pose T is reachable (found by bisection, see below) [deg].
BETA_MIN_POSE_T = -59.51


POSE_T_DESIGN = hx.Params(home_rotation=POSE_T_ROTATION, home_position=POSE_T_POSITION)  # reference: pose T


@pytest.fixture(scope="module")
def mech():
    return hx.build(POSE_T_DESIGN)


@pytest.fixture(scope="module")
def params():
    return POSE_T_DESIGN


def pose_t(params):
    return pose_T_placement()


def near_pose_t(params, rng, n, pos=0.02, ang=0.05):
    """n poses (R, P) drawn around pose T."""
    R0, P0 = pose_t(params)
    return [(pin.exp3(ang * rng.uniform(-1, 1, 3)) @ R0, P0 + pos * rng.uniform(-1, 1, 3)) for _ in range(n)]


def leg_geometry(params, R, P, beta, branch="elbow_out"):
    """Paper points A, B, C (rows) and axes u of the six legs at a pose."""
    alphas = hx.inverse_kinematics(params, R, P, beta, branch)
    A, B, C = hx.base_points(params, beta), hx.elbow_points(params, alphas, beta), hx.platform_points(params, R, P)
    return A, B, C, np.array([hx.leg_frame(th)[:, 2] for th in params.theta])


def paper_manipulabilities(params, R, P, beta, branch="elbow_out"):
    """``(w_rot, w_tras)`` of eqs. (35)-(37): ``J = (J_x^T Delta)^-1 J_q``, twists about O."""
    A, B, C, u = leg_geometry(params, R, P, beta, branch)
    w = (C - B) / params.LB
    JxT_delta = np.array([np.concatenate([np.cross(C[i], w[i]), w[i]]) for i in range(6)])  # rows S6^T Delta
    Jq = np.diag([u[i] @ np.cross(C[i], w[i]) + np.cross(A[i], u[i]) @ w[i] for i in range(6)])  # {S1; S6}
    J = np.linalg.solve(JxT_delta, Jq)
    return tuple(math.sqrt(np.linalg.det(Jp @ Jp.T)) for Jp in (J[:3], J[3:]))


# ---------------------------------------------------------------------- parameters
@pytest.mark.parametrize("kwargs, field", [
    ({"LA": -0.2}, "LA"), ({"LB": 0.0}, "LB"), ({"r": float("nan")}, "r"), ({"H0": float("inf")}, "H0"),
    ({"m_platform": -1.0}, "m_platform"), ({"layout": "mirror"}, "layout"), ({"theta": (0.1,) * 5}, "theta"),
    ({"home_rotation": (1.0, 0, 0, 0, 1.0, 0, 0, 0, -1.0)}, "home_rotation"),
    ({"home_position": (0.0, float("nan"), 0.0)}, "home_position"),
    ({"home_position": (0.0, -1.2, 0.0)}, "home_position"),  # too low for every leg
])
def test_invalid_parameters_raise_invalid_parameter_error(kwargs, field):
    """Non-positive or non-finite lengths, unknown layouts, bad home poses and unreachable home poses are refused."""
    with pytest.raises(InvalidParameterError) as exc:
        hx.reference_pose(hx.Params(**kwargs))
    assert exc.value.name == field


def test_unreachable_home_pose_message_names_the_leg():
    """An unreachable reference pose says which leg misses and how to fix the design."""
    with pytest.raises(InvalidParameterError, match=r"leg 1 misses by .* choose another home pose"):
        pkm.build("hexapod", home_position=(0.0, -1.2, 0.0))


# ---------------------------------------------------------------------- model
def test_model_sizes_and_mimic_joints(mech):
    """The tree has nq = 7 + 1 + 6 + 12 = 26 and nv = 25; beta_2 and beta_3 take no coordinate."""
    assert (mech.nq, mech.nv) == (26, 25)
    assert mech.joints["beta_2"].nq == mech.joints["beta_3"].nq == 0
    assert mech.actuated_names == ("alpha_1", "alpha_2", "alpha_3", "alpha_4", "alpha_5", "alpha_6", "beta_1")
    assert mech.n_constraints == 18 and mech.n_task == mech.na == 7
    assert "beta_2" not in mech.q_to_dict(mech.q_reference)


def test_moving_beta_1_turns_the_three_reconfiguration_links_together(mech, params):
    """The mimic joints reproduce the gear train: one beta places A_1, A_2, A_3 as eq. (2) says."""
    q = mech.q_reference.copy()
    for beta in (-0.9, 0.3, 1.4):
        q[mech.joints["beta_1"].idx_q] = beta
        pin.framesForwardKinematics(mech.model, mech.data, q)
        A = hx.base_points(params, beta)
        for n in (1, 2, 3):
            M = mech.data.oMf[mech.frame_id(f"arm_{n}")]
            assert np.allclose(M.translation, A[n - 1], atol=1e-15)
            # A_i = F_i + Rr (cos beta e_r + sin beta e_y), i.e. R = Rf + Rr cos beta, D = Rr sin beta
            e_r = hx.leg_frame(params.theta[n - 1])[:, 0]
            assert math.isclose(A[n - 1] @ e_r, params.Rf + params.Rr * math.cos(beta), abs_tol=1e-15)
            assert math.isclose(A[n - 1][1], params.Rr * math.sin(beta), abs_tol=1e-15)


def test_a_given_home_pose_is_the_reference(mech, params):
    """Given pose T as its home, the reference configuration is pose T (SVD-projected) at beta = 0, on elbow_out."""
    printed = np.reshape(POSE_T_ROTATION, (3, 3))
    R, P = pose_t(params)
    assert np.allclose(R.T @ R, np.eye(3), atol=1e-14) and np.abs(R - printed).max() < 1e-4
    task = TaskMap(mech)
    assert np.abs(task.error(hx.task_vector(R, P, 0.0), task.value(mech.q_reference))).max() < 1e-15
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() < 1e-15
    assert mech.on_branch(mech.q_reference, "elbow_out")


def test_paper_alpha_conversions(mech, params):
    """Joint alpha_1..3 are relative to the reconfiguration link: paper alpha = joint alpha + beta."""
    R, P = near_pose_t(params, np.random.default_rng(3), 1)[0]
    beta = 0.4
    y = hx.task_vector(R, P, beta)
    qa = hx.closed_form_ik(params, y)
    alphas = hx.inverse_kinematics(params, R, P, beta)
    assert np.allclose(hx.paper_alphas(qa), alphas, atol=1e-14)
    assert np.allclose(qa[:3], alphas[:3] - beta, atol=1e-14) and np.allclose(qa[3:6], alphas[3:], atol=1e-14)
    assert np.allclose(hx.actuated_from_paper(alphas, beta), qa, atol=1e-14)
    # the arm of each leg points along cos(alpha) e_r + sin(alpha) e_y in the world (eq. 3)
    q = hx.closed_form_configuration(mech, y)
    pin.framesForwardKinematics(mech.model, mech.data, q)
    for i in range(6):
        L = hx.leg_frame(params.theta[i])
        x_arm = mech.data.oMf[mech.frame_id(f"arm_{i + 1}")].rotation[:, 0]
        assert np.allclose(x_arm, L @ [math.cos(alphas[i]), math.sin(alphas[i]), 0.0], atol=1e-14)


# ---------------------------------------------------------------------- inverse kinematics
def paper_eq15(params, C, theta, beta, leg, printed=False):
    """Both roots of eq. (15) with eqs. (16)-(17); ``printed=True`` keeps the two typos."""
    R, D = (params.Rf + params.Rr * math.cos(beta), params.Rr * math.sin(beta)) if leg < 3 else (params.R2, -params.H0)
    Cx, Cy, Cz = C
    LA, LB = params.LA, params.LB
    S = (LB**2 - LA**2 - R**2 - D**2 + 2 * D * Cy - Cx**2 - Cy**2 - Cz**2) / LA
    Q = 2 * Cx * math.cos(theta) + 2 * Cz * (math.cos(theta) if printed else math.sin(theta))
    first = 4 * (D - 2 * Cy) ** 2 if printed else 4 * (Cy - D) ** 2
    rad = first + 4 * R**2 - S**2 - Q * (4 * R + 2 * S * R / LA) + Q**2 * (1 - R**2 / LA**2)
    den = -2 * R - S - Q * (R / LA - 1)
    if rad < 0:
        return None
    return [2 * math.atan((2 * Cy - 2 * D + sgn * math.sqrt(rad)) / den) for sgn in (1, -1)]


def test_corrected_eq15_equals_the_geometric_inverse_kinematics(params):
    """Eq. (15) with Q_i = 2 C_x cos th + 2 C_z sin th and radicand 4 (C_y - D)^2 + ... gives both branches."""
    rng = np.random.default_rng(0)
    worst = 0.0
    for R, P in near_pose_t(params, rng, 10):
        for beta in (-50 * DEG, -11 * DEG, 0.0, 45 * DEG, 90 * DEG):
            C = hx.platform_points(params, R, P)
            ik = {b: hx.inverse_kinematics(params, R, P, beta, b) for b in hx.BRANCHES}
            for i in range(6):
                roots = paper_eq15(params, C[i], params.theta[i], beta, i)
                geo = sorted([ik["elbow_out"][i], ik["elbow_in"][i]])
                worst = max(worst, np.abs(np.sort(roots) - geo).max())
    assert worst < 1e-12


def test_at_pose_t_the_plus_sign_of_eq15_gives_elbow_out(params):
    """At pose T, beta = 0, the '+' root of eq. (15) is the elbow_out solution for every leg."""
    R, P = pose_t(params)
    C = hx.platform_points(params, R, P)
    out = hx.inverse_kinematics(params, R, P, 0.0, "elbow_out")
    for i in range(6):
        assert math.isclose(paper_eq15(params, C[i], params.theta[i], 0.0, i)[0], out[i], abs_tol=1e-12)


def test_printed_eq15_and_eq17_are_wrong(params):
    """As printed (cos in Q_i, 4 (D - 2 C_y)^2 in the radicand) eq. (15) misses the solutions by degrees."""
    R, P = pose_t(params)
    C = hx.platform_points(params, R, P)
    ik = {b: hx.inverse_kinematics(params, R, P, 0.0, b) for b in hx.BRANCHES}
    for i in range(6):
        roots = paper_eq15(params, C[i], params.theta[i], 0.0, i, printed=True)
        geo = sorted([ik["elbow_out"][i], ik["elbow_in"][i]])
        assert roots is None or np.abs(np.sort(roots) - geo).max() > 1 * DEG


@pytest.mark.parametrize("branch, sign", [("elbow_out", -1), ("elbow_in", 1)])
def test_each_branch_is_assembled_with_its_knee_signs(mech, params, branch, sign):
    """Both working modes close the loops at poses near T for several beta, with knee_i of the branch's sign."""
    task = TaskMap(mech)
    for R, P in near_pose_t(params, np.random.default_rng(1), 4):
        for beta in (-40 * DEG, 0.0, 60 * DEG):
            y = hx.task_vector(R, P, beta)
            q = hx.closed_form_configuration(mech, y, branch)
            assert np.abs(constraints.residual(mech, q)).max() < 1e-14
            assert np.abs(task.error(y, task.value(q))).max() < 1e-14
            assert mech.on_branch(q, branch)
            assert all(np.sign(q[mech.joints[f"knee_{n}"].idx_q]) == sign for n in range(1, 7))


def test_branches_can_be_chosen_per_leg(mech, params):
    """A tuple of six branch names mixes working modes leg by leg."""
    y = TaskMap(mech).value(mech.q_reference)
    mixed = ("elbow_out", "elbow_in", "elbow_out", "elbow_in", "elbow_in", "elbow_out")
    q = hx.closed_form_configuration(mech, y, mixed)
    assert np.abs(constraints.residual(mech, q)).max() < 1e-14
    signs = [int(np.sign(q[mech.joints[f"knee_{n}"].idx_q])) for n in range(1, 7)]
    assert signs == [hx.BRANCHES[b] for b in mixed]


def test_knee_is_pi_at_the_folded_double_root(params):
    """knee_1 -> -pi / +pi and both branches merge as beta falls to the limit of leg 1 at pose T (LB folded on LA)."""
    R, P = pose_t(params)
    beta_star = _reachability_limit(params, "sector")
    for eps in (1e-4, 1e-8):
        vals = {b: hx.joint_values(params, R, P, beta_star + eps, b) for b in hx.BRANCHES}
        k_out, k_in = vals["elbow_out"]["knee_1"][0], vals["elbow_in"]["knee_1"][0]
        assert -math.pi < k_out < 0 < k_in <= math.pi
        assert max(math.pi + k_out, math.pi - k_in) < 10 * math.sqrt(eps)
        assert abs(vals["elbow_out"]["alpha_1"][0] - vals["elbow_in"]["alpha_1"][0]) < 10 * math.sqrt(eps)


def test_knee_is_zero_at_the_extended_double_root(params):
    """Lowering the platform until a leg is fully stretched brings its knee to 0 on both branches."""
    R, P0 = pose_t(params)
    lo, hi = 0.0, 0.5  # depth below pose T: reachable at lo, not at hi
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        try:
            hx.inverse_kinematics(params, R, P0 - [0.0, mid, 0.0], 0.0)
            lo = mid
        except UnreachableError as exc:
            hi, leg = mid, exc.leg
    C = hx.platform_points(params, R, P0 - [0.0, lo, 0.0])[leg - 1]
    A = hx.base_points(params, 0.0)[leg - 1]
    stretch = np.linalg.norm(C - A)  # = LA + LB up to the out-of-plane offset of C
    assert stretch > params.LB
    vals = {b: hx.joint_values(params, R, P0 - [0.0, lo, 0.0], 0.0, b)[f"knee_{leg}"][0] for b in hx.BRANCHES}
    assert max(abs(v) for v in vals.values()) < 1e-6


@pytest.mark.parametrize("P, leg", [((0.0, -0.35, 0.3), 6), ((0.3, -0.35, 0.0), 5), ((0.0, -0.10, 0.0), 1)])
def test_unreachable_pose_names_the_leg_and_its_excess(params, P, leg):
    """An unreachable pose raises UnreachableError with the first failing leg and its gap to the circle of B."""
    R = pose_t(params)[0]
    with pytest.raises(UnreachableError) as exc:
        hx.closed_form_ik(params, hx.task_vector(R, P, 0.0))
    assert exc.value.leg == leg and exc.value.unit == "m"
    # independent gap: distance from C to the circle of B, sampled, against LB
    A, C = hx.base_points(params, 0.0)[leg - 1], hx.platform_points(params, R, P)[leg - 1]
    L = hx.leg_frame(params.theta[leg - 1])
    a = np.linspace(-math.pi, math.pi, 200001)
    dist = np.linalg.norm(C - (A + params.LA * (np.outer(np.cos(a), L[:, 0]) + np.outer(np.sin(a), L[:, 1]))), axis=1)
    gap = dist.min() - params.LB if dist.min() > params.LB else params.LB - dist.max()
    assert exc.value.excess > 0 and math.isclose(exc.value.excess, gap, abs_tol=1e-8)


@pytest.mark.parametrize("y", [np.zeros(7), np.full(8, np.nan), [0, -0.35, 0, 0, 0, 0, 2.0, 0], "pose"])
def test_bad_task_vectors_raise_invalid_input_error(params, y):
    """Wrong shape, non-finite values, a non-unit quaternion or text are refused."""
    with pytest.raises(InvalidInputError):
        hx.closed_form_ik(params, y)


def test_bad_branch_and_actuated_vectors_raise_invalid_input_error(params):
    """Unknown branch names, a branch tuple of the wrong length and bad actuated vectors are refused."""
    y = hx.task_vector(*pose_t(params), 0.0)
    for branch in ("knee_out", ("elbow_out",) * 3):
        with pytest.raises(InvalidInputError):
            hx.closed_form_ik(params, y, branch)
    for qa in (np.zeros(6), [0, 0, 0, 0, 0, 0, np.inf]):
        with pytest.raises(InvalidInputError):
            hx.closed_form_fk(params, qa)


# ---------------------------------------------------------------------- forward kinematics
@pytest.mark.parametrize("layout", ["sector", "literal"])
def test_semi_closed_forward_kinematics_round_trips(layout):
    """Closed-form IK then the paper's FK (eqs. 4-13) returns the pose to 1e-9, for poses near T and several beta.

    The sector layout converges from the default seed (pose T) everywhere here. The literal layout
    is seeded 5 mm / 0.01 rad from the answer: from pose T, at beta = 85 deg, Newton's method
    lands on another assembly mode about 35 mm away (crossed legs 5 and 6 put one nearby).
    """
    params = hx.Params(layout=layout)
    rng = np.random.default_rng(2)
    worst = 0.0
    for R, P in near_pose_t(params, rng, 5):
        seed = None if layout == "sector" else hx.task_vector(pin.exp3(np.array([0.01, 0.0, 0.0])) @ R, P + 0.005, 0.0)
        for beta in (-50 * DEG, -11 * DEG, 0.0, 40 * DEG, 85 * DEG):
            y = hx.task_vector(R, P, beta)
            y_fk = hx.closed_form_fk(params, hx.closed_form_ik(params, y), seed=seed)
            assert y_fk[7] == beta
            worst = max(worst, np.abs(y_fk[:3] - P).max(), np.abs(pin.log3(R.T @ _rot(y_fk))).max())
    assert worst <= 1e-9


def test_forward_kinematics_points_satisfy_eqs_4_to_7(params):
    """The points returned by the FK are the platform's C_i: legs of length LB and a rigid prism."""
    R, P = near_pose_t(params, np.random.default_rng(5), 1)[0]
    beta = 0.3
    C = hx.forward_kinematics(params, hx.inverse_kinematics(params, R, P, beta), beta)
    assert np.abs(C - hx.platform_points(params, R, P)).max() < 1e-12
    _, B, _, _ = leg_geometry(params, R, P, beta)
    assert np.abs(np.linalg.norm(C - B, axis=1) - params.LB).max() < 1e-13


def test_forward_kinematics_accepts_a_task_vector_as_seed(params):
    """A seed pose near the answer is accepted (its beta is ignored)."""
    R, P = near_pose_t(params, np.random.default_rng(6), 1)[0]
    y = hx.task_vector(R, P, 0.2)
    seed = hx.task_vector(R, P + 0.01, -1.0)
    y_fk = hx.closed_form_fk(params, hx.closed_form_ik(params, y), seed=seed)
    assert np.abs(y_fk[:3] - P).max() < 1e-12 and y_fk[7] == 0.2


def test_forward_kinematics_without_assembly_raises_convergence_error(params):
    """Actuated angles that admit no assembly make Newton's method fail with its residual attached, as soon as it
    stalls (3 iterations without 1 % progress) rather than after all 50 allowed."""
    with pytest.raises(ConvergenceError) as exc:
        hx.closed_form_fk(params, np.zeros(7))
    assert exc.value.residual > 1e-3 and 3 <= exc.value.iterations < 50


# ---------------------------------------------------------------------- layouts (paper departures)
def test_sector_layout_needs_eqs_5_and_11_with_swapped_factors(params):
    """Sector layout: printed eq. (5) gives the upward normal and printed eq. (11) gives -z; the corrected ones hold."""
    for layout, printed_ok in (("sector", False), ("literal", True)):
        p = hx.Params(layout=layout)
        C = hx.platform_local_points(p)
        e = p.r * math.sqrt(3.0)
        g_printed = 2 / math.sqrt(3.0) * np.cross(C[1] - C[2], C[0] - C[2]) / e**2
        z_printed = (C[5] - C[4]) / np.linalg.norm(C[5] - C[4])
        down, z = np.array([0.0, -1.0, 0.0]), np.array([0.0, 0.0, 1.0])
        assert np.allclose(C[3:], C[:3] + p.h * (g_printed if printed_ok else -g_printed), atol=1e-15)
        assert np.allclose(g_printed, down if printed_ok else -down, atol=1e-15)
        assert np.allclose(z_printed, z if printed_ok else -z, atol=1e-15)
        R, P = hx.pose_from_points(p, C)  # corrected eqs. 8-13 give back the platform frame
        assert np.allclose(R, np.eye(3), atol=1e-15) and np.allclose(P, 0.0, atol=1e-15)


def test_literal_layout_crosses_legs_5_and_6(params):
    """In the literal layout C5 and C6 sit more than 90 deg away from their base joints; in the sector one, < 30 deg."""
    for layout, crossed in (("sector", False), ("literal", True)):
        p = hx.Params(layout=layout)
        C = hx.platform_points(p, *pose_t(p))
        for i in (4, 5):
            off = abs((math.atan2(C[i][2], C[i][0]) - p.theta[i] + math.pi) % (2 * math.pi) - math.pi)
            assert (off > 90 * DEG) if crossed else (off < 30 * DEG)


# ---------------------------------------------------------------------- sec. 4 claims about pose T
def bisect_beta_limit(p, R, P, lo, hi) -> float:
    """Edge of reachability in beta between an unreachable ``lo`` and a reachable ``hi`` (60 bisections) [rad]."""
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        try:
            hx.inverse_kinematics(p, R, P, mid)
            hi = mid
        except UnreachableError:
            lo = mid
    return hi


def _reachability_limit(params, layout) -> float:
    """Lowest beta in [-90, 0] deg where pose T is reachable (bisection) [rad]."""
    p = hx.Params(layout=layout)
    return bisect_beta_limit(p, *pose_t(p), -90 * DEG, 0.0)


@pytest.mark.parametrize("layout", ["sector", "literal"])
def test_pose_t_is_reachable_only_for_beta_above_minus_59_5_deg(layout):
    """Sec. 4 says pose T needs beta >= -60 deg; this model gives beta >= -59.51 deg (leg 1 folds below it).

    Within the studied [-90, 90] deg, pose T is reachable exactly on [-59.51, 90] deg, in both
    layouts and on both branches (a leg's reachability does not depend on its branch, and C1 is
    the same in both layouts). Below the limit leg 1 misses because |C1 - A1| < LB - LA.
    """
    params = hx.Params(layout=layout)
    R, P = pose_t(params)
    beta_min = _reachability_limit(params, layout)
    assert abs(beta_min / DEG - BETA_MIN_POSE_T) < 0.01
    for branch in hx.BRANCHES:
        for beta in np.linspace(beta_min + 1e-9, 90 * DEG, 30):
            hx.inverse_kinematics(params, R, P, beta, branch)
        for beta in (beta_min - 1e-6, -60 * DEG, -90 * DEG):
            with pytest.raises(UnreachableError) as exc:
                hx.inverse_kinematics(params, R, P, beta, branch)
            assert exc.value.leg == 1
    A1 = hx.base_points(params, beta_min - 1 * DEG)[0]
    assert np.linalg.norm(hx.platform_points(params, R, P)[0] - A1) < params.LB - params.LA


def test_default_layout_and_branch_reproduce_the_manipulability_optimum(params):
    """Sec. 4 (Fig. 7): both manipulabilities peak near beta = -11 deg at pose T.

    With the sector layout and elbow_out (the defaults) eq. (37) peaks at -10 deg (w_rot) and
    -11 deg (w_tras) on a 1-deg grid over [-59, 90] deg; with elbow_in, or with the literal
    layout, the peaks lie far away (elbow_in: -59 deg; literal: 40 deg), which is why they are
    not the defaults.
    """
    grid = np.arange(-59, 91)

    def peaks(p, branch):
        R, P = pose_t(p)
        w = np.array([paper_manipulabilities(p, R, P, b * DEG, branch) for b in grid])
        return grid[np.argmax(w[:, 0])], grid[np.argmax(w[:, 1])]

    assert peaks(params, "elbow_out") == (-10, -11)
    assert peaks(params, "elbow_in") == (-59, -59)
    assert peaks(hx.Params(layout="literal"), "elbow_out") == (40, 40)


def test_paper_jacobian_equals_the_generic_twist_jacobian(mech, params):
    """Eq. (37) with beta fixed equals the generic core's twist Jacobian referred to O (alpha columns)."""
    from pkm.core import twist_jacobian  # (the core builds its Jacobians from frame Jacobians: mimic joints too)

    R, P = pose_t(params)
    for beta in (-30 * DEG, 0.0, 50 * DEG):
        q = hx.closed_form_configuration(mech, hx.task_vector(R, P, beta))
        Jt = twist_jacobian(mech, q)[:, :6]  # [v_P; w] per alpha rate (beta fixed)
        w_rot = math.sqrt(np.linalg.det(Jt[3:] @ Jt[3:].T))
        Jv_o = Jt[:3] + pin.skew(P) @ Jt[3:]  # v_O = v_P + P x w
        w_tras = math.sqrt(np.linalg.det(Jv_o @ Jv_o.T))
        assert np.allclose((w_rot, w_tras), paper_manipulabilities(params, R, P, beta), rtol=1e-10)


def test_generic_inverse_kinematics_matches_the_closed_form_on_both_branches(mech, params):
    """The generic solver, seeded on a branch, lands on the closed-form solution of that branch."""
    rng = np.random.default_rng(4)
    for branch in hx.BRANCHES:
        for R, P in near_pose_t(params, rng, 2, pos=0.01, ang=0.03):
            y = hx.task_vector(R, P, 0.1)
            res = solve_ik(mech, y, branch=branch)
            assert np.abs(mech.actuated_q(res.q) - hx.closed_form_ik(params, y, branch)).max() < 1e-9


def _rot(y):
    return pin.Quaternion(y[6], y[3], y[4], y[5]).toRotationMatrix()


# ---------------------------------------------------------------------- assembly modes, rotation input
def test_assembly_mode_search_finds_the_reference_and_verifies_each_mode_with_the_core(mech, params):
    """Multistart FK (32 seeds) at pose T's actuated coordinates: the reference pose is among the modes, every
    mode closes the tree's loops (generic core residual <= 1e-9 m), holds the same actuators and they are distinct.

    Pose T lies near a direct singularity, so a second assembly mode sits about 3 mm away.
    """
    qa = mech.actuated_q(mech.q_reference)
    modes = hx.assembly_modes(mech, qa)
    R, P = pose_t(params)
    assert np.abs(modes[0].P - P).max() < 1e-10 and np.abs(pin.log3(modes[0].R.T @ R)).max() < 1e-10
    for m in modes:
        assert m.core_residual <= 1e-9 and np.abs(constraints.residual(mech, m.q)).max() <= 1e-9
        assert np.abs(mech.actuated_q(m.q) - qa).max() < 1e-12
    assert len(modes) >= 2
    for i, a in enumerate(modes):
        for b in modes[i + 1:]:
            assert np.abs(a.C - b.C).max() > 1e-6


def test_assembly_mode_search_without_assembly_raises(mech):
    """Actuated angles that admit no assembly raise AssemblyError after every seed failed."""
    with pytest.raises(AssemblyError, match="from all 4 seeds"):
        hx.assembly_modes(mech, np.zeros(7), n_starts=4)


@pytest.mark.parametrize("R, defect", [(np.diag([1.0, 1.0, 1.05]), "0.103"), (np.diag([1.0, 1.0, -1.0]), "0")])
def test_non_orthonormal_rotation_is_rejected_with_the_size_of_the_defect(params, R, defect):
    """The inverse kinematics refuses a non-rotation, quoting max|R^T R - I| and det R."""
    with pytest.raises(InvalidInputError, match=rf"max\|R\^T R - I\| = {defect} .*det R"):
        hx.inverse_kinematics(params, R, pose_T_placement()[1], 0.0)


def test_printed_four_digit_rotation_is_accepted_and_projected(params):
    """The pose T matrix as printed (defect ~1e-4) is accepted and projected on SO(3): same IK as the projection."""
    printed = np.reshape(POSE_T_ROTATION, (3, 3))
    assert 1e-6 < np.abs(printed.T @ printed - np.eye(3)).max() < hx.ROTATION_TOL
    a = hx.inverse_kinematics(params, printed, pose_T_placement()[1], 0.0)
    assert np.allclose(a, hx.inverse_kinematics(params, *pose_T_placement(), 0.0),
                       atol=1e-14)
