"""The service's typed contract: a pydantic request model and a response model per operation, for the OpenAPI schema
(``/openapi.json``) and for refusing unknown fields (422 naming them). Every field has a description with its units and
an example.

Arrays are NOT parsed by pydantic (a ``list[list[float]]`` of 10,000 samples would cost more than the query): an array
field's type (:data:`Positions`, :data:`Numbers`) documents its JSON schema (one sample: an array of numbers; a batch:
an array of such arrays; positions and rates also as strings with a unit, ``"10deg"``, ``"5mm"``, ``"-30deg/s"``) and
hands the raw value, a list or a numpy array from a msgpack body (:data:`pkm.serve.wire.ND_LAYOUT`), to pkm's own parsing (:mod:`pkm.serve.queries`: :func:`pkm.validation.as_array`,
:mod:`pkm.units`). The answers' arrays are ``null`` for a failed sample (never NaN, never a number as a string).
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, WithJsonSchema

from pkm.serve.wire import ND_LAYOUT

_NUMBER: dict[str, Any] = {"type": "number"}
_NUMBER_OR_UNIT: dict[str, Any] = {"anyOf": [_NUMBER, {"type": "string"}]}
_VECTOR: dict[str, Any] = {"type": "array", "items": _NUMBER}
_MATRIX: dict[str, Any] = {"type": "array", "items": _VECTOR}


def _samples(entry: dict[str, Any]) -> dict[str, Any]:
    """One sample (an array of ``entry``) or a batch (an array of such arrays); in msgpack either one may be a numpy
    array (:data:`pkm.serve.wire.ND_LAYOUT`, said in the schema: a field's own description replaces a type's)."""
    return {"anyOf": [{"type": "array", "items": entry, "description": f"One sample. {ND_LAYOUT}"},
                      {"type": "array", "items": {"type": "array", "items": entry},
                       "description": f"A list of samples. {ND_LAYOUT}"}]}


#: Positions: one sample (numbers in SI, or strings with a unit: ``"10deg"``, ``"5mm"``) or a list of samples.
Positions = Annotated[Any, WithJsonSchema(_samples(_NUMBER_OR_UNIT))]
#: Rates (numbers in SI, or strings with a rate's unit: ``"-30deg/s"``, ``"300rpm"``, ``"50mm/s"``): one sample or a
#: list of samples.
Rates = Positions
#: Accelerations (numbers in SI: no unit suffix names one): one sample or a list of samples.
Numbers = Annotated[Any, WithJsonSchema(_samples(_NUMBER))]
#: One configuration (numbers in SI, or strings with a unit).
Configuration = Annotated[Any, WithJsonSchema({"type": "array", "items": _NUMBER_OR_UNIT})]

def _column(entry: dict[str, Any] | list[dict[str, Any]]) -> dict[str, Any]:
    """An answer's column of ``entry`` per sample, ``null`` where the sample failed; in msgpack, where no sample
    failed, a numpy array (:data:`pkm.serve.wire.ND_LAYOUT`, stated in the requests' array schemas and the API's
    description: an array schema, not an ``allOf`` wrapper, which generated clients read as an object)."""
    return {"type": "array", "items": {"anyOf": [*(entry if isinstance(entry, list) else [entry]), {"type": "null"}]}}


#: An answer's column: one entry per sample (a number, a vector or a matrix), ``null`` where the sample failed.
Column = Annotated[Any, WithJsonSchema(_column([_NUMBER, _VECTOR, _MATRIX]))]
#: Integers per sample (``null`` where the sample failed).
IntColumn = Annotated[Any, WithJsonSchema(_column({"type": "integer"}))]
#: Booleans per sample (``null`` where the sample failed).
BoolColumn = Annotated[Any, WithJsonSchema(_column({"type": "boolean"}))]
#: Units: a unit per quantity (one for all its entries), per entry, or per matrix entry.
Units = dict[str, str | list[str] | list[list[str]]]
UNITS = "The unit of every quantity of the answer and of its inputs: one for all entries, one per entry, or one per " \
        "matrix entry (SI: m, rad, N, N m, s; 1: unitless)."

_Q_EXAMPLE = [-0.61, -2.2, 0.0, -0.61, -2.2, 0.0, -0.61, -2.2, 0.0, 0.0, 0.0, -0.35]
_QA_EXAMPLE = [-0.61, -0.61, -0.61]


def _field(description: str, example: Any, default: Any = ...) -> Any:
    return Field(default, description=description, examples=[example])


class _Request(BaseModel):
    model_config = ConfigDict(extra="forbid")


class _Answer(BaseModel):
    model_config = ConfigDict(extra="forbid")


# ------------------------------------------------------------------------------------------------------ requests
_SEED = "The configuration the first sample is solved from (nq numbers: rad, m; or strings with a unit); default the " \
        "model's reference. Each further sample starts from the previous one's solution."
_Q = "Closed configurations: every coordinate of q (nq numbers a sample: rad, m, or strings with a unit such as " \
     "'10deg'), one sample or a list of samples. Give q or qa, not both."
_QA = "Actuated values (na a sample: rad, m, or strings with a unit), one sample or a list; the loops are then closed " \
      "from seed (default the reference), each sample from the previous one's solution. Give q or qa, not both."


class FkRequest(_Request):
    """The forward kinematics: actuated values in, the closed configurations out."""

    qa: Positions = _field("Actuated values (na a sample: rad for a revolute actuator, m for a prismatic one, or strings "
                           "with a unit such as '10deg', '5mm'), one sample or a list of samples.", _QA_EXAMPLE)
    seed: Configuration | None = _field(_SEED, None, None)


class IkRequest(_Request):
    """The inverse kinematics: task values in, the configurations out."""

    y: Positions = _field("Task values laid out as the model's task_value_names (m, rad, or strings with a unit; a "
                          "pose's quaternion unitless), one sample or a list of samples.", [0.0, 0.0, -0.35])
    seed: Configuration | None = _field(_SEED, None, None)
    branch: str | None = _field("A named branch (working mode) of the model's spec, to stay in; default: none asked.",
                                None, None)


class _AtConfigurations(_Request):
    q: Positions | None = _field(_Q, None, None)
    qa: Positions | None = _field(_QA, _QA_EXAMPLE, None)
    seed: Configuration | None = _field(_SEED, None, None)


class JacobiansRequest(_AtConfigurations):
    """The forward and inverse Jacobians at closed configurations."""


class DiagnoseRequest(_AtConfigurations):
    """The distances to the singularities at closed configurations."""


class SceneRequest(_AtConfigurations):
    """The placements of the 3-D scene's bodies at closed configurations."""


