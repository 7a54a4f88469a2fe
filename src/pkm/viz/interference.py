"""Interference in a preview: where the mechanism has collision geometry (:mod:`pkm.core.collision`), a snapshot
at one configuration colours the drawn bodies of every pair that interpenetrates (:data:`INTERFERENCE_COLOR`) and
marks the witness points of those pairs (or, where none does, of the closest pair, :data:`CLOSEST_COLOR`): a
sphere on each and a bar between them, each said in the legend with its distance."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pkm.errors import InvalidInputError
from pkm.viz.bodies import JOINT_RADIUS, _clean, _segment
from pkm.viz.body import Body
from pkm.viz.scene import Scene

INTERFERENCE_COLOR = 0xD62728
"""Colour of the bodies that interpenetrate and of their witness points (red)."""
CLOSEST_COLOR = 0x111111
"""Colour of the closest pair's witness points where no two bodies interpenetrate (black)."""


@dataclass(frozen=True)
class Marks:
    """What a snapshot adds for interference (module doc).

    Attributes:
        bodies: The witness points' spheres and bars, on the world frame (``offset``: their world placement), under
            ``<root>/clearance/``.
        colors: ``{path: colour}`` of the drawn bodies recoloured (those of an interpenetrating pair's bodies).
        legend: ``(label, colours)`` rows the page's legend adds.
    """

    bodies: tuple[Body, ...]
    colors: dict[str, int]
    legend: tuple[tuple[str, tuple[int, ...]], ...]


def interference_marks(scene: Scene, q: np.ndarray) -> Marks | None:
    """The marks of :func:`pkm.clearance` at ``q``, where the mechanism has collision geometry and ``q`` closes its
    loops (a configuration drawn open: None, as without geometry)."""
    from pkm.core.collision.clearance import clearance
    from pkm.core.collision.interference import checks_collisions

    mech = scene.mechanism
    if not checks_collisions(mech):
        return None
    try:
        c = clearance(mech, q)
    except InvalidInputError:  # (loops open: no distance of the machine to show)
        return None
    hits = [p for p, d in c.pairs.items() if d < 0.0]
    model, world = mech.model, mech.model.frames[0].name
    joints = {model.names[model.frames[model.getFrameId(b, pin.FrameType.BODY)].parentJoint] for p in hits for b in p}
    colors = {b.path: INTERFERENCE_COLOR for b in scene.bodies if b.role in ("link", "platform") and b.joint in joints}
    r = 0.5 * JOINT_RADIUS * scene.length
    bodies, legend = [], []
    for a, b in hits or [c.closest]:
        d = c.pairs[(a, b)]
        color = INTERFERENCE_COLOR if d < 0.0 else CLOSEST_COLOR
        pa, pb = c.witness[(a, b)]
        path = f"{scene.root}/clearance/{_clean(a)}-{_clean(b)}"
        for side, p in (("a", pa), ("b", pb)):
            m = np.eye(4)
            m[:3, 3] = p
            bodies.append(Body(f"{path}/{side}", "sphere", "clearance", world, m, color, (r,), ends=(a, b)))
        if np.linalg.norm(pb - pa) > 1e-9 * scene.length:
            bodies.append(Body(f"{path}/bar", "cylinder", "clearance", world, _segment(pa, pb), color,
                               (float(np.linalg.norm(pb - pa)), 0.3 * r), ends=(a, b)))
        legend.append((f"{a} and {b} interpenetrate by {-d:.3g} m" if d < 0.0 else
                       f"closest: {a} and {b}, {d:.3g} m apart", (color,)))
    return Marks(tuple(bodies), colors, tuple(legend))


__all__ = ["CLOSEST_COLOR", "INTERFERENCE_COLOR", "Marks", "interference_marks"]
