"""pkm.core.timing.limits: the command line's limits read with their units."""

from __future__ import annotations

import math

import numpy as np
import pytest

import pkm
from pkm.core.timing.limits import parse_limits
from pkm.errors import UnitError


def test_limits_take_the_units_every_joint_value_takes():
    """``peak=390 mN m,speed=300rpm,omega0=600deg/s`` are the SI numbers (0.39 N m, 10 pi and 10 pi / 3 rad/s:
    factors written out here), as ``--rates`` reads them; a position's unit for a speed is refused."""
    delta = pkm.load("delta")
    units = parse_limits(delta, "peak=390 mN m,speed=300rpm,omega0=600deg/s,acceleration=500")
    si = parse_limits(delta, f"peak=0.39,speed={10 * math.pi!r},omega0={10 * math.pi / 3!r},acceleration=500")
    for a, b in ((units.lines, si.lines), (units.speed, si.speed), (units.acceleration, si.acceleration)):
        assert np.allclose(a, b, rtol=1e-15, atol=0)
    with pytest.raises(UnitError, match=r"'deg' is an angle unit but speed is in \[rad/s\]"):
        parse_limits(delta, "speed=5deg")
