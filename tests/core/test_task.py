"""pkm.core.task: Z-Y-X angles, rotation checks, the task map's retract/error pair."""

from __future__ import annotations

import numpy as np
import pytest

from pkm.core.task import TaskMap, as_rotation, zyx_angles, zyx_matrix
from pkm.errors import InvalidInputError


def test_zyx_angles_and_matrix_are_inverse():
    rng = np.random.default_rng(0)
    for _ in range(50):
        rpy = rng.uniform([-3.0, -1.5, -3.0], [3.0, 1.5, 3.0])
        np.testing.assert_allclose(zyx_angles(zyx_matrix(*rpy)), rpy, atol=1e-12)


def test_as_rotation_projects_printed_matrices_and_refuses_others():
    R = zyx_matrix(0.3, -0.2, 0.1)
    printed = np.round(R, 4)
    P = as_rotation(printed)
    np.testing.assert_allclose(P.T @ P, np.eye(3), atol=1e-14)
    assert np.abs(P - R).max() < 1e-4
    with pytest.raises(InvalidInputError, match="det R"):
        as_rotation(-R)
    with pytest.raises(InvalidInputError):
        as_rotation(2.0 * R)


@pytest.mark.parametrize("name", ["fivebar", "rrr3", "hexapod"])
def test_retract_and_error_are_inverse(name, built):
    """error(y, retract(y, d)) = d for small tangent steps (1e-10), positions, angles and joint outputs alike."""
    mech = built(name)
    task = TaskMap(mech)
    y = task.value(mech.q_reference)
    rng = np.random.default_rng(1)
    for _ in range(10):
        d = 0.05 * rng.standard_normal(task.size)
        np.testing.assert_allclose(task.error(task.retract(y, d), y), d, atol=1e-10)
