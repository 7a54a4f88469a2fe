"""The five-bar's design (SI units)."""

from __future__ import annotations

from dataclasses import dataclass

from pkm.mechanisms._common import check_numbers, check_positive

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
        home: Reference tip position (x, y) [m].
        m_link: Mass of each link [kg].
    """

    d: float = 0.20
    l1: float = 0.25
    l2: float = 0.30
    home: tuple[float, float] = (0.0, 0.35)
    m_link: float = 0.1

    def __post_init__(self):
        check_positive(self, "d", "l1", "l2", "m_link")
        check_numbers(self, "home", 2, "(x, y in m)")


Params = FiveBarParams
