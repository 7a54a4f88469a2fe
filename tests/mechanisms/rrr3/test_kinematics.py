"""Planar 3-RRR: parameters, working modes, eqs. (6), (9), (19)-(20), (25), singularities, forward kinematics.

The generic harness (tests/test_mechanisms_generic.py) already checks loop closure, generic
vs closed-form IK on the default mode, and the Jacobians; these tests cover what is
specific to the paper and to this module's conventions.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from scipy.optimize import brentq

from pkm.core import TaskMap, close_loops, diagnose, forward_jacobian, solve_ik
from pkm.core.kinematics import constraints
from pkm.errors import AssemblyError, InvalidInputError, InvalidParameterError, SingularityError, UnreachableError
from pkm.mechanisms import rrr3
from tests.fd import rel, richardson

P = rrr3.Rrr3Params()
Y_REF = rrr3.reference_pose(P)
MODE_NAMES = [f"mode{k}" for k in range(1, 9)]


@pytest.fixture(scope="module")
def mech():
    return rrr3.build()


def _wrap(a):
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


def _leg_targets(params, y):
    """Platform vertex minus base vertex for each leg, built from eqs. (1)-(2) independently."""
    G, phi, h, H = np.asarray(y[:2]), y[2], params.h, params.H
    A = G - h / math.sqrt(3.0) * np.array([math.cos(phi + math.pi / 6), math.sin(phi + math.pi / 6)])
    B = A + h * np.array([math.cos(phi), math.sin(phi)])
    C = A + h * np.array([math.cos(phi + math.pi / 3), math.sin(phi + math.pi / 3)])
    base = np.array([[0.0, 0.0], [H, 0.0], [H / 2, H * math.sqrt(3.0) / 2]])
    return np.array([A, B, C]) - base


def _eq6(params, target, theta):
    """The paper's eq. (6) in a leg's base-vertex frame [m^2]."""
    x, y = target
    a, b = params.a, params.b
    return x * x + y * y - 2 * x * a * math.cos(theta) - 2 * y * a * math.sin(theta) + a * a - b * b


def _eq9(params, target):
    """The paper's eq. (9) as printed (half-angle form): the ('+', '-') roots [rad]."""
    x, y = target
    a, b = params.a, params.b
    e1, e2, e3 = -2 * y * a, -2 * x * a, x * x + y * y + a * a - b * b
    s = math.sqrt(e1 * e1 + e2 * e2 - e3 * e3)
    return 2 * math.atan((-e1 + s) / (e3 - e2)), 2 * math.atan((-e1 - s) / (e3 - e2))


def _random_poses(n, seed, radius=0.12, dphi=0.3):
    rng = np.random.default_rng(seed)
    return [Y_REF + rng.uniform(-1, 1, 3) * [radius, radius, dphi] for _ in range(n)]


# ---------------------------------------------------------------------- parameters
def test_reference_design_is_the_papers_workspace_study():
    """The default design is sec. III's (links 40 cm, platform 10 cm, actuators 100 cm apart); its reference pose is
    found: centred, at the orientation of largest condition index on the 2.5 deg grid (5 deg; 0.93 at Phi = 0)."""
    assert (P.a, P.b, P.h, P.H, P.branch, P.home) == (0.40, 0.40, 0.10, 1.00, 1, None)
    np.testing.assert_allclose(Y_REF[:2], [0.5, 0.5 / math.sqrt(3.0)], atol=1e-15)
    grid = np.linspace(-math.pi / 3, math.pi / 3, rrr3.kinematics.REFERENCE_ORIENTATIONS)
    ci = [rrr3.kinematics.condition_index(P, [Y_REF[0], Y_REF[1], phi]) for phi in grid]
    assert Y_REF[2] == grid[int(np.argmax(ci))] and math.isclose(Y_REF[2], math.radians(5.0), abs_tol=1e-12)
    assert rrr3.kinematics.condition_index(P, Y_REF) > rrr3.kinematics.condition_index(P, [*Y_REF[:2], 0.0]) > 0.9


