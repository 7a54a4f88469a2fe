"""Quantities with units at the edges: ``"20mm"``, ``"5deg"``, ``"81cm"`` to SI, in the Python API as on the
command line.

pkm computes in SI (m, rad, kg). Wherever the API takes a joint value, a task coordinate or a design
parameter, it also takes a string with a unit suffix, converted here: lengths ``m cm mm``, angles
``rad deg``, masses ``kg g``, times ``s ms us`` (a simulation's duration and step), forces ``N mN kN``, torques
``N m`` (or ``N*m``, ``Nm``), ``mN m``, ``kN m``, angular velocities ``rad/s deg/s rpm`` and velocities ``m/s mm/s`` (an
actuator's effort and speed limits), stiffnesses ``N m/rad kN m/rad N m/deg`` (a revolute joint's) and ``N/m N/mm kN/m``
(a prismatic joint's: a drive's servo stiffness, a spring). A plain number (or a string
without suffix) is SI. A suffix of another kind than the value's is refused (``"3deg"`` for a length), never
silently converted::

    pkm.quantity("20mm")             # 0.02
    pkm.quantity("5deg", "angle")    # 0.0873
    pkm.close_loops(delta, ["-30deg", "-25deg", "-35deg"])
    pkm.solve_ik(delta, {"z": "-36cm"})       # the other task coordinates from the reference
"""

from __future__ import annotations

import math
import re
from collections.abc import Collection, Sequence

import numpy as np
from numpy.typing import ArrayLike

from pkm.errors import InvalidInputError, UnitError
from pkm.validation import as_scalar

#: Unit suffixes: suffix -> (kind, factor to SI). A product's parts are written with a space, ``*`` or nothing
#: between them (``"N m"``, ``"N*m"``, ``"Nm"``: :func:`parse_quantity` reads the first two as the third's spelling).
SUFFIXES: dict[str, tuple[str, float]] = {
    "m": ("length", 1.0), "cm": ("length", 1e-2), "mm": ("length", 1e-3),
    "rad": ("angle", 1.0), "deg": ("angle", math.pi / 180.0),
    "kg": ("mass", 1.0), "g": ("mass", 1e-3),
    "s": ("time", 1.0), "ms": ("time", 1e-3), "us": ("time", 1e-6),
    "N": ("force", 1.0), "mN": ("force", 1e-3), "kN": ("force", 1e3),
    "N m": ("torque", 1.0), "mN m": ("torque", 1e-3), "kN m": ("torque", 1e3),
    "rad/s": ("angular velocity", 1.0), "deg/s": ("angular velocity", math.pi / 180.0),
    "rpm": ("angular velocity", math.pi / 30.0),
    "m/s": ("velocity", 1.0), "mm/s": ("velocity", 1e-3),
    "N m/rad": ("rotational stiffness", 1.0), "kN m/rad": ("rotational stiffness", 1e3),
    "N m/deg": ("rotational stiffness", 180.0 / math.pi),
    "N/m": ("translational stiffness", 1.0), "N/mm": ("translational stiffness", 1e3),
    "kN/m": ("translational stiffness", 1e3),
}
#: The SI unit of each kind a suffix can convert to.
SI_UNITS = {"length": "m", "angle": "rad", "mass": "kg", "time": "s", "force": "N", "torque": "N m",
            "angular velocity": "rad/s", "velocity": "m/s", "rotational stiffness": "N m/rad",
            "translational stiffness": "N/m"}
#: The kind of each SI unit (``"m" -> "length"``), its other spellings too (``"N*m"``, ``"Nm"``, ``"Nm/rad"``).
KIND_OF_UNIT = {v: k for k, v in SI_UNITS.items()} | {"N*m": "torque", "Nm": "torque", "N*m/rad": "rotational stiffness",
                                                       "Nm/rad": "rotational stiffness"}
