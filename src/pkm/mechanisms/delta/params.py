"""The design parameters of the Delta (SI units, validated) and its fixed geometry."""

from __future__ import annotations

import math
from dataclasses import dataclass

from pkm.mechanisms._common import (
    check_numbers,
    check_positive,
    param,
)

NAME = "delta"


PHI = (0.0, 2.0 * math.pi / 3.0, 4.0 * math.pi / 3.0)


BRANCHES = {"knee_out": -1, "knee_in": 1}


@dataclass(frozen=True)
class DeltaParams:
    """Delta design (paper Table 1 by default).

    Attributes:
        La: Arm length [m] (110 mm).
        Lb: Forearm (parallelogram) length [m] (330 mm).
        r: Platform radius, centre to ball-joint line [m] (50 mm).
        R: Base radius, centre to motor axis [m] (150 mm for the paper's Fig. 4; studied 100-200 mm,
            120 mm chosen for construction).
        home: Reference platform position [m]; None (default): found for the design
            (``reference_pose``: the best-conditioned point on the axis). The paper's study point
            (0, 0, -375) mm is ``pkm.papers.delta.POSE``.
        m_arm: Arm mass [kg] (illustrative; not in the paper).
        m_forearm: Mass of one parallelogram (both rods) [kg] (illustrative).
        m_platform: Platform mass [kg] (illustrative).
        arm_radius: Radius of an arm's collision cylinder [m] (10 mm; illustrative: the paper
            gives no sizes).
        rod_radius: Radius of a forearm's collision cylinder, drawn on the parallelogram's centre line [m]
            (5 mm).
        platform_thickness: Thickness of the platform's collision disc (radius ``r``) [m] (10 mm).
        base_thickness: Thickness of the base's collision disc (radius ``R``, above the motor axes) [m] (10 mm).
    """

    La: float = param(0.110, "m")
    Lb: float = param(0.330, "m")
    r: float = param(0.050, "m")
    R: float = param(0.150, "m")
    home: tuple[float, float, float] | None = param(None, "m", length=3)
    m_arm: float = param(0.10, "kg")
    m_forearm: float = param(0.05, "kg")
    m_platform: float = param(0.20, "kg")
    arm_radius: float = param(0.010, "m")
    rod_radius: float = param(0.005, "m")
    platform_thickness: float = param(0.010, "m")
    base_thickness: float = param(0.010, "m")

    def __post_init__(self):
        check_positive(self, "La", "Lb", "r", "R", "m_arm", "m_forearm", "m_platform", "arm_radius", "rod_radius",
                       "platform_thickness", "base_thickness")
        if self.home is not None:
            check_numbers(self, "home", 3, "(a point x, y, z in m)")


#: The protocol's name for the design dataclass.
Params = DeltaParams
