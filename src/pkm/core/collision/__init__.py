"""Collision-aware kinematics: a mechanism's collision geometry and its clearance.

* :mod:`~pkm.core.collision.geometry`: the ``<collision>`` elements every format pkm reads carries into its URDF
  text, as Pinocchio's ``GeometryModel`` (coal shapes), and the pairs of bodies checked
  (:class:`CollisionModel`);
* :mod:`~pkm.core.collision.clearance`: the signed distances, witness points and the derivative of the smallest
  distance with respect to the actuated coordinates at a closed configuration (:func:`clearance`), and the
  smallest distance over many configurations (:func:`clearance_map`).
"""

from pkm.core.collision.clearance import Clearance, clearance, clearance_map
from pkm.core.collision.geometry import CollisionModel

__all__ = ["Clearance", "CollisionModel", "clearance", "clearance_map"]