def test_reference_configuration_is_assembled_regular_and_in_mode1():
    """Centred at Phi = 0 (sec. III), the spec's reference closes the loops, lands on the base centroid, is regular
    and has every psi_i = +99 deg."""
    mech = rrr3.build(rrr3.Params(home=(0.0, 0.0, 0.0)))
    q = mech.q_reference
    assert np.abs(constraints.residual(mech, q)).max() < 1e-15
    np.testing.assert_allclose(TaskMap(mech).value(q), [0.5, 0.5 / math.sqrt(3.0), 0.0], atol=1e-15)
    assert diagnose(mech, q).classification == "regular"
    psi = [mech.q_to_dict(q)[f"elbow_{n}"] for n in (1, 2, 3)]
    np.testing.assert_allclose(np.degrees(psi), 98.98, atol=0.01)
    assert mech.on_branch(q, "mode1") and mech.spec.default_branch == "mode1"


@pytest.mark.parametrize("field, value", [("h", 0.0), ("a", 0.0), ("a", -0.1), ("b", float("nan")),
                                          ("H", float("inf")), ("m_platform", 0.0)])
def test_non_positive_or_non_finite_lengths_and_masses_are_refused(field, value):
    """h = 0, a <= 0 and any non-finite length raise InvalidParameterError naming the field."""
    with pytest.raises(InvalidParameterError) as exc:
        rrr3.Rrr3Params(**{field: value})
    assert exc.value.name == field


@pytest.mark.parametrize("branch", [0, 9, True, "mode1", 1.0])
def test_branch_must_be_an_integer_from_1_to_8(branch):
    """A working mode outside 1..8 (or not an integer) raises InvalidParameterError naming branch."""
    with pytest.raises(InvalidParameterError, match="branch") as exc:
        rrr3.Rrr3Params(branch=branch)
    assert exc.value.name == "branch"


@pytest.mark.parametrize("home", [(0.0, 0.0), (0.0, float("nan"), 0.0), "centre"])
def test_malformed_home_is_refused(home):
    """A home that is not three finite numbers raises InvalidParameterError."""
    with pytest.raises(InvalidParameterError, match="home"):
        rrr3.reference_pose(rrr3.Rrr3Params(home=home))


def test_unreachable_home_is_refused_with_the_leg():
    """A reference pose out of reach raises InvalidParameterError that names the leg and the miss."""
    with pytest.raises(InvalidParameterError, match="leg 1 misses by"):
        rrr3.build(rrr3.Rrr3Params(home=(0.5, 0.0, 0.0)))


def test_stretched_home_is_refused_as_inverse_singular():
    """Links exactly spanning the centred pose (a + b = |PA|) put every leg at psi = 0: refused."""
    d = (1.0 - 0.1) / math.sqrt(3.0)
    with pytest.raises(InvalidParameterError, match="inverse"):
        rrr3.reference_pose(rrr3.Rrr3Params(a=d / 2, b=d / 2, home=(0.0, 0.0, 0.0)))


def test_direct_singular_home_is_refused():
    """A centred pose at the orientation where det J_x = 0 (mode1, Phi ~ 0.76 rad) is refused as direct-singular."""
    def det(phi):
        return np.linalg.det(rrr3.jacobians(P, [Y_REF[0], Y_REF[1], phi])[0])

    phi_s = brentq(det, 0.6, 0.9, xtol=1e-14)
    with pytest.raises(InvalidParameterError, match="direct"):
        rrr3.reference_pose(rrr3.Rrr3Params(home=(0.0, 0.0, phi_s)))
    rrr3.reference_pose(rrr3.Rrr3Params(home=(0.0, 0.0, phi_s - 0.05)))  # nearby orientations are fine


# ---------------------------------------------------------------------- working modes
def test_mode_names_follow_the_bits_of_k_minus_1():
    """mode k <-> bits of k-1 with leg 1 most significant, bit 0 -> psi > 0: mode1 = +++, mode3 = +-+, mode8 = ---."""
    assert rrr3.MODES["mode1"] == (1, 1, 1)
    assert rrr3.MODES["mode3"] == (1, -1, 1)
    assert rrr3.MODES["mode5"] == (-1, 1, 1)
    assert rrr3.MODES["mode8"] == (-1, -1, -1)
    assert rrr3.branch_signs(3) == rrr3.branch_signs("mode3") == rrr3.branch_signs(np.int64(3))
    for bad in (0, "mode9", "knee_out", None):
        with pytest.raises(InvalidInputError):
            rrr3.branch_signs(bad)