class VelocitiesRequest(_AtConfigurations):
    """Every joint's rate (and acceleration) from the actuated ones."""

    qd: Rates = _field("Actuated rates (na a sample: rad/s, m/s, or strings with a unit such as '-30deg/s', '300rpm', "
                       "'50mm/s'), one for every sample or one per sample.",
                         [0.1, 0.0, 0.0])
    qdd: Numbers | None = _field("Actuated accelerations (na a sample: rad/s^2, m/s^2); with them the accelerations "
                                 "are answered too.", [1.0, 0.0, 0.0], None)


class DynamicsRequest(_AtConfigurations):
    """The actuator-space dynamic model, and the inverse dynamics with qdd."""

    qd: Rates | None = _field("Actuated rates (na a sample: rad/s, m/s, or strings with a unit such as '-30deg/s', "
                              "'300rpm'); default 0.", [0.1, 0.0, 0.0], None)
    qdd: Numbers | None = _field("Actuated accelerations (na a sample: rad/s^2, m/s^2); with them the efforts tau are "
                                 "answered.", [1.0, 0.0, 0.0], None)


class CapabilityRequest(_AtConfigurations):
    """The wrench, twist or acceleration capability under the actuators' limits."""

    kind: Literal["wrench", "twist", "acceleration"] = _field("Which capability.", "wrench", "wrench")


# ------------------------------------------------------------------------------------------------------- answers
class Failure(_Answer):
    """One failed sample of a batch."""

    sample: int = _field("The sample's index in the batch (from 0).", 1)
    error: str = _field("The name of pkm's error (pkm.errors).", "UnreachableError")
    message: str = _field("What went wrong, in words.", "pose unreachable: leg 1 misses by 0.64 m or rad")


_STATUS = _field("Per sample: 'ok'; 'outside_limits' (solved, but a joint lies outside the position limits the "
                 "model states: named in outside_limits); or 'failed' (its values are then null, its error in "
                 "failures).", ["ok"])
