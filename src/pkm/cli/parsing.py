"""What the command line says, read: a mechanism's parameters with their units and descriptions (its ``Params``
dataclass and docstring), and the ``NAME=VALUE`` items of ``--param``, ``--pose``, ``--joints``, ``--q0``,
``--rates`` and ``--axis`` as SI values (units as :mod:`pkm.units` reads them, for joints by
:func:`pkm.units.parse_joint_value`: the route the library and the service take)."""

from __future__ import annotations

import dataclasses
import inspect
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

import pkm
from pkm._moved import current_name
from pkm.cli.usage import UsageError
from pkm.errors import InvalidInputError, UnknownNameError
from pkm.units import KIND_OF_UNIT, SI_UNITS, parse_joint_value, parse_quantity, split_range

_UNIT = re.compile(r"\[([A-Za-z][A-Za-z0-9^ /*.-]*|-)\]")
_ITEM = re.compile(r"^([A-Za-z_]\w*(?:\s*,\s*[A-Za-z_]\w*)*):\s*(.*)$")
_UNITLESS_TYPES = ("str", "int", "bool")


@dataclass(frozen=True)
class ParamInfo:
    """One field of a mechanism's ``Params`` dataclass, as documented.

    Attributes:
        name: Field name.
        type: Its annotation, as written (``"float"``, ``"tuple[float, ...]"``, ``"str"``).
        default: The default value (SI; None: found for the design, such as the reference pose).
        units: The field's units from its metadata (``("m",)``, ``("m", "rad")``); empty for a field
            without one (text, integers).
        description: The docstring entry, backticks removed.
        length: The number of values of a tuple field (its metadata), None for a scalar.
    """

    name: str
    type: str
    default: Any
    units: tuple[str, ...]
    description: str
    length: int | None = None

    @property
    def unitless(self) -> bool:
        """A text, integer or boolean field: no unit by nature."""
        return self.type in _UNITLESS_TYPES

    @property
    def unit(self) -> str:
        """The units for display (``"-"`` when none)."""
        return ", ".join(self.units) or "-"

    @property
    def summary(self) -> str:
        """The first sentence of the description, units and defaults in brackets left out."""
        first = re.split(r"(?<=\.)\s", self.description, maxsplit=1)[0]
        return re.sub(r"\s+([;,)])", r"\1", re.sub(r"\s+", " ", _UNIT.sub("", first))).strip().rstrip(".")


def attribute_docs(cls: type) -> dict[str, str]:
    """``{field: description}`` from the ``Attributes:`` section of a Google-style class docstring.

    An entry may name several fields (``Ixx3, Iyy3, Izz3: ...``); continuation lines are joined.
    """
    lines = inspect.cleandoc(cls.__doc__ or "").splitlines()
    try:
        start = next(i for i, ln in enumerate(lines) if ln.strip() == "Attributes:") + 1
    except StopIteration:
        return {}
    base = len(lines[start - 1]) - len(lines[start - 1].lstrip())
    out: dict[str, str] = {}
    names: list[str] = []
    indent = None
    for ln in lines[start:]:
        if not ln.strip():
            continue
        ind = len(ln) - len(ln.lstrip())
        if ind <= base:
            break
        if indent is None:
            indent = ind
        m = _ITEM.match(ln.strip()) if ind == indent else None
        if m:
            names = [n.strip() for n in m.group(1).split(",")]
            for n in names:
                out[n] = m.group(2).strip()
        else:
            for n in names:
                out[n] += " " + ln.strip()
    return out


def param_info(mechanism: str) -> dict[str, ParamInfo]:
    """The parameters of ``mechanism`` with their defaults, their units (the fields' metadata, see
    :func:`pkm.mechanisms._common.param`) and their descriptions (the class docstring).

    Raises:
        UnknownNameError: ``mechanism`` is not one of :data:`pkm.MECHANISMS`.
    """
    cls = pkm.mechanism_module(mechanism).Params
    docs = attribute_docs(cls)
    defaults = cls()
    out = {}
    for f in dataclasses.fields(cls):
        text = docs.get(f.name, "").replace("``", "")
        units = tuple(f.metadata.get("units", ()))
        ftype = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", str(f.type))
        out[f.name] = ParamInfo(f.name, ftype, getattr(defaults, f.name), units, text, f.metadata.get("length"))
    return out


