"""The design parameters of the planar 3-RRR (SI units, validated) and its fixed geometry."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pkm._moved import renamed, renamed_fields
from pkm.errors import InvalidInputError, InvalidParameterError
from pkm.mechanisms._common import (
    check_numbers,
    check_params,
    check_positive,
    param,
)

NAME = "rrr3"


SQRT3 = math.sqrt(3.0)


MODES: dict[str, tuple[int, int, int]] = {
    f"mode{k + 1}": (-1 if k & 4 else 1, -1 if k & 2 else 1, -1 if k & 1 else 1) for k in range(8)
}
"""Working mode (branch) name -> signs of ``(psi_1, psi_2, psi_3)`` (see the module doc)."""


REACH_TOL = 1e-12  # relative to a + b: a distance this close to the reach limits counts as on them


@renamed_fields(mode="branch")
@dataclass(frozen=True)
class Rrr3Params:
    """Planar 3-RRR design (paper sec. III workspace study by default).

    Attributes:
        a: Proximal (actuated) link length [m] (40 cm).
        b: Distal link length [m] (40 cm).
        h: Platform side ``AB = BC = CA`` [m] (10 cm).
        H: Base side, the actuator separation ``PQ = QR = RP`` [m] (100 cm).
        branch: Working mode 1..8 of the reference configuration (the spec's default branch
            ``"mode<branch>"``, see the module doc); ``mode=`` is its deprecated former name.
        home: Reference placement ``(dx, dy, Phi)``: the platform centroid's offset from the
            base centroid [m] and the orientation [rad]; ``(0, 0, 0)``: centred, ``Phi = 0``; None
            (default): found for the design (``reference_pose``: centred, the orientation of
            largest condition index in ``branch``).
        m_proximal: Mass of a proximal link [kg] (illustrative; not in the paper).
        m_distal: Mass of a distal link [kg] (illustrative).
        m_platform: Platform mass [kg] (illustrative).
        link_radius: Radius of the links' collision cylinders [m] (10 mm; illustrative: the paper
            gives no sizes).
        platform_thickness: Thickness of the platform's collision disc, normal to the plane [m] (20 mm).
    """

    a: float = param(0.40, "m")
    b: float = param(0.40, "m")
    h: float = param(0.10, "m")
    H: float = param(1.00, "m")
    branch: int = param(1)
    home: tuple[float, float, float] | None = param(None, "m", "rad", length=3)
    m_proximal: float = param(0.20, "kg")
    m_distal: float = param(0.15, "kg")
    m_platform: float = param(0.10, "kg")
    link_radius: float = param(0.010, "m")
    platform_thickness: float = param(0.020, "m")

    def __post_init__(self):
        check_positive(self, "a", "b", "h", "H", "m_proximal", "m_distal", "m_platform", "link_radius",
                       "platform_thickness")
        if isinstance(self.branch, bool) or not isinstance(self.branch, int) or not 1 <= self.branch <= 8:
            raise InvalidParameterError("branch", f"must be an integer 1..8 (working mode 'mode1'..'mode8'), got "
                                                  f"{self.branch!r}", self.branch)
        if self.home is not None:
            check_numbers(self, "home", 3, "(dx, dy, Phi) in m, m, rad")

    @property
    def mode(self) -> int:
        """Deprecated former name of :attr:`branch` (a :class:`DeprecationWarning`)."""
        renamed("Rrr3Params", "mode", "branch")
        return self.branch


# ---------------------------------------------------------------------- geometry
def branch_signs(branch: int | str) -> tuple[int, int, int]:
    """Signs of ``(psi_1, psi_2, psi_3)`` of a working mode (branch) given as ``k`` or ``"modek"`` (k = 1..8)."""
    key = f"mode{branch}" if isinstance(branch, (int, np.integer)) and not isinstance(branch, bool) else branch
    if not isinstance(key, str) or key not in MODES:
        raise InvalidInputError("branch", f"use 1..8 or 'mode1'..'mode8', got {branch!r}", branch)
    return MODES[key]


def mode_signs(mode: int | str) -> tuple[int, int, int]:
    """Deprecated former name of :func:`branch_signs` (a :class:`DeprecationWarning`)."""
    renamed("pkm.mechanisms.rrr3", "mode_signs", "branch_signs")
    return branch_signs(mode)


def base_vertices(params: Rrr3Params) -> np.ndarray:
    """Base vertices ``P, Q, R`` as rows [m], shape (3, 2)."""
    params = check_params(params, Rrr3Params)
    H = params.H
    return np.array([[0.0, 0.0], [H, 0.0], [H / 2.0, H * SQRT3 / 2.0]])


def base_centroid(params: Rrr3Params) -> np.ndarray:
    """Centroid of the base triangle [m], shape (2,)."""
    params = check_params(params, Rrr3Params)
    return np.array([params.H / 2.0, params.H / (2.0 * SQRT3)])


#: The protocol's name for the design dataclass.
Params = Rrr3Params