_OUTSIDE = _field("Per sample, the joints outside the position limits the model states (empty: none; null: a failed "
                  "sample), each with its value and limits [rad, m].",
                  [[{"joint": "motor_1", "value": 1.62, "limit": [-1.5, 1.5]}]])
_FAILURES = _field("The failed samples with their error (absent when every sample is ok).", None, None)
_COMPUTE = _field("The server's time for the computation [s].", 0.0004)
_ANSWER_Q = _field("The closed configurations (nq a sample: units in units.q).", [_Q_EXAMPLE])


class OutsideLimit(_Answer):
    """A joint outside the position limits the model states."""

    joint: str = _field("The joint's name.", "motor_1")
    value: float = _field("Its coordinate [rad, m].", 1.62)
    limit: list[float | None] = _field("Its limits [lower, upper] [rad, m] (null: no limit that side).", [-1.5, 1.5])


class _Batch(_Answer):
    status: list[Literal["ok", "outside_limits", "failed"]] = _STATUS
    outside_limits: list[list[OutsideLimit] | None] = _OUTSIDE
    failures: list[Failure] | None = _FAILURES
    compute_s: float = _COMPUTE


class FkAnswer(_Batch):
    """The closed configurations, their task values and the closures' residuals."""

    q: Column = _ANSWER_Q
    y: Column = _field("The task values (as task_value_names: m, rad; units in units.y).", [[0.0, 0.0, -0.35]])
    residual: Column = _field("The closure residual per sample [m or rad].", [2e-16])
    iterations: IntColumn = _field("Newton iterations per sample.", [3])
    units: Units = _field(UNITS, {"q": ["rad"] * 9 + ["m"] * 3, "y": ["m", "m", "m"], "residual": "m or rad",
                                  "iterations": "1", "qa": ["rad", "rad", "rad"]})


class IkAnswer(_Batch):
    """The configurations reaching the task values."""

    q: Column = _ANSWER_Q
    qa: Column = _field("The actuated values (na a sample: rad, m).", [_QA_EXAMPLE])
    residual: Column = _field("The residual per sample [m or rad].", [1e-15])
    iterations: IntColumn = _field("Newton iterations per sample.", [4])
    units: Units = _field(UNITS, {"q": ["rad"] * 9 + ["m"] * 3, "qa": ["rad"] * 3, "residual": "m or rad",
                                  "iterations": "1", "y": ["m", "m", "m"]})


class JacobiansAnswer(_Batch):
    """The forward Jacobian J (task rates per actuated rate) and the inverse K (actuated rates per task rate)."""

    q: Column = _ANSWER_Q
    J: Column = _field("Forward Jacobians (n_task x na a sample; units per entry in units.J).",
                       [[[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]]])
    K: Column = _field("Inverse Jacobians (na x n_task a sample; units per entry in units.K).",
                       [[[10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0, 0.0, 10.0]]])
    units: Units = _field(UNITS, {"J": [["m/rad"] * 3] * 3, "K": [["rad/m"] * 3] * 3})


class DiagnoseAnswer(_Batch):
    """The distances to the direct and inverse singularities, in [0, 1] (0: singular)."""

    q: Column = _ANSWER_Q
    direct_distance: Column = _field("Distance to a direct (forward) singularity per sample, in [0, 1] [1].", [0.42])
    inverse_distance: Column = _field("Distance to an inverse singularity per sample, in [0, 1] [1].", [0.57])
    units: Units = _field(UNITS, {"direct_distance": "1", "inverse_distance": "1"})


class VelocitiesAnswer(_Batch):
    """Every joint's rate and the task rates; with qdd, the accelerations."""

    q: Column = _ANSWER_Q
    v: Column = _field("Every joint's rate (nv a sample: rad/s, m/s; units in units.v).", [[0.1] * 12])
    yd: Column = _field("Task rates (n_task a sample: m/s, rad/s).", [[0.01, 0.0, 0.0]])
    a: Column | None = _field("Every joint's acceleration (nv: rad/s^2, m/s^2), with qdd.", None, None)
    ydd: Column | None = _field("Task accelerations (m/s^2, rad/s^2), with qdd.", None, None)
    units: Units = _field(UNITS, {"v": ["rad/s"] * 12, "yd": ["m/s"] * 3})


