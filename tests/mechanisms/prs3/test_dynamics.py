"""3-PRS inverse dynamics: the closed-form twin against the Pinocchio route, sec. 5's claims, op counts."""

import math

import numpy as np
import pytest

import pkm
from pkm.errors import InvalidInputError, SingularityError, UnreachableError
from pkm.mechanisms import prs3
from pkm.mechanisms.prs3 import dynamics as PD
from pkm.motion import load_motions

DESIGNS = {
    "table2_P": prs3.Prs3Params(),
    "inclined_P": prs3.Prs3Params(gamma=1.2),
    "inclined_R": prs3.Prs3Params(gamma=1.2, actuation="R"),
    "outward_R": prs3.Prs3Params(gamma=2.0, actuation="R", g=0.8, reference=(0.9, 0.0, 0.0)),
}


@pytest.fixture(scope="module", params=list(DESIGNS))
def dyn(request):
    return PD.Prs3Dynamics(DESIGNS[request.param])


def test_twin_equals_the_pinocchio_route_everywhere_it_is_evaluated(dyn):
    """Single calls (CasADi graph) and batches (numpy) = Khalil projection of Pinocchio's RNEA, to 1e-9.

    Random states around the reference, a random external wrench, both working modes.
    """
    rng = np.random.default_rng(11)
    y0 = prs3.reference_pose(dyn.params)
    Y = y0 + rng.uniform(-1, 1, (6, 3)) * [0.03, 0.1, 0.1]
    Yd, Ydd, W = rng.normal(size=(6, 3)), rng.normal(size=(6, 3)), rng.normal(size=(6, 6))
    batch = dyn.batch(Y, Yd, Ydd, W)
    for k in range(6):
        ref = dyn.pinocchio(Y[k], Yd[k], Ydd[k], W[k])
        tol = 1e-9 * max(1.0, np.abs(ref).max())
        assert np.abs(dyn.forces(Y[k], Yd[k], Ydd[k], W[k]) - ref).max() <= tol
        assert np.abs(batch.tau[k] - ref).max() <= tol
        q, v, _ = dyn.state(Y[k], Yd[k], Ydd[k])
        mech = dyn.mechanism
        assert np.allclose(batch.q_actuated[k], q[mech.act_q], atol=1e-12)
        assert np.allclose(batch.qd_actuated[k], v[mech.act_v], atol=1e-12)


def test_the_other_working_mode_gives_other_forces_and_still_matches():
    """slider_above: a different branch of eq. (10), still equal to the Pinocchio route."""
    dyn = PD.Prs3Dynamics(prs3.Prs3Params(reference=(2.2, 0.0, 0.0)), branch="slider_above")
    below = PD.Prs3Dynamics(prs3.Prs3Params(reference=(2.2, 0.0, 0.0)))
    y, yd, ydd = [2.2, 0.05, -0.04], [0.1, 0.3, -0.2], [0.5, -1.0, 2.0]
    assert np.allclose(dyn.forces(y, yd, ydd), dyn.pinocchio(y, yd, ydd), rtol=1e-9)
    assert not np.allclose(dyn.forces(y, yd, ydd), below.forces(y, yd, ydd), rtol=1e-3)


def test_case_2_matches_the_closed_form_of_a_translating_robot():
    """Case 2 (eqs. 41-43): every body translates, so F_i = (m_p/3 + m_1 + m_2)(g + z''), to 1e-9 N."""
    p = prs3.Prs3Params()
    t, Y, Yd, Ydd = load_motions("prs3_motions.toml")["2"].sample()
    res = PD.Prs3Dynamics(p).batch(Y, Yd, Ydd, t=t)
    closed = (p.m_platform / 3 + p.m_slider + p.m_coupler) * (PD.G + Ydd[:, 0])
    assert np.abs(res.tau - closed[:, None]).max() < 1e-9


def test_sec5_claims_equal_powers_in_case_2_and_opposite_powers_in_case_3():
    """Case 2: the three powers are equal. Case 3: P2 and P3 have opposite signs with peaks in the same
    range, and leg 1's peak is under 10 % of theirs (sec. 5, Figs. 3-4)."""
    motions = load_motions("prs3_motions.toml")
    dyn = PD.Prs3Dynamics()
    P2 = dyn.batch(*motions["2"].sample()[1:]).power
    assert np.ptp(P2, axis=1).max() < 1e-9
    P3 = dyn.batch(*motions["3"].sample()[1:]).power
    peaks = np.abs(P3).max(axis=0)
    assert peaks[0] < 0.1 * min(peaks[1], peaks[2])
    assert 0.5 < peaks[1] / peaks[2] < 2.0
    moving = np.abs(P3[:, 1]) > 1e-3 * peaks[1]
    assert np.all(P3[moving, 1] * P3[moving, 2] < 0)