#: The kind of a joint's value of each order, for a revolute and a prismatic joint (``None``: no suffix, a plain
#: number in SI): positions, rates and efforts take units alike in the API, the CLI and the service.
JOINT_KINDS: dict[str, tuple[str | None, str | None]] = {
    "position": ("angle", "length"), "rate": ("angular velocity", "velocity"), "acceleration": (None, None),
    "effort": ("torque", "force"), "stiffness": ("rotational stiffness", "translational stiffness")}
#: The SI unit of a joint's value of each order, revolute and prismatic.
JOINT_UNITS: dict[str, tuple[str, str]] = {
    "position": ("rad", "m"), "rate": ("rad/s", "m/s"), "acceleration": ("rad/s^2", "m/s^2"), "effort": ("N m", "N"),
    "stiffness": ("N m/rad", "N/m")}
_NUMBER = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-z](?:[A-Za-z*/ ]*[A-Za-z])?)?\s*$")
_PRODUCT = re.compile(r"^(m|k)?N\s*\*?\s*m(/rad|/deg)?$")  # (N m, N*m, Nm; mN m, kN m; N m/rad, Nm/deg)


def _suffix(text: str) -> str:
    """A suffix in :data:`SUFFIXES`' spelling: a torque's product written ``N m`` (from ``N*m``, ``Nm``, ``N  m``), a
    rotational stiffness's ``N m/rad``."""
    m = _PRODUCT.match(text)
    return f"{m.group(1) or ''}N m{m.group(2) or ''}" if m else text


def _listing() -> str:
    """Every suffix by kind, for messages: ``m, cm, mm (length), ...``."""
    kinds: dict[str, list[str]] = {}
    for suffix, (kind, _) in SUFFIXES.items():
        kinds.setdefault(kind, []).append(suffix)
    return "; ".join(f"{', '.join(v)} ({k})" for k, v in kinds.items())


def parse_quantity(text: str, kinds: Collection[str | None], what: str = "value", unit: str = "SI") -> float:
    """A number with an optional unit suffix, converted to SI.

    Args:
        text: ``"120mm"``, ``"-11deg"``, ``"0.81"``, ``"2.5 N m"`` (``"2.5N*m"``, ``"2.5Nm"``), ``"300rpm"``,
            ``"50 mm/s"``.
        kinds: Kinds the quantity may have (:data:`SI_UNITS`' keys: ``"length"``, ``"angle"``, ``"torque"``,
            ``"angular velocity"``...; ``None``: a unit without suffixes, e.g. ``kg m^2``); a plain number is always
            accepted (SI).
        what: Name of the quantity, for messages.
        unit: Its unit(s) as documented, for messages.

    Raises:
        UnitError: Not a number, an unknown suffix, or a suffix of another kind.
    """
    if not isinstance(text, str):
        raise UnitError(what, f"expected a number or a string such as '20mm', got {type(text).__name__}", text)
    m = _NUMBER.match(text)
    if not m:
        raise UnitError(what, f"{what}={text!r} is not a number (with an optional unit: {_listing()})", text)
    value, suffix = float(m.group(1)), _suffix(m.group(2) or "")
    if not math.isfinite(value):
        raise UnitError(what, f"{what}={text!r} is not finite", text)
    if not suffix:
        return value
    if suffix not in SUFFIXES:
        raise UnitError(what, f"{what}={text}: unknown unit {suffix!r}; use {_listing()}, or no unit for SI", text)
    kind, factor = SUFFIXES[suffix]
    if kind not in kinds:
        accepted = [s for s, (k, _) in SUFFIXES.items() if k in kinds]
        hint = f"use {', '.join(accepted)} or no unit" if accepted else "give the number in that unit, no suffix"
        article = "an" if kind[0] in "aeiou" else "a"
        raise UnitError(what, f"{what}={text}: {suffix!r} is {article} {kind} unit but {what} is in [{unit}]; {hint}",
                        text)
    return value * factor


