"""pkm: parallel kinematic machines on Pinocchio.

Examples:
    A quick start: a shipped mechanism (the paper's reference design, from ``urdf/``) or one built from your
    own parameters (SI units, or strings with units), its forward and inverse kinematics and Jacobian.

    >>> import numpy as np
    >>> import pkm
    >>> delta = pkm.load("delta")
    >>> mine = pkm.build("delta", R="120mm")
    >>> fk = pkm.close_loops(delta, [-0.9, -0.8, -1.0])
    >>> {k: round(v, 4) for k, v in pkm.task_values(delta, fk.q).items()}
    {'x': -0.0232, 'y': 0.0002, 'z': -0.3691}
    >>> ik = pkm.solve_ik(delta, [0.02, 0.0, -0.36])
    >>> np.round(delta.actuated_q(ik.q), 4)
    array([-0.8243, -0.9097, -0.7367])
    >>> np.round(pkm.forward_jacobian(delta, ik.q) @ [0.1, 0.2, 0.3], 4)
    array([ 0.0108, -0.0198,  0.0257])
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

from pkm import errors
from pkm._lazy import lazy
from pkm.core import _EXPORTS as _CORE_EXPORTS
from pkm.errors import InvalidInputError, PkmError, UnknownNameError
from pkm.mechanisms import REGISTRY as MECHANISMS
from pkm.mechanisms import definition as mechanism_definition
from pkm.mechanisms import module as mechanism_module

#: The public names imported on first use (``import pkm`` stays cheap: no Pinocchio until needed), by module: the
#: one declaration that the lazy lookup and ``__all__`` are derived from (the ``TYPE_CHECKING`` block below is its
#: static view for type checkers; a test checks that the two agree).
_EXPORTS: dict[str, tuple[str, ...]] = {
    **_CORE_EXPORTS,
    "pkm.core.analysis.maps": ("workspace_map", "task_map"),  # (task_map: the deprecated name)
    "pkm.core.analysis.reconfiguration": ("reconfigure",),
    "pkm.core.export": ("CLibrary", "export_c"),
    "pkm.core.modes": ("assembly_modes", "track_assembly_mode", "track_working_mode", "working_modes"),
    "pkm.core.transmissions": ("SerialEquivalent", "Transmission", "serial_equivalent", "transmissions",
                               "write_serial_equivalent"),
    "pkm.core.timing": ("TimeOptimal", "time_optimal", "verify_time_optimal"),
    "pkm.core.twin": ("Kernels", "Twin"),
    "pkm.sweeps": ("sweep",),
    "pkm.units": ("quantity",),
}
_WHERE = {name: module for module, names in _EXPORTS.items() for name in names}

if TYPE_CHECKING:  # the static view of the lazy names
    import os
    from collections.abc import Sequence
    from pathlib import Path
    from typing import Any

    from pkm.core import (
        Actuator,
        ActuatorSpaceModel,
        BaseGeometry,
        BaseInverseDynamics,
        BaseParameters,
        Beam,
        Branch,
        Calibration,
        CalibrationModel,
        CalibrationParameters,
        Capability,
        Clearance,
        Closure,
        ClosureProblem,
        ClosureSpec,
        CollisionModel,
        Configuration,
        ConsistentEstimate,
        Diagnostics,
        Estimate,
        Event,
        Excitation,
        IKProblem,
        Jump,
        Material,
        Measurements,
        Mechanism,
        ModeLabel,
        OperationalSpace,
        Parameters,
        Polytope,
        PosePlan,
        Region,
        Simulation,
        SolveResult,
        Stiffness,
        TaskMap,
        TaskSpec,
        ToleranceRow,
        Trajectory,
        Validation,
        VibrationModes,
        accelerations,
        actuator_model,
        assemble,
        base_geometry,
        base_inverse_dynamics,
        base_parameters,
        bias_efforts,
        branch_seed,
        calibrate,
        calibration_parameters,
        calibration_poses,
        capability,
        clearance,
        clearance_map,
        close_loops,
        consistent_estimate,
        constraint_dynamics,
        coriolis_matrix,
        diagnose,
        estimate,
        excite,
        feasible_region,
        follow_actuators,
        follow_task,
        forward_dynamics,
        forward_jacobian,
        from_strings,
        gravity_efforts,
        idle_motions,
        inverse_accelerations,
        inverse_dynamics,
        inverse_jacobian,
        inverse_velocities,
        joint_efforts,
        mass_matrix,
        measurements,
        mode_label,
        motor_efforts,
        motor_values,
        nearest_assembly,
        operational_space,
        parameters,
        passive_map,
        regressor,
        regressor_batch,
        scale_configuration,
        scaled_mechanism,
        simulate,
        solve_ik,
        spring_efforts,
        stiffness,
        task_acceleration,
        task_values,
        task_velocity,
        tolerance_table,
        twist_jacobian,
        validate,
        velocities,
        vibration_modes,
        with_actuators,
        write_calibrated,
        write_identified,
        zyx_angles,
        zyx_matrix,
    )
    from pkm.core.analysis.maps import task_map, workspace_map
    from pkm.core.analysis.reconfiguration import reconfigure
    from pkm.core.export import CLibrary, export_c
    from pkm.core.modes import assembly_modes, track_assembly_mode, track_working_mode, working_modes
    from pkm.core.timing import TimeOptimal, time_optimal, verify_time_optimal
    from pkm.core.transmissions import (
        SerialEquivalent,
        Transmission,
        serial_equivalent,
        transmissions,
        write_serial_equivalent,
    )
    from pkm.core.twin import Kernels, Twin
    from pkm.sweeps import sweep
    from pkm.units import quantity


__getattr__, __dir__ = lazy("pkm", globals(), _WHERE)

__version__ = "0.2.0"


def load(name: str | os.PathLike[str], *, actuated: Sequence[str] | str | None = None,
         task: Any = None) -> Mechanism:
    """A mechanism: a registered name's reference design (from its shipped ``urdf/`` files, or built from
    its default parameters when it ships none), or one's own files: a closure spec
    (``path/to/my.closures.toml``, naming its URDF; see :mod:`pkm.core.model.spec`), or a URDF + YAML
    in the convention of Gepetto's toolbox-parallel-robots (the folder, the YAML or the URDF, whatever their
    names: recognised by content), an MJCF file
    (``.xml``, loops as ``<equality>`` connect/weld, actuators from ``<actuator>``) or an SDF file (loops
    as links with several parents; it names no actuators, so it comes through a spec): see
    :mod:`pkm.core.formats`. Or a model an installed package ships, by name ``"<package>:<model>"``
    (``"example-robot-data:cassie"``: :mod:`pkm.core.formats.packages`), or a third-party robot pkm ships, by name
    ``"<source>:<robot>"`` (``"gepetto:robot_delta"``, ``"menagerie:cassie"``: :mod:`pkm.core.formats.catalogue`).

    A file that names no actuators (an MJCF with loops and no ``<actuator>``, an SDF, a Gepetto YAML with no
    ``name_mot``, a spec with ``actuated = []``) loads with them given in code: ``actuated`` (joint names, or
    ``"j1,j2"``) and optionally ``task``, the task in the spec's terms: ``"FRAME"`` (its origin, ``x, y, z``),
    ``"FRAME:KIND"`` or ``(frame, kind)`` with KIND ``"pose"`` or components (``"x,z"``, of ``x y z roll pitch
    yaw``), or the spec's dict ``{"end_effector": ..., "components": [...], "joints": [...]}``
    (:func:`pkm.core.formats.load.given_task`); without ``task``, the task is the actuated joints. Where the files
    name actuators or a task, these replace them (a :class:`~pkm.errors.PkmWarning` when the actuated joints
    differ). Files and installed packages' models only: a shipped mechanism's design states its own.

    Raises:
        UnknownNameError: ``name`` is neither registered (:data:`MECHANISMS`) nor an existing file.
        InvalidInputError: ``actuated`` or ``task`` malformed, or given for a shipped mechanism.
        SpecError: the files are missing, damaged or do not fit together; no reader takes the path (the
            message says why each declined: :func:`pkm.core.formats.load.load_path`); a joint of ``actuated``
            or a frame of ``task`` the model lacks (:class:`~pkm.errors.SpecNameError`, listing the valid ones).

    Examples:
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> delta
        Mechanism('delta': nq=12, nv=12, actuated=['motor_1', 'motor_2', 'motor_3'], closures=3 (9 equations), task=['x', 'y', 'z'])
        >>> delta.actuated_names
        ('motor_1', 'motor_2', 'motor_3')
        >>> gepetto = pkm.load("gepetto:robot_delta")
        >>> gepetto.na, gepetto.nq
        (2, 14)
    """
    import os
    from pathlib import Path

    from pkm.core.formats.load import given as read_given

    def exists(path: str) -> bool:
        try:
            return Path(path).exists()
        except (OSError, ValueError):  # (a name too long for a path, a NUL in it)
            return False

    given = read_given(actuated, task)

    if isinstance(name, str) and ":" in name and not exists(name):  # "example-robot-data:cassie", "gepetto:..."
        from pkm.core.formats.catalogue import CATALOGUE, catalogue_path
        from pkm.core.formats.load import load_package_model, load_path
        from pkm.core.formats.packages import PACKAGES

        if name.partition(":")[0] in PACKAGES:
            return load_package_model(name, given)
        if name.partition(":")[0] in {n.partition(":")[0] for n in CATALOGUE}:
            return load_path(catalogue_path(name), given)
    from pkm.core.formats.base import suffixes

    if isinstance(name, os.PathLike) or (isinstance(name, str) and name not in MECHANISMS
                                         and (name.endswith((".toml", ".yaml", ".yml", *suffixes())) or exists(name))):
        from pkm.core.formats.load import load_path

        return load_path(Path(name), given)  # by content: Gepetto URDF + YAML, closure spec, MJCF or SDF
    if isinstance(name, str) and name not in MECHANISMS:
        raise UnknownNameError("mechanism", name, MECHANISMS, "the registry, nor is it a file (give a closure spec's "
                                                              "path, such as path/to/my.closures.toml)")
    if not given.empty:
        raise InvalidInputError("actuated" if actuated is not None else "task",
                                f"{name!r} is a shipped mechanism, its actuators and task stated by its design; "
                                "actuated= and task= are for files (save it with pkm.save and load the files)",
                                actuated if actuated is not None else task)
    entry = mechanism_definition(name)
    mod = entry.module()
    if entry.reference is None:
        return mod.build(mod.Params())
    from pkm.core.model.builder import from_files
    from pkm.data import data_dir
    from pkm.mechanisms._common import params_from_table

    mech = from_files(data_dir("urdf") / entry.reference)
    mech.params = params_from_table(mod.Params, mech.spec.parameters)  # the design the files state
    return mech


def save(mech: Mechanism, path: str | os.PathLike[str], to: str | None = None) -> Path:
    """Write ``mech`` at ``path`` in the format its suffix names, or ``to``, so that :func:`load` reads it back:

    * ``.closures.toml`` / ``.toml`` (``to="pkm"``): a closure spec and the URDF beside it (``<stem>.urdf``, the spec's
      ``urdf`` key set to it): the same model back, reference configuration included;
    * ``.xml`` / ``.mjcf`` (``to="mjcf"``): MuJoCo's MJCF, loops as stiff ``<connect>``/``<weld>`` equalities
      (:mod:`pkm.core.formats.to_mjcf`);
    * ``.yaml`` / ``.yml`` (``to="gepetto"``): URDF + YAML in the convention of Gepetto's toolbox-parallel-robots, the
      URDF beside the YAML (:mod:`pkm.core.formats.to_gepetto`);
    * ``.urdf`` (``to="urdfplus"``): MIT's URDF+, loops as ``<loop>`` elements (:mod:`pkm.core.formats.to_urdfplus`);
    * ``.sdf`` (``to="sdf"``): SDFormat, loops as cut joints, with a closure spec beside it (``<stem>.closures.toml``,
      the main file: the actuated joints, the task, the drives) (:mod:`pkm.core.formats.to_sdf`);
    * a path without a suffix, with ``to``: a folder, the files in it (:mod:`pkm.core.formats.writers`).

    What the chosen format cannot hold (the task in MJCF and Gepetto's format, the reference configuration...) is
    left out with a :class:`~pkm.errors.PkmWarning` that lists it (and, in the YAML, written as comments).

    Returns:
        The path of the main file written (the one :func:`load` takes).

    Raises:
        InvalidInputError: not a Mechanism, a bad path, a suffix no writer takes (the message lists the formats and
            their suffixes).
        UnknownNameError: ``to`` is not one of ``"pkm"``, ``"mjcf"``, ``"gepetto"``, ``"urdfplus"``, ``"sdf"``.
        SpecError: the format cannot hold something the mechanism needs (named in the message, with the file; for
            pkm's spec, Gepetto's and URDF+, a mechanism without URDF text too).

    Examples:
        >>> import tempfile
        >>> from pathlib import Path
        >>> import numpy as np
        >>> import pkm
        >>> small = pkm.build("delta", R="100mm")
        >>> path = pkm.save(small, Path(tempfile.mkdtemp()) / "my_delta.closures.toml")
        >>> sorted(p.name for p in path.parent.iterdir())
        ['my_delta.closures.toml', 'my_delta.urdf']
        >>> back = pkm.load(path)
        >>> np.allclose(back.q_reference, small.q_reference)
        True
    """
    import warnings

    from pkm.core.formats.writers import write

    written = write(mech, path, to)
    if written.dropped:
        warnings.warn(f"{written.files[0]}: the {written.format} format cannot hold, left out: "
                      + "; ".join(written.dropped), errors.PkmWarning, stacklevel=2)
    return written.files[0]


def design_params(name: str, **params: Any) -> Any:
    """The design dataclass (``Params``) of mechanism ``name`` from parameters (SI units, or strings with units:
    ``R="120mm"``; unspecified ones keep the paper's values), validated as :func:`build` does, without building.

    Returns:
        An instance of the mechanism's own ``Params`` dataclass (``DeltaParams``, ``Rrr3Params``, ...: one class per
        mechanism, hence typed ``Any``).

    Raises:
        UnknownNameError: an unknown mechanism or parameter name (the valid ones listed).
        InvalidParameterError: a parameter out of range or with a unit of another kind.

    Examples:
        >>> import pkm
        >>> p = pkm.design_params("delta", R="120mm")
        >>> type(p).__name__, p.R
        ('DeltaParams', 0.12)
    """
    from pkm._moved import renamed_keywords
    from pkm.units import KIND_OF_UNIT, parse_quantity

    mod = mechanism_module(name)
    fields = {f.name: f for f in dataclasses.fields(mod.Params)}
    params = renamed_keywords(mod.Params.__name__, params, getattr(mod.Params, "RENAMED", {}))  # (deprecated names)
    for key in params:
        if key not in fields:
            raise UnknownNameError("parameter", key, fields, f"pkm.build({name!r})")

    def si(key: str, value, units: tuple[str, ...]):  # a string with a unit, by the field's units
        if not isinstance(value, str):
            return value
        try:
            return parse_quantity(value, {KIND_OF_UNIT.get(u) for u in units}, key, "/".join(units))
        except errors.UnitError as exc:
            raise errors.InvalidParameterError(key, str(exc), value) from None

    for key, value in params.items():
        units = tuple(fields[key].metadata.get("units", ()))
        if not units:
            continue
        if isinstance(value, (tuple, list)):
            per = [(u,) for u in units] if len(units) == len(value) else [units] * len(value)
            params[key] = tuple(si(key, v, u) for v, u in zip(value, per))
        else:
            params[key] = si(key, value, units)
    return mod.Params(**params)


def build(name: str, **params: Any) -> Mechanism:
    """Mechanism ``name`` generated from parameters (SI units, or strings with units: ``R="120mm"``;
    unspecified ones keep the paper's values).

    Raises:
        UnknownNameError: an unknown mechanism or parameter name (the valid ones listed).
        InvalidParameterError: a parameter out of range, or a design that cannot assemble at its
            reference pose (see the mechanism's ``Params``).

    Examples:
        >>> import pkm
        >>> small = pkm.build("delta", R="100mm")
        >>> small.params.R
        0.1
        >>> round(pkm.task_values(small, small.q_reference)["z"], 4)
        -0.2888
    """
    return mechanism_module(name).build(design_params(name, **params))


__all__ = sorted(["MECHANISMS", "PkmError", "build", "design_params", "errors", "load", "mechanism_definition",
                  "mechanism_module", "save", *_WHERE])
