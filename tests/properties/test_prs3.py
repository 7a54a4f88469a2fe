"""3-PRS: properties over random designs (sliders or knees driven), poses, working modes and motions.

Designs from :func:`tests.properties.prs3_designs` (couplers 0.5-1.5 m, platform 0.4-0.7 of them, rails
at 52-129 deg, the base radius set so that the couplers make a drawn angle with the rail normals at the
reference, random masses and physical platform inertias); poses within 5 % of the coupler length and
0.15 rad of it; each leg on either branch of eq. (10).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

import pkm
from pkm.core import TaskMap, close_loops
from pkm.core.dynamics.projection import KhalilProjection
from pkm.core.kinematics import constraints
from pkm.core.kinematics.task import zyx_matrix
from pkm.errors import SingularityError
from pkm.mechanisms import prs3
from pkm.mechanisms.prs3 import dynamics as PD
from tests import fd
from tests.properties import (
    DECADES,
    assert_vanishes,
    derivative_error,
    examples,
    floats,
    path_derivative_errors,
    path_state,
    power_balance_error,
    prs3_designs,
    prs3_pose,
    reachable,
    record,
    regular,
    richardson2,
    seed_fraction,
    sines,
    unit_box,
)

branch_sets = st.tuples(*[st.sampled_from(sorted(prs3.BRANCHES))] * 3)


def _case(p, u, branches, margin=1e-2):
    """Mechanism, pose, actuated coordinates and closed-form configuration; regular (both singularity measures
    above ``margin`` coupler lengths) or rejected."""
    mech = prs3.build(p)
    y = prs3_pose(p, u)
    qa = reachable(prs3.closed_form_ik, p, y, branches)
    q = prs3.configuration(mech, y, branches)
    assume(regular(mech, q, margin * p.l))
    return mech, y, qa, q


def _motion(p, y, motion):
    """The task motion ``y0 + sines`` through ``y`` at ``motion.t`` (1 % of l, 0.05 rad)."""
    return motion.through(y, np.array([0.01 * p.l, 0.05, 0.05]))


@examples(100)
@given(prs3_designs(), unit_box(3), unit_box(3), branch_sets)
def test_inverse_kinematics_then_loop_closure_gives_the_pose_back(p, u, du, branches):
    """Closed-form IK (eq. 10 corrected) on any branch per leg, then the core's loop closure from a nearby
    assembly on the same branches (closer near a direct singularity: :func:`seed_fraction`): the task comes
    back to 1e-9 and the whole configuration to 1e-8 (the paper has no forward kinematics)."""
    mech, y, qa, q = _case(p, u, branches, margin=1e-3)
    offset = np.array([0.005 * p.l, 0.01, 0.01]) * seed_fraction(mech, q, p.l) * du
    seed = reachable(prs3.configuration, mech, y + offset, branches)
    res = close_loops(mech, qa, seed)
    task = TaskMap(mech)
    assert record("prs3 IK->close_loops (task)", np.abs(task.error(y, task.value(res.q))).max()) <= 1e-9
    assert np.abs(pin.difference(mech.model, q, res.q)).max() <= 1e-8


@examples(80)
@given(prs3_designs(), unit_box(3), branch_sets, floats(0.1, 10.0))
def test_jacobians_match_finite_differences(p, u, branches, lam):
    """The closed-form J = dq_a/dy (Prs3Dynamics) equals Richardson differences of the closed-form IK and the
    core's inverse Jacobian; the core's forward Jacobian equals differences of its loop closure; the
    homogeneous Jacobian is unchanged when every length is multiplied by lam (1e-9)."""
    mech, y, _, q = _case(p, u, branches)
    dyn = PD.Prs3Dynamics(p, branches)
    J = dyn.jacobian(y)

    def diff(h):
        return np.column_stack([(prs3.closed_form_ik(p, y + e, branches) - prs3.closed_form_ik(p, y - e, branches))
                                / (2 * h) for e in h * np.eye(3)])

    assert record("prs3 closed-form J vs FD (rel)", fd.rel(J, fd.richardson(diff, 1e-5))) <= 1e-6
    assert record("prs3 closed-form J vs core (rel)", fd.rel(J, pkm.inverse_jacobian(mech, q))) <= 1e-9
    assert record("prs3 core forward J vs FD (rel)", fd.forward_jacobian_error(mech, q)) <= 1e-6
    scaled = prs3.Prs3Params(gamma=p.gamma, l=lam * p.l, h=lam * p.h, g=lam * p.g, actuation=p.actuation,
                             reference=(lam * p.reference[0], 0.0, 0.0))
    Js = PD.Prs3Dynamics(scaled, branches).homogeneous_jacobian(y * [lam, 1.0, 1.0])
    assert record("prs3 homogeneous J unit invariance (rel)", fd.rel(Js, dyn.homogeneous_jacobian(y))) <= 1e-9


@examples(60)
@given(prs3_designs(), unit_box(3), branch_sets, sines(3))
def test_accelerations_match_differences_of_velocities(p, u, branches, motion):
    """Along a random sum of sines, the closed-form actuated rates and accelerations (Prs3Dynamics.batch) are
    the derivatives of the actuated coordinates and rates (1e-7), and the core's inverse velocities and
    accelerations those of the closed-form configuration and of the velocities (1e-6)."""
    mech, y, _, _ = _case(p, u, branches)
    dyn = PD.Prs3Dynamics(p, branches)
    motion_at = _motion(p, y, motion)

    def batch(t):
        return dyn.batch(*(np.atleast_2d(x) for x in motion_at(t)))

    t, h = motion.t, 1e-3
    res = batch(t)
    qad = richardson2(lambda hh: (batch(t + hh).q_actuated - batch(t - hh).q_actuated)[0] / (2 * hh), h)
    qadd = richardson2(lambda hh: (batch(t + hh).qd_actuated - batch(t - hh).qd_actuated)[0] / (2 * hh), h)
    err_v = derivative_error(res.qd_actuated[0], qad, res.q_actuated[0], h)
    err_a = derivative_error(res.qdd_actuated[0], qadd, res.qd_actuated[0], h)
    assert record("prs3 closed-form qd_a vs FD (rel)", err_v) <= 1e-7
    assert record("prs3 closed-form qdd_a vs FD (rel)", err_a) <= 1e-7

    def state(tt):
        return path_state(mech, lambda yy: prs3.configuration(mech, yy, branches), motion_at, tt)

    ev, ea = path_derivative_errors(mech, state, t)
    assert record("prs3 inverse velocities vs FD (rel)", ev) <= 1e-6
    assert record("prs3 inverse accelerations vs FD (rel)", ea) <= 1e-6
    _, _, a = state(t)
    assert fd.rel(res.qdd_actuated[0], a[mech.act_v]) <= 1e-9


@examples(40)
@given(prs3_designs(inclined=True), floats(0.1, 0.3), st.integers(0, 5), floats(-0.45, 0.45), floats(0.2, 0.5))
def test_a_leg_at_full_reach_is_approached_as_an_inverse_singularity(p, tilt, sector, offset, s_max):
    """Inclined rails, the platform tilted, raised or lowered until the farthest leg's coupler makes the angle
    s with its rail normal (theta_k = s), s -> 0 (coupler perpendicular to the rail, eq. 10's double root):
    the core's sigma_inverse falls monotonically and linearly to 1e-8 of its start; the class is regular at
    s_max and inverse at s = 1e-8 s_max and at s = 0, where the closed form (Prs3Dynamics) and Khalil's
    projection raise SingularityError('inverse') for that leg."""
    mech = prs3.build(p)
    direction = sector * math.pi / 3 + offset  # near multiples of 60 deg one leg is clearly the farthest
    pitch, roll = tilt * math.cos(direction), tilt * math.sin(direction)
    a, u1, w, _, b = prs3.leg_geometry(p)
    xp, yp, alpha = prs3.parasitic_motion(p.h, pitch, roll)
    c0 = np.array([xp, yp, 0.0]) + b @ zyx_matrix(roll, pitch, alpha).T - a  # B_i - a_i at z = 0
    cw0 = np.einsum("ij,ij->i", c0, w)
    k = int(np.argmax(cw0))  # the leg farthest from its rail at any height
    assume(np.sort(cw0)[-1] - np.sort(cw0)[-2] > 0.01 * p.l)  # the other legs clear of the same singularity
    cg = math.cos(p.gamma)
    dyn = PD.Prs3Dynamics(p)
    index = []
    for j, s in enumerate([*(s_max * DECADES), 0.0]):
        z = (p.l * math.cos(s) - cw0[k]) / cg  # c_k . w_k = l cos(s)
        y = np.array([z, pitch, roll])
        values = reachable(prs3.joint_values, p, y)
        c = c0[k] + z * np.array([0.0, 0.0, 1.0])
        values |= {f"slider_{k + 1}": [float(c @ u1[k] - p.l * math.sin(s))], f"knee_{k + 1}": [s]}
        q = mech.q_from_dict(values)
        assert np.abs(constraints.residual(mech, q)).max() <= 1e-12 * p.l
        diag = pkm.diagnose(mech, q)
        index.append(diag.sigma_inverse)
        if j == 0:
            assume(diag.classification == "regular")
            assert np.all(np.isfinite(dyn.forces(y, np.zeros(3), np.zeros(3))))
        if j >= 8:
            assert diag.classification == "inverse", (s, diag)
            with pytest.raises(SingularityError) as err:
                dyn.forces(y, np.zeros(3), np.zeros(3))
            assert err.value.kind == "inverse" and f"leg {k + 1}" in str(err.value)
    with pytest.raises(SingularityError) as err:
        KhalilProjection(mech).projection(q)
    assert err.value.kind == "inverse" and f"ball_{k + 1}" in str(err.value)
    assert_vanishes(index[:-1], "prs3 leg at full reach, core sigma_inverse")


@examples(60)
@given(prs3_designs(), unit_box(3), branch_sets, sines(3))
def test_power_balance_along_random_motions(p, u, branches, motion):
    """Along a random sum of sines, the closed-form efforts (Prs3Dynamics, sliders or knees driven) equal
    Khalil's projection of Pinocchio's RNEA (1e-9) and their power sum tau_i qd_i equals the rate of change
    of the bodies' energy (1e-8 of the gross power)."""
    mech, y, _, _ = _case(p, u, branches)
    dyn = PD.Prs3Dynamics(p, branches)
    motion_at = _motion(p, y, motion)

    def state(t):
        return path_state(mech, lambda yy: prs3.configuration(mech, yy, branches), motion_at, t)

    y_t, yd_t, ydd_t = motion_at(motion.t)
    tau = dyn.forces(y_t, yd_t, ydd_t)
    q, v, a = state(motion.t)
    ref = KhalilProjection(mech).inverse_dynamics(q, v, a)
    assert record("prs3 closed-form tau vs Khalil (rel)", fd.rel(tau, ref)) <= 1e-9
    err = power_balance_error(mech, state, lambda *_: tau, motion.t)
    assert record("prs3 power balance (rel. to gross power)", err) <= 1e-8
