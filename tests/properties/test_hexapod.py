"""Reconfigurable hexapod: properties over random designs, poses, working modes and motions.

Designs from :func:`tests.properties.hexapod_designs` (Table 1 scaled by 0.5-2, each length within
10 % and each leg angle within 5 deg, random masses, a reference pose turned 20-40 deg about Y);
poses within 5 % of the arm length and 0.05 rad of it, beta within 0.2 rad; each leg on either
elbow branch. The singular configurations are those of the paper (sec. 3.3, Figs. 4a and 5),
constructed exactly on random designs.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
from hypothesis import assume, given
from hypothesis import strategies as st

import pkm
from pkm.core import TaskMap, close_loops
from pkm.core.dynamics.projection import virtual_work_dynamics
from pkm.core.kinematics import constraints
from pkm.mechanisms import hexapod as hx
from pkm.mechanisms._common import rot_y
from pkm.mechanisms.hexapod import screws as hs
from pkm.mechanisms.hexapod import singularities as hsg
from tests import fd
from tests.properties import (
    DECADES,
    assert_vanishes,
    examples,
    floats,
    forward_acceleration_errors,
    hexapod_designs,
    hexapod_pose,
    path_derivative_errors,
    path_state,
    power_balance_error,
    reachable,
    record,
    regular,
    rotation_path,
    round_trip_tolerance,
    seed_fraction,
    sines,
    two_link_reach,
    unit_box,
    wrap,
)

branch_sets = st.tuples(*[st.sampled_from(sorted(hx.BRANCHES))] * 6)
DEG = math.pi / 180.0


def _case(p, u, branches, margin=1e-2):
    """Mechanism, task vector, actuated coordinates and closed-form configuration; regular (both singularity
    measures above ``margin`` arm lengths) or rejected."""
    mech = hx.build(p)
    y = hexapod_pose(p, u)
    qa = reachable(hx.closed_form_ik, p, y, branches)
    q = hx.closed_form_configuration(mech, y, branches)
    assume(regular(mech, q, margin * p.LA))
    return mech, y, qa, q


def _pose(y):
    return pin.Quaternion(y[6], *y[3:6]).toRotationMatrix(), y[:3].copy(), float(y[7])


class _Motion:
    """A random sum of sines in the 7 task coordinates (position, rotation vector, beta) through ``y`` at
    ``motion.t``; ``at(t)`` gives the task vector, its rates ``[v_P; w; beta_dot]`` and accelerations
    ``[a_P; w_dot; beta_ddot]`` in closed form (:func:`tests.properties.rotation_path`)."""

    def __init__(self, p, y, motion):
        self.motion = motion
        self.scale = np.r_[np.full(3, 0.01 * p.LA), np.full(3, 0.03), 0.1]
        x = motion.at(motion.t, self.scale)[0]
        R, P, beta = _pose(y)
        E = rotation_path((x[3:6], np.zeros(3), np.zeros(3)), np.eye(3))[0]
        self.R0, self.P0, self.beta0 = E.T @ R, P - x[:3], beta - x[6]

    def at(self, t):
        x, xd, xdd = self.motion.at(t, self.scale)
        R, w, wd = rotation_path((x[3:6], xd[3:6], xdd[3:6]), self.R0)
        return (hx.task_vector(R, self.P0 + x[:3], self.beta0 + x[6]), np.r_[xd[:3], w, xd[6]],
                np.r_[xdd[:3], wd, xdd[6]])


@examples(100)
@given(hexapod_designs(), unit_box(7), unit_box(7), branch_sets)
def test_inverse_then_forward_kinematics_gives_the_pose_back(p, u, du, branches):
    """Closed-form IK on any elbow branch per leg, then the paper's semi-closed forward kinematics (eqs. 4-13)
    seeded with a nearby pose, and the core's loop closure seeded with a nearby assembly: both give back the
    pose and beta (1e-9 m, rad; near a singularity, what a residual of 1e-12 allows), in both layouts.

    The seeds are 0.05 of the pose offsets away, less near a direct singularity (:func:`seed_fraction`).
    """
    mech, y, qa, q = _case(p, u, branches, margin=1e-4)
    tol = round_trip_tolerance(mech, q)
    task = TaskMap(mech)
    near = hexapod_pose(p, u + 0.05 * seed_fraction(mech, q, p.LA) * du)
    y_fk = hx.closed_form_fk(p, qa, seed=near)
    assert record("hexapod IK->FK (semi-closed, eqs. 4-13)", np.abs(task.error(y, y_fk)).max()) <= tol
    res = close_loops(mech, qa, reachable(hx.closed_form_configuration, mech, near, branches))
    assert record("hexapod IK->close_loops", np.abs(task.error(y, task.value(res.q))).max()) <= tol


@examples(60)
@given(hexapod_designs(layout="sector"), unit_box(7), branch_sets)
def test_jacobians_match_finite_differences(p, u, branches):
    """The screw twist Jacobian (J_x^T DELTA)^-1 [J_q, J'_q] (eqs. 22-25) equals the core's twist Jacobian
    (1e-9) and Richardson differences of the semi-closed forward kinematics (1e-6); the core's forward and
    inverse Jacobians equal differences of its loop closure and of the closed-form IK (1e-6)."""
    mech, y, qa, q = _case(p, u, branches)
    R, P, beta = _pose(y)
    J = hs.jacobians(p, R, P, beta, branches).twist_jacobian("P")  # [w; v_P] per actuated rate
    Jt = pkm.twist_jacobian(mech, q)  # [v_P; w]
    assert record("hexapod screw J vs core (rel)", fd.rel(J, np.vstack([Jt[3:], Jt[:3]]))) <= 1e-9

    def diff(h):
        cols = []
        for e in h * np.eye(7):
            (Rp, Pp, _), (Rm, Pm, _) = (_pose(hx.closed_form_fk(p, qa + sg * e, seed=y)) for sg in (1, -1))
            cols.append(np.r_[pin.log3(Rp @ Rm.T), Pp - Pm] / (2 * h))
        return np.column_stack(cols)

    assert record("hexapod screw J vs FD of FK (rel)", fd.rel(J, fd.richardson(diff, 1e-5))) <= 1e-6
    assert record("hexapod core forward J vs FD (rel)", fd.forward_jacobian_error(mech, q)) <= 1e-6
    ik = lambda yy: qa + wrap(hx.closed_form_ik(p, yy, branches) - qa)
    assert record("hexapod core inverse J vs FD (rel)", fd.inverse_jacobian_error(mech, q, ik)) <= 1e-6


@examples(48)
@given(hexapod_designs(layout="sector"), unit_box(7), branch_sets, sines(7), st.integers(0, 2**32 - 1))
def test_accelerations_match_the_motion_and_differences_of_velocities(p, u, branches, motion, seed):
    """Along a random smooth motion of the pose and beta (sums of sines), with the actuated rates and
    accelerations from the core's inverse kinematics of velocity and acceleration: the screw twist (eq. 22)
    and reduced acceleration (eq. 33, Lie screws) are the motion's own (1e-9); the core's velocities and
    accelerations are the derivatives of the closed-form configuration and of the velocities (1e-6); along
    an actuated parabola, the core's forward accelerations are those of its loop closure (1e-6)."""
    mech, y, _, q0 = _case(p, u, branches)
    m = _Motion(p, y, motion)

    def state(t):
        return path_state(mech, lambda yy: hx.closed_form_configuration(mech, yy, branches), m.at, t)

    t = motion.t
    _, v, a = state(t)
    yt, yd, ydd = m.at(t)
    R, P, beta = _pose(yt)
    w, vP, wd, aP = yd[3:6], yd[:3], ydd[3:6], ydd[:3]
    vO = vP - np.cross(w, P)  # velocity of the platform point at O
    aO = aP - np.cross(wd, P) - np.cross(w, np.cross(w, P))
    qd, qdd = v[mech.act_v], a[mech.act_v]
    V, A = hs.twist(p, R, P, beta, qd, branches), hs.acceleration(p, R, P, beta, qd, qdd, branches)
    V_ref, A_ref = np.r_[w, vO], np.r_[wd, aO - np.cross(w, vO)]
    # relative to the motion, or to the scale of what the actuated rates give (moving beta alone, the arms can
    # keep the platform still)
    err_v = np.linalg.norm(V - V_ref) / max(np.linalg.norm(V_ref), p.LA * np.linalg.norm(qd), 1e-300)
    err_a = np.linalg.norm(A - A_ref) / max(np.linalg.norm(A_ref), p.LA * (np.linalg.norm(qdd) + qd @ qd), 1e-300)
    assert record("hexapod screw twist vs motion (rel)", err_v) <= 1e-9
    assert record("hexapod screw acceleration vs motion (rel)", err_a) <= 1e-9
    ev, ea = path_derivative_errors(mech, state, t)
    assert record("hexapod inverse velocities vs FD (rel)", ev) <= 1e-6
    assert record("hexapod inverse accelerations vs FD (rel)", ea) <= 1e-6
    err = forward_acceleration_errors(mech, q0, seed)
    assert record("hexapod forward accelerations vs FD (rel)", err["joint"]) <= 1e-6
    assert record("hexapod task accelerations vs FD (rel)", err["task"]) <= 1e-6


@st.composite
def _lengths(draw):
    """Table 1's lengths scaled by a random factor (0.5-2) and each perturbed by up to 10 %."""
    T, lam = hx.HexapodParams(), draw(floats(0.5, 2.0))
    return {k: lam * getattr(T, k) * draw(floats(0.9, 1.1)) for k in ("Rf", "Rr", "R2", "LA", "LB", "h", "r")}


def _thetas(first, offset):
    """Legs 1-3 at ``first`` + 0, 120, 240 deg and legs 4-6 turned by ``offset`` from them [rad]."""
    t = [first + k * 2.0 * math.pi / 3.0 for k in range(3)]
    return tuple(t + [x + offset for x in t])


@examples(40)
@given(_lengths(), floats(0.0, 2.0 * math.pi), st.sampled_from([-1, 1]), floats(5.0, 20.0), floats(-0.3, 0.3),
       st.sampled_from(sorted(hx.BRANCHES)), floats(0.2, 0.5))
def test_stretched_legs_of_m1_are_approached_as_an_inverse_singularity(L, first, side, offset, beta, branch, s_max):
    """Fig. 4a: the platform turned to face legs 1-3 (C_1..C_3 in their leg planes) and lowered until the rod
    LB of each makes the angle s with its arm LA, s -> 0: the closed-form transmission of legs 1-3 equals
    |sin s| (1e-9, down to s = 1e-4 s_max: below, the pose fixes the arm angle only to sqrt(eps)); the core's
    sigma_inverse, on the exact configuration, falls monotonically and linearly to 1e-8 of its start; the
    class is regular at s_max, and inverse with legs (1, 2, 3) at s = 1e-8 s_max and at s = 0 (classify with
    its 1e-6 threshold, and the core)."""
    R = rot_y(-first)
    x = L["r"] - (L["Rf"] + L["Rr"] * math.cos(beta))  # radial offset of C_i from A_i in legs 1-3
    sign = hx.BRANCHES[branch]  # the sign of knee_i
    depth = L["Rr"] * math.sin(beta) + two_link_reach(L["LA"], L["LB"], sign * s_max, x)[1] - L["h"]  # of P
    # H0 such that legs 4-6 reach C_4..C_6 with |C - A|^2 = LA^2 + LB^2 (elbow at right angles)
    theta = _thetas(first, side * offset * DEG)
    horiz = np.hypot(L["r"] * math.cos(first) - L["R2"] * math.cos(theta[3]),
                     L["r"] * math.sin(first) - L["R2"] * math.sin(theta[3]))
    assume(horiz**2 < L["LA"] ** 2 + L["LB"] ** 2)
    H0 = -math.sqrt(L["LA"] ** 2 + L["LB"] ** 2 - horiz**2) - depth
    p = reachable(hx.HexapodParams, **L, H0=H0, theta=theta, home_rotation=tuple(R.ravel()),
                  home_position=(0.0, depth, 0.0), home_beta=beta)
    mech = reachable(hx.build, p)
    index_cf, index_core = [], []
    for k, s in enumerate([*(sign * s_max * DECADES), 0.0]):
        alpha, rel_y = two_link_reach(p.LA, p.LB, s, x)
        P = np.array([0.0, p.Rr * math.sin(beta) + rel_y - p.h, 0.0])
        values = reachable(hx.joint_values, p, R, P, beta, branch)
        for n in (1, 2, 3):  # exact: no inverse kinematics near the double root
            values |= {f"alpha_{n}": [float(wrap(alpha - beta))], f"knee_{n}": [s], f"knee_{n}_b": [0.0]}
        q = mech.q_from_dict(values)
        assert np.abs(constraints.residual(mech, q)).max() <= 1e-12 * p.LB
        rep = hsg.classify(p, R, P, beta, branch)
        diag = pkm.diagnose(mech, q)
        if k <= 4:
            assert np.abs(rep.transmission[:3] - abs(math.sin(s))).max() <= 1e-9
        index_cf.append(rep.transmission[:3].max())
        index_core.append(diag.sigma_inverse)
        if k == 0:
            assume(rep.kind == "regular" == diag.classification)
        if k >= 8:
            assert rep.kind == "inverse" and rep.inverse_legs == (1, 2, 3), (s, rep)
            assert diag.classification == "inverse", (s, diag)
    assert_vanishes(index_cf[:5], "hexapod stretched M1 legs, closed form (to s = 1e-4 s_max)", final=2e-4)
    assert_vanishes(index_core[:-1], "hexapod stretched M1 legs, core sigma_inverse")


@examples(40)
@given(_lengths(), floats(0.0, 2.0 * math.pi), st.sampled_from([-1, 1]), floats(5.0, 20.0), floats(-0.3, 0.3),
       st.sampled_from([-1, 1]), floats(0.05, 0.15))
def test_concurrent_rods_of_m2_are_approached_as_a_direct_singularity(L, first, side, offset, beta, sign, s_max):
    """Fig. 5: with R2 = r + LB, the arms of legs 4-6 pointing straight down and the platform facing them, the
    rods of M2 are horizontal, coplanar and meet at P; turning the platform about Y by s away from it, s -> 0:
    the closed-form sigma_direct and sigma_m2 (homogenised J_x) and the core's sigma_direct fall monotonically
    and linearly to 1e-8 of their start; the class is regular at s_max and direct at s = 1e-8 s_max and at
    s = 0 (closed form and core)."""
    L = L | {"R2": L["r"] + L["LB"]}
    theta = _thetas(first + side * offset * DEG, -side * offset * DEG)  # legs 4-6 at first + 0, 120, 240 deg
    # H0 such that legs 1-3 reach C_1..C_3 with |C - A|^2 = LA^2 + LB^2
    a_r = L["Rf"] + L["Rr"] * math.cos(beta)
    horiz = np.hypot(L["r"] * math.cos(first) - a_r * math.cos(theta[0]),
                     L["r"] * math.sin(first) - a_r * math.sin(theta[0]))
    assume(horiz**2 < L["LA"] ** 2 + L["LB"] ** 2)
    H0 = math.sqrt(L["LA"] ** 2 + L["LB"] ** 2 - horiz**2) - L["LA"] + L["h"] - L["Rr"] * math.sin(beta)
    P = np.array([0.0, -H0 - L["LA"], 0.0])
    p = reachable(hx.HexapodParams, **L, H0=H0, theta=theta, home_rotation=tuple(rot_y(-first - sign * s_max).ravel()),
                  home_position=tuple(P), home_beta=beta)
    mech = reachable(hx.build, p)
    index = {"cf": [], "m2": [], "core": []}
    for k, s in enumerate([*(sign * s_max * DECADES), 0.0]):
        R = rot_y(-(first + s))
        q = reachable(hx.configuration, mech, hx.task_vector(R, P, beta))
        rep = hsg.classify(p, R, P, beta)
        diag = pkm.diagnose(mech, q)
        for key, val in (("cf", rep.sigma_direct), ("m2", rep.sigma_m2), ("core", diag.sigma_direct)):
            index[key].append(val)
        if k == 0:
            assume(rep.kind == "regular" == diag.classification)
        if k >= 8:
            assert rep.kind == "direct" and rep.inverse_legs == (), (s, rep)
            assert diag.classification == "direct", (s, diag)
    assert np.abs(hx.inverse_kinematics(p, R, P, beta)[3:] + math.pi / 2).max() <= 1e-9  # arms 4-6 straight down
    assert_vanishes(index["cf"][:-1], "hexapod concurrent M2 rods, closed form sigma_direct")
    assert_vanishes(index["m2"][:-1], "hexapod concurrent M2 rods, closed form sigma_m2")
    assert_vanishes(index["core"][:-1], "hexapod concurrent M2 rods, core sigma_direct")


@examples(48)
@given(hexapod_designs(), unit_box(7), branch_sets, sines(7))
def test_power_balance_along_random_motions(p, u, branches, motion):
    """Along a random smooth motion of the pose and beta, the virtual-work efforts G^T rnea have the power
    sum tau_i qd_i equal to the rate of change of the bodies' energy (1e-8 of the gross power). (Khalil's
    projection does not take the hexapod: Pinocchio's constraint routines refuse its mimic joints.)"""
    mech, y, _, _ = _case(p, u, branches)
    m = _Motion(p, y, motion)

    def state(t):
        return path_state(mech, lambda yy: hx.closed_form_configuration(mech, yy, branches), m.at, t)

    efforts = lambda q, v, a: virtual_work_dynamics(mech, q, v, a)
    err = power_balance_error(mech, state, efforts, motion.t)
    assert record("hexapod power balance (rel. to gross power)", err) <= 1e-8