class DynamicsAnswer(_Batch):
    """The actuator-space model tau = M qdd + h (h includes the gravity g)."""

    q: Column = _ANSWER_Q
    M: Column = _field("Actuator-space mass matrices (na x na a sample; units per entry in units.M, e.g. "
                       "N m/(rad/s^2)).", [[[0.05, 0.0, 0.0], [0.0, 0.05, 0.0], [0.0, 0.0, 0.05]]])
    h: Column = _field("Actuator-space bias efforts (na a sample: N m, N), gravity and joint springs included.",
                       [[0.3, 0.3, 0.3]])
    g: Column = _field("Actuator-space static efforts, gravity's and the joint springs' (na a sample: N m, N).",
                       [[0.3, 0.3, 0.3]])
    tau: Column | None = _field("Actuator efforts tau = M qdd + h (na a sample: N m, N), with qdd.", [[0.35, 0.3, 0.3]],
                                None)
    units: Units = _field(UNITS, {"M": [["N m/(rad/s^2)"] * 3] * 3, "h": ["N m"] * 3, "tau": ["N m"] * 3})


class CapabilityAnswer(_Batch):
    """The capability polytope's extent along the task axes, its isotropic values and vertices."""

    q: Column = _ANSWER_Q
    kind: Literal["wrench", "twist", "acceleration"] = _field("Which capability.", "wrench")
    axes: list[str] = _field("The task axes of along and of the vertices' coordinates.", ["x", "y", "z"])
    along: Column = _field("The largest value along each task axis, per sample (units in units.along).",
                           [[12.0, 12.0, 30.0]])
    isotropic: Column = _field("The largest value reachable in every direction, per unit kind (units.isotropic).",
                               [[9.5]])
    vertices: Column = _field("The polytope's vertices per sample (one row per vertex, coordinates along axes).",
                              [[[12.0, 0.0, 30.0]]])
    origin_inside: BoolColumn = _field("Whether the actuators can hold the weight at rest (else the indices are 0).",
                                       [True])
    units: Units = _field(UNITS, {"along": ["N", "N", "N"], "isotropic": ["N"]})


class StiffnessAnswer(_Batch):
    """The end effector's compliance (its inverse is the stiffness where rank is 6), its principal compliances and,
    with a wrench, the exact and first-order deflections."""

    q: Column = _ANSWER_Q
    compliance: Column = _field("The compliance C (6 x 6 a sample): the small displacement (dx, dy, dz, rx, ry, rz) "
                                "per wrench (fx, fy, fz, mx, my, mz) at the end effector's origin, world axes; units "
                                "per entry in units.compliance.", [[[1e-5] + [0.0] * 5] * 6])
    rank: IntColumn = _field("The rank of C (6: invert it for the stiffness; fewer: rigid along the others).", [3])
    force_compliance: Column = _field("Under a pure force: the principal compliances, largest first [m/N] (1/each: "
                                      "the principal stiffnesses; 0: rigid).", [[3e-5, 3e-5, 8e-6]])
    force_directions: Column = _field("Their unit directions (3 x 3 a sample, one per row), world axes.",
                                      [[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]])
    moment_compliance: Column = _field("Under a pure moment: the principal compliances, largest first [rad/(N m)].",
                                       [[0.0, 0.0, 0.0]])
    moment_directions: Column = _field("Their unit directions (3 x 3 a sample), world axes.",
                                       [[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]])
    displacement: Column | None = _field("With a wrench: the exact deflection (dx, dy, dz [m], rotation vector [rad]).",
                                         None, None)
    first_order: Column | None = _field("With a wrench: the first-order deflection C W, same layout.", None, None)
    gap: Column | None = _field("With a wrench: their relative difference (homogenised by the model's size).", None,
                                None)
    loaded_compliance: Column | None = _field("With a wrench: the tangent compliance at the deflected equilibrium "
                                              "(6 x 6 a sample; the geometric stiffness of the load included; not "
                                              "symmetric in general), units as compliance's.", None, None)
    links: dict[str, dict[str, Any]] = _field("The compliant links counted: a beam's radius, inner radius [m], E, G "
                                              "[Pa], or a 6 x 6 compliance (the spec's).",
                                              {"cylinder_1": {"radius": 0.03, "inner": 0.0, "E": 2.1e11, "G": 8.1e10}},
                                              {})
    rigid_links: dict[str, str] = _field("With a material: the links taken rigid and why (no collision geometry, not "
                                         "one cylinder or capsule, a disc, a span of no length).",
                                         {"base": "no collision geometry"}, {})
    sprung: dict[str, float] = _field("Each joint's stiffness counted (N m/rad for a revolute, N/m for a prismatic "
                                      "joint); the actuated joints not named held rigid.", {"motor_1": 500.0})
    sources: dict[str, str] = _field("Where each one came from: joints (this request's springs or drives), actuator "
                                     "(the drive's own servo stiffness, the spec's [actuators.<joint>] stiffness), "
                                     "spring (the model's [springs]), actuator+spring (both, in parallel).",
                                     {"motor_1": "joints"})
    units: Units = _field(UNITS, {"force_compliance": "m/N", "moment_compliance": "rad/(N m)"})


