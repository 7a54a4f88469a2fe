"""Delta workspace grids: the vectorised inverse kinematics and condition numbers against the
one-pose closed forms, and the workspace volume."""

from __future__ import annotations

import itertools
import math
import warnings

import numpy as np
import pytest

from pkm.core.differential.indices import KINDS, condition_number
from pkm.errors import InvalidInputError, UnreachableError
from pkm.mechanisms import delta as D
from pkm.mechanisms.delta.workspace import condition_numbers, inverse_kinematics_batch, workspace

P = D.DeltaParams()


@pytest.fixture(scope="module")
def cloud():
    """600 points in a box around the workspace, about half of them reachable."""
    rng = np.random.default_rng(0)
    return rng.uniform([-0.3, -0.3, -0.45], [0.3, 0.3, 0.0], (600, 3))


@pytest.mark.parametrize("branch", ["knee_out", "knee_in", ("knee_in", "knee_out", "knee_in")], ids=str)
def test_batch_inverse_kinematics_is_the_scalar_one(cloud, branch):
    """Reachable exactly where the scalar inverse kinematics does not raise, with the same angles to 1e-12 rad."""
    theta, reachable = inverse_kinematics_batch(P, cloud, branch)
    assert 0.2 < reachable.mean() < 0.8
    for p, th, ok in zip(cloud, theta, reachable):
        try:
            ref = D.inverse_kinematics(P, p, branch)
        except UnreachableError:
            assert not ok
            continue
        assert ok
        np.testing.assert_allclose(th, ref, atol=1e-12)


def test_points_near_the_float_range_reach_nothing_and_get_finite_angles():
    """Coordinates whose terms overflow (1.7e308 on two axes: their sum is inf, their difference NaN) are unreachable,
    their angles finite (0) as the docstring says, their condition numbers inf; no overflow warning."""
    far = np.array([[1.7e308, 1.7e308, -1.7e308], [-1.7e308, 1.7e308, 0.0], [1e308, 0.0, -0.3]])
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        theta, reachable = inverse_kinematics_batch(P, far)
        K, _ = condition_numbers(P, far)
    assert not reachable.any() and np.all(np.isfinite(theta))
    assert all(np.all(np.isinf(k)) for k in K.values())


def test_batch_condition_numbers_are_those_of_the_jacobian(cloud):
    """Each convention, computed on J^-1 = diag(d)^-1 A, equals pkm.core.differential.indices on the one-pose Jacobian
    (1e-9 relative); unreachable points are inf, never NaN."""
    K, reachable = condition_numbers(P, cloud, "knee_out")
    for kind in KINDS:
        assert not np.any(np.isnan(K[kind]))
        assert np.all(np.isinf(K[kind][~reachable]))
    for p in cloud[reachable][:60]:
        J = D.jacobian(P, D.inverse_kinematics(P, p), p)
        for kind in KINDS:
            k, = condition_numbers(P, p[None], "knee_out", (kind,))[0][kind]
            assert k == pytest.approx(condition_number(J, kind), rel=1e-9)
    assert np.all(K["fro"][reachable] >= 3.0 - 1e-12)
    np.testing.assert_allclose(K["fro_normalized"], K["fro"] / 3.0)


def test_workspace_volume_converges_with_the_grid():
    """The reachable volume below the base on 10 mm and 5 mm grids agrees within 1 %, and the 5 mm grid's
    nodes are reachable exactly where the scalar inverse kinematics succeeds (checked on 300 nodes)."""
    design = D.DeltaParams(R=0.2)
    coarse, fine = workspace(design, 0.010, kinds=("2",)), workspace(design, 0.005, kinds=("2",))
    assert fine.volume == pytest.approx(coarse.volume, rel=0.01)
    rng = np.random.default_rng(1)
    idx = [rng.integers(0, n, 300) for n in fine.reachable.shape]
    for i, j, k in zip(*idx):
        p = [fine.axes[0][i], fine.axes[1][j], fine.axes[2][k]]
        try:
            D.inverse_kinematics(design, p)
            reached = True
        except UnreachableError:
            reached = False
        assert reached == fine.reachable[i, j, k]