def _kinds(units: Sequence[str]) -> set[str | None]:
    return {KIND_OF_UNIT.get(u) for u in units}


def split_item(item: str, what: str) -> tuple[str, str]:
    """``NAME=VALUE`` as ``(name, value)``, stripped; :class:`UsageError` naming option ``what`` otherwise."""
    name, eq, value = item.partition("=")
    if not eq or not name.strip() or not value.strip():
        raise UsageError(f"{what} {item!r} must read NAME=VALUE (e.g. R=120mm)")
    return name.strip(), value.strip()

def parse_params(mechanism: str, items: Sequence[str]) -> dict[str, Any]:
    """``--param`` items ``NAME=VALUE`` as keyword arguments of the mechanism's ``Params`` (SI).

    Raises:
        UsageError: Missing ``=``, a bad number or unit, or the wrong number of tuple entries.
        UnknownNameError: A name that is not a parameter (the valid names listed).
    """
    info = param_info(mechanism)
    out: dict[str, Any] = {}
    for item in items:
        name, text = split_item(item, "--param")
        name = current_name(pkm.mechanism_module(mechanism).Params, name)  # a deprecated former name: warned
        if name not in info:
            raise UnknownNameError("parameter", name, list(info), mechanism)
        p = info[name]
        if p.type == "str":
            out[name] = text
        elif p.type == "int":
            try:
                out[name] = int(text)
            except ValueError:
                raise UsageError(f"{name}={text!r}: {name} takes an integer") from None
        elif p.type == "bool":
            if text.lower() not in ("true", "false", "1", "0"):
                raise UsageError(f"{name}={text!r}: {name} takes true or false")
            out[name] = text.lower() in ("true", "1")
        elif p.length is not None:
            parts = text.split(",")
            if len(parts) != p.length:
                raise UsageError(f"{name} takes {p.length} comma-separated values, got {len(parts)} in {text!r}")
            per = [{KIND_OF_UNIT.get(u)} for u in p.units] if len(p.units) == len(parts) else \
                [_kinds(p.units)] * len(parts)
            out[name] = tuple(parse_quantity(s, k, name, p.unit) for s, k in zip(parts, per))
        else:
            out[name] = parse_quantity(text, _kinds(p.units), name, p.unit)
    return out



def joint_value(mech: pkm.Mechanism, name: str, text: str, order: str = "position") -> float:
    """Joint ``name``'s value of ``order`` (``"position"``, ``"rate"``, ``"effort"``) written with or without its
    unit, in SI (:func:`pkm.units.parse_joint_value`: the route the library and the service take too)."""
    return parse_joint_value(text, mech.joints[name].revolute, order, name)


def parse_task(mech: pkm.Mechanism, items: Sequence[str], option: str = "--pose") -> dict[str, float]:
    """``--pose`` items ``NAME=VALUE`` (units allowed) as the task coordinates they name, in SI.

    Raises:
        UnitError: a bad number or unit; UsageError: a missing ``=``.
        UnknownNameError: A name that is not a task coordinate.
    """
    task = pkm.TaskMap.of(mech)
    out: dict[str, float] = {}
    for item in items:
        name, text = split_item(item, option)
        if name not in task.kinds:
            raise UnknownNameError("task coordinate", name, list(task.keys), mech.name)
        kind = task.kinds[name]
        out[name] = parse_quantity(text, {kind}, name, SI_UNITS[kind])
    return out


