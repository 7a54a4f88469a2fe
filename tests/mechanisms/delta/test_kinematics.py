"""Delta: the paper's sphere-intersection forward kinematics (eqs. 1-8), both knee branches of the
inverse kinematics, and the closed-form Jacobian J = dX/dth (eq. 12), against the generic core.

The generic harness (tests/test_mechanisms_generic.py) already checks knee out against the core;
these tests add the second root of the forward problem, knee in and mixed branches, and the
Jacobian.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import pkm
from pkm.core import TaskMap, close_loops, solve_ik
from pkm.core.kinematics import constraints
from pkm.errors import AssemblyError, InvalidInputError, SingularityError, UnreachableError
from pkm.mechanisms import delta as D
from tests import fd

P = D.DeltaParams()
BRANCH_SETS = ["knee_out", "knee_in", ("knee_out", "knee_in", "knee_out"), ("knee_in", "knee_in", "knee_out")]


@pytest.fixture(scope="module")
def mech():
    return D.build(P)


def _poses(n, seed=0, scale=0.06, centre=(0.0, 0.0, -0.33)):
    """n reachable platform centres drawn uniformly in a cube of half-side ``scale`` [m] about ``centre`` [m]."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        p = np.array(centre) + rng.uniform(-scale, scale, 3)
        try:
            D.inverse_kinematics(P, p)
        except UnreachableError:
            continue
        out.append(p)
    return out


def _fk_jacobian_fd(theta, root):
    """Richardson central differences of the paper's forward kinematics (root 0: lower, 1: upper)."""
    def diff(h):
        return np.column_stack([(D.forward_kinematics(P, theta + e, both=True)[root]
                                 - D.forward_kinematics(P, theta - e, both=True)[root]) / (2 * h)
                                for e in h * np.eye(3)])
    return fd.richardson(diff, 1e-5)


def test_defaults_are_the_papers_table_1():
    """La = 110, Lb = 330, r = 50 mm, R = 150 mm (Fig. 4); the reference pose is found, not stated."""
    assert (P.La, P.Lb, P.r, P.R, P.home) == (0.110, 0.330, 0.050, 0.150, None)


def test_sphere_centres_are_eqs_4_6_7_as_printed():
    """B'_1, B'_2, B'_3 equal eqs. (4), (6), (7) transcribed from the paper, to 1e-15 m."""
    th = np.array([-0.7, -0.9, -1.1])
    Y = P.R + P.La * np.cos(th) - P.r
    Z = P.La * np.sin(th)
    s3 = math.sqrt(3.0) / 2.0
    printed = np.array([[0.0, Y[0], Z[0]], [-s3 * Y[1], -0.5 * Y[1], Z[1]], [s3 * Y[2], -0.5 * Y[2], Z[2]]])
    np.testing.assert_allclose(D.sphere_centres(P, th), printed, atol=1e-15)


@pytest.mark.parametrize("branch", BRANCH_SETS, ids=str)
def test_both_roots_of_eq_8_lie_on_the_three_spheres(branch):
    """Both roots returned by the forward kinematics satisfy (8a)-(8c) to 1e-12 m^2; the lower one is the pose."""
    for p in _poses(20, seed=1):
        th = D.inverse_kinematics(P, p, branch)
        roots = D.forward_kinematics(P, th, both=True)
        c = D.sphere_centres(P, th)
        for x in roots:
            assert np.abs(np.sum((x - c) ** 2, axis=1) - P.Lb**2).max() <= 1e-12
        assert roots[0, 2] <= roots[1, 2]
        np.testing.assert_allclose(roots[0], p, atol=1e-12)
        np.testing.assert_allclose(D.forward_kinematics(P, th), p, atol=1e-12)


def test_upper_root_is_an_assembly_the_core_accepts(mech):
    """The upper root is a real assembly: some branch per arm gives the motors back (1e-12 rad), and
    the tree configuration built from it closes every loop to 1e-10 and stays there under the core's
    loop closure."""
    for p in _poses(10, seed=2):
        th = D.inverse_kinematics(P, p)
        up = D.forward_kinematics(P, th, both=True)[1]
        match = [b for b in [(a, b, c) for a in D.BRANCHES for b in D.BRANCHES for c in D.BRANCHES]
                 if np.abs(D.inverse_kinematics(P, up, b) - th).max() <= 1e-12]
        assert match, f"no branch reproduces the motors at the upper root {up}"
        q = D.configuration(mech, up, match[0])
        assert np.abs(constraints.residual(mech, q)).max() <= 1e-10
        res = close_loops(mech, th, q)
        np.testing.assert_allclose(TaskMap(mech).value(res.q), up, atol=1e-10)


@pytest.mark.parametrize("branch", BRANCH_SETS, ids=str)
def test_closed_form_configurations_close_the_loops_on_every_branch(mech, branch):
    """The closed-form configuration of any branch combination closes the loops to 1e-10 and has the
    knee signs of the spec (knee out: knee_i < 0)."""
    branches = (branch,) * 3 if isinstance(branch, str) else branch
    for p in _poses(20, seed=3):
        q = D.configuration(mech, p, branch)
        assert np.abs(constraints.residual(mech, q)).max() <= 1e-10
        knees = [mech.q_to_dict(q)[f"knee_{n}"] for n in (1, 2, 3)]
        assert all(np.sign(k) == mech.spec.branches[b].signs[f"knee_{n}"]
                   for n, (k, b) in enumerate(zip(knees, branches), start=1))