def test_spec_lists_the_eight_modes_on_the_elbows(mech):
    """The spec has branches mode1..mode8 whose signs are those of (elbow_1, elbow_2, elbow_3)."""
    assert list(mech.spec.branches) == MODE_NAMES
    for name in MODE_NAMES:
        assert mech.spec.branches[name].signs == dict(zip(("elbow_1", "elbow_2", "elbow_3"), rrr3.MODES[name]))


def test_eight_modes_give_eight_distinct_closed_configurations(mech):
    """At the reference pose the 8 modes give 8 distinct assembled configurations, each on its own mode."""
    task = TaskMap(mech)
    configs = []
    for name in MODE_NAMES:
        q = rrr3.closed_form_configuration(mech, Y_REF, name)
        assert np.abs(constraints.residual(mech, q)).max() < 1e-15
        assert np.abs(task.error(Y_REF, task.value(q))).max() < 1e-15
        assert mech.on_branch(q, name)
        assert [m for m in MODE_NAMES if mech.on_branch(q, m)] == [name]
        configs.append(q)
    gaps = [np.abs(_wrap(p - q)).max() for i, p in enumerate(configs) for q in configs[i + 1:]]
    assert min(gaps) > 1.0  # rad


def test_closed_form_satisfies_eq6_for_every_leg_and_mode():
    """Each motor angle of the closed form makes the paper's eq. (6) vanish (to 1e-15 m^2) on every leg."""
    worst = 0.0
    for y in _random_poses(40, seed=1):
        targets = _leg_targets(P, y)
        for name in MODE_NAMES:
            theta = rrr3.closed_form_ik(P, y, name)
            worst = max(worst, max(abs(_eq6(P, t, th)) for t, th in zip(targets, theta)))
    assert worst < 1e-15


def test_plus_root_of_eq9_is_negative_psi():
    """Where eq. (9) as printed is defined, its '+' root is the psi_i < 0 posture and its '-' root psi_i > 0."""
    for y in _random_poses(20, seed=2):
        targets = _leg_targets(P, y)
        plus, minus = np.array([_eq9(P, t) for t in targets]).T
        np.testing.assert_allclose(_wrap(rrr3.closed_form_ik(P, y, "mode8") - plus), 0.0, atol=1e-12)
        np.testing.assert_allclose(_wrap(rrr3.closed_form_ik(P, y, "mode1") - minus), 0.0, atol=1e-12)


def test_atan2_form_is_defined_where_the_half_angle_form_divides_by_zero():
    """Departure: at e3 = e2 (a regular pose) eq. (9) as printed divides by zero; the atan2 form solves both postures.

    Leg 1 gets theta_1 = pi/2 with psi_1 > 0 (the '-' root, 0/0 as printed) and theta_1 = pi with psi_1 < 0.
    """
    params = rrr3.Rrr3Params(a=2.0, b=2.0)
    A = (-2.0, 2.0)  # leg 1: e1 = -8, e2 = e3 = 8 (Python floats: the division raises)
    with pytest.raises(ZeroDivisionError):
        _eq9(params, A)
    th_pos = rrr3.inverse_kinematics(params, A, 0.0, "mode1")[0]
    th_neg = rrr3.inverse_kinematics(params, A, 0.0, "mode5")[0]
    assert th_pos == pytest.approx(math.pi / 2, abs=1e-15)
    assert abs(th_neg) == pytest.approx(math.pi, abs=1e-15)
    assert abs(_eq6(params, A, th_pos)) < 1e-14 and abs(_eq6(params, A, th_neg)) < 1e-14


def test_generic_ik_agrees_with_the_closed_form_in_every_mode(mech):
    """pkm.core.solve_ik on branch modeK, seeded on that mode, equals the closed form (to 1e-10 rad) at a few poses.

    The seed is the closed form at the reference pose: the core's own branch seed (elbows of the
    reference mirrored, loops re-closed) does not yet reach every mode of this mechanism.
    """
    seeds = {name: rrr3.closed_form_configuration(mech, Y_REF, name) for name in MODE_NAMES}
    worst = 0.0
    for y in _random_poses(3, seed=3, radius=0.04, dphi=0.15):
        for name in MODE_NAMES:
            res = solve_ik(mech, y, q0=seeds[name], branch=name)
            worst = max(worst, np.abs(_wrap(mech.actuated_q(res.q) - rrr3.closed_form_ik(P, y, name))).max())
    assert worst < 1e-10


