"""The scene model: the bodies that draw a mechanism (:class:`Scene`), their placements at any configuration, the
camera that frames them and the legend of their colours."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from pkm.core.model.mechanism import Mechanism
from pkm.errors import InvalidInputError
from pkm.viz.bodies import JOINT_RADIUS, build_bodies
from pkm.viz.body import Body
from pkm.viz.colors import AXIS_COLORS, BASE_COLOR, CLOSURE_COLOR, JOINT_COLORS, LINK_COLOR, PLATFORM_COLOR

ROOT = "/meshcat/pkm"
"""Meshcat path under which a snapshot draws the mechanism."""

# Camera: direction (world) from the mechanism's centre; placed as near as lets every joint and frame origin (and a
# joint radius about it) fill at most _FILL of meshcat's vertical field of view (75 deg), and of the horizontal one
# of a 4:3 window (wider windows show more).
_VIEW_DIRECTION = np.array([1.0, 0.5, 0.9])
_FOV = math.radians(75.0)
_ASPECT = 4.0 / 3.0
_FILL = 0.8


@dataclass(frozen=True, eq=False)
class Scene:
    """The primitives that draw a mechanism, and their placements at any configuration.

    Build it with :meth:`from_mechanism`.

    Attributes:
        mechanism: The mechanism drawn.
        root: Meshcat path of the node every body hangs under.
        bodies: The drawn bodies.
        length: Characteristic length of the mechanism [m] (diagonal of the bounding box of its
            joint and frame origins at the reference configuration); primitive sizes scale with it.
        platform_joint: Name of the joint that carries the platform (None if the end effector is
            fixed to the world).
    """

    mechanism: Mechanism
    root: str
    bodies: tuple[Body, ...]
    length: float
    platform_joint: str | None
    _frame_ids: tuple[int, ...] = field(repr=False, default=())
    _data: pin.Data = field(repr=False, default=None)

    @classmethod
    def from_mechanism(cls, mech: Mechanism, root: str = ROOT) -> Scene:
        """The scene of ``mech``, its paths under ``root`` (a meshcat path such as ``"/meshcat/pkm"``)."""
        if not isinstance(mech, Mechanism):
            raise InvalidInputError("mech", f"expected a pkm Mechanism, got {type(mech).__name__}", mech)
        root = "/" + "/".join(p for p in str(root).split("/") if p)
        bodies, length, platform = build_bodies(mech, root)
        model = mech.model
        ids = tuple(mech.frame_id(b.frame) for b in bodies)
        return cls(mech, root, tuple(bodies), length, platform, ids, model.createData())

    def body(self, path: str) -> Body:
        """The body drawn at meshcat ``path``."""
        for b in self.bodies:
            if b.path == path:
                return b
        raise InvalidInputError("path", f"no body is drawn at {path!r}; see Scene.bodies", path)

    def frame_placements(self, q) -> list[np.ndarray]:
        """World placement (4x4) of every Pinocchio frame at ``q`` (validated), in model order."""
        q = self.mechanism.check_q(q)
        model, data = self.mechanism.model, self._data
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        return [data.oMf[i].homogeneous for i in range(model.nframes)]

    def transforms(self, q) -> dict[str, np.ndarray]:
        """World placement (4x4 homogeneous, m) of every drawn body at configuration ``q``.

        Each is the placement of the body's frame (Pinocchio forward kinematics) composed with
        the body's offset. Raises :class:`~pkm.errors.InvalidInputError` for a bad ``q``.
        """
        oMf = self.frame_placements(q)
        return {b.path: oMf[i] @ b.offset for b, i in zip(self.bodies, self._frame_ids)}

    def camera_distance(self, qs, direction) -> float:
        """Distance [m] from the centre of :meth:`bounds` along unit ``direction`` at which the camera frames the
        mechanism over configurations ``qs``: every joint and frame origin, padded by a joint radius, within
        ``_FILL`` of the half field of view (vertical 75 deg; horizontal of a 4:3 window)."""
        origins = self._origins(qs)
        centre, radius = self._sphere(origins)
        pts = origins - centre
        f = -np.asarray(direction, float)
        right = np.cross(f, [0.0, 0.0, 1.0])
        right /= np.linalg.norm(right)
        up = np.cross(right, f)
        pad, tan = JOINT_RADIUS * self.length, math.tan(_FOV / 2.0) * _FILL

        def fits(t: float) -> bool:
            rel = pts + t * f  # (points seen from the eye at -t f)
            depth = rel @ f - pad
            if np.any(depth <= 0.0):
                return False
            x = (np.abs(rel @ right) + pad) / depth / _ASPECT
            y = (np.abs(rel @ up) + pad) / depth
            return bool(max(x.max(), y.max()) <= tan)

        lo, hi = 0.0, radius / math.sin(math.atan(tan / _ASPECT)) + radius  # (about where the bounding sphere fits)
        for _ in range(60):
            if fits(hi):
                break
            lo, hi = hi, 2.0 * hi
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if fits(mid) else (mid, hi)
        return hi

    def bounds(self, qs) -> tuple[np.ndarray, float]:
        """Centre [m] and radius [m] of a sphere around the mechanism over configurations ``qs``.

        The sphere bounds the box of every joint and frame origin over ``qs``, padded by a joint radius.
        """
        return self._sphere(self._origins(qs))

    def _origins(self, qs) -> np.ndarray:
        """Every frame origin (world, m) at every configuration of ``qs``, stacked."""
        return np.concatenate([np.array([m[:3, 3] for m in self.frame_placements(q)]) for q in qs])

    def _sphere(self, pts: np.ndarray) -> tuple[np.ndarray, float]:
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        radius = 0.5 * float(np.linalg.norm(hi - lo)) + JOINT_RADIUS * self.length
        return 0.5 * (lo + hi), max(radius, 0.05 * self.length)

    def legend(self) -> list[tuple[str, tuple[int, ...]]]:
        """``(label, colours)`` of everything drawn, in the order the page lists them: the joints' actuation, the
        platform, the base, the closures, each leg (named after its actuated joints), the triads' axes."""
        out: list[tuple[str, int | tuple[int, ...]]] = []
        roles = {b.role for b in self.bodies}
        for kind in ("actuated", "passive", "mimic"):
            if any(b.actuation == kind for b in self.bodies):
                out.append((f"{kind} joint" + (" (driven by another)" if kind == "mimic" else ""), JOINT_COLORS[kind]))
        if "platform" in roles:
            out.append(("platform", PLATFORM_COLOR))
        if "base" in roles:
            out.append(("base", BASE_COLOR))
        if "closure" in roles:
            out.append(("loop closure (dot centred in its bubble: closed)", CLOSURE_COLOR))
        legs = dict.fromkeys((b.leg, b.color) for b in self.bodies if b.role == "link" and b.leg is not None)
        out += [(name if name.lower().startswith("leg") else f"leg {name}", color) for name, color in legs]
        if any(b.role == "link" and b.leg is None for b in self.bodies):
            out.append(("link of the platform", LINK_COLOR))
        if "triad" in roles:
            out.append(("x, y, z axes (world, end effector)", AXIS_COLORS))
        return [(label, c if isinstance(c, tuple) else (c,)) for label, c in out]

    def view_direction(self, q) -> np.ndarray:
        """Unit vector from the mechanism towards the camera, for configuration ``q``.

        Meshcat keeps the world z up on screen. A platform facing up or down (Delta, 3-PRS,
        3-RRR) is seen from ``(1, 0.5, 0.9)``, about 40 degrees above the horizon; a platform
        facing sideways (the hexapod's axis is its y) is seen obliquely from its own side,
        the side away from the base, from 40 degrees up.
        """
        default = _VIEW_DIRECTION / np.linalg.norm(_VIEW_DIRECTION)
        platform = [b for b in self.bodies if b.role == "platform"]
        base = [b for b in self.bodies if b.role == "base"]
        if not platform:
            return default
        tr = self.transforms(q)
        world = [(tr[b.path][:3, :3] @ b.vertices.T).T + tr[b.path][:3, 3] for b in platform + base]
        centre = world[0].mean(axis=0)
        normal = np.linalg.svd(world[0] - centre)[2][2]
        if abs(normal[2]) >= 0.5:
            return default
        away = centre - (world[1].mean(axis=0) if base else np.zeros(3))
        if normal @ away < 0:
            normal = -normal
        horizontal = normal - normal[2] * np.array([0.0, 0.0, 1.0])
        horizontal /= np.linalg.norm(horizontal)
        side = np.cross([0.0, 0.0, 1.0], horizontal)
        d = horizontal + 0.5 * side + 0.9 * np.array([0.0, 0.0, 1.0])
        return d / np.linalg.norm(d)
