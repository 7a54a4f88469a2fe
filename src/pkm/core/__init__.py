"""The generic closed-loop core: knows no particular robot."""

from pkm.core.differential import (
    Diagnostics,
    accelerations,
    diagnose,
    forward_jacobian,
    inverse_accelerations,
    inverse_jacobian,
    inverse_velocities,
    passive_map,
    task_acceleration,
    task_velocity,
    twist_jacobian,
    velocities,
)
from pkm.core.mechanism import Mechanism
from pkm.core.solve import SolveResult, branch_seed, close_loops, solve_ik
from pkm.core.spec import Branch, Closure, ClosureSpec, TaskSpec
from pkm.core.task import TaskMap, zyx_angles, zyx_matrix

__all__ = [
    "Branch", "Closure", "ClosureSpec", "Diagnostics", "Mechanism", "SolveResult", "TaskMap", "TaskSpec",
    "accelerations", "branch_seed", "close_loops", "diagnose", "forward_jacobian", "inverse_accelerations",
    "inverse_jacobian", "inverse_velocities", "passive_map", "solve_ik", "task_acceleration", "task_velocity",
    "twist_jacobian", "velocities", "zyx_angles", "zyx_matrix",
]