# ---------------------------------------------------------------------- paper helpers
def test_centroid_and_a_conversions_are_inverse_and_match_eqs_1_2():
    """G is the mean of A, B, C of eqs. (1)-(2), and a_from_centroid undoes centroid_from_a."""
    rng = np.random.default_rng(4)
    for _ in range(10):
        A, phi = rng.uniform(-1, 1, 2), rng.uniform(-4, 4)
        G = rrr3.centroid_from_a(P, A, phi)
        np.testing.assert_allclose(G, rrr3.platform_vertices(P, A, phi).mean(axis=0), atol=1e-15)
        np.testing.assert_allclose(rrr3.a_from_centroid(P, G, phi), A, atol=1e-15)


def test_platform_frames_sit_on_the_vertices_and_yaw_is_phi(mech):
    """In the tree, platform_A/B/C sit at eqs. (1)-(2)'s vertices and the task yaw equals Phi."""
    for y in _random_poses(5, seed=5):
        q = rrr3.closed_form_configuration(mech, y)
        pin.framesForwardKinematics(mech.model, mech.data, q)
        V = rrr3.platform_vertices(P, rrr3.a_from_centroid(P, y[:2], y[2]), y[2])
        for k, v in enumerate("ABC"):
            np.testing.assert_allclose(mech.data.oMf[mech.frame_id(f"platform_{v}")].translation, [*V[k], 0.0],
                                       atol=1e-15)
        assert TaskMap(mech).value(q)[2] == pytest.approx(y[2], abs=1e-15)


def test_rebuilt_eq19_20_give_the_generic_forward_jacobian(mech):
    """J_x^-1 J_q from the rebuilt eqs. (19)-(20) equals the core's forward Jacobian, and J_q = diag(a sin psi)."""
    worst = 0.0
    for y in _random_poses(10, seed=6):
        for name in ("mode1", "mode8", "mode6"):
            q = rrr3.closed_form_configuration(mech, y, name)
            if diagnose(mech, q).classification != "regular":
                continue
            Jx, Jq = rrr3.jacobians(P, y, name)
            worst = max(worst, np.abs(np.linalg.solve(Jx, Jq) - forward_jacobian(mech, q)).max())
            psi = [mech.q_to_dict(q)[f"elbow_{n}"] for n in (1, 2, 3)]
            np.testing.assert_allclose(np.diag(Jq), P.a * np.sin(psi), atol=1e-15)
    assert worst < 1e-10


# ---------------------------------------------------------------------- reach and inputs
@pytest.mark.parametrize("offset, leg", [((0.5, 0.0, 0.0), 1), ((-0.45, 0.2, 0.0), 2), ((0.0, -0.5, 0.0), 3)])
def test_out_of_reach_names_the_leg_and_the_excess(offset, leg):
    """A pose beyond a + b raises UnreachableError with the first failing leg and excess = distance - (a + b)."""
    y = Y_REF + offset
    d = np.hypot(*_leg_targets(P, y)[leg - 1])
    with pytest.raises(UnreachableError) as exc:
        rrr3.closed_form_ik(P, y)
    assert exc.value.leg == leg
    assert exc.value.excess == pytest.approx(d - (P.a + P.b), abs=1e-15) and exc.value.excess > 0


def test_inside_the_inner_circle_names_the_leg_and_the_excess():
    """With a != b, a platform vertex closer than |a - b| to its base vertex raises with excess |a - b| - distance."""
    params = rrr3.Rrr3Params(a=0.55, b=0.35)
    G = rrr3.centroid_from_a(params, [0.85, 0.05], 0.0)  # B = (0.95, 0.05), 0.07 m from Q
    with pytest.raises(UnreachableError) as exc:
        rrr3.closed_form_ik(params, [*G, 0.0])
    assert exc.value.leg == 2
    assert exc.value.excess == pytest.approx(0.2 - math.hypot(0.05, 0.05), abs=1e-15)


