"""Tests specific to the 3-PRS of Diaz-Rodriguez et al. (2016): Table 2 data, parameter checks, the
corrected eq. (10), the parasitic motion against eq. (15), working modes, actuation, reachability."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

from pkm.core import TaskMap, branch_seed, diagnose, solve_ik
from pkm.core.kinematics import constraints
from pkm.errors import InvalidInputError, InvalidParameterError, UnreachableError
from pkm.mechanisms import prs3

REF = np.array([0.81, 0.0, 0.0])  # sec. 5, eq. (41) at t = 0: z_p [m], beta, phi [rad]
PHI = np.deg2rad([0.0, 120.0, 240.0])


@pytest.fixture(scope="module")
def mech():
    return prs3.build(prs3.Params(reference=tuple(REF)))


def eq1(alpha: float, beta: float, phi: float) -> np.ndarray:
    """The paper's eq. (1), transcribed: R = Rz(alpha) Ry(beta) Rx(phi)."""
    ca, sa, cb, sb, cf, sf = (math.cos(alpha), math.sin(alpha), math.cos(beta), math.sin(beta), math.cos(phi),
                              math.sin(phi))
    return np.array([[ca * cb, ca * sb * sf - sa * cf, ca * sb * cf + sa * sf],
                     [sa * cb, sa * sb * sf + ca * cf, sa * sb * cf - ca * sf],
                     [-sb, cb * sf, cb * cf]])


def leg_plane_residuals(h: float, motion: tuple[float, float, float], beta: float, phi: float,
                        offset: float = 0.0) -> np.ndarray:
    """``e_t,i . B_i`` (eqs. 12-14) for legs at ``phi_i + offset``, platform pose from ``(x_p, y_p, alpha)``."""
    x, y, alpha = motion
    R, p = eq1(alpha, beta, phi), np.array([x, y, 0.3])
    out = []
    for f in PHI + offset:
        e_r, e_t = np.array([math.cos(f), math.sin(f), 0.0]), np.array([-math.sin(f), math.cos(f), 0.0])
        out.append(e_t @ (p + R @ (h * e_r)))
    return np.array(out)


def rails(params) -> tuple[np.ndarray, np.ndarray]:
    """Rail origins a_i (eq. 7) and directions u_1,i, rows i = 1..3."""
    e_r = np.column_stack([np.cos(PHI), np.sin(PHI), np.zeros(3)])
    u1 = math.cos(params.gamma) * e_r + math.sin(params.gamma) * np.array([0.0, 0.0, 1.0])
    return params.g * e_r, u1


def frame_positions(m, q, name: str) -> np.ndarray:
    """World positions of frames ``name_1 .. name_3`` (``{}`` in ``name`` is the leg number)."""
    pin.framesForwardKinematics(m.model, m.data, q)
    return np.array([m.data.oMf[m.frame_id(name.format(n))].translation for n in (1, 2, 3)])


def random_tasks(rng, n: int, scale=(0.06, 0.15, 0.15)) -> np.ndarray:
    return REF + rng.uniform(-1.0, 1.0, (n, 3)) * np.array(scale)


# ---------------------------------------------------------------------- Table 2
def test_table2_file_holds_the_published_values_and_obeys_its_formulas():
    """The stored Table 2 has the published values, and each derived entry equals its formula."""
    t = prs3.table2()
    assert (t["gamma"], t["l"], t["h"], t["g"]) == (math.pi / 2, 1.0, 0.5, 1.0)
    assert t["m1"] == t["m2"] == 0.1 * t["mp"] == 0.5
    assert t["Izz2"] == pytest.approx(t["m2"] * t["l"] ** 2 / 12, rel=1e-15) == pytest.approx(0.5 / 12)
    assert t["mx2"] == t["l"] / 2 * t["m2"] and t["my2"] == 0.0
    assert t["Ixx3"] == t["Iyy3"] == t["mp"] * t["h"] ** 2 / 4 == 0.3125
    assert t["Izz3"] == t["mp"] * t["h"] ** 2 / 2 == 0.625
    assert t["Ixy3"] == t["Ixz3"] == t["Iyz3"] == 0.0


