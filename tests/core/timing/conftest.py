"""A short Delta path shared by the timing tests (its coefficients computed once)."""

from __future__ import annotations

import numpy as np
import pytest

from pkm.core.timing import path_coefficients, waypoint_path

ARC = np.array([[-0.1, 0.0, -0.36], [-0.05, 0.02, -0.33], [0.05, 0.02, -0.33], [0.1, 0.0, -0.36]])


@pytest.fixture(scope="module")
def delta(built):
    return built("delta")


@pytest.fixture(scope="module")
def arc(delta):
    """``(path, coefficients)`` of the arc on 21 points, by the core."""
    path = waypoint_path(delta, ARC)
    return path, path_coefficients(delta, path, np.linspace(0.0, 1.0, 21))