class ClearanceAnswer(_Batch):
    """The signed distances between the bodies' collision geometry, the smallest and its derivative."""

    q: Column = _ANSWER_Q
    pairs: list[list[str]] = _field("The pairs of bodies checked, in the order of distances.",
                                    [["rod_1", "rod_2"], ["rod_1", "rod_3"]])
    distances: Column = _field("Each pair's signed distance per sample [m] (negative: penetration depth).",
                               [[0.17, 0.25]])
    minimum: Column = _field("The smallest distance per sample [m].", [0.17])
    closest: IntColumn = _field("The index in pairs of the closest pair per sample.", [0])
    interferes: BoolColumn = _field("Whether two bodies interpenetrate (minimum < 0).", [False])
    gradient: Column = _field("d minimum / d actuated coordinates per sample (na: m/rad, m/m); None at a direct "
                              "singularity.", [[0.01, -0.02, 0.0]])
    units: Units = _field(UNITS, {"distances": "m", "minimum": "m", "gradient": ["m/rad"] * 3})


class SceneAnswer(_Batch):
    """The world placement of every body of the model's 3-D scene."""

    q: Column = _ANSWER_Q
    paths: list[str] = _field("The scene's body paths (meshcat), in the order of matrices.", ["/pkm/base"])
    matrices: Column = _field("Per sample and body, the 4 x 4 homogeneous transform's 16 entries column-major "
                              "(translation, entries 12 to 14, in m).",
                              [[[1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.0, 0.0, 0.0, 1]]])
    units: Units = _field(UNITS, {"matrices": ["1"] * 12 + ["m"] * 3 + ["1"]})


class StiffnessRequest(_AtConfigurations):
    """The end effector's compliance with joint springs (pkm.stiffness), and a load's deflection."""

    springs: dict[str, float] | None = _field("A joint's stiffness by name (N m/rad for a revolute, N/m for a "
                                              "prismatic joint; 0 frees it), over the model's own springs.",
                                              {"motor_1": 500.0}, None)
    drives: float | None = _field("Every actuated joint's stiffness not named in springs (SI); default: each "
                                  "drive's own servo stiffness (the spec's [actuators.<joint>] stiffness), else "
                                  "held rigid.", 500.0, None)
    wrench: list[float] | None = _field("A constant load at the end effector's origin, world axes (fx, fy, fz [N], "
                                        "mx, my, mz [N m]): its exact deflection is answered too.",
                                        [0.0, 0.0, -10.0, 0.0, 0.0, 0.0], None)
    links: str | dict[str, float] | None = _field("The links: spec (default: the spec's [links] compliances, else "
                                                  "rigid), rigid, steel, aluminium, or {E, G} in Pa: every link whose "
                                                  "collision geometry is one cylinder or capsule a beam of that "
                                                  "material.", "steel", None)


class ClearanceRequest(_AtConfigurations):
    """The signed distances between the bodies at closed configurations (pkm.clearance)."""


#: Per query: (request model, answer model, summary).
QUERY_MODELS: dict[str, tuple[type[BaseModel], type[BaseModel], str]] = {
    "fk": (FkRequest, FkAnswer, "Forward kinematics: close the loops at actuated values"),
    "ik": (IkRequest, IkAnswer, "Inverse kinematics: the configuration at task values"),
    "jacobians": (JacobiansRequest, JacobiansAnswer, "The forward and inverse Jacobians"),
    "diagnose": (DiagnoseRequest, DiagnoseAnswer, "The distances to the singularities"),
    "velocities": (VelocitiesRequest, VelocitiesAnswer, "Joint and task rates and accelerations"),
    "dynamics": (DynamicsRequest, DynamicsAnswer, "The actuator-space dynamic model and the inverse dynamics"),
    "capability": (CapabilityRequest, CapabilityAnswer, "The wrench, twist or acceleration capability"),
    "scene": (SceneRequest, SceneAnswer, "The 3-D scene's body placements"),
    "stiffness": (StiffnessRequest, StiffnessAnswer, "The end effector's compliance with joint springs"),
    "clearance": (ClearanceRequest, ClearanceAnswer, "The signed distances between the bodies (collision geometry)"),
}