def test_stretched_leg_is_reachable_with_psi_zero():
    """A platform vertex exactly at a + b from its base vertex is reached (inverse singular) with psi = 0."""
    u = np.array([math.cos(0.3), math.sin(0.3)])
    vals = rrr3.joint_values(P, [*rrr3.centroid_from_a(P, 0.8 * u, 0.0), 0.0])
    assert vals["elbow_1"][0] == pytest.approx(0.0, abs=1e-7)
    assert vals["motor_1"][0] == pytest.approx(0.3, abs=1e-7)


def test_platform_vertex_on_its_base_vertex_is_singular_when_a_equals_b():
    """With a = b, A = P leaves theta_1 undetermined: SingularityError, not NaN."""
    with pytest.raises(SingularityError):
        rrr3.inverse_kinematics(P, [0.0, 0.0], 0.5)


@pytest.mark.parametrize("y", [[0.5, float("nan"), 0.0], [0.5, 0.3], [[0.5, 0.3, 0.0]], "pose", None])
def test_bad_task_vectors_are_refused(mech, y):
    """Non-finite or wrongly shaped task vectors raise InvalidInputError in every closed form."""
    with pytest.raises(InvalidInputError):
        rrr3.closed_form_ik(P, y)
    with pytest.raises(InvalidInputError):
        rrr3.closed_form_configuration(mech, y)


def test_bad_paper_inputs_are_refused():
    """inverse_kinematics refuses a malformed A, a non-finite Phi and an unknown mode with InvalidInputError."""
    for args in (([0.4], 0.0, 1), ([0.4, 0.2], float("inf"), 1), ([0.4, 0.2], [0.0, 1.0], 1),
                 ([0.4, 0.2], 0.0, "mode0")):
        with pytest.raises(InvalidInputError):
            rrr3.inverse_kinematics(P, *args)


# ---------------------------------------------------------------------- homogenised Jacobians (eq. 25)
def _fd_inverse(fun, x, h=1e-6):
    """Richardson central differences of ``fun`` (motor angles) at ``x``, one column per coordinate."""
    def diff(hh):
        return np.column_stack([_wrap(fun(x + e) - fun(x - e)) / (2 * hh) for e in hh * np.eye(3)])
    return richardson(diff, h)


@pytest.mark.parametrize("mode", ["mode1", "mode4", "mode8"])
def test_homogenised_jacobian_about_the_centroid_is_the_derivative_of_the_ik(mode):
    """J_q^-1 J_x (moment column / L, moments about G) equals d theta / d(x_G, y_G, L Phi) by FD of the IK (1e-6 rel)."""
    L = rrr3.characteristic_length(P)
    for y in _random_poses(5, seed=7, radius=0.05, dphi=0.2):
        Jx, Jq = rrr3.homogenized_jacobians(P, y, mode)
        fd_ = _fd_inverse(lambda z: rrr3.closed_form_ik(P, [z[0], z[1], z[2] / L], mode), np.r_[y[:2], L * y[2]])
        assert rel(np.linalg.solve(Jq, Jx), fd_) <= 1e-6


def test_homogenised_jacobian_about_a_is_the_derivative_of_the_papers_ik():
    """With moments about A, J_q^-1 J_x equals d theta / d(x_A, y_A, L Phi) of eq. (9) by FD, for any explicit L."""
    for L in (0.03, 0.25):
        for y in _random_poses(3, seed=8, radius=0.05, dphi=0.2):
            A = rrr3.a_from_centroid(P, y[:2], y[2])
            Jx, Jq = rrr3.homogenized_jacobians(P, y, length=L, reference="A")
            fd_ = _fd_inverse(lambda z, L=L: rrr3.inverse_kinematics(P, z[:2], z[2] / L), np.r_[A, L * y[2]])
            assert rel(np.linalg.solve(Jq, Jx), fd_) <= 1e-6


