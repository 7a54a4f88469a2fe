"""The twin's spatial algebra on CasADi (:mod:`pkm.core.twin.spatial`) equals Pinocchio's SE3, Motion and Force
operations and logarithms at random arguments (Pinocchio as the independent route), and its Euler-angle rates equal
central differences of the angles along a rotation."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pinocchio as pin
import pytest

from pkm.core.twin import spatial as sp

TOL = 1e-14


def num(x) -> np.ndarray:
    """A CasADi DM (or SX of constants) as a numpy array, column vectors flattened."""
    a = np.array(cs.evalf(cs.SX(x)) if isinstance(x, cs.SX) else cs.DM(x))
    return a.ravel() if a.ndim == 2 and a.shape[1] == 1 else a


@pytest.fixture
def rng():
    pin.seed(5)
    return np.random.default_rng(5)


def test_placements_compose_and_invert_as_pinocchios(rng):
    """M N, M^-1 and the 6 x 6 motion action of random placements: Pinocchio's (1e-14)."""
    for _ in range(5):
        M, N = pin.SE3.Random(), pin.SE3.Random()
        S = sp.SE3.of(M) * sp.SE3.of(N)
        assert np.abs(num(S.R) - (M * N).rotation).max() <= TOL and np.abs(num(S.p) - (M * N).translation).max() <= TOL
        inv = sp.SE3.of(M).inverse()
        assert np.abs(num(inv.R) - M.inverse().rotation).max() <= TOL
        assert np.abs(num(inv.p) - M.inverse().translation).max() <= TOL
        assert np.abs(num(sp.SE3.of(M).action()) - M.action).max() <= TOL


def test_motions_and_forces_are_acted_on_as_pinocchios(rng):
    """Ad(M) m, Ad(M^-1) m, the dual action on a force, m x n and m x* f: Pinocchio's Motion/Force operations (1e-14
    relative)."""
    for _ in range(5):
        M, m, n, f = pin.SE3.Random(), pin.Motion.Random(), pin.Motion.Random(), pin.Force.Random()
        S, mv, nv, fv = sp.SE3.of(M), cs.DM(m.vector), cs.DM(n.vector), cs.DM(f.vector)
        pairs = [(S.act_motion(mv), M.act(m).vector), (S.inv_act_motion(mv), M.actInv(m).vector),
                 (S.act_force(fv), M.act(f).vector), (sp.motion_cross(mv, nv), m.cross(n).vector),
                 (sp.force_cross(mv, fv), m.cross(f).vector)]
        for got, want in pairs:
            assert np.abs(num(got) - want).max() <= TOL * max(1.0, np.abs(want).max())


def test_cross_skew_rodrigues_and_quaternions_are_the_textbook_ones(rng):
    """a x b and [a] b against numpy's cross; the rotation about an axis against pin.AngleAxis; a quaternion
    (x, y, z, w) against pin.Quaternion (1e-14)."""
    a, b = rng.normal(size=3), rng.normal(size=3)
    assert np.abs(num(sp.cross(cs.DM(a), cs.DM(b))) - np.cross(a, b)).max() <= TOL
    assert np.abs(num(sp.skew(cs.DM(a)) @ cs.DM(b)) - np.cross(a, b)).max() <= TOL
    axis, angle = a / np.linalg.norm(a), 2.3
    R = num(sp.rodrigues(axis, np.cos(angle), np.sin(angle)))
    assert np.abs(R - pin.AngleAxis(angle, axis).matrix()).max() <= TOL
    quat = rng.normal(size=4)
    quat /= np.linalg.norm(quat)
    assert np.abs(num(sp.quat_matrix(*quat)) - pin.Quaternion(quat).toRotationMatrix()).max() <= TOL


@pytest.mark.parametrize("angle", [0.0, 1e-9, 1e-5, 0.3, 2.0, 3.0])
def test_the_logarithms_are_pinocchios_down_to_the_identity(rng, angle):
    """log3 and log6 of a rotation by `angle` about a random axis, with a random translation: pin.log3/log6, through
    the series branches near the identity (1e-12)."""
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    M = pin.SE3(pin.AngleAxis(angle, axis).matrix(), rng.normal(size=3))
    assert np.abs(num(sp.log3(cs.DM(M.rotation))) - pin.log3(M.rotation)).max() <= 1e-12
    assert np.abs(num(sp.log6(sp.SE3.of(M))) - pin.log6(M).vector).max() <= 1e-12


def test_euler_angles_and_their_rates(rng):
    """zyx_angles against pin.rpy.matrixToRpy; euler_rates(R) w against central differences of the angles along the
    world rotation exp(w t) R (1e-8)."""
    for _ in range(4):
        rpy = rng.uniform(-1.2, 1.2, size=3)
        R = pin.rpy.rpyToMatrix(*rpy)
        assert np.abs(num(sp.zyx_angles(cs.DM(R))) - pin.rpy.matrixToRpy(R)).max() <= 1e-14
        w, h = rng.normal(size=3), 1e-6
        fd = (pin.rpy.matrixToRpy(pin.exp3(w * h) @ R) - pin.rpy.matrixToRpy(pin.exp3(-w * h) @ R)) / (2 * h)
        assert np.abs(num(sp.euler_rates(cs.DM(R)) @ cs.DM(w)) - fd).max() <= 1e-8 * max(1.0, np.abs(fd).max())
