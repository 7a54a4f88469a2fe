"""The design parameters of the Gough-Stewart platform (6-UPS; SI units, validated)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pkm.errors import InvalidParameterError
from pkm.mechanisms._common import check_nonnegative, check_positive, param

NAME = "gough_stewart"


def _hexagon(radius: float, centre_deg: tuple[float, ...], half_deg: float, z: float = 0.0):
    """Six points on a circle, in pairs ``centre +- half`` (a semi-regular hexagon)."""
    out = []
    for c in centre_deg:
        for s in (-1.0, 1.0):
            a = math.radians(c + s * half_deg)
            out.append((radius * math.cos(a), radius * math.sin(a), z))
    return tuple(out)


#: The default design: a 6-6 platform on semi-regular hexagons (base radius 0.5 m, platform radius 0.3 m, each
#: leg leaning the other way from its neighbour), as in most textbook Gough-Stewart platforms.
BASE = _hexagon(0.5, (0.0, 120.0, 240.0), 15.0)
PLATFORM = _hexagon(0.3, (0.0, 120.0, 240.0), 40.0)


def _points(obj, name: str) -> None:
    v = getattr(obj, name)
    try:
        arr = np.asarray(v, dtype=float)
    except (TypeError, ValueError, OverflowError):
        arr = np.zeros(0)
    if arr.size == 18:
        arr = arr.reshape(6, 3)
    if arr.shape != (6, 3) or not np.all(np.isfinite(arr)) or np.abs(arr).max() > 1e3:
        raise InvalidParameterError(name, f"must be six points [[x, y, z], ...] of finite coordinates in m, got {v!r}", v)
    object.__setattr__(obj, name, tuple(tuple(float(c) for c in row) for row in arr))


@dataclass(frozen=True)
class GoughStewartParams:
    """A 6-UPS Gough-Stewart platform.

    Attributes:
        base: The six universal joints' centres in the base frame [m] (``[[x, y, z], ...]``, leg order).
        platform: The six spherical joints' centres in the platform frame [m] (same order).
        leg_min: Shortest leg (universal to spherical centre) [m].
        leg_max: Longest leg [m].
        m_leg: Mass of each leg [kg], half in its cylinder (on the universal joint), half in its rod.
        m_platform: Platform mass [kg] (a uniform disc of the platform points' largest radius).
        cylinder_radius: Radius of each leg's cylinder [m]: its collision capsule, from the universal joint's centre
            ``leg_min / 2`` along the leg (:mod:`pkm.core.collision`).
        rod_radius: Radius of each leg's rod [m]: its collision capsule, from the ball joint's centre ``leg_min / 2``
            back along the leg.
        platform_thickness: Thickness of the platform [m]: its collision geometry, a disc of the platform points'
            largest radius centred on the platform frame.
        reference: The reference pose ``(x, y, z [m], roll, pitch, yaw [rad])``; None (default): the level platform
            above the base centre at the height where the mean leg is mid-stroke.
    """

    base: tuple[tuple[float, float, float], ...] = param(BASE, "m", length=6)
    platform: tuple[tuple[float, float, float], ...] = param(PLATFORM, "m", length=6)
    leg_min: float = param(0.5, "m")
    leg_max: float = param(1.0, "m")
    m_leg: float = param(1.0, "kg")
    m_platform: float = param(5.0, "kg")
    reference: tuple[float, float, float, float, float, float] | None = param(None, "m", "rad", length=6)
    cylinder_radius: float = param(0.03, "m")
    rod_radius: float = param(0.02, "m")
    platform_thickness: float = param(0.02, "m")

    def __post_init__(self):
        _points(self, "base")
        _points(self, "platform")
        check_positive(self, "leg_min", "leg_max", "m_platform", "cylinder_radius", "rod_radius", "platform_thickness")
        check_nonnegative(self, "m_leg")
        if not self.leg_min < self.leg_max:
            raise InvalidParameterError("leg_max", f"must exceed leg_min ({self.leg_min} m), got {self.leg_max}",
                                        self.leg_max)
        for name in ("base", "platform"):
            P = np.array(getattr(self, name))
            if np.linalg.matrix_rank(P[1:] - P[0], tol=1e-9) < 2:
                raise InvalidParameterError(name, "the six points are collinear: the platform would turn freely "
                                                  "about their line", getattr(self, name))
        if self.reference is not None:
            try:
                ref = np.asarray(self.reference, dtype=float)
            except (TypeError, ValueError, OverflowError):
                ref = np.zeros(0)
            if ref.shape != (6,) or not np.all(np.isfinite(ref)):
                raise InvalidParameterError("reference", f"must be 6 finite numbers (x, y, z, roll, pitch, yaw), got "
                                                         f"{self.reference!r}", self.reference)
            object.__setattr__(self, "reference", tuple(float(v) for v in ref))

    @property
    def base_points(self) -> np.ndarray:
        return np.array(self.base)

    @property
    def platform_points(self) -> np.ndarray:
        return np.array(self.platform)


#: The protocol's name for the design dataclass.
Params = GoughStewartParams