def test_moments_about_the_origin_describe_the_same_motion():
    """About the origin O the task rates are (v_O, L w) with v_O = v_G + w x (O - G): both give the same motor rates."""
    rng = np.random.default_rng(9)
    for y in _random_poses(5, seed=9):
        KG = np.linalg.solve(*rrr3.homogenized_jacobians(P, y)[::-1])
        KO = np.linalg.solve(*rrr3.homogenized_jacobians(P, y, reference="origin")[::-1])
        vG, w = rng.normal(size=2), rng.normal()
        vO = vG + w * np.array([y[1], -y[0]])  # w z x (O - G), O = 0
        L = rrr3.characteristic_length(P)
        np.testing.assert_allclose(KO @ np.r_[vO, L * w], KG @ np.r_[vG, L * w], rtol=1e-12, atol=1e-12)


def test_printed_eq25_depends_on_the_unit_of_length_ours_does_not():
    """Departure: eq. (25) as printed (direction column / L) gives a CI that changes from m to cm; ours (moment / L) does not."""
    y = Y_REF + [0.03, -0.02, 0.1]
    Pcm = rrr3.Rrr3Params(a=40.0, b=40.0, h=10.0, H=100.0)
    y_cm = np.r_[100 * y[:2], y[2]]

    def ci(params, yy, printed):
        Jx, Jq = rrr3.jacobians(params, yy)
        if printed:
            Jx = Jx.copy()
            Jx[:, :2] /= rrr3.characteristic_length(params)
        else:
            Jx, Jq = rrr3.homogenized_jacobians(params, yy)
        return 1.0 / np.linalg.cond(np.linalg.solve(Jq, Jx))

    assert ci(P, y, False) == pytest.approx(ci(Pcm, y_cm, False), rel=1e-10)
    assert abs(ci(P, y, True) - ci(Pcm, y_cm, True)) > 0.01


def test_bad_length_and_reference_are_refused():
    """A non-positive or non-finite L and an unknown reference point raise InvalidInputError."""
    for kwargs in ({"length": 0.0}, {"length": float("nan")}, {"reference": "B"}):
        with pytest.raises(InvalidInputError):
            rrr3.homogenized_jacobians(P, Y_REF, **kwargs)


# ---------------------------------------------------------------------- singularity classification
def test_classification_agrees_with_the_generic_core(mech):
    """Regular at the reference; a stretched leg is 'inverse' and a det J_x = 0 pose 'direct', for us and for diagnose."""
    assert rrr3.classify_singularity(P, Y_REF) == "regular" == diagnose(mech, mech.q_reference).classification
    u = np.array([math.cos(0.3), math.sin(0.3)])
    y_inv = np.r_[rrr3.centroid_from_a(P, (P.a + P.b) * u, 0.0), 0.0]
    assert rrr3.classify_singularity(P, y_inv, tol=1e-6) == "inverse"
    assert diagnose(mech, rrr3.closed_form_configuration(mech, y_inv)).classification == "inverse"
    phi_s = brentq(lambda p: np.linalg.det(rrr3.jacobians(P, [Y_REF[0], Y_REF[1], p])[0]), 0.6, 0.9, xtol=1e-15)
    y_dir = np.r_[Y_REF[:2], phi_s]
    assert rrr3.classify_singularity(P, y_dir) == "direct"
    assert diagnose(mech, rrr3.closed_form_configuration(mech, y_dir)).classification == "direct"


def test_combined_singularity_is_found_with_a_stretched_leg_on_a_direct_singularity():
    """Leg 1 stretched (psi_1 = 0) at the angle where det J_x vanishes: classified 'combined' (eqs. 19-20 both singular)."""
    phi = 0.3

    def pose(alpha):
        A = (P.a + P.b) * np.array([math.cos(alpha), math.sin(alpha)])
        return np.r_[rrr3.centroid_from_a(P, A, phi), phi]

    def det(alpha):
        return np.linalg.det(rrr3.homogenized_jacobians(P, pose(alpha))[0])

    alphas = np.linspace(0.2, 0.3, 21)
    vals = [det(a) for a in alphas]
    k = next(i for i in range(20) if vals[i] * vals[i + 1] < 0)
    alpha = brentq(det, alphas[k], alphas[k + 1], xtol=1e-15)
    assert rrr3.classify_singularity(P, pose(alpha), tol=1e-6) == "combined"
    inv, direct = rrr3.singularity_measures(P, pose(alpha))
    assert inv < 1e-6 and direct < 1e-9
    assert rrr3.classify_singularity(P, pose(alpha - 0.02), tol=1e-6) == "inverse"


