"""Compliance: the elastostatics and the small vibrations of a closed-loop mechanism whose joints are springs and
whose links may be beams.

* :mod:`~pkm.core.compliance.stiffness`: the Cartesian stiffness at the end-effector frame, the deflection under a
  constant wrench (exact and first order), and the natural frequencies with their mode shapes;
* :mod:`~pkm.core.compliance.stiffness`'s :meth:`Stiffness.loaded`: the tangent stiffness under a constant wrench,
  the geometric stiffness of the loaded members included;
* :mod:`~pkm.core.compliance.links`: compliant links as virtual six-dimensional springs (:class:`Beam`), or beams of
  their collision cylinders and capsules in a :class:`Material`.
"""

from pkm.core.compliance.links import Beam, Material
from pkm.core.compliance.stiffness import LoadedStiffness, Stiffness, VibrationModes, stiffness, vibration_modes

__all__ = ["Beam", "LoadedStiffness", "Material", "Stiffness", "VibrationModes", "stiffness", "vibration_modes"]
