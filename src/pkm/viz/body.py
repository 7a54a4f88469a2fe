"""One drawn primitive (sphere, cylinder or mesh), rigidly attached to a Pinocchio frame."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True, eq=False)
class Body:
    """One drawn primitive, rigidly attached to a Pinocchio frame.

    Attributes:
        path: Its meshcat path (absolute).
        kind: ``"sphere"``, ``"cylinder"`` (axis along its local y, centred) or ``"mesh"``.
        role: ``"joint"``, ``"link"``, ``"platform"``, ``"base"``, ``"triad"`` or ``"closure"``.
        frame: Name of the Pinocchio frame it rides on.
        offset: Its placement in that frame, 4x4 homogeneous [m].
        color: RGB colour as an integer 0xRRGGBB.
        size: ``(radius,)`` for a sphere, ``(height, radius)`` for a cylinder, ``()`` for a mesh [m].
        opacity: 1 for opaque.
        vertices: Mesh vertices in the body's local frame, (k, 3) [m]; empty otherwise.
        faces: Mesh triangles, (m, 3) indices into ``vertices``; empty otherwise.
        joint: For a joint sphere, the joint's name; for a link, the joint whose body it belongs to.
        actuation: For a joint sphere: ``"actuated"``, ``"passive"`` or ``"mimic"``.
        ends: For a link: the names of the joint or frame at each end (the far one
            :data:`~pkm.viz.bodies.CENTRE_OF_MASS` for a link to its body's centre of mass); for a closure marker,
            the closure's name and the frame it marks.
        halo: Drawn by its back faces only: a sphere around another shows as a ring around it.
        leg: For a link of a leg, the leg's name (see :meth:`Scene.legend`).
    """

    path: str
    kind: str
    role: str
    frame: str
    offset: np.ndarray
    color: int
    size: tuple[float, ...] = ()
    opacity: float = 1.0
    vertices: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    faces: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=int))
    joint: str | None = None
    actuation: str | None = None
    ends: tuple[str, str] | None = None
    halo: bool = False
    leg: str | None = None
