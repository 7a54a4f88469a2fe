"""Condition numbers, manipulability and homogenisation of Jacobians."""

import numpy as np
import pytest

from pkm.core.differential import indices
from pkm.errors import InvalidInputError


def test_condition_numbers_of_a_diagonal_matrix_follow_their_definitions():
    """diag(1, 2, 4): kappa_2 = 4, ||J||_F ||J^-1||_F = sqrt(21) sqrt(21/16) = 5.25, normalised 1.75."""
    J = np.diag([1.0, 2.0, 4.0])
    assert indices.condition_number(J, "2") == pytest.approx(4.0)
    assert indices.condition_number(J, "fro") == pytest.approx(5.25)
    assert indices.condition_number(J, "fro_normalized") == pytest.approx(1.75)
    assert indices.inverse_condition(J) == pytest.approx(0.25)
    assert indices.manipulability(J) == pytest.approx(8.0)


def test_condition_numbers_are_invariant_under_rotations_and_vectorised():
    """Orthogonal factors leave every kind unchanged; a stack gives one value per matrix, inf where singular."""
    rng = np.random.default_rng(0)
    J = rng.normal(size=(4, 4))
    Q1, _ = np.linalg.qr(rng.normal(size=(4, 4)))
    Q2, _ = np.linalg.qr(rng.normal(size=(4, 4)))
    stack = np.stack([J, Q1 @ J @ Q2, np.zeros((4, 4))])
    for kind in indices.KINDS:
        k = indices.condition_number(stack, kind)
        assert k.shape == (3,)
        assert k[1] == pytest.approx(k[0], rel=1e-10)
        assert np.isinf(k[2])
        assert indices.condition_number(J, kind) == pytest.approx(k[0], rel=1e-12)
    assert indices.condition_number(J, "fro") == pytest.approx(
        np.linalg.norm(J) * np.linalg.norm(np.linalg.inv(J)), rel=1e-10)


def test_homogenize_scales_the_angular_rows_only():
    """Rows named as angular are multiplied by the characteristic length; the input is untouched."""
    J = np.ones((3, 3))
    H = indices.homogenize(J, [2], 0.5)
    assert np.array_equal(H[:2], J[:2]) and np.allclose(H[2], 0.5) and np.all(J == 1.0)


@pytest.mark.parametrize("bad, kind", [(np.ones(3), "2"), (np.full((2, 2), np.nan), "2"), (np.eye(2), "max"),
                                       (np.ones((2, 3)), "fro")])
def test_bad_jacobians_and_kinds_raise(bad, kind):
    """Vectors, non-finite entries, unknown kinds and non-square Frobenius requests are refused."""
    with pytest.raises(InvalidInputError):
        indices.condition_number(bad, kind)
    with pytest.raises(InvalidInputError):
        indices.homogenize(np.eye(2), [0], -1.0)


def test_singularity_class_names_the_four_cases():
    """One mapping for the core's diagnose, the 3-RRR and the hexapod (whose paper numbers the types 0-3)."""
    from pkm.mechanisms.hexapod.singularities import KINDS

    assert [indices.singularity_class(i, d) for d in (False, True) for i in (False, True)] == list(
        indices.SINGULARITY_CLASSES) == ["regular", "inverse", "direct", "combined"]
    assert KINDS == dict(enumerate(indices.SINGULARITY_CLASSES))


def test_several_kinds_from_one_decomposition_are_each_kind_s_own_bit_for_bit():
    """``condition_numbers(J, kinds)`` (one SVD) gives what ``condition_number(J, kind)`` gives a kind at a time,
    singular matrices (inf) included; a non-square stack takes the 2-norm kind only."""
    from pkm.core.differential.indices import KINDS, condition_number, condition_numbers
    rng = np.random.default_rng(3)
    J = rng.normal(size=(50, 3, 3))
    J[7] = np.diag([2.0, 1.0, 0.0])  # singular
    many = condition_numbers(J, KINDS)
    for kind in KINDS:
        assert np.array_equal(many[kind], condition_number(J, kind)), kind
    assert many["2"][7] == np.inf
    assert condition_numbers(J[:, :2], ("2",))["2"].shape == (50,)
    with pytest.raises(InvalidInputError, match="square"):
        condition_numbers(J[:, :2], ("fro",))


def _prescribed(rng, n, sigma):
    """Matrices ``U diag(sigma) V^T`` (random orthogonal U, V) with the singular values ``sigma`` (rows, largest first)."""
    U = np.linalg.qr(rng.normal(size=(n, 3, 3)))[0]
    V = np.linalg.qr(rng.normal(size=(n, 3, 3)))[0]
    return U * sigma[:, None, :] @ np.swapaxes(V, -1, -2)


def test_jacobi_singular_values_are_lapack_s(monkeypatch):
    """One-sided Jacobi against np.linalg.svd (LAPACK's bidiagonal route) and against prescribed singular values, on
    random 3x3, near-singular ones (sigma_min down to 1e-16), exactly singular ones, wide and tall stacks, over several
    blocks: every singular value within 10 eps sigma_max of both, and independent of the rest of the stack; K_2 through condition_numbers within 10 eps K
    relative; a matrix not converged within the allowed sweeps is LAPACK's, bit for bit."""
    eps = np.finfo(float).eps
    rng = np.random.default_rng(4)
    monkeypatch.setattr(indices, "JACOBI_BLOCK", 700)
    sigma = np.stack([np.ones(2000), 10 ** rng.uniform(-8, 0, 2000), 10 ** rng.uniform(-16, 0, 2000)], axis=-1)
    sigma = -np.sort(-sigma, axis=-1)
    near = _prescribed(rng, 2000, sigma)
    assert np.all(np.abs(indices.jacobi_singular_values(near) - sigma) <= 10 * eps)
    singular = rng.normal(size=(50, 3, 3))
    singular[:, :, 1] = 0.0
    cases = [rng.normal(size=(2000, 3, 3)), near, singular, rng.normal(size=(40, 2, 5)), rng.normal(size=(40, 6, 4)),
             rng.normal(size=(4, 5, 3, 3))]
    for J in cases:
        s, ref = indices.jacobi_singular_values(J), np.linalg.svd(J, compute_uv=False)
        assert s.shape == ref.shape
        assert np.all(np.abs(s - ref) <= 10 * eps * ref[..., :1])
    assert np.all(indices.jacobi_singular_values(singular)[:, -1] == 0.0)
    whole = indices.jacobi_singular_values(near)  # each matrix's values its own, whatever the others of its block
    assert np.array_equal(indices.jacobi_singular_values(near[350:1000]), whole[350:1000])
    J = cases[0] / np.max(np.abs(cases[0]), axis=(1, 2), keepdims=True)
    K, ref = (indices.condition_numbers(J, ("2",), method)["2"] for method in ("jacobi", "lapack"))
    assert np.all(np.abs(K / ref - 1.0) <= 10 * eps * ref)
    monkeypatch.setattr(indices, "JACOBI_SWEEPS", 1)
    assert np.array_equal(indices.jacobi_singular_values(J), np.linalg.svd(J, compute_uv=False))
    with pytest.raises(InvalidInputError, match="method"):
        indices.condition_numbers(J, ("2",), "qr")