def test_knee_in_inverse_kinematics_equals_the_generic_solver(mech):
    """On knee in, the generic inverse kinematics (seeded on knee in) equals the closed form to 1e-9 rad, and
    the generic loop closure from a nearby knee-in assembly equals the paper's forward kinematics to 1e-9 m.

    The poses are about (0, 0, -0.35) m: on the axis, knee in has three vertical forearms (a direct
    singularity) at z = -Lb +- sqrt(La^2 - (R - r)^2), -0.376 m (next to the reference pose) and -0.284 m,
    and its motor angles cross +-180 deg near z = -0.33 m, where a straight path in wrapped motor angles
    would go the long way round.
    """
    seed_q = D.configuration(mech, [0.0, 0.0, -0.35], "knee_in")
    for p in _poses(5, seed=4, scale=0.012, centre=(0.0, 0.0, -0.35)):
        th = D.inverse_kinematics(P, p, "knee_in")
        res = solve_ik(mech, p, seed_q, branch="knee_in")
        assert res.converged
        assert np.abs(mech.actuated_q(res.q) - th).max() <= 1e-9
        fk = close_loops(mech, th, seed_q)
        np.testing.assert_allclose(TaskMap(mech).value(fk.q), D.forward_kinematics(P, th), atol=1e-9)


@pytest.mark.parametrize("branch", BRANCH_SETS, ids=str)
def test_jacobian_matches_finite_differences_and_the_core(mech, branch):
    """J = A^-1 diag(d) equals Richardson differences of the paper's forward kinematics and the core's
    forward Jacobian, both to 1e-6 relative."""
    for p in _poses(8, seed=5):
        th = D.inverse_kinematics(P, p, branch)
        J = D.jacobian(P, th)
        assert fd.rel(J, _fk_jacobian_fd(th, 0)) <= 1e-6
        assert fd.rel(J, pkm.forward_jacobian(mech, D.configuration(mech, p, branch))) <= 1e-6


def test_jacobian_at_the_upper_root_matches_its_differences():
    """Given the upper root, the Jacobian is that assembly's (1e-6 relative to differences of the upper root)."""
    for p in _poses(5, seed=6):
        th = D.inverse_kinematics(P, p)
        up = D.forward_kinematics(P, th, both=True)[1]
        assert fd.rel(D.jacobian(P, th, up), _fk_jacobian_fd(th, 1)) <= 1e-6


def test_jacobian_refuses_a_pose_not_assembled_with_the_motors():
    """A platform point 1 mm off the assembly is refused with the forearm that does not fit."""
    home = D.reference_pose(P)
    th = D.inverse_kinematics(P, home)
    with pytest.raises(InvalidInputError, match="forearm"):
        D.jacobian(P, th, home + [0.0, 0.0, 1e-3])


def test_jacobian_raises_at_the_knee_in_direct_singularity():
    """Knee in with three vertical forearms (R = r + sqrt(La^2 - (z + Lb)^2) at the axis pose) is a direct
    singularity: the Jacobian raises SingularityError of kind 'direct'."""
    z = -0.375
    R_s = P.r + math.sqrt(P.La**2 - (z + P.Lb) ** 2)
    design = D.DeltaParams(R=R_s, home=(0.0, 0.0, z))
    th = D.inverse_kinematics(design, design.home, "knee_in")
    with pytest.raises(SingularityError) as info:
        D.jacobian(design, th, design.home)
    assert info.value.kind == "direct"


def test_unreachable_pose_names_the_arm_and_the_shortfall():
    """Too deep on the axis, every arm misses by |(R - r, z)| - (La + Lb) and arm 1 is named; far out
    on arm 1's side, arm 1 reaches and arm 2, the first that misses, is named."""
    z = -0.5
    with pytest.raises(UnreachableError) as info:
        D.inverse_kinematics(P, [0.0, 0.0, z])
    assert info.value.leg == 1
    assert info.value.excess == pytest.approx(math.hypot(P.R - P.r, z) - P.La - P.Lb, abs=1e-12)
    with pytest.raises(UnreachableError) as info:
        D.inverse_kinematics(P, [0.0, 0.30, -0.30])
    assert info.value.leg == 2 and info.value.excess > 0.0


def test_bad_inputs_raise_pkm_errors():
    """Wrong shapes, non-finite values and unknown branches are InvalidInputError; motor angles whose
    spheres do not meet are AssemblyError."""
    with pytest.raises(InvalidInputError):
        D.inverse_kinematics(P, [0.0, 0.0])
    with pytest.raises(InvalidInputError):
        D.jacobian(P, [0.0, np.nan, 0.0])
    with pytest.raises(InvalidInputError):
        D.inverse_kinematics(P, D.reference_pose(P), "elbow_up")
    short = D.DeltaParams(La=0.2, Lb=0.15, home=(0.0, 0.0, -0.25))  # forearms too short to join level arms
    with pytest.raises(AssemblyError):
        D.forward_kinematics(short, [0.0, 0.0, 0.0])
