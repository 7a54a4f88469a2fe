"""Actuators: the motor and transmission behind each actuated joint.

An :class:`Actuator` holds what the dynamics needs of a drive, in the joint's own units (a revolute joint's
[N m], [rad/s]; a prismatic joint's [N], [m/s]):

* the **reflected inertia** added to the joint's diagonal of the mass matrix: ``rotor_inertia * gear_ratio**2 +
  armature`` (MuJoCo's and Pinocchio's ``armature`` is that sum for a rotor of inertia ``rotor_inertia`` [kg m^2]
  turning ``gear_ratio`` times faster than the joint);
* **friction**: ``viscous`` [N m s/rad] and ``coulomb`` [N m] (MuJoCo's ``damping`` and ``frictionloss``, URDF's
  ``<dynamics damping friction>``), opposing the joint's rate;
* **limits**: ``effort_limit`` (continuous) and ``peak_effort`` [N m], ``velocity_limit`` [rad/s]; ``inf`` for
  none. The peak bounds what a simulation applies (:func:`pkm.simulate` saturates there), the continuous limit is
  the one a capability analysis holds for ever;
* the **servo stiffness** ``stiffness`` [N m/rad; N/m]: how stiffly the position-controlled drive holds its joint
  (the controller's proportional gain seen at the joint, the transmission's compliance in series), the compliance
  :func:`pkm.stiffness` gives an actuated joint its ``joints=`` argument does not; ``inf`` (the default): a rigid
  drive. The dynamics do not apply it (it is a controller's gain: :func:`pkm.simulate`'s controllers hold the
  drives), and no model file states it (MJCF's ``<position kp>`` is not read as one).

Where the values come from, later sources overriding earlier ones per field:

1. the model file: a URDF through Pinocchio's own fields of the model (``armature``, ``rotorInertia``,
   ``rotorGearRatio``, ``damping``, ``friction``, ``effortLimit``, ``velocityLimit``: ``<limit effort
   velocity>`` and ``<dynamics damping friction>``); an MJCF through the reader's table
   (:attr:`pkm.core.formats.base.Imported.actuators`: joint ``armature``, ``damping``, ``frictionloss``, the
   motor's ``gear`` times its ``forcerange``/``ctrlrange``; see :mod:`pkm.core.formats.mjcf`). A limit of 0 or of
   at least 1e6 in a file means "not given" (exporters write ``effort="0"`` on passive joints and ``1e30`` for
   "unlimited"); it reads as ``inf``;
2. the closure spec's ``[actuators.<joint>]`` tables (:mod:`pkm.core.model.spec`), keys as the attributes below::

       [actuators.motor_1]
       rotor_inertia = 3.3e-5       # kg m^2
       gear_ratio = 50.0
       viscous = 0.02               # N m s/rad
       coulomb = 0.1                # N m
       effort_limit = 20.0          # N m, continuous
       peak_effort = 60.0           # N m
       velocity_limit = 6.0         # rad/s
       stiffness = "2000 N m/rad"   # servo stiffness: a number (SI) or a string with its unit (pkm.units)

Every field is a number in SI; ``stiffness`` may also be a string with its unit (``"2 kN m/rad"``, ``"5 N/mm"`` for a
prismatic drive), kept as written in the spec (:func:`pkm.save` writes it back so) and converted when the mechanism is
built, where the joint's kind is known: a prismatic joint's unit on a revolute drive is refused, never converted.

The mechanism writes the merged values back into its Pinocchio model (``armature`` = the reflected inertia, so
that ``crba``, ``rnea`` and the kinetic energy include it; ``damping``, ``friction``, the limits), so every
algorithm of pkm and of Pinocchio sees the same drives.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.errors import InvalidInputError, SpecError, UnitError
from pkm.units import JOINT_KINDS, JOINT_UNITS, parse_joint_value, parse_quantity

UNLIMITED = 1e6  # a file's limit at least this large (or 0) means "none": it reads as inf
#: A stiffness (or damping) at least this large is no spring a file (or a caller) means: a unit mistake.
MAGNITUDE = 1e12


@dataclass(frozen=True)
class Actuator:
    """The drive of one actuated joint (SI, the joint's units; see the module doc).

    Attributes:
        joint: The actuated joint's name.
        rotor_inertia: The rotor's inertia about its axis [kg m^2] (a linear motor's moving mass [kg]).
        gear_ratio: Rotor turns per joint turn (> 0).
        armature: Reflected inertia added to ``rotor_inertia * gear_ratio**2`` [kg m^2 or kg] (MuJoCo's
            ``armature``: a file that gives the reflected inertia directly puts it here).
        viscous: Viscous friction [N m s/rad or N s/m].
        coulomb: Coulomb (dry) friction [N m or N].
        effort_limit: Continuous effort limit [N m or N]; ``inf``: none.
        peak_effort: Peak effort limit [N m or N]; ``inf``: the continuous limit.
        velocity_limit: Joint speed limit [rad/s or m/s]; ``inf``: none.
        stiffness: The servo stiffness [N m/rad or N/m] (> 0, below :data:`MAGNITUDE`); ``inf`` (default): a rigid
            drive. :func:`pkm.stiffness` takes it where its ``joints=`` gives the joint none.
    """

    joint: str
    rotor_inertia: float = 0.0
    gear_ratio: float = 1.0
    armature: float = 0.0
    viscous: float = 0.0
    coulomb: float = 0.0
    effort_limit: float = math.inf
    peak_effort: float = math.inf
    velocity_limit: float = math.inf
    stiffness: float = math.inf

    def __post_init__(self) -> None:
        if not isinstance(self.joint, str):
            raise InvalidInputError("joint", f"expected the actuated joint's name, got {self.joint!r}", self.joint)
        for f in NUMBERS:
            value = getattr(self, f)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
                raise InvalidInputError(f, f"actuator {self.joint!r}: expected a number, got {value!r}", value)
            try:
                value = float(value)
            except OverflowError:  # (an int beyond the floats)
                value = math.inf if value > 0 else -math.inf
            if math.isnan(value) or value < 0.0 or (math.isinf(value) and f not in INFINITE):
                raise InvalidInputError(f, f"actuator {self.joint!r}: {f} must be a finite number >= 0"
                                           f"{' (or inf: none)' if f in INFINITE else ''}, got {value!r}", value)
            object.__setattr__(self, f, value)
        zero = next((f for f in ("gear_ratio", "effort_limit", "peak_effort", "velocity_limit", "stiffness")
                     if getattr(self, f) == 0.0), None)
        if zero is not None:
            free = " (a drive that yields freely: its joint given 0 in pkm.stiffness's joints=)" \
                if zero == "stiffness" else ""
            raise InvalidInputError(zero, f"actuator {self.joint!r}: {zero} must be > 0{free}", 0.0)
        if MAGNITUDE <= self.stiffness < math.inf:
            raise InvalidInputError("stiffness", f"actuator {self.joint!r}: a servo stiffness below {MAGNITUDE:g} "
                                                 "(N m/rad, N/m: a unit mistake?), or inf for a rigid drive",
                                    self.stiffness)
        if math.isfinite(self.peak_effort) and math.isfinite(self.effort_limit) and self.peak_effort < self.effort_limit:
            raise InvalidInputError("peak_effort", f"actuator {self.joint!r}: the peak effort {self.peak_effort:g} is "
                                                   f"below the continuous limit {self.effort_limit:g}", self.peak_effort)
        if not math.isfinite(self.reflected_inertia):
            raise InvalidInputError("rotor_inertia", f"actuator {self.joint!r}: the reflected inertia rotor_inertia * "
                                                     "gear_ratio**2 + armature overflows", self.rotor_inertia)

    @property
    def reflected_inertia(self) -> float:
        """``rotor_inertia * gear_ratio**2 + armature`` [kg m^2 or kg]: the inertia the joint feels."""
        return self.rotor_inertia * self.gear_ratio * self.gear_ratio + self.armature  # (no pow: it raises on overflow)

    @property
    def max_effort(self) -> float:
        """The largest effort the drive applies: the peak limit, else the continuous one [N m or N]."""
        return self.peak_effort if math.isfinite(self.peak_effort) else self.effort_limit


NUMBERS = tuple(f.name for f in fields(Actuator) if f.name != "joint")
LIMITS = ("effort_limit", "peak_effort", "velocity_limit")
#: The fields that may be ``inf`` (a limit: none; the servo stiffness: a rigid drive).
INFINITE = (*LIMITS, "stiffness")
#: The fields a spec may write as a string with its unit (:mod:`pkm.units`): ``{field: its order}``
#: (:data:`pkm.units.JOINT_KINDS`, a revolute's unit or a prismatic's).
WITH_UNITS = {"stiffness": "stiffness"}
UNITS = {"rotor_inertia": "kg m^2", "gear_ratio": "1", "armature": "kg m^2", "viscous": "N m s/rad",
         "coulomb": "N m", "effort_limit": "N m", "peak_effort": "N m", "velocity_limit": "rad/s",
         "stiffness": "N m/rad"}
"""The unit of each field for a revolute joint (a prismatic joint's: kg, N s/m, N, m/s)."""


def number_tables(raw: object, section: str, keys: tuple[str, ...], source: str,
                  units: Mapping[str, str] | None = None) -> dict[str, dict[str, Any]]:
    """A closure spec's ``[<section>.<joint>]`` tables of numbers (``[actuators]``, ``[springs]``): ``{joint: {key:
    value}}``, each key one of ``keys``, each value a number (as a float; its range is the caller's to check), or, for
    a key of ``units`` (``{key: a joint value's order}``, :data:`pkm.units.JOINT_KINDS`), a string with a unit of that
    order, a revolute's or a prismatic's (kept as written: the joint's kind decides at build, :func:`si_value`).

    Raises:
        SpecError: not a table of tables, an unknown key, a value that is not a number, a string that is no
            quantity of its order.
    """
    if not isinstance(raw, Mapping):
        raise SpecError(source, f"[{section}] must be a table of [{section}.<joint>] tables")
    out: dict[str, dict[str, float]] = {}
    for joint, table in raw.items():
        if not isinstance(table, Mapping):
            raise SpecError(source, f"{section}.{joint} must be a table (keys: {', '.join(keys)})")
        unknown = sorted(set(table) - set(keys))
        if unknown:
            raise SpecError(source, f"{section}.{joint}: unknown keys {unknown}; known: {list(keys)}")
        values: dict[str, Any] = {}
        for key, value in table.items():
            if isinstance(value, str) and units and key in units:
                try:
                    si_value(key, value)
                except UnitError as exc:
                    raise SpecError(source, f"{section}.{joint}: {exc}") from None
                values[key] = value
                continue
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise SpecError(source, f"{section}.{joint}.{key} must be a number, got {type(value).__name__}")
            values[key] = float(value)
        out[str(joint)] = values
    return out


def parse_table(raw: object, source: str) -> dict[str, dict[str, Any]]:
    """The ``[actuators]`` table of a closure spec: ``{joint: {field: value}}``, checked (a ``stiffness`` may be a
    string with its unit, kept as written: module doc).

    Raises:
        SpecError: not a table of tables, an unknown key, a value that is not a number, negative or NaN, a unit that
            is no stiffness's.
    """
    out = number_tables(raw, "actuators", NUMBERS, source, WITH_UNITS)
    for joint, values in out.items():
        try:
            Actuator(str(joint), **{k: si_value(k, v) for k, v in values.items()})
        except InvalidInputError as exc:
            raise SpecError(source, f"actuators.{joint}: {exc}") from None
    return out


def si_value(key: str, value: float | str, revolute: bool | None = None) -> float:
    """A spec table's value in SI: a number as it is, a string with a unit (a key of :data:`WITH_UNITS`) converted
    with the unit of a revolute joint's value (``revolute``), of a prismatic's, or (``None``: the joint not known
    yet) of either.

    Raises:
        UnitError: not a quantity, or a unit of another kind (a prismatic joint's stiffness on a revolute).
    """
    if not isinstance(value, str):
        return float(value)
    order = WITH_UNITS.get(key)
    if order is None:
        raise UnitError(key, f"{key} is a number (SI), got {value!r}", value)
    if revolute is None:
        return parse_quantity(value, set(JOINT_KINDS[order]), key, " or ".join(JOINT_UNITS[order]))
    return parse_joint_value(value, revolute, order, key)


def _limit(value: float) -> float:
    value = abs(float(value))
    return math.inf if value == 0.0 or value >= UNLIMITED or not math.isfinite(value) else value


def from_model(model: pin.Model, joint: str, idx_v: int, overrides: Mapping[str, float | str] | None = None) \
        -> Actuator:
    """The actuator of ``joint`` (velocity index ``idx_v``) from Pinocchio's fields of ``model``, then
    ``overrides`` (a spec's table; a value with a unit converted with the joint's kind, :func:`si_value`).

    Pinocchio's ``armature`` is read as the whole reflected inertia (what its algorithms use), so the actuator's
    own ``armature`` is what it holds beyond ``rotorInertia * rotorGearRatio**2`` (none if it holds less): a model
    written by :func:`write_model` reads back the same actuator."""
    ratio = float(model.rotorGearRatio[idx_v])
    ratio = ratio if ratio > 0.0 and math.isfinite(ratio) else 1.0
    rotor = max(float(model.rotorInertia[idx_v]), 0.0)
    base = Actuator(joint,
                    rotor_inertia=rotor,
                    gear_ratio=ratio,
                    armature=max(float(model.armature[idx_v]) - rotor * ratio * ratio, 0.0),
                    viscous=max(float(model.damping[idx_v]), 0.0),
                    coulomb=max(float(model.friction[idx_v]), 0.0),
                    effort_limit=_limit(model.effortLimit[idx_v]),
                    velocity_limit=_limit(model.velocityLimit[idx_v]))
    revolute = not model.joints[model.getJointId(joint)].shortname().startswith("JointModelP")
    values = {k: si_value(k, v, revolute) for k, v in (overrides or {}).items()}
    return replace(base, **values)  # type: ignore[arg-type]  # (field names checked by parse_table)


def write_model(model: pin.Model, actuator: Actuator, idx_v: int) -> None:
    """Write ``actuator`` into Pinocchio's fields of ``model`` at velocity index ``idx_v`` (``armature`` = the
    reflected inertia; limits ``inf`` as Pinocchio's ``inf``)."""
    for name, value in (("armature", actuator.reflected_inertia), ("rotorInertia", actuator.rotor_inertia),
                        ("rotorGearRatio", actuator.gear_ratio), ("damping", actuator.viscous),
                        ("friction", actuator.coulomb), ("effortLimit", actuator.effort_limit),
                        ("velocityLimit", actuator.velocity_limit)):
        vec = np.array(getattr(model, name), dtype=float)
        vec[idx_v] = value
        setattr(model, name, vec)
    # rotorInertia * ratio^2 is already in armature: keep Pinocchio from adding it again if a version ever does
    # (4.1 reads only armature)


def limit_sources(mech: object) -> dict[str, dict[str, tuple[float, str]]]:
    """Each actuated joint's limits and where each comes from: ``{joint: {field: (value, source)}}`` for the
    fields of :data:`LIMITS`, the source ``"spec"`` (the closure spec's ``[actuators.<joint>]`` table, where
    :func:`pkm.with_actuators` writes too), ``"file <source>"`` (the model file's ``<limit>``) or ``"none"`` (no limit:
    ``inf``). ``mech``: a :class:`~pkm.core.model.mechanism.Mechanism`."""
    spec_tables = mech.spec.actuators  # type: ignore[attr-defined]
    source = mech.spec.urdf or mech.source  # type: ignore[attr-defined]
    out: dict[str, dict[str, tuple[float, str]]] = {}
    for a in mech.actuators:  # type: ignore[attr-defined]
        stated = spec_tables.get(a.joint, {})
        row = {}
        for f in LIMITS:
            value = float(getattr(a, f))
            row[f] = (value, "spec" if f in stated else "none" if not math.isfinite(value) else f"file {source}")
        out[a.joint] = row
    return out


def as_actuators(values: ArrayLike | Mapping[str, object], names: tuple[str, ...],
                 revolute: Mapping[str, bool] | None = None) -> dict[str, Actuator]:
    """Checked ``{joint: Actuator}`` from ``{joint: Actuator | {field: value}}`` (joints among ``names``; a
    ``stiffness`` may be a string with its unit, of a revolute joint's or a prismatic's as ``revolute`` says)."""
    if not isinstance(values, Mapping):
        raise InvalidInputError("actuators", "expected {joint: Actuator or {field: value}}", values)
    out = {}
    for joint, value in values.items():
        if joint not in names:
            raise InvalidInputError("actuators", f"{joint!r} is not an actuated joint; actuated: {list(names)}", joint)
        if isinstance(value, Actuator):
            out[joint] = replace(value, joint=joint)
        elif isinstance(value, Mapping):
            unknown = sorted(set(value) - set(NUMBERS))
            if unknown:
                raise InvalidInputError("actuators", f"{joint}: unknown fields {unknown}; known: {list(NUMBERS)}",
                                        unknown)
            kind = (revolute or {}).get(joint)
            out[joint] = Actuator(joint, **{str(k): si_value(str(k), v, kind) if isinstance(v, str) else v
                                            for k, v in value.items()})  # type: ignore[arg-type]
        else:
            raise InvalidInputError("actuators", f"{joint}: expected an Actuator or a table, got {value!r}", value)
    return out


__all__ = [
    "INFINITE",
    "LIMITS",
    "MAGNITUDE",
    "NUMBERS",
    "UNITS",
    "Actuator",
    "as_actuators",
    "from_model",
    "limit_sources",
    "parse_table",
    "si_value",
    "write_model",
]