# ------------------------------------------------------------------------------------------ models, jobs, errors
class ErrorAnswer(BaseModel):
    """A failure: pkm's error (or the service's) with its message and data."""

    error: str = _field("The error's name (pkm.errors, or InvalidRequest, NotFound, Busy...).", "UnreachableError")
    message: str = _field("What went wrong, in words.", "pose unreachable: leg 1 misses by 0.64 m or rad")
    data: Any = _field("The error's data (its fields; for InvalidRequest, each refused field's loc, msg, type).",
                       {"leg": 1})


class Health(_Answer):
    """The service answers."""

    status: Literal["ok"] = _field("Always ok.", "ok")
    version: str = _field("pkm's version.", "1.0.0")


class ModelEntry(_Answer):
    """A model the service knows."""

    id: str = _field("The model's id, as the {model} of the paths: a registered name, an upload's hash, a variant's "
                     "name@hash.", "delta")
    kind: Literal["registered", "uploaded", "variant"] = _field("Where it comes from.", "registered")
    name: str = _field("The mechanism's name.", "delta")
    files: dict[str, int] = _field("An upload's file names and their sizes [bytes].", {})


class ModelList(_Answer):
    """Every model the service knows."""

    models: list[ModelEntry] = _field("The registered mechanisms, the uploads and the variants.",
                                      [{"id": "delta", "kind": "registered", "name": "delta", "files": {}}])


class ModelDescription(ModelEntry):
    """A model's sizes, names and units: what a client needs to ask about it."""

    nq: int = _field("Coordinates of a configuration q.", 12)
    nv: int = _field("Coordinates of a velocity v.", 12)
    na: int = _field("Actuators.", 3)
    joints: list[str] = _field("Every joint's name.", ["motor_1"])
    actuated: list[str] = _field("The actuated joints, in the order of qa.", ["motor_1", "motor_2", "motor_3"])
    actuated_q: list[int] = _field("The index in q of each actuated joint.", [0, 3, 6])
    actuated_units: list[str] = _field("The unit of each actuated value (rad, m).", ["rad", "rad", "rad"])
    task: list[str] = _field("The task's coordinates (its tangent space: rates, Jacobian rows).", ["x", "y", "z"])
    task_units: dict[str, str] = _field("The unit of each task coordinate.", {"x": "m", "y": "m", "z": "m"})
    task_value_names: list[str] = _field("The entries of a task value y (a pose: x y z qx qy qz qw).",
                                         ["x", "y", "z"])
    task_value_units: list[str] = _field("The unit of each entry of y (a quaternion's: 1).", ["m", "m", "m"])
    q_reference: list[float] = _field("The reference configuration [rad, m].", _Q_EXAMPLE)
    q_units: list[str] = _field("The unit of each coordinate of q (rad, m, 1).", ["rad"] * 9 + ["m"] * 3)
    branches: list[str] = _field("The spec's named branches (working modes).", [])
    limits: dict[str, list[float]] = _field("Position limits of the joints that have some [rad, m].",
                                            {"motor_1": [-1.5, 1.5]})


class Parameter(_Answer):
    """A design parameter of a registered mechanism."""

    name: str = _field("Its name.", "R")
    default: Any = _field("Its default value (SI).", 0.2)
    units: list[str] = _field("Its unit(s).", ["m"])
    description: str = _field("What it is.", "base radius")


class Parameters(_Answer):
    """The design parameters of a registered mechanism (none for an upload)."""

    model: str = _field("The model asked.", "delta")
    registered: str | None = _field("The registered mechanism it is, or is a variant of (null: an upload).", "delta")
    parameters: list[Parameter] = _field("Its design parameters.", [])


class VariantRequest(_Request):
    """A registered mechanism built with other design parameters (as pkm.build)."""

    params: dict[str, float | str] = _field("Design parameters: SI numbers or strings with a unit ('16cm').",
                                            {"R": 0.16})


