"""The mechanisms pkm ships, one package each, and the registry every consumer iterates.

A mechanism package ``pkm.mechanisms.<name>`` implements :class:`MechanismModule`: its design
dataclass ``Params`` (the geometry in SI units, validated for sign and finiteness, and an optional
reference pose), ``reference_pose(params)`` (the given pose, checked, or one found for the design:
reachable and well conditioned), the generators ``urdf_xml``, ``closure_spec`` and ``build``, and the closed forms over the task vector of :class:`pkm.core.TaskMap`
(``closed_form_ik``, ``closed_form_configuration``, and ``closed_form_fk`` or None where it has
no closed-form forward kinematics). :data:`REGISTRY` maps each name to its
:class:`MechanismDefinition`; the command line, the report, the papers, the benchmarks, the
generic and property tests and the fuzzing iterate it.

Optional capabilities are fields of the entry that may be None: its paper study (``paper``), its reference files
(``reference``), its closed-form sweep objectives (``sweeps``, a module of its package; :mod:`pkm.sweeps` finds
them here and names no mechanism).

Adding a mechanism: one package implementing the protocol, and one :data:`REGISTRY` entry (or
:func:`register` at run time, as the tests do for their toy five-bar). See the docs' contributing page
(docs/tour/contributing.md).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import Any, Protocol, cast, runtime_checkable

from pkm.errors import InvalidInputError, UnknownNameError


@runtime_checkable
class MechanismModule(Protocol):
    """What a mechanism package provides (its ``__init__`` re-exports these)."""

    NAME: str
    Params: type

    def urdf_xml(self, params: Any) -> str: ...

    def closure_spec(self, params: Any) -> Any: ...

    def build(self, params: Any = None) -> Any: ...

    def reference_pose(self, params: Any) -> Any: ...

    def closed_form_ik(self, params: Any, y: Any, branch: str | None = None) -> Any: ...

    def closed_form_configuration(self, mech: Any, y: Any, branch: str | None = None) -> Any: ...

    #: Closed-form forward kinematics ``(params, q_actuated, seed=None) -> task vector``, or None.
    closed_form_fk: Callable[..., Any] | None


@dataclass(frozen=True)
class MechanismDefinition:
    """One registered mechanism.

    Attributes:
        name: Its name (``pkm.load(name)``, ``pkm ik NAME``).
        title: One line: what it is and where it comes from.
        package: Import path of the package implementing :class:`MechanismModule`.
        paper: The study module in :mod:`pkm.papers` that reproduces its paper, or None.
        task_scale: Typical excursion of the task about the reference: position [m], angle [rad],
            joint outputs [rad]; used to draw poses near the reference (tests, fuzzing, benchmarks).
        reference: The closure spec of the reference design, a file name in pkm's ``urdf/`` data
            folder (shipped in the wheel; ``pkm.load`` reads it and its URDF), or None: ``pkm.load``
            builds the default ``Params()``.
        origin: Where the task coordinates are measured from, and along which axes (``pkm list`` says it).
        sweeps: Import path of the module of its package declaring its closed-form sweep objectives (the fast
            paths :func:`pkm.sweep` takes: ``CLOSED_FORMS``, objective name -> :class:`pkm.sweeps.objectives.ClosedForm`),
            or None: the generic routes only.
    """

    name: str
    title: str
    package: str
    paper: str | None = None
    task_scale: tuple[float, float, float] = (0.05, 0.1, 0.1)
    reference: str | None = None
    origin: str = "the world frame of the URDF"
    sweeps: str | None = None

    def tangent_scale(self, coordinates: Sequence[str]) -> list[float]:
        """:attr:`task_scale` spread over task coordinates (``x y z`` positions, ``roll pitch yaw wx wy wz``
        angles, anything else a joint output), for drawing poses about the reference."""
        pos, ang, joint = self.task_scale
        return [pos if c in ("x", "y", "z") else ang if c in ("roll", "pitch", "yaw", "wx", "wy", "wz") else joint
                for c in coordinates]

    def module(self) -> MechanismModule:
        """The mechanism's package, imported on first use."""
        return cast(MechanismModule, importlib.import_module(self.package))


