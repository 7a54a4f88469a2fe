"""The five-bar's design (SI units)."""

from __future__ import annotations

from dataclasses import dataclass

from pkm.mechanisms._common import check_numbers, check_positive, param

NAME = "fivebar"
#: Working mode -> sign of the root taken for each motor (``theta_i = atan2(v_i) + s_i acos(...)``).
BRANCHES = {"elbows_out": (1, -1), "elbows_in": (-1, 1)}


@dataclass(frozen=True)
class FiveBarParams:
    """A planar five-bar.

    Attributes:
        d: Distance between the motors [m].
        l1: Proximal link length [m].
        l2: Distal link length [m].
        home: Reference tip position (x, y) [m], or None (default): found by ``reference_pose``.
        m_link: Mass of each link [kg].
    """

    d: float = param(0.20, "m")
    l1: float = param(0.25, "m")
    l2: float = param(0.30, "m")
    home: tuple[float, float] | None = param(None, "m", length=2)
    m_link: float = param(0.1, "kg")

    def __post_init__(self):
        check_positive(self, "d", "l1", "l2", "m_link")
        if self.home is not None:
            check_numbers(self, "home", 2, "(x, y in m)")


Params = FiveBarParams