def test_table2_masses_and_inertias_are_the_link_inertias_of_the_pinocchio_model(mech):
    """Sliders 0.5 kg; couplers 0.5 kg at l/2 with 0.5/12 kg m^2 about both transverse axes; platform 5 kg."""
    model = mech.model
    platform = model.inertias[mech.joint("platform").id]
    assert platform.mass == 5.0
    np.testing.assert_allclose(platform.lever, 0.0, atol=1e-15)
    np.testing.assert_allclose(platform.inertia, np.diag([0.3125, 0.3125, 0.625]), atol=1e-15)
    for n in (1, 2, 3):
        slider = model.inertias[mech.joint(f"slider_{n}").id]
        coupler = model.inertias[mech.joint(f"knee_{n}").id]
        assert slider.mass == 0.5
        assert coupler.mass == 0.5
        np.testing.assert_allclose(coupler.lever, [0.0, 0.0, 0.5], atol=1e-15)
        # about the revolute axis direction (local y) and the other transverse axis; 0 along the coupler
        np.testing.assert_allclose(coupler.inertia, np.diag([0.5 / 12, 0.5 / 12, 0.0]), atol=1e-15)
        assert model.joints[mech.joint(f"knee_{n}").id].shortname() == "JointModelRY"


# ---------------------------------------------------------------------- parameters
@pytest.mark.parametrize("kwargs", [
    {"l": 0.0}, {"l": -1.0}, {"l": math.nan}, {"h": 0.0}, {"g": -0.2},
    {"gamma": 0.0}, {"gamma": math.pi}, {"gamma": -0.1}, {"gamma": 3.5}, {"gamma": math.inf},
    {"actuation": "PR"}, {"m_platform": 0.0}, {"m_slider": -0.1}, {"m_coupler": math.nan},
    {"Izz3": 1.0},  # principal moments 0.3125, 0.3125, 1.0 break the triangle inequality
    {"Ixx3": -0.1},
    {"l": 0.4},  # the spherical joints are 0.5 m from the rails at every level pose: unreachable
    {"l": 0.5},  # exactly reachable: couplers perpendicular to the rails (double root) at every level pose
    {"l": 0.5, "reference": (0.81, 0.0, 0.0)},
    {"reference": (0.81, 2.0, 0.0)}, {"reference": (0.81, 0.0)}, {"reference": (math.nan, 0.0, 0.0)},
])
def test_invalid_parameters_are_refused(kwargs):
    """Non-positive lengths, rails outside (0, pi), bad actuation, masses or inertia, and designs that cannot
    assemble at their reference pose (or only at a double root) raise InvalidParameterError."""
    with pytest.raises(InvalidParameterError):
        prs3.reference_pose(prs3.Params(**kwargs))


def test_unreachable_reference_message_says_how_to_fix_it():
    """The error for an unreachable reference names the leg, the miss and what to change."""
    with pytest.raises(InvalidParameterError, match=r"leg 1 misses by 0\.1 m\); lengthen l"):
        prs3.build(prs3.Params(l=0.4, reference=(0.81, 0.0, 0.0)))
    with pytest.raises(InvalidParameterError, match=r"none of them assembles; the first: .*leg 1 misses by 0\.1 m"):
        prs3.build(prs3.Params(l=0.4))


# ---------------------------------------------------------------------- eq. (10)
def test_corrected_eq10_solves_eq9_and_the_printed_one_does_not(mech):
    """With the square restored, d_i puts the revolute at distance l from the platform point (eq. 9), for both
    signs; the printed eq. (10) misses by centimetres at the reference."""
    params, rng = mech.params, np.random.default_rng(10)
    a, u1 = rails(params)
    worst = 0.0
    for y in np.vstack([REF, random_tasks(rng, 30)]):
        B = frame_positions(mech, prs3.closed_form_configuration(mech, y), "platform_ball_{}")
        c = B - a
        cu, cc = np.einsum("ij,ij->i", c, u1), np.einsum("ij,ij->i", c, c)
        for sign, branch in ((-1.0, "slider_below"), (1.0, "slider_above")):
            d = cu + sign * np.sqrt(cu**2 - cc + params.l**2)
            worst = max(worst, np.abs(np.linalg.norm(c - d[:, None] * u1, axis=1) - params.l).max())
            np.testing.assert_allclose(prs3.inverse_kinematics(params, y, branch)[0], d, atol=1e-14)
    assert worst < 1e-14
    # eq. (10) as printed: (c.u) instead of (c.u)^2 under the root
    c = frame_positions(mech, mech.q_reference, "platform_ball_{}") - a
    cu, cc = np.einsum("ij,ij->i", c, u1), np.einsum("ij,ij->i", c, c)
    d_printed = cu - np.sqrt(cu - cc + params.l**2)
    miss = np.abs(np.linalg.norm(c - d_printed[:, None] * u1, axis=1) - params.l)
    assert miss.min() > 0.04


