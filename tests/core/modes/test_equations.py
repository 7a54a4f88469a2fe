"""The reduced equations and their algebra, against independent routes: finite differences for the Jacobian, the
distances of the legs themselves for the Study-parameter spheres, a round trip for the parametrisations, the
shipped generic starts' residuals, Smale's test on a simple and a double root."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.modes.certify import ALPHA0, alpha_test
from pkm.core.modes.equations import FKSystem, equations, pose_from_study, study_from_pose
from pkm.core.modes.polynomial import System, fix, variables
from pkm.core.modes.reduce import reduce_mechanism
from pkm.core.modes.starts import _DIR, GenericStart
from pkm.errors import StructureError


def test_jacobian_and_hessians_are_derivatives():
    rng = np.random.default_rng(0)
    x = variables(3)
    p = [x[0] * x[1] * 2.0 + x[2] * x[2] - 1.5 * x[0] + 0.25, x[0] * x[0] * x[1] - x[2], x[1] - 3.0 + x[0] * x[2]]
    S = System(p)
    z = rng.normal(size=3) + 1j * rng.normal(size=3)
    h = 1e-6
    fd = np.column_stack([(S(z + h * e) - S(z - h * e)) / (2 * h) for e in np.eye(3)])
    assert np.abs(S.jacobian(z) - fd).max() < 1e-8
    Q = System([p[0], p[2]] + [x[0] * 1.0])
    H = Q.hessians()
    fdH = np.stack([(Q.jacobian(z + h * e) - Q.jacobian(z - h * e)) / (2 * h) for e in np.eye(3)], axis=-1)
    assert np.abs(H - fdH).max() < 1e-8
    with pytest.raises(ValueError):
        S.hessians()  # a cubic has no constant Hessian
    # a projective polynomial on a chart
    q = x[0] * x[1] + x[2] * x[2]
    assert q.homogeneous() and abs(fix(q, 2, 1.0)(np.array([2.0, 3.0])) - 7.0) < 1e-15


def test_study_spheres_are_the_legs_distances():
    """At random poses the Study-parameter sphere of each hexapod leg equals D (|R b + t - A|^2 - |r|^2) on the
    Study quadric (the equation divided by D, Husty's form), and the parameters round-trip to the pose."""
    mech = pkm.load("hexapod")
    red = reduce_mechanism(mech)
    d = mech.model.createData()
    pin.forwardKinematics(mech.model, d, mech.q_reference)
    system = FKSystem(red, d)
    S = System(system.polys)
    rng = np.random.default_rng(1)
    for _ in range(5):
        R = pin.Quaternion(*rng.normal(size=4)).normalized().toRotationMatrix()
        t = rng.normal(scale=0.3, size=3)
        x = study_from_pose(R, t) * rng.uniform(0.5, 2.0)  # any scale: homogeneous
        R2, t2 = pose_from_study(x)
        assert np.abs(R2 - R).max() < 1e-12 and np.abs(t2 - t).max() < 1e-12
        D = x[:4] @ x[:4]
        F = S(x).real
        assert abs(F[0]) < 1e-14 * D  # the Study quadric
        for k, leg in enumerate(red.legs, start=1):
            A, r, _ = leg.geometry(d)
            direct = np.sum((R @ leg.platform_point + t - A) ** 2) - r @ r
            assert abs(F[k] - D * direct) < 1e-12 * D


def test_planar_and_translational_systems_vanish_at_the_reference():
    for name, group in (("rrr3", "SE2"), ("delta", "T3"), ("prs3", "SE3")):
        mech = pkm.load(name)
        red = reduce_mechanism(mech)
        assert red.group == group
        d = mech.model.createData()
        pin.forwardKinematics(mech.model, d, mech.q_reference)
        system = FKSystem(red, d)
        x0 = system.encode(np.eye(3), np.zeros(3))
        assert np.abs(System(system.polys)(x0)).max() < 1e-12
        R, t = system.displacement(x0)
        assert np.abs(R - np.eye(3)).max() < 1e-14 and np.abs(t).max() < 1e-14


@pytest.mark.parametrize("path", sorted(_DIR.glob("*.json")), ids=lambda p: p.stem)
def test_shipped_generic_starts_solve_their_systems(path):
    """Every shipped start point solves its family at its generic parameters (residual 1e-8 of the point's size)
    and is a pose; the counts are the literature's (6 spheres: 40; 3-PRS: 16)."""
    start = GenericStart.from_json(path.read_text())
    group, kinds = start.signature.split(":")
    S = System(equations(group, start.params, variables(8)))
    for x in start.points:
        assert np.abs(S(x)).max() < 1e-8 * np.abs(x).max() ** 2
        assert np.linalg.norm(x[:4]) > 1e-6 * np.linalg.norm(x)
    assert start.complete and len(start.points) == {"ssssss": 40, "ccc": 16}[kinds]


def test_smales_test_certifies_a_simple_root_and_not_a_double_one():
    (x,) = variables(1)
    simple = System([x * x - 2.0])
    c = alpha_test(simple, np.array([np.sqrt(2.0) + 1e-9]))
    assert c.certified and c.alpha < ALPHA0 and c.radius >= 1e-9 * 0.99
    double = System([x * x])
    assert not alpha_test(double, np.array([1e-9])).certified
    far = alpha_test(simple, np.array([0.1]))
    assert not far.certified


def test_the_reduction_names_each_legs_kind_and_refuses_what_it_does_not_cover(built):
    """The shipped mechanisms' legs: spheres (RUS, UPS, the Delta's centre lines, planar RR) and circles (PRS); the
    toy five-bar (its tip is the closure itself, no platform) is a StructureError."""
    kinds = {name: [leg.kind for leg in reduce_mechanism(pkm.load(name)).legs]
             for name in ("hexapod", "delta", "rrr3", "prs3", "gough_stewart")}
    assert kinds == {"hexapod": ["sphere"] * 6, "delta": ["sphere"] * 3, "rrr3": ["sphere"] * 3,
                     "prs3": ["circle"] * 3, "gough_stewart": ["sphere"] * 6}
    with pytest.raises(StructureError, match="not covered"):
        reduce_mechanism(built("fivebar"))
