"""Manipulability indices w_rot, w_tras (paper eqs. 34-37) and condition numbers, against the generic core."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.differential import indices as core_indices
from pkm.errors import InvalidInputError
from pkm.mechanisms import hexapod as hx
from pkm.mechanisms.hexapod import indices as hi
from pkm.papers.hexapod import pose_T_placement

DEG = math.pi / 180.0


@pytest.fixture(scope="module")
def mech():
    return hx.build()


def core_indices_at(mech, R, P, beta, point):
    """w_rot, w_tras from the core's twist Jacobian (alpha columns, beta fixed), v at O or P."""
    q = hx.closed_form_configuration(mech, hx.task_vector(R, P, beta))
    Jt = pkm.twist_jacobian(mech, q)[:, :6]  # [v_P; w]
    Jv = Jt[:3] + pin.skew(P) @ Jt[3:] if point == "O" else Jt[:3]
    return core_indices.manipulability(Jt[3:]), core_indices.manipulability(Jv), Jt


@pytest.mark.parametrize("point", ["O", "P"])
def test_indices_equal_those_of_the_generic_core(mech, point):
    """w_rot, w_tras and kappa of the screw Jacobian (eq. 37) = the core's, for several beta (rel. 1e-9)."""
    p = mech.params
    R, P = pose_T_placement()
    for beta in (-45 * DEG, -11 * DEG, 20 * DEG, 70 * DEG):
        ind = hi.indices(p, R, P, beta, point=point)
        w_rot, w_tras, Jt = core_indices_at(mech, R, P, beta, point)
        assert math.isclose(ind.w_rot, w_rot, rel_tol=1e-9) and math.isclose(ind.w_tras, w_tras, rel_tol=1e-9)
        assert math.isclose(ind.kappa_rot, core_indices.condition_number(Jt[3:]), rel_tol=1e-9)
        batch = {idx: hi.PoseIndex(p, [(R, P)], idx, point=point)(np.zeros(1, int), np.array([beta]))[0]
                 for idx in hi.INDICES}
        assert math.isclose(batch["w_rot"], w_rot, rel_tol=1e-9) and math.isclose(batch["w_tras"], w_tras, rel_tol=1e-9)


def test_batch_index_over_poses_and_branches_matches_one_by_one(mech):
    """PoseIndex over (pose, beta) pairs equals indices() per configuration, elbow_in included (1e-10)."""
    p = mech.params
    rng = np.random.default_rng(0)
    R0, P0 = pose_T_placement()
    poses = [(pin.exp3(0.05 * rng.uniform(-1, 1, 3)) @ R0, P0 + 0.02 * rng.uniform(-1, 1, 3)) for _ in range(3)]
    k, betas = np.array([0, 1, 2, 1]), np.array([-0.3, 0.0, 0.5, 0.9])
    for branch in ("elbow_out", "elbow_in"):
        f = hi.PoseIndex(p, poses, "w_tras", branch)
        ref = [hi.indices(p, *poses[i], b, branch).w_tras for i, b in zip(k, betas)]
        assert np.allclose(f(k, betas), ref, rtol=1e-10)


def test_unreachable_betas_have_zero_index(mech):
    """Below the reachability limit of pose T (-59.5 deg) the batch index is 0; just above it, small."""
    p = mech.params
    f = hi.PoseIndex(p, [pose_T_placement()], "w_rot")
    v = f(np.zeros(3, int), np.radians([-70.0, -59.6, -59.4]))
    assert v[0] == v[1] == 0.0 and 0 < v[2] < 0.2 * f(np.zeros(1, int), np.radians([-11.0]))[0]


def test_bad_index_point_and_rotation_are_refused(mech):
    """Unknown index or point names and non-rotations raise InvalidInputError."""
    p = mech.params
    R, P = pose_T_placement()
    with pytest.raises(InvalidInputError):
        hi.PoseIndex(p, [(R, P)], "w_both")
    with pytest.raises(InvalidInputError):
        hi.indices(p, R, P, 0.0, point="Q")
    with pytest.raises(InvalidInputError, match=r"max\|R\^T R - I\| = 0\.21"):
        hi.PoseIndex(p, [(1.1 * R, P)])
