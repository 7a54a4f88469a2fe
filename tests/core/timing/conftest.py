"""A short Delta path shared by the timing tests (its coefficients computed once)."""

from __future__ import annotations

from pathlib import Path

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


ANKLE = Path(__file__).resolve().parents[3] / "examples" / "humanoid_ankle" / "ankle.closures.toml"
#: A pitch of 0.8 rad (its range +-0.6) on the humanoid ankle, the motors taken to 1.047 and 1.032 rad (range +-1).
PITCH = np.array([[0.0, 0.0], [0.4, 0.0], [0.8, 0.0]])


@pytest.fixture(scope="module")
def ankle():
    """The humanoid ankle (MJCF), whose file states position limits for its motors, pitch and roll."""
    import pkm

    return pkm.load(ANKLE)
