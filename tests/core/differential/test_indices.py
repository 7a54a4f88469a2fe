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
