"""The generic closed-loop core: knows no particular robot.

Its names are imported on first use (PEP 562), so that ``import pkm.core.differential.screws`` or
``pkm.core.differential.indices`` (numpy only) does not load Pinocchio.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pkm._lazy import lazy

#: The public names, by module: the one declaration the lazy lookup and ``__all__`` are derived from (the
#: ``TYPE_CHECKING`` block is its static view for type checkers; a test checks that the two agree).
_EXPORTS: dict[str, tuple[str, ...]] = {
    "pkm.core.kinematics.configuration": ("Configuration",),
    "pkm.core.differential.velocity": ("Diagnostics", "accelerations", "diagnose", "forward_jacobian", "idle_motions",
                              "inverse_accelerations", "inverse_jacobian", "inverse_velocities", "passive_map",
                              "task_acceleration", "task_velocity", "twist_jacobian", "velocities"),
    "pkm.core.dynamics.projection": ("BaseInverseDynamics", "base_inverse_dynamics", "constraint_dynamics",
                                     "forward_dynamics", "inverse_dynamics"),
    "pkm.core.dynamics.model": ("ActuatorSpaceModel", "OperationalSpace", "actuator_model", "bias_efforts",
                                "coriolis_matrix", "gravity_efforts", "mass_matrix", "operational_space",
                                "spring_efforts"),
    "pkm.core.dynamics.simulate": ("Event", "Simulation", "simulate"),
    "pkm.core.analysis.capability": ("Capability", "Polytope", "capability"),
    "pkm.core.compliance": ("Beam", "Material", "Stiffness", "VibrationModes", "stiffness", "vibration_modes"),
    "pkm.core.collision": ("Clearance", "CollisionModel", "clearance", "clearance_map"),
    "pkm.core.analysis.region": ("Region", "feasible_region"),
    "pkm.core.calibration.estimate": ("Calibration", "calibrate"),
    "pkm.core.calibration.identifiable": ("BaseGeometry", "base_geometry"),
    "pkm.core.calibration.measurement": ("CalibrationModel",),
    "pkm.core.calibration.parameters": ("CalibrationParameters", "calibration_parameters"),
    "pkm.core.calibration.poses": ("PosePlan", "calibration_poses"),
    "pkm.core.calibration.tolerance": ("ToleranceRow", "tolerance_table"),
    "pkm.core.calibration.writeback": ("write_calibrated",),
    "pkm.core.identification.base": ("BaseParameters", "base_parameters"),
    "pkm.core.identification.consistent": ("ConsistentEstimate", "consistent_estimate"),
    "pkm.core.identification.estimate": ("Estimate", "estimate"),
    "pkm.core.identification.excitation": ("Excitation", "excite"),
    "pkm.core.identification.export": ("Validation", "validate", "write_identified"),
    "pkm.core.identification.measurements": ("Measurements", "measurements"),
    "pkm.core.identification.regressor": ("Parameters", "parameters", "regressor", "regressor_batch"),
    "pkm.core.model.actuators": ("Actuator",),
    "pkm.core.model.builder": ("from_strings", "scaled_mechanism", "with_actuators"),
    "pkm.core.model.mechanism": ("Mechanism",),
    "pkm.core.dynamics.motors": ("joint_efforts", "motor_efforts", "motor_values"),
    "pkm.core.model.scale": ("scale_configuration",),
    "pkm.core.kinematics.labels": ("ModeLabel", "mode_label"),
    "pkm.core.kinematics.solve": ("ClosureProblem", "IKProblem", "SolveResult", "assemble", "branch_seed",
                                  "close_loops", "nearest_assembly", "solve_ik"),
    "pkm.core.model.spec": ("Branch", "Closure", "ClosureSpec", "TaskSpec"),
    "pkm.core.kinematics.task": ("TaskMap", "zyx_angles", "zyx_matrix"),
    "pkm.core.kinematics.trajectory": ("Jump", "Trajectory", "follow_actuators", "follow_task", "task_values"),
}
_WHERE = {name: module for module, names in _EXPORTS.items() for name in names}

if TYPE_CHECKING:  # the static view of the lazy names
    from pkm.core.analysis.capability import Capability, Polytope, capability
    from pkm.core.analysis.region import Region, feasible_region
    from pkm.core.calibration.estimate import Calibration, calibrate
    from pkm.core.calibration.identifiable import BaseGeometry, base_geometry
    from pkm.core.calibration.measurement import CalibrationModel
    from pkm.core.calibration.parameters import CalibrationParameters, calibration_parameters
    from pkm.core.calibration.poses import PosePlan, calibration_poses
    from pkm.core.calibration.tolerance import ToleranceRow, tolerance_table
    from pkm.core.calibration.writeback import write_calibrated
    from pkm.core.collision import Clearance, CollisionModel, clearance, clearance_map
    from pkm.core.compliance import Beam, Material, Stiffness, VibrationModes, stiffness, vibration_modes
    from pkm.core.differential.velocity import (
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
    from pkm.core.dynamics.model import (
        ActuatorSpaceModel,
        OperationalSpace,
        actuator_model,
        bias_efforts,
        coriolis_matrix,
        gravity_efforts,
        mass_matrix,
        operational_space,
        spring_efforts,
    )
    from pkm.core.dynamics.motors import joint_efforts, motor_efforts, motor_values
    from pkm.core.dynamics.projection import (
        BaseInverseDynamics,
        base_inverse_dynamics,
        constraint_dynamics,
        forward_dynamics,
        inverse_dynamics,
    )
    from pkm.core.dynamics.simulate import Event, Simulation, simulate
    from pkm.core.identification.base import BaseParameters, base_parameters
    from pkm.core.identification.consistent import ConsistentEstimate, consistent_estimate
    from pkm.core.identification.estimate import Estimate, estimate
    from pkm.core.identification.excitation import Excitation, excite
    from pkm.core.identification.export import Validation, validate, write_identified
    from pkm.core.identification.measurements import Measurements, measurements
    from pkm.core.identification.regressor import Parameters, parameters, regressor, regressor_batch
    from pkm.core.kinematics.configuration import Configuration
    from pkm.core.kinematics.labels import ModeLabel, mode_label
    from pkm.core.kinematics.solve import (
        ClosureProblem,
        IKProblem,
        SolveResult,
        assemble,
        branch_seed,
        close_loops,
        nearest_assembly,
        solve_ik,
    )
    from pkm.core.kinematics.task import TaskMap, zyx_angles, zyx_matrix
    from pkm.core.kinematics.trajectory import Jump, Trajectory, follow_actuators, follow_task, task_values
    from pkm.core.model.actuators import Actuator
    from pkm.core.model.builder import from_strings, scaled_mechanism, with_actuators
    from pkm.core.model.mechanism import Mechanism
    from pkm.core.model.scale import scale_configuration
    from pkm.core.model.spec import Branch, Closure, ClosureSpec, TaskSpec


__getattr__, __dir__ = lazy("pkm.core", globals(), _WHERE)

__all__ = sorted(_WHERE)