def test_a_constant_height_offset_changes_no_effort_in_case_3():
    """Vertical rails: case 3 at z = h (as printed) and at z = 0.81 m give the same forces (to 1e-9 N)."""
    _t, Y, Yd, Ydd = load_motions("prs3_motions.toml")["3"].sample()
    dyn = PD.Prs3Dynamics()
    lifted = Y.copy()
    lifted[:, 0] = 0.81
    assert np.abs(dyn.batch(Y, Yd, Ydd).tau - dyn.batch(lifted, Yd, Ydd).tau).max() < 1e-9


def test_operation_counts_beat_the_published_ones():
    """With symbolic inertial parameters: <= 700 mult/div and <= 550 add/sub (paper: 860/680);
    all numeric: <= 550/450. Each count is of the function the other tests evaluate."""
    sym = PD.operation_count(mode="inertial")
    num = PD.operation_count(mode="numeric")
    full = PD.operation_count(mode="symbolic")
    assert sym.mul <= 700 and sym.add <= 550
    assert num.mul <= 550 and num.add <= 450
    assert num.mul <= sym.mul <= full.mul and num.add <= sym.add <= full.add
    assert sym.functions == {"sin": 3, "cos": 3, "sqrt": 3, "atan2": 1}


def test_symbolic_twin_evaluates_to_the_numeric_route():
    """The twin with symbolic inertial parameters, fed Table 2's values, gives the batch route's forces."""
    p = prs3.Prs3Params()
    f = PD.twin(p, mode="inertial")
    P = PD.numeric_parameters(p)
    y, yd, ydd = [0.8, 0.1, -0.2], [0.1, -0.4, 0.3], [1.0, 2.0, -3.0]
    out = np.asarray(f(y, yd, ydd, *[P[k] for k in PD.INERTIAL])).ravel()
    assert np.allclose(out, PD.Prs3Dynamics(p).forces(y, yd, ydd), rtol=1e-12)


def test_a_motion_leaving_the_workspace_names_the_time_and_the_leg():
    """With short couplers, tilting far enough pulls a spherical joint out of its coupler's reach."""
    dyn = PD.Prs3Dynamics(prs3.Prs3Params(l=0.52))
    t = np.linspace(0.0, 1.0, 11)
    Y = np.column_stack([np.full(11, 0.81), 0.5 * t, np.zeros(11)])
    with pytest.raises(UnreachableError) as err:
        dyn.batch(Y, np.zeros((11, 3)), np.zeros((11, 3)), t=t)
    assert err.value.leg in (1, 2, 3) and err.value.excess > 0 and "t = " in str(err.value)
    k = int(str(err.value).split("sample ")[1].split()[0])
    with pytest.raises(UnreachableError):
        dyn.forces(Y[k], [0, 0, 0], [0, 0, 0])
    dyn.forces(Y[k - 1], [0, 0, 0], [0, 0, 0])


def test_the_reach_limit_is_an_inverse_singularity_reported_not_divided_by():
    """At the edge of the workspace a coupler is perpendicular to its rail (eq. 10's double root).

    Bisection on beta finds the edge to 1e-15 rad; just inside it the leg is reported singular,
    just outside unreachable, and a little further inside the forces are finite.
    """
    dyn = PD.Prs3Dynamics(prs3.Prs3Params(l=0.52))

    def reachable(b):
        try:
            dyn.forces([0.81, b, 0.0], [0, 0, 0], [0, 0, 0])
        except UnreachableError:
            return False
        except SingularityError:
            return True
        return True

    lo, hi = 0.0, 0.5
    assert reachable(lo) and not reachable(hi)
    while hi - lo > 1e-15:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if reachable(mid) else (lo, mid)
    with pytest.raises(SingularityError) as err:
        dyn.forces([0.81, lo, 0.0], [0, 0, 0], [0, 0, 0])
    assert err.value.kind == "inverse" and "leg" in str(err.value)
    assert np.all(np.isfinite(dyn.forces([0.81, lo - 1e-3, 0.0], [0, 0, 0], [0, 0, 0])))


def test_dependent_leg_wrenches_are_a_direct_singularity():
    """A vanishing elimination pivot (the 6x6 wrench system loses rank) is a direct singularity."""
    dyn = PD.Prs3Dynamics()
    with pytest.raises(SingularityError) as err:
        dyn._check(np.array([[0.3, 0.3, 0.3, 0.5, 0.5, 0.5, 1, 1, 1e-13, 1, 1, 1]]), None)
    assert err.value.kind == "direct"


