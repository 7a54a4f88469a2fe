"""The generic closed-loop core: knows no particular robot.

Its names are imported on first use (PEP 562), so that ``import pkm.core.screws`` or
``pkm.core.indices`` (numpy only) does not load Pinocchio.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pkm._lazy import lazy

_EXPORTS = {
    "pkm.core.configuration": ("Configuration",),
    "pkm.core.differential": ("Diagnostics", "accelerations", "diagnose", "forward_jacobian", "idle_motions",
                              "inverse_accelerations", "inverse_jacobian", "inverse_velocities", "passive_map",
                              "task_acceleration", "task_velocity", "twist_jacobian", "velocities"),
    "pkm.core.dynamics": ("inverse_dynamics",),
    "pkm.core.mechanism": ("Mechanism",),
    "pkm.core.solve": ("SolveResult", "assemble", "branch_seed", "close_loops", "solve_ik"),
    "pkm.core.spec": ("Branch", "Closure", "ClosureSpec", "TaskSpec"),
    "pkm.core.task": ("TaskMap", "zyx_angles", "zyx_matrix"),
    "pkm.core.trajectory": ("Jump", "Trajectory", "follow_actuators", "follow_task", "task_values"),
}
_WHERE = {name: module for module, names in _EXPORTS.items() for name in names}

if TYPE_CHECKING:  # the static view of the lazy names
    from pkm.core.configuration import Configuration
    from pkm.core.differential import (
        Diagnostics,
        accelerations,
        diagnose,
        forward_jacobian,
        idle_motions,
        inverse_accelerations,
        inverse_jacobian,
        inverse_velocities,
        passive_map,
        task_acceleration,
        task_velocity,
        twist_jacobian,
        velocities,
    )
    from pkm.core.dynamics import inverse_dynamics
    from pkm.core.mechanism import Mechanism
    from pkm.core.solve import SolveResult, assemble, branch_seed, close_loops, solve_ik
    from pkm.core.spec import Branch, Closure, ClosureSpec, TaskSpec
    from pkm.core.task import TaskMap, zyx_angles, zyx_matrix
    from pkm.core.trajectory import Jump, Trajectory, follow_actuators, follow_task, task_values


__getattr__, __dir__ = lazy("pkm.core", globals(), _WHERE)

__all__ = [
    "Branch", "Closure", "ClosureSpec", "Configuration", "Diagnostics", "Jump", "Mechanism", "SolveResult", "TaskMap",
    "TaskSpec", "Trajectory", "accelerations", "assemble", "branch_seed", "close_loops", "diagnose", "follow_actuators",
    "follow_task", "forward_jacobian", "idle_motions", "inverse_accelerations", "inverse_dynamics", "inverse_jacobian",
    "inverse_velocities", "passive_map", "solve_ik", "task_acceleration", "task_values", "task_velocity",
    "twist_jacobian", "velocities", "zyx_angles", "zyx_matrix",
]
