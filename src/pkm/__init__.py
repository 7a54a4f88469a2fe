"""pkm: parallel kinematic machines on Pinocchio.

Quick start::

    import pkm
    delta = pkm.load("delta")                       # the paper's reference design (urdf/)
    delta = pkm.build("delta", R=0.12)              # or your own parameters (SI units)
    res = pkm.close_loops(delta, [-0.9, -0.8, -1.0])  # forward kinematics, generic core
    ik = pkm.solve_ik(delta, [0.02, 0.0, -0.36])      # inverse kinematics
    J = pkm.forward_jacobian(delta, ik.q)
"""

from __future__ import annotations

import dataclasses

from pkm import errors
from pkm.core import (
    ClosureSpec,
    Diagnostics,
    Mechanism,
    SolveResult,
    TaskMap,
    accelerations,
    close_loops,
    diagnose,
    forward_jacobian,
    inverse_accelerations,
    inverse_jacobian,
    inverse_velocities,
    passive_map,
    solve_ik,
    task_acceleration,
    task_velocity,
    twist_jacobian,
    velocities,
)
from pkm.data import spec_path
from pkm.errors import PkmError, UnknownNameError
from pkm.mechanisms import NAMES as MECHANISMS
from pkm.mechanisms import module as mechanism_module

__version__ = "0.1.0"


def load(name: str) -> Mechanism:
    """The reference design of mechanism ``name`` from the shipped ``urdf/`` files.

    Raises:
        UnknownNameError: ``name`` is not one of :data:`MECHANISMS`.
        SpecError: the shipped files are damaged.
    """
    mod = mechanism_module(name)
    mech = Mechanism.from_files(spec_path(name))
    mech.params = mod.Params()
    return mech


def build(name: str, **params) -> Mechanism:
    """Mechanism ``name`` generated from parameters (SI units; unspecified ones keep the paper's values).

    Raises:
        UnknownNameError: an unknown mechanism or parameter name (the valid ones listed).
        InvalidParameterError: a parameter out of range, or a design that cannot assemble at its
            reference pose (see the mechanism's ``Params``).
    """
    mod = mechanism_module(name)
    fields = [f.name for f in dataclasses.fields(mod.Params)]
    for key in params:
        if key not in fields:
            raise UnknownNameError("parameter", key, fields, f"pkm.build({name!r})")
    return mod.build(mod.Params(**params))


__all__ = [
    "MECHANISMS", "ClosureSpec", "Diagnostics", "Mechanism", "PkmError", "SolveResult", "TaskMap",
    "accelerations", "build", "close_loops", "diagnose", "errors", "forward_jacobian", "inverse_accelerations",
    "inverse_jacobian", "inverse_velocities", "load", "mechanism_module", "passive_map", "solve_ik",
    "task_acceleration", "task_velocity", "twist_jacobian", "velocities",
]