# ---------------------------------------------------------------------- eq. (15)
def test_derived_parasitic_motion_keeps_each_spherical_joint_in_its_leg_plane():
    """x_p, y_p, alpha of parasitic_motion satisfy eqs. (12)-(14) for the layout of eqs. (6)-(7)."""
    rng = np.random.default_rng(15)
    worst = max(np.abs(leg_plane_residuals(0.5, prs3.parasitic_motion(0.5, b, f), b, f)).max()
                for b, f in rng.uniform(-0.6, 0.6, (200, 2)))
    assert worst < 1e-15


def test_printed_eq15_holds_only_for_the_layout_rotated_by_90_degrees():
    """Eq. (15) as printed breaks the leg-plane conditions of eqs. (6)-(7) at second order in the angles, yet
    satisfies them exactly when every leg is rotated by 90 deg about Z; its alpha is right for both."""
    rng = np.random.default_rng(16)
    on_paper_layout, on_rotated_layout = 0.0, 0.0
    for b, f in rng.uniform(-0.6, 0.6, (200, 2)):
        printed, derived = prs3.paper_parasitic_motion(0.5, b, f), prs3.parasitic_motion(0.5, b, f)
        on_paper_layout = max(on_paper_layout, np.abs(leg_plane_residuals(0.5, printed, b, f)).max())
        on_rotated_layout = max(on_rotated_layout,
                                np.abs(leg_plane_residuals(0.5, printed, b, f, math.pi / 2)).max())
        # printed (x, y) is the derived (x, y) turned by -90 deg: x_paper = y, y_paper = -x
        np.testing.assert_allclose(printed, (derived[1], -derived[0], derived[2]), atol=1e-15)
    assert on_rotated_layout < 1e-15
    assert on_paper_layout > 1e-2
    assert prs3.paper_parasitic_motion(0.5, 0.0, 0.0) == pytest.approx(prs3.parasitic_motion(0.5, 0.0, 0.0))
    # case 3 of sec. 5 at its largest roll (10 deg): the derived drift is along x, the printed one along y
    x, y, alpha = prs3.parasitic_motion(0.5, 0.0, math.pi / 18)
    assert (x, y, alpha) == pytest.approx((0.25 * (1 - math.cos(math.pi / 18)), 0.0, 0.0), abs=1e-16)
    assert prs3.paper_parasitic_motion(0.5, 0.0, math.pi / 18)[:2] == pytest.approx((0.0, -x), abs=1e-16)


# ---------------------------------------------------------------------- working modes
@pytest.mark.parametrize("gamma", [math.pi / 2, math.pi / 3, 2 * math.pi / 3])
def test_both_branches_are_reachable_and_correctly_signed(gamma):
    """slider_below has every knee > 0 and the slider below its spherical joint along the rail; slider_above the
    opposite; a per-leg mix works too; every configuration closes its loops."""
    m = prs3.build(prs3.Params(gamma=gamma))
    _, u1 = rails(m.params)
    y = REF + np.array([0.02, 0.05, -0.08])
    for branch, sign in (("slider_below", 1), ("slider_above", -1)):
        q = prs3.closed_form_configuration(m, y, branch)
        assert m.on_branch(q, branch)
        assert np.abs(constraints.residual(m, q)).max() < 1e-14
        along = np.einsum("ij,ij->i", frame_positions(m, q, "platform_ball_{}")
                          - frame_positions(m, q, "slider_link_{}"), u1)
        assert np.all(sign * along > 0.1)
    mixed = ("slider_below", "slider_above", "slider_below")
    q = prs3.closed_form_configuration(m, y, mixed)
    assert [np.sign(q[m.joint(f"knee_{n}").idx_q]) for n in (1, 2, 3)] == [1, -1, 1]
    assert np.abs(constraints.residual(m, q)).max() < 1e-14