@pytest.mark.parametrize("chunk, design", [(1, P), (1000, P), (1 << 20, P),
                                           (1000, D.DeltaParams(La=0.3, Lb=0.12, R=0.25, r=0.03))])
def test_workspace_grid_is_the_batch_of_every_node(monkeypatch, chunk, design):
    """The grid, computed on the vertical lines that may reach, in chunks of z slices (one slice, several with a
    partial last, all at once), reachable nodes first: its mask and K are those of :func:`condition_numbers` on every
    node of the grid at once (Jacobi rotations), bit for bit, and those of LAPACK's SVD within 10 eps K relative (the
    paper's proportions, and long arms on short forearms)."""
    import pkm.mechanisms.delta.workspace as W

    monkeypatch.setattr(W, "CHUNK_NODES", chunk)
    grid = workspace(design, 0.04 * (design.La + design.Lb) / (P.La + P.Lb))
    nodes = np.stack(np.meshgrid(*grid.axes, indexing="ij"), axis=-1)
    K, reachable = condition_numbers(design, nodes, method="jacobi")
    lapack, _ = condition_numbers(design, nodes)
    assert 0.01 < reachable.mean() < 0.9
    np.testing.assert_array_equal(grid.reachable, reachable)
    for kind in KINDS:
        np.testing.assert_array_equal(grid.K[kind], K[kind])
        k, ref = K[kind][reachable], lapack[kind][reachable]
        assert np.all(np.abs(k / ref - 1.0) <= 10 * np.finfo(float).eps * ref)


def test_workspace_volumes_are_ordered_and_threefold_symmetric():
    """Conditioned volume <= volume, growing with the bound; the integral of 1/K <= volume; the mask is
    invariant under the 120 deg rotation of the base (up to nodes on the boundary: 0.5 %)."""
    grid = workspace(P, 0.012)
    v = [grid.conditioned_volume(k, "2") for k in (1.5, 3.0, 6.0, 1e9)]
    assert v == sorted(v) and v[-1] <= grid.volume
    assert 0.0 < grid.weighted_volume("2") < grid.volume
    x, y, z = np.meshgrid(*grid.axes, indexing="ij")
    c, s = math.cos(2 * math.pi / 3), math.sin(2 * math.pi / 3)
    pts = np.stack([c * x - s * y, s * x + c * y, z], axis=-1)[grid.reachable]
    _, rotated = inverse_kinematics_batch(P, pts)
    assert rotated.mean() >= 0.995


def test_workspace_shrinks_as_R_grows_over_the_papers_range():
    """Sec. 5: 'the larger R, the smaller the workspace' holds from 100 to 200 mm (12 mm grid, 25 mm steps)."""
    vols = [workspace(D.DeltaParams(R=R), 0.012, kinds=("2",)).volume for R in (0.100, 0.125, 0.150, 0.175, 0.200)]
    assert all(a > b for a, b in itertools.pairwise(vols))


def test_bad_grid_inputs_raise_pkm_errors():
    """Bad points, spacings, kinds and bounds are InvalidInputError; a grid of unreachable points is an
    explicit empty result (all unreachable, K = inf), not an error or a NaN."""
    with pytest.raises(InvalidInputError):
        inverse_kinematics_batch(P, np.zeros((4, 2)))
    with pytest.raises(InvalidInputError):
        condition_numbers(P, [[0.0, 0.0, np.nan]])
    with pytest.raises(InvalidInputError):
        condition_numbers(P, [[0.0, 0.0, -0.3]], kinds=("inf",))
    with pytest.raises(InvalidInputError, match="method"):  # (also where no point is reachable)
        condition_numbers(P, [[0.0, 0.0, -2.0]], method="qr")
    with pytest.raises(InvalidInputError):
        workspace(P, 0.0)
    grid = workspace(P, 0.11, kinds=("2",))
    with pytest.raises(InvalidInputError):
        grid.conditioned_volume(0.5)
    with pytest.raises(InvalidInputError):
        grid.weighted_volume("fro")
    K, reachable = condition_numbers(P, [[0.0, 0.0, -2.0], [1.0, 0.0, -0.3]])
    assert not reachable.any() and np.all(np.isinf(K["2"]))