# ---------------------------------------------------------------------- forward kinematics
def _multistart(params, theta, n, rng):
    """Brute force: vectorised Newton on the three leg equations from n random (x_A, y_A, Phi); distinct solutions."""
    D = rrr3.base_vertices(params) + params.a * np.column_stack([np.cos(theta), np.sin(theta)])
    span = params.H + params.a + params.b
    x = np.column_stack([rng.uniform(-span, span + params.H, (n, 2)), rng.uniform(-np.pi, np.pi, n)])
    off = np.array([0.0, 0.0, math.pi / 3])
    for _ in range(60):
        ang = x[:, 2:3] + off
        cos, sin = np.cos(ang) * [0, 1, 1], np.sin(ang) * [0, 1, 1]
        ex = x[:, :1] + params.h * cos - D[:, 0]
        ey = x[:, 1:2] + params.h * sin - D[:, 1]
        f = ex * ex + ey * ey - params.b ** 2
        J = np.stack([2 * ex, 2 * ey, 2 * params.h * (-ex * sin + ey * cos)], axis=-1)
        ok = np.abs(np.linalg.det(J)) > 1e-14
        x[ok] -= np.linalg.solve(J[ok], f[ok][..., None])[..., 0]
    found = []
    for xa in x:
        V = rrr3.platform_vertices(params, xa[:2], xa[2]) if np.all(np.isfinite(xa)) else None
        if V is None or np.max(np.abs(np.linalg.norm(V - D, axis=1) - params.b)) > 1e-10:
            continue
        y = np.r_[rrr3.centroid_from_a(params, xa[:2], xa[2]), _wrap(xa[2])]
        if not any(np.max(np.abs(np.r_[y[:2] - z[:2], _wrap(y[2] - z[2])])) < 1e-7 for z in found):
            found.append(y)
    return found


def test_forward_kinematics_loses_no_solution_against_a_brute_force_multistart():
    """On 40 random designs and motor angles, every solution of a 400-start Newton multistart is among ours (1e-7),
    and we return nothing it does not find; the sample includes 6-solution cases."""
    rng = np.random.default_rng(11)
    counts, checked = [], 0
    while checked < 40:
        a, b = rng.uniform(0.2, 1.0, 2)
        h = rng.uniform(0.05, 1.0)
        try:
            params = rrr3.Rrr3Params(a=a, b=b, h=h, home=(0.0, 0.0, 0.0))
            rrr3.reference_pose(params)  # the designs that assemble centred
        except InvalidParameterError:
            continue
        theta = rng.uniform(-np.pi, np.pi, 3)
        try:
            ours = [s.y for s in rrr3.forward_kinematics(params, theta)]
        except AssemblyError:
            continue
        brute = _multistart(params, theta, 400, rng)
        for z in brute:
            assert any(np.max(np.abs(np.r_[z[:2] - o[:2], _wrap(z[2] - o[2])])) < 1e-7 for o in ours)
        assert len(brute) == len(ours)
        counts.append(len(ours))
        checked += 1
    assert max(counts) == 6 and min(counts) >= 2


def test_every_forward_solution_closes_the_loops_in_the_generic_core():
    """Each assembly mode, rebuilt as a tree configuration, has the given motors, closes to 1e-10 and is a fixed point
    of pkm.core.close_loops; the pose the motors came from is among them (every working mode)."""
    built = {}
    for y in _random_poses(4, seed=12, radius=0.08, dphi=0.3):
        for name in ("mode1", "mode3", "mode8"):
            theta = rrr3.closed_form_ik(P, y, name)
            sols = rrr3.forward_kinematics(P, theta)
            assert any(np.max(np.abs(np.r_[s.y[:2] - y[:2], _wrap(s.y[2] - y[2])])) < 1e-10 for s in sols)
            for s in sols:
                assert s.residual <= 1e-10 and s.branch is not None
                mech = built.setdefault(s.branch, rrr3.build(rrr3.Rrr3Params()))
                q = rrr3.closed_form_configuration(mech, s.y, s.branch)
                assert np.abs(_wrap(mech.actuated_q(q) - theta)).max() <= 1e-10
                assert np.abs(constraints.residual(mech, q)).max() <= 1e-10
                res = close_loops(mech, theta, q)
                assert res.converged and np.abs(_wrap(res.q - q)).max() <= 1e-9