class FilesAnswer(_Answer):
    """An upload's files."""

    files: dict[str, str] = _field("Each file's name and text.", {"robot.urdf": "<robot name='r'>...</robot>"})


class JobError(_Answer):
    error: str = _field("The error's name.", "InvalidInputError")
    message: str = _field("What went wrong.", "y: expected 3 numbers a sample")


class JobState(_Answer):
    """A job's state."""

    id: str = _field("The job's id.", "0123456789abcdef")
    kind: Literal["assembly_modes", "working_modes", "map", "sweep"] = _field("What it computes.", "map")
    model: str = _field("The model's id.", "delta")
    state: Literal["queued", "running", "done", "failed", "cancelled"] = _field("Where it is.", "running")
    progress: float = _field("From 0 to 1.", 0.7)
    error: JobError | None = _field("Why it failed (state failed).", None)
    created: float = _field("When it was started [s since the epoch].", 1.7e9)
    finished: float | None = _field("When it ended [s since the epoch].", None)


class JobList(_Answer):
    jobs: list[JobState] = _field("The jobs kept (finished ones for an hour).", [])


class AssemblyModesJob(_Request):
    """Every assembly mode at actuated values (pkm.assembly_modes)."""

    qa: Positions = _field("The actuated values (na: rad, m, or strings with a unit).", _QA_EXAMPLE)


class WorkingModesJob(_Request):
    """Every working mode at a task value (pkm.working_modes)."""

    y: Positions = _field("The task value (as task_value_names: m, rad, or strings with a unit).", [0.0, 0.0, -0.35])


class MapJob(_Request):
    """A workspace map (pkm.workspace_map), optionally with the capability at every node."""

    axes: dict[str, list[float | str]] = _field("1 to 3 task coordinates, each [start, stop, count] (start and stop in "
                                                "SI or strings with a unit, '-10cm'; count an integer).",
                                                {"x": [-0.1, 0.1, 21], "y": ["-10cm", "10cm", 21]})
    fixed: dict[str, float | str] | None = _field("The other task coordinates' values (SI, or strings with a unit).",
                                                  {"z": -0.35}, None)
    length: float | str | None = _field("The characteristic length of the condition index [m, or a string with a "
                                        "unit: '5cm']; default the model's.", None, None)
    index: Literal["wrench", "twist", "acceleration"] | None = _field("A capability to map too.", None, None)


class SweepJob(_Request):
    """A design sweep of a registered mechanism (pkm.sweep on Dask)."""

    grid: dict[str, str] = _field("Per parameter, START:STOP:COUNT with units as pkm sweep reads them.",
                                  {"R": "10cm:20cm:5"})
    objectives: list[str] = _field("Objective names or specs.", ["condition"])
    fixed: dict[str, Any] | None = _field("Other parameters' values.", None, None)
    scheduler: str | None = _field("null: a local Dask cluster; 'serial'; or a scheduler's address.", "serial", None)
    workers: int | None = _field("Local workers (1 to 8).", None, None)


_MODES_OUTSIDE = _field("Per mode, the joints outside the position limits the model states, each with its value "
                        "and limits [rad, m] (empty: none; a mode is geometry, listed whether or not it is within).",
                        [[]])


class AssemblyModesResult(_Answer):
    count: int = _field("Assembly modes found.", 2)
    complete: bool = _field("Whether the search is certified complete.", True)
    q: list[list[float]] = _field("Each mode's configuration [rad, m].", [_Q_EXAMPLE])
    y: list[list[float]] = _field("Each mode's task value [m, rad].", [[0.0, 0.0, -0.35]])
    residual: list[float] = _field("Each mode's closure residual [m or rad].", [1e-15])
    labels: list[str] = _field("Each mode's label.", ["(1,)"])
    outside_limits: list[list[OutsideLimit]] = _MODES_OUTSIDE
    seconds: float = _field("The search's time [s].", 0.5)
    units: Units = _field(UNITS, {"q": ["rad"] * 9 + ["m"] * 3, "y": ["m", "m", "m"], "residual": "m or rad",
                                  "seconds": "s"})


