"""The design parameters of the reconfigurable hexapod (SI units, validated) and its fixed geometry."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pkm.core.kinematics.task import ROTATION_TOL, as_rotation  # noqa: F401 (ROTATION_TOL: part of this module's API)
from pkm.errors import InvalidInputError, InvalidParameterError
from pkm.mechanisms._common import (
    check_finite,
    check_numbers,
    check_positive,
    param,
    rot_y,
)

NAME = "hexapod"


LAYOUTS = {"sector": (0.0, 120.0, 240.0), "literal": (0.0, 240.0, 120.0)}  # psi of C4, C5, C6 [deg]


BRANCHES = {"elbow_out": -1, "elbow_in": 1}  # sign of knee_i


DEFAULT_BRANCH = "elbow_out"


ACTUATED = ("alpha_1", "alpha_2", "alpha_3", "alpha_4", "alpha_5", "alpha_6", "beta_1")


#: Largest ``max|R^T R - I|`` accepted for a platform rotation given by the user (then projected on SO(3)).
HOME_ROTATION_TOL = 1e-2  # parameter files may carry coarser matrices


@dataclass(frozen=True)
class HexapodParams:
    """Reconfigurable hexapod design (paper Table 1 by default).

    Attributes:
        Rf: Radius of the reconfiguration pivots ``F_i`` (M1) [m] (50 mm).
        Rr: Reconfiguration link length (``R_r`` of Table 1, ``R_c`` of eq. 2) [m] (150 mm).
        R2: Radius of the actuated joints ``A_4..A_6`` (M2) [m] (450 mm).
        H0: Depth of the plane of ``A_4..A_6`` below O [m] (200 mm).
        LA: Arm length [m] (200 mm).
        LB: Rod length (``B_i`` to ``C_i``) [m] (400 mm).
        h: Height of the platform prism [m] (34 mm).
        r: Circumradius of the platform triangles [m] (50 mm).
        theta: Angular position ``th_i`` of leg i about Y, from +X [rad] (35, 155, 275, 25, 145, 265 deg).
        layout: ``"sector"`` or ``"literal"`` platform layout (see the module doc).
        home_rotation: Reference platform orientation, rows of a 3x3 matrix [-] (projected on SO(3) by
            SVD); None (default): level. The paper's pose T is ``pkm.papers.hexapod.POSE_T_ROTATION``.
        home_position: Reference position of ``P`` [m]; None (default): found for the design
            (``reference_pose``: the best-conditioned depth below the base). Pose T's is
            ``pkm.papers.hexapod.POSE_T_POSITION``.
        home_beta: Reference reconfiguration angle [rad] (0).
        m_recon: Mass of a reconfiguration link [kg] (illustrative; not in the paper).
        m_arm: Mass of an arm ``LA`` [kg] (illustrative).
        m_rod: Mass of a rod ``LB`` [kg] (illustrative).
        m_platform: Platform mass [kg] (illustrative).
        link_radius: Radius of the collision cylinders of the reconfiguration links, arms and rods [m] (10 mm;
            illustrative: the paper gives no sizes). The platform's is the prism's own ``r`` and ``h``.
    """

    Rf: float = param(0.050, "m")
    Rr: float = param(0.150, "m")
    R2: float = param(0.450, "m")
    H0: float = param(0.200, "m")
    LA: float = param(0.200, "m")
    LB: float = param(0.400, "m")
    h: float = param(0.034, "m")
    r: float = param(0.050, "m")
    theta: tuple[float, ...] = param(tuple(math.radians(a) for a in (35.0, 155.0, 275.0, 25.0, 145.0, 265.0)), "rad")
    layout: str = param("sector")
    home_rotation: tuple[float, ...] | None = param(None, "-", length=9)
    home_position: tuple[float, float, float] | None = param(None, "m", length=3)
    home_beta: float = param(0.0, "rad")
    m_recon: float = param(0.15, "kg")
    m_arm: float = param(0.25, "kg")
    m_rod: float = param(0.15, "kg")
    m_platform: float = param(0.80, "kg")
    link_radius: float = param(0.010, "m")

    def __post_init__(self):
        check_positive(self, "Rf", "Rr", "R2", "LA", "LB", "h", "r", "m_recon", "m_arm", "m_rod", "m_platform",
                       "link_radius")
        check_finite(self, "H0", "home_beta")
        if not isinstance(self.layout, str) or self.layout not in LAYOUTS:
            raise InvalidParameterError("layout", f"must be one of {sorted(LAYOUTS)}, got {self.layout!r}",
                                        self.layout)
        check_numbers(self, "theta", 6, "(angles in rad)")
        if self.home_position is not None:
            check_numbers(self, "home_position", 3, "(a point in m)")
        if self.home_rotation is not None:
            check_numbers(self, "home_rotation", 9, "(rows of a rotation)")
            try:
                as_rotation(self.home_rotation, "home_rotation", HOME_ROTATION_TOL)
            except InvalidInputError as exc:
                raise InvalidParameterError("home_rotation", f"must be the rows of a rotation matrix ({exc})",
                                            self.home_rotation) from None


# ---------------------------------------------------------------------- geometry
def leg_frame(theta_i: float) -> np.ndarray:
    """Axes ``(e_r, e_y, u_i)`` of leg frame i as columns (``= Ry(-th_i)``)."""
    return rot_y(-theta_i)


#: The protocol's name for the design dataclass.
Params = HexapodParams
