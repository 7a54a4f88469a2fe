"""What every model-file reader gives and where the readers are registered.

:class:`Imported` is pkm's one representation of a model file (URDF text plus what a closure spec adds: loops,
joint types, actuators). :data:`FORMATS` is the one table of model-file formats: each :class:`Format` names its
suffixes, its XML root element and its reader (a function ``read(text, source) -> Imported``, named as
``"module:function"`` and imported on first use). :func:`pkm.load`, ``pkm spec init`` and the command line go
through it (:func:`~pkm.core.formats.imported.import_model`), so adding a format is one reader module and one
:func:`register_format` call (or one line of :data:`FORMATS`). The readers import this module, the dispatcher
imports them on use: no import cycle."""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Callable
from dataclasses import dataclass

from pkm.core.model.spec import Closure


@dataclass(frozen=True)
class Imported:
    """A model file read into pkm's one representation.

    Attributes:
        urdf: The tree as URDF text (frames for the closures' anchors included).
        closures: The loops the file closes (none for a plain URDF).
        joint_types: Joints URDF cannot state (``spherical``, ``universal``), for ``[joint_types]``.
        actuated: The actuated joints the file names (empty when it names none).
        name: The model's name.
        format: ``"urdf"``, ``"urdfplus"`` (URDF+ ``<loop>``), ``"urdfdom"`` (the proposed ``<constraint>``),
            ``"mjcf"``, ``"sdf"`` or ``"usd"``.
        floating_base: The free-flyer joint that carries the whole tree (an MJCF root ``<freejoint>``), or None.
        reference: Joint values the file states (an MJCF free body's pose), for ``[reference]``.
        notes: What the reader interpreted or ignored, one sentence each (a tendon actuator read as its joint, a
            velocity limit read as none...): :attr:`pkm.core.Mechanism.notes` after loading.
        actuators: The drives' values the file states that its URDF text cannot carry, ``{actuated joint: {field:
            value}}`` as a spec's ``[actuators.<joint>]`` tables (:mod:`pkm.core.model.actuators`; an MJCF
            joint's ``armature``, its actuators' force limits...), under the spec's own.
        seed: Joint values where the assembly starts for the joints ``reference`` leaves out (an MJCF joint's
            ``ref``: MuJoCo's ``qpos0``, where the file's poses hold), instead of the neutral configuration.
        springs: The joints' springs and dampers the file states, ``{joint: {"stiffness", "rest", "damping": value}}``
            as a spec's ``[springs.<joint>]`` tables (:mod:`pkm.core.model.springs`), under the spec's own.
        hold: Joints of ``seed`` the assembly holds where the loops allow (an MJCF keyframe's actuated joints and
            free bodies): values the file states, released (a note says how far they moved) where they over-determine
            the loops, as ``reference`` is not (:func:`pkm.core.model.builder.build`).
        motors: The motors that drive several actuated joints through a constant linear map (an MJCF differential:
            motors on fixed tendons), ``{motor: {joint: coefficient}}`` as a spec's ``[motors.<name>]`` tables
            (:mod:`pkm.core.model.motors`), under the spec's own.
    """

    urdf: str
    closures: tuple[Closure, ...]
    joint_types: dict[str, str]
    actuated: tuple[str, ...]
    name: str
    format: str
    floating_base: str | None = None
    reference: dict[str, tuple[float, ...]] = dataclasses.field(default_factory=dict)
    notes: tuple[str, ...] = ()
    actuators: dict[str, dict[str, float]] = dataclasses.field(default_factory=dict)
    seed: dict[str, tuple[float, ...]] = dataclasses.field(default_factory=dict)
    springs: dict[str, dict[str, float]] = dataclasses.field(default_factory=dict)
    motors: dict[str, dict[str, float]] = dataclasses.field(default_factory=dict)
    hold: tuple[str, ...] = ()


@dataclass(frozen=True)
class Format:
    """A model-file format pkm reads.

    Attributes:
        name: Its name (``"mjcf"``), as :attr:`Imported.format` gives it.
        suffixes: The file suffixes read as this format when the root element says nothing (lower case, with the dot).
        root: The XML root element that identifies it (``"mujoco"``), whatever the suffix.
        reader: ``read(text, source) -> Imported``, or its ``"module:function"`` name (imported on first use).
        opens: The reader opens the file itself (a binary format, or one whose file names others: USD), given its
            path as ``source`` and ``""`` as ``text``; its ``root`` is ``""`` (no XML root element).
    """

    name: str
    suffixes: tuple[str, ...]
    root: str
    reader: str | Callable[[str, str], Imported]
    opens: bool = False

    def read(self, text: str, source: str) -> Imported:
        """The file's text read by this format's reader."""
        reader = self.reader
        if isinstance(reader, str):
            module, _, function = reader.partition(":")
            reader = getattr(importlib.import_module(module), function)
        return reader(text, source)


#: The model-file formats, by name (:func:`register_format` adds one); the first is the default of a file whose
#: suffix and root element say nothing.
FORMATS: dict[str, Format] = {
    "urdf": Format("urdf", (".urdf",), "robot", "pkm.core.formats.urdfplus:read_urdf"),  # (URDF+ and urdfdom loops too)
    "mjcf": Format("mjcf", (".xml", ".mjcf"), "mujoco", "pkm.core.formats.mjcf:read_mjcf"),
    "sdf": Format("sdf", (".sdf",), "sdf", "pkm.core.formats.sdf:read_sdf"),
    "usd": Format("usd", (".usda", ".usd", ".usdc"), "", "pkm.core.formats.usd:read_usd", opens=True),
}


def register_format(fmt: Format) -> None:
    """Add ``fmt`` to :data:`FORMATS` (replacing one of the same name)."""
    if not isinstance(fmt, Format):
        from pkm.errors import InvalidInputError

        raise InvalidInputError("fmt", f"expected a pkm.core.formats.base.Format, got {type(fmt).__name__}", fmt)
    FORMATS[fmt.name] = fmt


def suffixes() -> dict[str, str]:
    """``{suffix: format name}`` of every registered format."""
    return {suffix: f.name for f in FORMATS.values() for suffix in f.suffixes}


def by_root(root: str | None) -> Format | None:
    """The registered format whose root element is ``root``, or None."""
    return next((f for f in FORMATS.values() if root and f.root == root), None)


def __getattr__(name: str) -> object:
    if name == "SUFFIXES":  # (the old constant: {suffix: format name}, now read from FORMATS)
        return suffixes()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["FORMATS", "Format", "Imported", "by_root", "register_format", "suffixes"]
