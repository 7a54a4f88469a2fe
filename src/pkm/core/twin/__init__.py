"""The symbolic twin of any mechanism (:mod:`~pkm.core.twin.tree`) and what is generated from it.

* :mod:`~pkm.core.twin.spatial`: SE(3) and spatial algebra on CasADi SX;
* :mod:`~pkm.core.twin.joint`: one joint of a Pinocchio tree as SX;
* :mod:`~pkm.core.twin.linear`: sparse LU with pivots fixed at a reference;
* :mod:`~pkm.core.twin.tree`: :class:`Twin`, the tree's kinematics, closures and dynamics as expressions;
* :mod:`~pkm.core.twin.task`: its task, inverse kinematics and map iterations;
* :mod:`~pkm.core.twin.codegen`: generated C with batch and path drivers, compiled and loaded;
* :mod:`~pkm.core.twin.jaxgen`: any kernel as a JAX function (jit, vmap, grad; ``pkm-robotics[jax]``);
* :mod:`~pkm.core.twin.kernels`: :class:`Kernels`, the twin's functions run on states, batches and paths;
* :mod:`~pkm.core.twin.dynamics`: the actuator-space model (``M_a``, ``h_a``, forward dynamics) as expressions;
* :mod:`~pkm.core.twin.simulation`: :func:`pkm.simulate`'s RK4 in generated C.
"""

from pkm.core.twin.codegen import compile_function
from pkm.core.twin.kernels import Kernels, PathResult
from pkm.core.twin.tree import Twin

__all__ = ["Kernels", "PathResult", "Twin", "compile_function"]