def split_range(text: str, what: str, max_count: int = 10**7) -> tuple[str, str, int]:
    """``START:STOP:COUNT`` as its two texts (units parsed by the caller, who knows the kind) and the count.

    Raises:
        InvalidInputError: not three fields, or a count that is not a whole number in ``[1, max_count]``.
    """
    parts = text.split(":") if isinstance(text, str) else []
    count = parts[2].strip() if len(parts) == 3 else ""
    if not (count.isascii() and count.isdigit()) or not 1 <= int(count) <= max_count:
        raise InvalidInputError(what, f"{what}={text!r}: expected START:STOP:COUNT with a COUNT in [1, {max_count}], "
                                      "e.g. 30cm:80cm:11", text)
    return parts[0], parts[1], int(count)


def quantity(value: object, kind: str | None = None, what: str = "value") -> float:
    """``value`` in SI: a number as it is, a string parsed with its unit (:func:`parse_quantity`).

    Args:
        value: ``0.02``, ``"20mm"``, ``"5deg"``.
        kind: A kind of :data:`SI_UNITS` (``"length"``, ``"angle"``, ``"torque"``...) to accept only its units;
            None: any.
        what: Its name, for messages.

    Raises:
        UnitError: a bad string (see :func:`parse_quantity`); InvalidInputError: neither a number nor a string,
            or not finite.

    Examples:
        >>> import pkm
        >>> pkm.quantity("20mm")
        0.02
        >>> round(pkm.quantity("90deg", "angle"), 6)
        1.570796
        >>> pkm.quantity(0.5)
        0.5
    """
    if kind is not None and (not isinstance(kind, str) or kind not in SI_UNITS):
        raise InvalidInputError("kind", f"use one of {list(SI_UNITS)} or None", kind)
    if isinstance(value, str):
        kinds = {kind} if kind else set(SI_UNITS)
        return parse_quantity(value, kinds, what, SI_UNITS[kind] if kind else "SI")
    return as_scalar(value, what)


def joint_kind(revolute: bool, order: str = "position") -> str | None:
    """The kind (:data:`SI_UNITS`' keys) of a joint's value of ``order`` (:data:`JOINT_KINDS`: ``"position"``,
    ``"rate"``, ``"acceleration"``, ``"effort"``), revolute or prismatic; None: a plain number only."""
    return JOINT_KINDS[order][0 if revolute else 1]


def joint_unit(revolute: bool, order: str = "position") -> str:
    """The SI unit of a joint's value of ``order`` (:data:`JOINT_UNITS`), revolute or prismatic."""
    return JOINT_UNITS[order][0 if revolute else 1]


def parse_joint_value(text: str, revolute: bool, order: str, what: str) -> float:
    """A joint's value of ``order`` written ``"-30deg/s"``, ``"2 N m"``, ``"0.5"`` (SI), converted to SI: the one
    route of the CLI's ``--joints``, ``--rates``, ``--q0`` and of the service's unit strings.

    Raises:
        UnitError: not a number, or a unit of another kind.
    """
    kind = joint_kind(revolute, order)
    return parse_quantity(text, {kind} if kind else set(), what, joint_unit(revolute, order))


def quantities(values: ArrayLike, kinds: Sequence[str | None], what: str) -> ArrayLike:
    """``values`` (a sequence) with every string entry converted by the kind at its position; other entries as
    they are (the numeric checks follow in :func:`pkm.validation.as_vector`); a numpy array of strings as its list."""
    if isinstance(values, np.ndarray) and values.dtype.kind in "UO" and values.ndim == 1:
        values = values.tolist()
    if isinstance(values, (str, bytes)) or not isinstance(values, (list, tuple)):
        return values
    if not any(isinstance(v, str) for v in values):
        return values
    return [quantity(v, k, f"{what}[{i}]") if isinstance(v, str) else v for i, (v, k) in
            enumerate(zip(values, kinds))] + list(values[len(kinds):])


__all__ = ["JOINT_KINDS", "JOINT_UNITS", "KIND_OF_UNIT", "SI_UNITS", "SUFFIXES", "joint_kind", "joint_unit",
           "parse_joint_value", "parse_quantity", "quantities", "quantity"]