@pytest.mark.parametrize("bad", [np.zeros((4, 2)), np.full((2, 3), np.nan), np.zeros((0, 3)), "abc"])
def test_malformed_trajectories_are_rejected(bad):
    with pytest.raises(InvalidInputError):
        PD.Prs3Dynamics().batch(bad, np.zeros((2, 3)), np.zeros((2, 3)))


def test_pitch_beyond_the_euler_range_is_rejected():
    with pytest.raises(InvalidInputError):
        PD.Prs3Dynamics().forces([0.81, math.pi / 2, 0.0], [0, 0, 0], [0, 0, 0])


def _ik_difference(params, y, h):
    return np.column_stack([(prs3.closed_form_ik(params, y + e) - prs3.closed_form_ik(params, y - e)) / (2 * h)
                            for e in h * np.eye(3)])


def test_jacobian_equals_differences_of_the_ik_and_the_generic_core(dyn):
    """J = dq_a/dy: Richardson differences of the closed-form IK (1e-7 rel.) and the core's inverse
    Jacobian (1e-9) agree, beta = phi = 0 included."""
    import pkm
    from tests.fd import rel, richardson
    for y in (prs3.reference_pose(dyn.params), prs3.reference_pose(dyn.params) + [0.02, 0.1, -0.07]):
        J = dyn.jacobian(y)
        assert rel(J, richardson(lambda h, y=y: _ik_difference(dyn.params, y, h), 1e-4)) < 1e-7
        q = prs3.configuration(dyn.mechanism, y)
        assert rel(J, pkm.inverse_jacobian(dyn.mechanism, q)) < 1e-9


def test_actuated_accelerations_are_the_derivatives_of_the_rates():
    """q_a'' from the closed form = Richardson differences of q_a' along case 4's motion (1e-8 rel.)."""
    from tests.fd import rel, richardson
    m = load_motions("prs3_motions.toml")["4"]
    dyn = PD.Prs3Dynamics()
    t = np.array([0.5, 2.0, 3.3])

    def rates(tt):
        return dyn.batch(*m.sample(tt)[1:]).qd_actuated

    fd = richardson(lambda h: (rates(t + h) - rates(t - h)) / (2 * h), 1e-3)
    assert rel(dyn.batch(*m.sample(t)[1:]).qdd_actuated, fd) < 1e-8


def test_the_papers_eq26_cannot_be_evaluated_where_the_trajectories_start():
    """At beta = phi = 0, J_r2 of eq. (25) has rank 1 (eq. 26 inverts it); ours is regular there."""
    p = prs3.Prs3Params()
    Jr1, Jr2 = prs3.paper_constraint_jacobians(p, [0.81, 0.0, 0.0])
    assert np.linalg.matrix_rank(Jr2, tol=1e-12) == 1 and np.linalg.matrix_rank(Jr1) == 2
    assert np.linalg.matrix_rank(prs3.paper_constraint_jacobians(p, [0.81, 0.2, -0.1])[1]) == 3
    assert np.linalg.cond(PD.Prs3Dynamics(p).homogeneous_jacobian([0.81, 0.0, 0.0])) < 10


def test_homogeneous_jacobian_does_not_depend_on_the_unit_of_length():
    """Scaling every length by 1000 (m -> mm) leaves the homogeneous Jacobian unchanged."""
    p = prs3.Prs3Params(gamma=1.2, actuation="R")
    mm = prs3.Prs3Params(gamma=1.2, actuation="R", l=1000 * p.l, h=1000 * p.h, g=1000 * p.g,
                         reference=(1000 * prs3.reference_pose(p)[0], 0.0, 0.0))
    y = np.array([0.8, 0.05, -0.1])
    J, Jmm = (PD.Prs3Dynamics(x).homogeneous_jacobian(y * [s, 1, 1]) for x, s in ((p, 1), (mm, 1000)))
    assert np.allclose(J, Jmm, rtol=1e-9)


def test_the_generic_call_gives_the_hand_written_twins_efforts(dyn):
    """pkm.inverse_dynamics on the 3-PRS model, both methods, at the states of sec. 5 case 3: the efforts of the
    hand-written twin Prs3Dynamics.forces (1e-9 relative)."""
    t, Y, Yd, Ydd = load_motions("prs3_motions.toml")["3"].sample()
    for k in range(0, len(t), max(1, len(t) // 6)):
        ref = dyn.forces(Y[k], Yd[k], Ydd[k])
        q, v, a = dyn.state(Y[k], Yd[k], Ydd[k])
        for method in ("khalil", "virtual_work"):
            tau = pkm.inverse_dynamics(dyn.mechanism, q, v, a, method=method)
            assert np.abs(tau - ref).max() <= 1e-9 * np.abs(ref).max(), (k, method)
