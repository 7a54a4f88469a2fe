"""The symbolic twin of any mechanism (:mod:`~pkm.core.twin.tree`) and what is generated from it.

* :mod:`~pkm.core.twin.spatial`: SE(3) and spatial algebra on CasADi SX;
* :mod:`~pkm.core.twin.joint`: one joint of a Pinocchio tree as SX;
* :mod:`~pkm.core.twin.tree`: :class:`Twin`, the tree's kinematics, closures and dynamics as expressions;
* :mod:`~pkm.core.twin.codegen`: generated C, compiled and loaded.
"""

from pkm.core.twin.codegen import compile_function
from pkm.core.twin.tree import Twin

__all__ = ["Twin", "compile_function"]