def test_knee_zero_is_the_coupler_perpendicular_to_the_rail_pointing_inward():
    """At theta_i = 0 the coupler is normal to the rail and points to the centre; theta_i > 0 turns it up the rail."""
    m = prs3.build(prs3.Params(gamma=math.pi / 3))
    a, u1 = rails(m.params)
    for theta, up in ((0.0, 0.0), (0.4, math.sin(0.4))):
        q = m.q_from_dict({f"knee_{n}": theta for n in (1, 2, 3)} | {f"slider_{n}": 0.1 for n in (1, 2, 3)})
        S = frame_positions(m, q, "slider_link_{}")
        coupler = (frame_positions(m, q, "coupler_{}_tip") - S) / m.params.l
        np.testing.assert_allclose(S, a + 0.1 * u1, atol=1e-15)
        np.testing.assert_allclose(np.einsum("ij,ij->i", coupler, u1), up, atol=1e-15)
        assert np.all(np.einsum("ij,ij->i", coupler, a) < 0)  # inward
        np.testing.assert_allclose(np.linalg.norm(coupler, axis=1), 1.0, atol=1e-15)


@pytest.mark.parametrize("branch", ["slider_below", "slider_above"])
def test_closed_form_matches_generic_inverse_kinematics_on_each_branch(mech, branch):
    """From the generic seed of the same branch, pkm.core.solve_ik finds the closed-form sliders and the derived
    parasitic motion (platform x, y and yaw)."""
    rng = np.random.default_rng(20)
    seed = branch_seed(mech, branch)
    worst_d, worst_pose = 0.0, 0.0
    for y in random_tasks(rng, 8):
        res = solve_ik(mech, y, seed, branch=branch)
        worst_d = max(worst_d, np.abs(mech.actuated_q(res.q) - prs3.closed_form_ik(mech.params, y, branch)).max())
        x, yp, alpha = prs3.parasitic_motion(mech.params.h, y[1], y[2])
        pin.framesForwardKinematics(mech.model, mech.data, res.q)
        M = mech.data.oMf[mech.ee_frame]
        yaw = math.atan2(M.rotation[1, 0], M.rotation[0, 0])
        worst_pose = max(worst_pose, abs(M.translation[0] - x), abs(M.translation[1] - yp), abs(yaw - alpha))
    assert worst_d < 1e-10
    assert worst_pose < 1e-10


# ---------------------------------------------------------------------- actuation
def test_reference_is_regular_with_slider_actuation(mech):
    """At z = 0.81 m, beta = phi = 0 the P-actuated Table 2 robot is regular with mobility 3."""
    d = diagnose(mech, mech.q_reference)
    assert (d.classification, d.mobility, d.constraint_rank) == ("regular", 3, 9)
    assert min(d.sigma_direct, d.sigma_inverse) > 0.3


@pytest.mark.parametrize("gamma", [math.pi / 2, math.pi / 3, 2 * math.pi / 3])
def test_knee_actuation_builds_with_mobility_3_and_needs_inclined_rails(gamma):
    """Actuating the knees gives mobility 3 and the closed form returns the knee angles; with vertical rails the
    passive sliders are parallel and the platform can rise with the knees locked (a direct singularity: the load
    warns that the knees fall short of the mobility there, and only there)."""
    import warnings

    from pkm.errors import PkmWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m = prs3.build(prs3.Params(actuation="R", gamma=gamma, reference=tuple(REF)))
    warned = [w for w in caught if issubclass(w.category, PkmWarning)]
    assert len(warned) == (gamma == math.pi / 2) and all("3 degree(s) of freedom move the task" in str(w.message)
                                                         for w in warned)
    assert m.actuated_names == ("knee_1", "knee_2", "knee_3")
    d = diagnose(m, m.q_reference)
    assert d.mobility == 3
    y = REF + np.array([0.01, -0.05, 0.04])
    q = prs3.closed_form_configuration(m, y)
    np.testing.assert_allclose(prs3.closed_form_ik(m.params, y), m.actuated_q(q), atol=1e-15)
    if gamma == math.pi / 2:
        assert d.classification == "direct" and d.sigma_direct < 1e-12
        with pytest.raises(InvalidParameterError, match="well-conditioned"):  # singular everywhere: no default
            prs3.build(prs3.Params(actuation="R", gamma=gamma))
    else:
        assert d.classification == "regular"
        res = solve_ik(m, y)
        assert np.abs(m.actuated_q(res.q) - prs3.closed_form_ik(m.params, y)).max() < 1e-10