def parse_pose(mech: pkm.Mechanism, items: Sequence[str]) -> tuple[dict[str, float], Any]:
    """``--pose`` items as (named values, target for :func:`pkm.solve_ik`); others keep the reference.

    Raises:
        UnitError: a bad number or unit; UsageError: a missing ``=``.
        UnknownNameError: A name that is not a task coordinate.
    """
    values = pkm.TaskMap.of(mech).named(mech.q_reference) | parse_task(mech, items)
    return values, values


def parse_joints(mech: pkm.Mechanism, items: Sequence[str], option: str = "--joints") -> np.ndarray:
    """``--joints`` items ``NAME=VALUE`` as actuated coordinates; actuated joints not named keep the reference.

    Raises:
        UsageError: Missing ``=`` or a bad number or unit.
        UnknownNameError: A name that is not an actuated joint.
    """
    return _actuated_items(mech, items, option, mech.actuated_q(mech.q_reference),
                           lambda name, text: joint_value(mech, name, text))


def parse_seed(mech: pkm.Mechanism, items: Sequence[str] | None, option: str = "--q0") -> np.ndarray | None:
    """``--q0`` items ``NAME=VALUE`` (any one-coordinate joint: revolute or prismatic, actuated or passive; units
    allowed) as a seed configuration (nq,): the joints not named keep the reference. None without items.

    Raises:
        UsageError: Missing ``=``; UnitError: a bad number or unit.
        UnknownNameError: A name that is not a joint of one coordinate.
    """
    if not items:
        return None
    q = mech.q_reference.copy()
    names = [n for n, j in mech.joints.items() if j.nq == 1]
    for item in items:
        name, text = split_item(item, option)
        if name not in names:
            raise UnknownNameError("joint of one coordinate", name, names, mech.name)
        q[mech.joints[name].idx_q] = joint_value(mech, name, text)
    return q


def parse_rates(mech: pkm.Mechanism, items: Sequence[str], option: str = "--rates") -> np.ndarray:
    """Items ``NAME=VALUE`` as actuated rates in SI [rad/s or m/s], written with or without a rate unit
    (``-30deg/s``, ``300rpm``, ``50mm/s``; a position's unit is refused: deg is not deg/s); actuated joints not
    named: zero.

    Raises:
        UsageError: Missing ``=``; UnitError: not a number, or a unit that is not a rate's.
        UnknownNameError: A name that is not an actuated joint.
    """
    return _actuated_items(mech, items, option, np.zeros(mech.na),
                           lambda name, text: joint_value(mech, name, text, "rate"))


def _actuated_items(mech: pkm.Mechanism, items: Sequence[str], option: str, values: np.ndarray,
                    parse: Callable[[str, str], float]) -> np.ndarray:
    """``values`` (na,) with the actuated joints named by ``NAME=VALUE`` items set to ``parse(name, text)``."""
    names = list(mech.actuated_names)
    for item in items:
        name, text = split_item(item, option)
        if name not in names:
            raise UnknownNameError("actuated joint", name, names, mech.name)
        values[names.index(name)] = parse(name, text)
    return values



def parse_axis(mech: pkm.Mechanism, item: str) -> tuple[str, np.ndarray]:
    """An ``--axis`` item ``NAME=START:STOP:COUNT`` (units allowed on START and STOP) as ``(name, values)`` in SI.

    Raises:
        UsageError: not of that form; UnitError: a bad number or unit; UnknownNameError: not a task coordinate.
    """
    name, text = split_item(item, "--axis")
    task = pkm.TaskMap.of(mech)
    if name not in task.kinds:
        raise UnknownNameError("task coordinate", name, list(task.keys), mech.name)
    try:
        a, b, count = split_range(text, name)
    except InvalidInputError:
        raise UsageError(f"--axis {item!r}: expected NAME=START:STOP:COUNT, e.g. x=-5cm:5cm:101") from None
    kind = task.kinds[name]
    start, stop = (parse_quantity(t, {kind}, name, SI_UNITS[kind]) for t in (a, b))
    return name, np.linspace(start, stop, count)
