"""Compliance: the elastostatics and the small vibrations of a closed-loop mechanism whose joints are springs.

:mod:`~pkm.core.compliance.stiffness`: the Cartesian stiffness at the end-effector frame, the deflection under a
constant wrench (exact and first order), and the natural frequencies with their mode shapes.
"""

from pkm.core.compliance.stiffness import Stiffness, VibrationModes, stiffness, vibration_modes

__all__ = ["Stiffness", "VibrationModes", "stiffness", "vibration_modes"]