def test_sec5_trajectories_move_the_legs_as_the_paper_describes(mech):
    """Case 2 (harmonic z) moves the three sliders alike; case 3 (harmonic roll) moves sliders 2 and 3 in opposite
    directions while slider 1 moves less than 10 % as much."""
    t = np.linspace(0.0, 5.0, 51)
    case2 = np.array([prs3.closed_form_ik(mech.params, (0.81 + 0.005 * (1 - math.cos(math.pi / 3 * s)), 0, 0))
                      for s in t])
    np.testing.assert_allclose(case2 - case2[0], np.repeat((case2[:, :1] - case2[0, 0]), 3, axis=1), atol=1e-15)
    case3 = np.array([prs3.closed_form_ik(mech.params, (0.5, 0.0, math.pi / 36 * (1 - math.cos(math.pi / 3 * s))))
                      for s in t])
    moves = case3 - case3[0]
    assert np.all(moves[1:, 1] * moves[1:, 2] < 0)
    assert np.abs(moves[:, 0]).max() < 0.1 * min(np.abs(moves[:, 1]).max(), np.abs(moves[:, 2]).max())


# ---------------------------------------------------------------------- bad input
@pytest.mark.parametrize("y, leg", [((0.81, 0.6, 0.0), 1), ((0.81, 0.0, 0.9), 2), ((0.81, -0.2, 0.7), 3),
                                    ((0.81, 0.2, -0.9), 2)])
def test_unreachable_pose_names_the_first_leg_and_its_excess(y, leg):
    """The error names the first leg whose spherical joint is farther than l from its rail, by that distance."""
    params = prs3.Params(l=0.6)
    a, u1 = rails(params)
    x, yp, alpha = prs3.parasitic_motion(params.h, y[1], y[2])
    B = np.array([x, yp, y[0]]) + (eq1(alpha, y[1], y[2]) @ (params.h / params.g * a.T)).T
    c = B - a
    dist = np.linalg.norm(c - np.einsum("ij,ij->i", c, u1)[:, None] * u1, axis=1)
    first = int(np.flatnonzero(dist > params.l)[0]) + 1
    assert first == leg
    with pytest.raises(UnreachableError) as exc:
        prs3.closed_form_ik(params, y)
    assert exc.value.leg == leg and exc.value.unit == "m"
    assert exc.value.excess == pytest.approx(dist[leg - 1] - params.l, rel=1e-12) and exc.value.excess > 0
    if leg == 1:  # pure pitch: leg 1 is g + h/2 - 3h/2 cos(beta) from its rail
        assert exc.value.excess == pytest.approx(1.25 - 0.75 * math.cos(0.6) - 0.6, rel=1e-12)


@pytest.mark.parametrize("y", [(0.81, 0.0), (0.81, 0.0, 0.0, 0.0), [[0.81, 0.0, 0.0]], (math.nan, 0.0, 0.0),
                               (0.81, math.inf, 0.0), "abc", None, (0.81, math.pi / 2, 0.0)])
def test_malformed_task_vectors_are_refused(mech, y):
    """Wrong shapes, non-finite values and a pitch of +-90 deg raise InvalidInputError."""
    with pytest.raises(InvalidInputError):
        prs3.closed_form_ik(mech.params, y)
    with pytest.raises(InvalidInputError):
        prs3.closed_form_configuration(mech, y)


@pytest.mark.parametrize("branch", ["up", ("slider_below", "slider_above"), ("slider_below", "x", "slider_above")])
def test_unknown_branches_are_refused(mech, branch):
    """A branch other than slider_below / slider_above (or three of them) raises InvalidInputError."""
    with pytest.raises(InvalidInputError):
        prs3.closed_form_ik(mech.params, REF, branch)


def test_task_vector_of_the_closed_form_configuration_is_the_input(mech):
    """TaskMap reads back (z, pitch, roll) from the closed-form configuration, on both branches."""
    task = TaskMap(mech)
    assert task.names == ("z", "pitch", "roll")
    for y in random_tasks(np.random.default_rng(3), 20):
        for branch in prs3.BRANCHES:
            np.testing.assert_allclose(task.value(prs3.closed_form_configuration(mech, y, branch)), y, atol=1e-15)