#: name -> definition, in the order the report and ``pkm list`` show them.
REGISTRY: dict[str, MechanismDefinition] = {
    d.name: d for d in (
        MechanismDefinition("hexapod", "reconfigurable hexapod of two 3-RUS sub-manipulators (Sanchez-Alonso et al. "
                                       "2016)", "pkm.mechanisms.hexapod", "hexapod", (0.03, 0.08, 0.3),
                            "hexapod.closures.toml", "O, the centre of the reconfiguration pivots F1 F2 F3 (the "
                            "paper's frame: Y the hexapod's axis); position of P, the centre of C4 C5 C6",
                            "pkm.mechanisms.hexapod.sweeps"),
        MechanismDefinition("rrr3", "planar 3-RRR (singularities and global condition index)", "pkm.mechanisms.rrr3",
                            "rrr3", (0.12, 0.3, 0.0), "rrr3.closures.toml",
                            "the base joint A1 of leg 1, x along A1 A2 (the paper's frame): the base centroid is at "
                            "x = H/2, y = H/(2 sqrt 3); position of the platform centroid G",
                            "pkm.mechanisms.rrr3.sweeps"),
        MechanismDefinition("delta", "Delta robot with reconfigurable base radius R (Hernandez Reyna & "
                                     "Sandoval-Castro 2018)", "pkm.mechanisms.delta", "delta", (0.06, 0.0, 0.0),
                            "delta.closures.toml", "the centre of the base, in the plane of the motor axes (the "
                            "paper's frame 0), z up; position of the end-effector centre",
                            "pkm.mechanisms.delta.sweeps"),
        MechanismDefinition("prs3", "3-PRS (Diaz-Rodriguez et al. 2016: kinematics and inverse dynamics)",
                            "pkm.mechanisms.prs3", "prs3", (0.06, 0.15, 0.0), "prs3.closures.toml",
                            "the base centre {O}, z along the sliders' axis of symmetry; height and tilts of the "
                            "platform frame {p}"),
        MechanismDefinition("gough_stewart", "6-UPS Gough-Stewart platform (every assembly mode by homotopy "
                                             "continuation)", "pkm.mechanisms.gough_stewart", None, (0.03, 0.08, 0.0),
                            "gough_stewart.closures.toml", "the centre of the base anchors, z up; pose of the "
                            "platform frame at the centre of its anchors"),
    )
}


def names(*, with_files: bool = False) -> tuple[str, ...]:
    """The registered mechanisms, in registry order; ``with_files``: only those whose reference design
    ships as files (URDF + closure spec in pkm's data folder)."""
    return tuple(n for n, d in REGISTRY.items() if d.reference is not None or not with_files)


def definition(name: str) -> MechanismDefinition:
    """The registry entry of ``name``; :class:`UnknownNameError` listing the registered ones otherwise.

    Examples:
        >>> import pkm
        >>> entry = pkm.mechanism_definition("delta")
        >>> entry.name, entry.reference
        ('delta', 'delta.closures.toml')
        >>> entry.title
        'Delta robot with reconfigurable base radius R (Hernandez Reyna & Sandoval-Castro 2018)'
    """
    if not isinstance(name, str) or name not in REGISTRY:
        raise UnknownNameError("mechanism", repr(name) if not isinstance(name, str) else name, names())
    return REGISTRY[name]


def module(name: str) -> ModuleType:
    """The package of mechanism ``name``.

    Examples:
        >>> import pkm
        >>> mod = pkm.mechanism_module("rrr3")
        >>> mod.__name__, type(mod.Params()).__name__
        ('pkm.mechanisms.rrr3', 'Rrr3Params')
    """
    return cast(ModuleType, definition(name).module())


def register(entry: MechanismDefinition, *, replace: bool = False) -> MechanismDefinition:
    """Add ``entry`` to :data:`REGISTRY` (a mechanism of one's own; the tests register a toy five-bar).

    Its package must import and implement :class:`MechanismModule`.

    Raises:
        InvalidInputError: not a :class:`MechanismDefinition`, the name is taken (unless
            ``replace``), the package lacks part of the protocol, or its ``sweeps`` module declares no
            ``CLOSED_FORMS``.
    """
    if not isinstance(entry, MechanismDefinition):
        raise InvalidInputError("entry", f"expected a MechanismDefinition, got {type(entry).__name__}", entry)
    if entry.name in REGISTRY and not replace:
        raise InvalidInputError("entry", f"a mechanism named {entry.name!r} is registered already", entry.name)
    mod = entry.module()
    missing = [n for n in ("NAME", "Params", "urdf_xml", "closure_spec", "build", "reference_pose", "closed_form_ik",
                           "closed_form_configuration", "closed_form_fk") if not hasattr(mod, n)]
    if missing:
        raise InvalidInputError("entry", f"{entry.package} does not implement MechanismModule: no {missing}",
                                entry.package)
    if entry.sweeps is not None and not isinstance(getattr(importlib.import_module(entry.sweeps), "CLOSED_FORMS",
                                                           None), dict):
        raise InvalidInputError("entry", f"{entry.sweeps} declares no CLOSED_FORMS (objective name -> "
                                         "pkm.sweeps.objectives.ClosedForm)", entry.sweeps)
    REGISTRY[entry.name] = entry
    return entry


def unregister(name: str) -> None:
    """Remove ``name`` from :data:`REGISTRY` (undoes :func:`register`)."""
    definition(name)
    del REGISTRY[name]


__all__ = ["REGISTRY", "MechanismDefinition", "MechanismModule", "definition", "module", "names", "register",
           "unregister"]
