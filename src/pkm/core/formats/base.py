"""What every model-file reader gives: :class:`Imported`, pkm's one representation of a model file (URDF text plus
what a closure spec adds: loops, joint types, actuators), and the file suffixes the readers take. The readers
(:mod:`~pkm.core.formats.mjcf`, :mod:`~pkm.core.formats.sdf`) import this module, the dispatcher
(:mod:`~pkm.core.formats.imported`) imports them: no import cycle."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from pkm.core.model.spec import Closure

#: File suffixes and the format they are read as.
SUFFIXES = {".urdf": "urdf", ".xml": "mjcf", ".mjcf": "mjcf", ".sdf": "sdf"}


@dataclass(frozen=True)
class Imported:
    """A model file read into pkm's one representation.

    Attributes:
        urdf: The tree as URDF text (frames for the closures' anchors included).
        closures: The loops the file closes (none for a URDF).
        joint_types: Joints URDF cannot state (``spherical``, ``universal``), for ``[joint_types]``.
        actuated: The actuated joints the file names (empty when it names none).
        name: The model's name.
        format: ``"urdf"``, ``"mjcf"`` or ``"sdf"``.
        floating_base: The free-flyer joint that carries the whole tree (an MJCF root ``<freejoint>``), or None.
        reference: Joint values the file states (an MJCF free body's pose), for ``[reference]``.
        notes: What the reader interpreted or ignored, one sentence each (a tendon actuator read as its joint, a
            velocity limit read as none...): :attr:`pkm.core.Mechanism.notes` after loading.
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


__all__ = ["SUFFIXES", "Imported"]