class WorkingModesResult(_Answer):
    count: int = _field("Working modes found.", 8)
    complete: bool = _field("Whether the search is certified complete.", True)
    q: list[list[float]] = _field("Each mode's configuration [rad, m].", [_Q_EXAMPLE])
    qa: list[list[float]] = _field("Each mode's actuated values [rad, m].", [_QA_EXAMPLE])
    labels: list[str] = _field("Each mode's label.", ["(1, 1, 1)"])
    outside_limits: list[list[OutsideLimit]] = _MODES_OUTSIDE
    seconds: float = _field("The search's time [s].", 0.5)
    units: Units = _field(UNITS, {"q": ["rad"] * 9 + ["m"] * 3, "qa": ["rad"] * 3, "seconds": "s"})


class MapCapability(_Answer):
    kind: str = _field("Which capability.", "wrench")
    units: dict[str, str] = _field("The unit of each task axis' capability.", {"x": "N"})
    isotropic: dict[str, Any] = _field("Per unit, the isotropic value at every node (null: unreachable).", {})
    along: dict[str, Any] = _field("Per axis, plus and minus at every node (null: unreachable).", {})


class MapResult(_Answer):
    axes: dict[str, list[float]] = _field("Each mapped axis' node values (SI).", {"x": [-0.1, 0.0, 0.1]})
    reachable: Any = _field("Whether each node is reachable (an array over the axes, the last axis first).",
                            [[True]])
    condition_index: Any = _field("The condition index at each node, in [0, 1] (null: unreachable) [1].", [[0.5]])
    nodes: int = _field("Reachable nodes.", 1)
    size: float = _field("The reachable region's length, area or volume (in units.size: m^2, m rad...).", 0.01)
    gci: float | None = _field("The global condition index (its mean over the reachable nodes) [1].", 0.5)
    how: str = _field("How the map was computed.", "ik")
    length: float | None = _field("The characteristic length dividing the angular rates [m] (given, else the "
                                  "mechanism's where the task mixes lengths and angles; null: a task of one kind).",
                                  0.2, None)
    within_limits: Any = _field("Whether each node's configuration lies within the joints' position limits (absent "
                                "where the map did not check them).", [[True]], None)
    clearance: Any = _field("The smallest signed distance between the bodies checked for collision at each node [m] "
                            "(negative: interpenetration; null: unreachable; absent: no collision geometry, or a map "
                            "too large to check by default).", [[0.01]], None)
    interferes: Any = _field("Whether two bodies interpenetrate at each node (absent where not checked).",
                             [[False]], None)
    feasible: Any = _field("Each node reachable, within the limits and free of interference, as far as checked.",
                           [[True]])
    capability: MapCapability | None = _field("With index: the capability at every node.", None, None)
    units: dict[str, Any] = _field("The units: of each axis (m, rad), of size, of the condition index (1).",
                                   {"axes": {"x": "m", "y": "m"}, "size": "m^2", "condition_index": "1", "gci": "1"})


class SweepResult(_Answer):
    columns: list[str] = _field("The table's columns.", ["R", "condition", "status"])
    rows: dict[str, list[Any]] = _field("Each column's values, a row per design.", {"R": [0.1]})
    designs: int = _field("Designs evaluated.", 3)
    failed: int = _field("Designs whose evaluation failed.", 0)


class JobResult(JobState):
    """A finished job's state and result."""

    result: AssemblyModesResult | WorkingModesResult | MapResult | SweepResult = _field(
        "The result, by the job's kind.", {"count": 2})


#: Per job kind: (request model, summary).
JOB_MODELS: dict[str, tuple[type[BaseModel], str]] = {
    "assembly_modes": (AssemblyModesJob, "Every assembly mode at actuated values"),
    "working_modes": (WorkingModesJob, "Every working mode at a task value"),
    "map": (MapJob, "A workspace map, with the capability on request"),
    "sweep": (SweepJob, "A design sweep of a registered mechanism"),
}

#: The request models (their schemas are added to the OpenAPI components by the app).
REQUESTS: list[type[BaseModel]] = [m for m, _, _ in QUERY_MODELS.values()] + [m for m, _ in JOB_MODELS.values()] \
    + [VariantRequest]


def request_schemas() -> dict[str, Any]:
    """The JSON schemas of :data:`REQUESTS`, by model name, with references into ``#/components/schemas``."""
    from pydantic.json_schema import models_json_schema

    _, defs = models_json_schema([(m, "validation") for m in REQUESTS], ref_template="#/components/schemas/{model}")
    return dict(defs.get("$defs", {}))