def test_no_assembly_raises_assembly_error_with_the_deficit():
    """Motors turned so the elbows are far apart (all outward) admit no platform: AssemblyError with deficit > 0."""
    theta = np.radians([-150.0, -30.0, 90.0])
    with pytest.raises(AssemblyError) as exc:
        rrr3.forward_kinematics(P, theta)
    assert exc.value.deficit > 0.1


@pytest.mark.parametrize("theta", [[0.1, 0.2], [0.1, float("nan"), 0.2], "up"])
def test_bad_motor_angles_are_refused(theta):
    """Wrongly shaped or non-finite motor angles raise InvalidInputError."""
    with pytest.raises(InvalidInputError):
        rrr3.forward_kinematics(P, theta)


# ---------------------------------------------------------------------- the former names (deprecated in 0.2.0)
KEYWORD_FUNCTIONS = {
    "inverse_kinematics": lambda **kw: rrr3.inverse_kinematics(P, rrr3.a_from_centroid(P, Y_REF[:2], Y_REF[2]),
                                                               Y_REF[2], **kw),
    "joint_values": lambda **kw: rrr3.joint_values(P, Y_REF, **kw),
    "jacobians": lambda **kw: rrr3.jacobians(P, Y_REF, **kw),
    "homogenized_jacobians": lambda **kw: rrr3.homogenized_jacobians(P, Y_REF, **kw, reference="A"),
    "singularity_measures": lambda **kw: rrr3.singularity_measures(P, Y_REF, **kw),
    "classify_singularity": lambda **kw: rrr3.classify_singularity(P, Y_REF, **kw),
}


@pytest.mark.parametrize("name", sorted(KEYWORD_FUNCTIONS))
def test_the_former_mode_keyword_warns_and_gives_the_same_result(name):
    """Each function's mode= is its branch= with a DeprecationWarning naming branch; a bad value raises the same
    InvalidInputError."""
    f = KEYWORD_FUNCTIONS[name]
    for value in (3, "mode6"):
        with pytest.warns(DeprecationWarning, match=f"{name}: 'mode' is now 'branch'"):
            old = f(mode=value)
        new = f(branch=value)
        if isinstance(new, dict):
            assert old == new
        else:
            np.testing.assert_array_equal(np.asarray(old, dtype=object if isinstance(new, str) else float),
                                          np.asarray(new, dtype=object if isinstance(new, str) else float))
    with pytest.raises(InvalidInputError) as exc_new:
        f(branch="mode9")
    with pytest.warns(DeprecationWarning), pytest.raises(InvalidInputError) as exc_old:
        f(mode="mode9")
    assert str(exc_old.value) == str(exc_new.value) and exc_old.value.name == "branch"


def test_configuration_takes_the_former_keyword(mech):
    with pytest.warns(DeprecationWarning, match="'mode' is now 'branch'"):
        q = rrr3.configuration(mech, Y_REF, mode=2)
    np.testing.assert_array_equal(q, rrr3.configuration(mech, Y_REF, branch=2))


def test_an_fk_solution_names_its_working_mode_branch():
    """FkSolution.branch is the working-mode name; .mode (and FkSolution(mode=...)) warn and give the same."""
    th = rrr3.inverse_kinematics(P, rrr3.a_from_centroid(P, Y_REF[:2], Y_REF[2]), Y_REF[2])
    s = next(s for s in rrr3.forward_kinematics(P, th) if s.branch == "mode1")
    with pytest.warns(DeprecationWarning, match="FkSolution: 'mode' is now 'branch'"):
        assert s.mode == s.branch == "mode1"
    with pytest.warns(DeprecationWarning, match="'mode' is now 'branch'"):
        assert rrr3.FkSolution(s.y, s.a_point, s.psi, mode="mode1", residual=s.residual).branch == "mode1"
