"""Meshcat previews of any pkm mechanism, drawn from primitives.

The URDFs carry no meshes, so a mechanism is drawn from what its Pinocchio tree and
closure spec say:

* every joint as a sphere on its origin, coloured by its actuation: actuated
  (:data:`ACTUATED_COLOR`), passive (:data:`PASSIVE_COLOR`) or mimic, i.e. driven by another
  joint (:data:`MIMIC_COLOR`); a joint whose origin never leaves its parent's (a universal
  joint's second axis, a knee on a slider) is a larger sphere around its parent's, drawn by its
  back faces only, so that it shows as a ring around it;
* every body as cylinders from its joint's origin to the origins of its child joints and to
  the frames it carries (leg tips, closure frames), each leg in a colour of its own
  (:data:`LEG_COLORS`; a leg: the joints hung on the world, or on the platform, with their
  descendants up to the platform), named after its actuated joints;
* the platform (the body holding the end-effector frame) as the convex hull of the closure
  frames it carries: a triangle for the 3-RRR, Delta and 3-PRS, a prism for the hexapod;
* the base, translucent, through the anchor points of the joints hung on the world
  (free-flyers excepted) and the closure frames fixed to it: their polygon when they are
  coplanar, one polygon per layer when they lie in parallel planes (the hexapod's two
  3-RUS), else their convex hull;
* the world and end-effector frames as triads (x red, y green, z blue);
* each closure as a small white sphere on ``frame_a`` inside a translucent bubble on
  ``frame_b``: the two are concentric when the loop is closed.

The page of :func:`snapshot_html` carries a legend of these colours (:meth:`Scene.legend`).

:class:`Scene` lists these bodies (meshcat path, primitive, the Pinocchio frame it rides
on, its offset in that frame) and gives their placements at any configuration;
:func:`snapshot_html` turns a scene into a self-contained HTML page (the meshcat viewer
inlined, no server process), :func:`show` sends it to a live meshcat viewer.

Example::

    import pkm
    from pkm import viz
    delta = pkm.load("delta")
    viz.write_html("delta.html", delta)                        # open it in a browser
    ik = pkm.solve_ik(delta, [0.02, -0.01, -0.36])
    viz.write_html("delta_ik.html", delta, ik.q)
    vis = viz.show(delta)                                      # live, in a meshcat server
"""

from __future__ import annotations

import base64
import contextlib
import html
import io
import json
import math
import subprocess
import uuid
import warnings
from dataclasses import dataclass, field
from itertools import combinations
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from pkm.core.mechanism import Mechanism
from pkm.errors import InvalidInputError, PkmError
from pkm.validation import as_scalar

ACTUATED_COLOR = 0xE7298A
"""Colour of actuated joints (pink)."""
PASSIVE_COLOR = 0xE6AB02
"""Colour of passive joints (mustard)."""
MIMIC_COLOR = 0xF4A6CF
"""Colour of mimic joints, driven by another joint (light pink)."""
LINK_COLOR = 0xBDBDBD
"""Colour of links that belong to no leg (those of the platform's own body)."""
LEG_COLORS = (0x1F77B4, 0x9467BD, 0x8C564B, 0x17BECF, 0x393B79, 0x637939, 0x843C39, 0x7B4173)
"""Colours of the legs' links, in the order of the legs' first joints (then again from the first): hues apart from
the joints', the platform's, the triads' and the grey background's."""
PLATFORM_COLOR = 0x1B9E77
BASE_COLOR = 0x525252
CLOSURE_COLOR = 0xFFFFFF
AXIS_COLORS = (0xFF0000, 0x00C000, 0x0000FF)

BACKGROUND = ((0.97, 0.97, 0.97), (0.78, 0.78, 0.80))
"""The page's background, top and bottom colours (RGB in [0, 1])."""

JOINT_COLORS = {"actuated": ACTUATED_COLOR, "passive": PASSIVE_COLOR, "mimic": MIMIC_COLOR}

FPS = 30.0
"""Frame rate [1/s] of the animation keys, and of a trajectory given without times."""

ROOT = "/meshcat/pkm"
"""Meshcat path under which a snapshot draws the mechanism."""

# Sizes relative to the mechanism's characteristic length (diagonal of its bounding box).
_JOINT_RADIUS = 0.02
_LINK_RADIUS = 0.4  # of the joint radius
_BASE_BAR = 0.6  # the radius of the bar drawn between two base anchors, of the joint radius
_PLATFORM_FRACTION = 0.15  # largest joint radius, of the platform's diameter
_NESTED_SCALE = 1.35  # radius of a joint's ring around its parent's sphere
_TRIAD_LENGTH = 0.12
_TRIAD_RADIUS = 0.2 * _JOINT_RADIUS
# Camera: direction (world) from the mechanism's centre; placed as near as lets every joint and frame origin (and a
# joint radius about it) fill at most _FILL of meshcat's vertical field of view (75 deg), and of the horizontal one
# of a 4:3 window (wider windows show more).
_VIEW_DIRECTION = np.array([1.0, 0.5, 0.9])
_FOV = math.radians(75.0)
_ASPECT = 4.0 / 3.0
_FILL = 0.8
_UUID_NAMESPACE = uuid.UUID("6f1b4c1e-8d4a-4e0b-9a51-7c6d2f3e9b10")


class VizDependencyError(PkmError, ImportError):
    """meshcat (or its msgpack encoder) is not installed.

    Attributes:
        missing: The module that could not be imported.
    """

    def __init__(self, missing: str):
        self.missing = missing
        super().__init__("pkm.viz needs meshcat: pip install meshcat")


def _meshcat():
    """The meshcat modules pkm.viz uses, imported on first use."""
    try:
        with warnings.catch_warnings():  # meshcat imports its server, which imports a deprecated zmq module
            warnings.simplefilter("ignore", DeprecationWarning)
            import meshcat.animation
            import meshcat.commands
            import meshcat.geometry
            import meshcat.path
            import umsgpack
    except ImportError as exc:
        raise VizDependencyError(exc.name or "meshcat") from None
    return meshcat, umsgpack


# ---------------------------------------------------------------------------------------- scene
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
        ends: For a link: the names of the joint or frame at each end; for a closure marker,
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
        bodies, length, platform = _build_bodies(mech, root)
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
        pad, tan = _JOINT_RADIUS * self.length, math.tan(_FOV / 2.0) * _FILL

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
        radius = 0.5 * float(np.linalg.norm(hi - lo)) + _JOINT_RADIUS * self.length
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


def _build_bodies(mech: Mechanism, root: str) -> tuple[list[Body], float, str | None]:
    model = mech.model
    data = model.createData()
    pin.forwardKinematics(model, data, mech.q_reference)
    pin.updateFramePlacements(model, data)
    pts = np.array([data.oMf[i].translation for i in range(model.nframes)]
                   + [data.oMi[j].translation for j in range(model.njoints)])
    length = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
    if not length > 1e-9:
        length = 1.0
    eps = 1e-9 * length
    bodies: list[Body] = []
    eye = np.eye(4)

    def joint_frame(j: int) -> str:
        name = model.names[j]
        if j > 0 and model.existFrame(name, pin.FrameType.JOINT):
            return name
        for f in model.frames:  # a model built without JOINT frames: any frame on the joint at its origin
            if f.parentJoint == j and np.allclose(f.placement.homogeneous, eye):
                return f.name
        return model.frames[0].name if j == 0 else name

    def local(frame_id: int) -> np.ndarray:
        """Position of frame ``frame_id`` in its parent joint's frame."""
        return np.array(model.frames[frame_id].placement.translation)

    # the platform: the body holding the end effector, drawn through the closure frames it carries
    pj = model.frames[mech.ee_frame].parentJoint
    platform_joint = model.names[pj] if pj > 0 else None
    closure_ids = sorted({f for pair in mech.closure_frames for f in pair})
    if pj > 0:
        verts = [local(f) for f in closure_ids if model.frames[f].parentJoint == pj]
        if len(_unique(np.array(verts).reshape(-1, 3), eps)) < 3:
            verts.append(np.zeros(3))  # a leg carries the platform: its joint is a corner too
        hull = _convex_hull(np.array(verts), eps)
        if hull is not None:
            bodies.append(Body(f"{root}/platform", "mesh", "platform", joint_frame(pj), eye.copy(),
                               PLATFORM_COLOR, vertices=hull[0], faces=hull[1], joint=model.names[pj]))
    # joint spheres: a fraction of the mechanism's size, small enough to leave the platform visible
    # and the end-effector triad no longer than the platform is wide
    r_joint, ee_triad = _JOINT_RADIUS * length, _TRIAD_LENGTH * length
    if bodies:
        v = bodies[0].vertices
        diameter = float(np.max(np.linalg.norm(v[:, None] - v[None], axis=-1)))
        r_joint, ee_triad = min(r_joint, _PLATFORM_FRACTION * diameter), min(ee_triad, diameter)

    # the base: anchors of the joints hung on the world, and closure frames fixed to it
    anchors = [np.array(model.jointPlacements[j].translation) for j in range(1, model.njoints)
               if model.parents[j] == 0 and model.joints[j].shortname() != "JointModelFreeFlyer"]
    anchors += [local(f) for f in closure_ids if model.frames[f].parentJoint == 0]
    hull = _layered_polygons(np.array(anchors).reshape(-1, 3), eps)
    if hull is not None:
        bodies.append(Body(f"{root}/base", "mesh", "base", joint_frame(0), eye.copy(), BASE_COLOR, opacity=0.5,
                           vertices=hull[0], faces=hull[1], joint=model.names[0]))
    elif len(ends := _unique(np.array(anchors).reshape(-1, 3), eps)) >= 2:  # two anchors, or a line: a bar
        far = np.linalg.norm(ends[:, None] - ends[None], axis=-1)
        a, b = np.unravel_index(int(np.argmax(far)), far.shape)
        bodies.append(Body(f"{root}/base", "cylinder", "base", joint_frame(0), _segment(ends[a], ends[b]),
                           BASE_COLOR, (float(far[a, b]), _BASE_BAR * r_joint), joint=model.names[0]))

    # links: cylinders from each joint's origin to its children and to the frames it carries, coloured by leg
    legs = _legs(mech, pj)
    rank = {pin.FrameType.BODY: 1, pin.FrameType.OP_FRAME: 2, pin.FrameType.FIXED_JOINT: 3}
    for j in range(1, model.njoints):
        targets = [(model.names[c], np.array(model.jointPlacements[c].translation))
                   for c in range(1, model.njoints) if model.parents[c] == j]
        if j != pj:
            frames = [f for f in range(model.nframes) if model.frames[f].parentJoint == j
                      and model.frames[f].type in rank]
            frames.sort(key=lambda f: (rank[model.frames[f].type], f))
            targets += [(model.frames[f].name, local(f)) for f in frames]
        seen: list[np.ndarray] = []
        for name, p in targets:
            if np.linalg.norm(p) <= eps or any(np.linalg.norm(p - s) <= eps for s in seen):
                continue
            seen.append(p)
            leg, color = legs.get(j, (None, LINK_COLOR))
            bodies.append(Body(f"{root}/links/{_clean(model.names[j])}-{_clean(name)}", "cylinder", "link",
                               joint_frame(j), _segment(np.zeros(3), p), color,
                               (float(np.linalg.norm(p)), _LINK_RADIUS * r_joint), joint=model.names[j],
                               ends=(model.names[j], name), leg=leg))

    # joints; a joint whose origin never leaves its parent's (a universal joint's second axis,
    # a knee on a slider) is a larger sphere around its parent's, seen as a ring (back faces only)
    nested = _nested_joints(mech)
    radius = {0: r_joint / _NESTED_SCALE}
    for j in range(1, model.njoints):
        radius[j] = radius[model.parents[j]] * _NESTED_SCALE if j in nested else r_joint
    actuated = set(mech.actuated_names)
    for j in range(1, model.njoints):
        name = model.names[j]
        kind = ("actuated" if name in actuated else
                "mimic" if model.joints[j].shortname() == "JointModelMimic" else "passive")
        bodies.append(Body(f"{root}/joints/{_clean(name)}", "sphere", "joint", joint_frame(j), eye.copy(),
                           JOINT_COLORS[kind], (radius[j],), joint=name, actuation=kind, halo=j in nested))

    # closures: a small sphere on frame_a inside a bubble on frame_b
    for c in mech.spec.closures:
        for side, fname, size, opacity in (("a", c.frame_a, 0.55 * r_joint, 1.0),
                                           ("b", c.frame_b, 1.3 * r_joint, 0.35)):
            bodies.append(Body(f"{root}/closures/{_clean(c.name)}/{side}", "sphere", "closure", fname, eye.copy(),
                               CLOSURE_COLOR, (size,), opacity, ends=(c.name, fname)))

    # triads: world and end effector
    world = model.frames[0].name
    triads = [("world", world, _TRIAD_LENGTH * length)]
    if mech.spec.end_effector is not None:
        triads.append((mech.spec.end_effector, mech.spec.end_effector, ee_triad))
    for label, fname, size in triads:
        for k, axis in enumerate("xyz"):
            tip = np.zeros(3)
            tip[k] = size
            bodies.append(Body(f"{root}/frames/{_clean(label)}/{axis}", "cylinder", "triad", fname,
                               _segment(np.zeros(3), tip), AXIS_COLORS[k], (size, _TRIAD_RADIUS * length)))
    return bodies, length, platform_joint


def _legs(mech: Mechanism, platform: int) -> dict[int, tuple[str, int]]:
    """Joint index -> ``(leg name, colour)``: the tree cut at the world and at the platform's joint, each piece a
    leg, named after its actuated joints (else its first joint) and coloured in the order of its first joint."""
    model = mech.model
    first: dict[int, int] = {}
    for j in range(1, model.njoints):
        if j == platform:
            continue
        k = j
        while model.parents[k] not in (0, platform):
            k = model.parents[k]
        first[j] = k
    actuated = set(mech.actuated_names)
    out = {}
    for n, head in enumerate(sorted(set(first.values()))):
        members = [j for j in first if first[j] == head]
        names = [model.names[j] for j in members if model.names[j] in actuated] or [model.names[head]]
        for j in members:
            out[j] = (", ".join(names), LEG_COLORS[n % len(LEG_COLORS)])
    return out


def _nested_joints(mech: Mechanism) -> set[int]:
    """Joints whose origin stays at their parent joint's origin (checked at two configurations)."""
    model = mech.model
    data = model.createData()
    v = np.random.default_rng(0).uniform(-0.3, 0.3, model.nv)
    out = set(range(1, model.njoints))
    for q in (mech.q_reference, pin.integrate(model, mech.q_reference, v)):
        pin.forwardKinematics(model, data, q)
        out = {j for j in out if model.parents[j] > 0 and np.linalg.norm(
            data.oMi[j].translation - data.oMi[model.parents[j]].translation) <= 1e-12 * (1.0 + np.linalg.norm(
                data.oMi[j].translation))}
    return out


def _clean(name: str) -> str:
    """A name usable as one element of a meshcat path."""
    return name.replace("/", "_") or "_"


def _segment(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Placement (4x4) of a y-axis cylinder centred between ``a`` and ``b``, its axis from a to b."""
    d = np.asarray(b, dtype=float) - np.asarray(a, dtype=float)
    y = d / np.linalg.norm(d)
    helper = np.array([1.0, 0.0, 0.0]) if abs(y[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    x = helper - (helper @ y) * y
    x /= np.linalg.norm(x)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2] = x, y, np.cross(x, y)
    m[:3, 3] = 0.5 * (np.asarray(a, dtype=float) + np.asarray(b, dtype=float))
    return m


def _unique(points: np.ndarray, tol: float) -> np.ndarray:
    out: list[np.ndarray] = []
    for p in points:
        if not any(np.linalg.norm(p - o) <= tol for o in out):
            out.append(p)
    return np.array(out).reshape(-1, 3)


def _hull2d(xy: np.ndarray, tol: float) -> list[int]:
    """Indices of the convex hull of 2-D points, counter-clockwise, collinear points dropped."""
    order = sorted(range(len(xy)), key=lambda i: (xy[i, 0], xy[i, 1]))

    def cross(o, a, b):
        return (xy[a, 0] - xy[o, 0]) * (xy[b, 1] - xy[o, 1]) - (xy[a, 1] - xy[o, 1]) * (xy[b, 0] - xy[o, 0])

    lower: list[int] = []
    for i in order:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], i) <= tol:
            lower.pop()
        lower.append(i)
    upper: list[int] = []
    for i in reversed(order):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], i) <= tol:
            upper.pop()
        upper.append(i)
    return lower[:-1] + upper[:-1]


def _convex_hull(points: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Vertices (k, 3) and triangles (m, 3) of the convex hull of a few points; None if flatter than a plane.

    Coplanar points give their polygon (one face); otherwise every face of the solid hull
    gets its own vertices (flat shading), triangles wound counter-clockwise seen from outside.
    """
    pts = _unique(np.asarray(points, dtype=float), tol)
    if len(pts) < 3:
        return None
    centre = pts.mean(axis=0)
    _, s, vt = np.linalg.svd(pts - centre)
    scale = max(float(s[0]), 1.0)
    if s[1] <= tol * scale:
        return None
    rings: list[np.ndarray] = []
    if len(pts) == 3 or s[2] <= tol * scale:
        ring = _hull2d((pts - centre) @ vt[:2].T, tol * scale)
        rings.append(pts[ring])
    else:
        planes: list[tuple[np.ndarray, float]] = []
        for i, j, k in combinations(range(len(pts)), 3):
            n = np.cross(pts[j] - pts[i], pts[k] - pts[i])
            if np.linalg.norm(n) <= tol * scale:
                continue
            n /= np.linalg.norm(n)
            d = (pts - pts[i]) @ n
            if np.all(d >= -tol):
                n, d = -n, -d
            elif not np.all(d <= tol):
                continue
            off = float(n @ pts[i])
            if any(np.allclose(n, n2, atol=1e-9) and abs(off - o2) <= tol for n2, o2 in planes):
                continue
            planes.append((n, off))
            on = pts[np.abs(d) <= tol]
            u = on[1] - on[0]
            u /= np.linalg.norm(u)
            basis = np.array([u, np.cross(n, u)])
            rings.append(on[_hull2d((on - on.mean(axis=0)) @ basis.T, tol * scale)])
    return _fans(rings)


def _fans(rings: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and fan triangles of convex polygons (each an ordered ring of points)."""
    verts: list[np.ndarray] = []
    faces: list[tuple[int, int, int]] = []
    for ring in rings:
        base = len(verts)
        verts.extend(ring)
        faces.extend((base, base + i, base + i + 1) for i in range(1, len(ring) - 1))
    return np.array(verts), np.array(faces, dtype=int)


def _layered_polygons(points: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Polygons through points lying in parallel planes, else their convex hull.

    The base anchors of a mechanism are coplanar (one polygon) or, like the hexapod's two
    3-RUS, lie in a few parallel layers of three or more points (one polygon per layer,
    across the direction of least spread); otherwise they get their solid convex hull.
    """
    pts = _unique(np.asarray(points, dtype=float), tol)
    if len(pts) < 3:
        return None
    centre = pts.mean(axis=0)
    _, s, vt = np.linalg.svd(pts - centre)
    if len(pts) > 3 and s[2] > tol * max(float(s[0]), 1.0):
        height = (pts - centre) @ vt[2]
        order = np.argsort(height)
        cuts = np.flatnonzero(np.diff(height[order]) > 1e3 * tol) + 1
        layers = np.split(order, cuts)
        hulls = [_convex_hull(pts[layer], tol) if len(layer) >= 3 else None for layer in layers]
        if len(layers) > 1 and all(h is not None and len(h[1]) == len(h[0]) - 2 for h in hulls):
            return _fans([h[0] for h in hulls if h is not None])
    return _convex_hull(pts, tol)


# ------------------------------------------------------------------------------------- commands
def _check_trajectory(mech: Mechanism, trajectory, times) -> tuple[np.ndarray, np.ndarray]:
    try:
        traj = np.asarray(trajectory, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError("trajectory", f"expected an array (N, {mech.nq}) of configurations, "
                                              f"got {type(trajectory).__name__}", trajectory) from None
    if traj.ndim != 2 or traj.shape[1] != mech.nq or len(traj) == 0:
        raise InvalidInputError("trajectory", f"expected shape (N, {mech.nq}) with N >= 1, got {traj.shape}",
                                trajectory)
    traj = np.array([mech.check_q(row, f"trajectory[{k}]") for k, row in enumerate(traj)])
    if times is None:
        return traj, np.arange(len(traj)) / FPS
    try:
        t = np.asarray(times, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError("times", f"expected {len(traj)} numbers [s], got {type(times).__name__}",
                                times) from None
    if t.shape != (len(traj),):
        raise InvalidInputError("times", f"expected shape ({len(traj)},) like the trajectory, got {t.shape}", times)
    if not np.all(np.isfinite(t)) or np.any(t < 0) or np.any(np.diff(t) <= 0):
        raise InvalidInputError("times", "expected finite, non-negative, strictly increasing times [s]", times)
    return traj, t


def _path(mc, path: str):
    return mc.path.Path(tuple(p for p in path.split("/") if p))


def _primitive(mc, body: Body):
    """The meshcat object of ``body``, with uuids derived from its path (deterministic output)."""
    g = mc.geometry
    if body.kind == "sphere":
        geom = g.Sphere(float(body.size[0]))
    elif body.kind == "cylinder":
        geom = g.Cylinder(float(body.size[0]), float(body.size[1]))
    else:
        geom = g.TriangularMeshGeometry(body.vertices, body.faces)
    extra: dict[str, Any] = {"depthWrite": body.opacity == 1.0, "side": 1 if body.halo else 2}  # three.js BackSide, DoubleSide
    if body.role == "base":  # behind anything drawn in its plane (a planar mechanism's platform)
        extra.update(polygonOffset=True, polygonOffsetFactor=1.0, polygonOffsetUnits=1.0)
    mat = g.MeshLambertMaterial(color=int(body.color), opacity=float(body.opacity), **extra)
    obj = g.Mesh(geom, mat)
    for part, el in (("geometry", geom), ("material", mat), ("object", obj)):
        el.uuid = str(uuid.uuid5(_UUID_NAMESPACE, f"{body.path}#{part}"))
    return obj


def scene_commands(scene: Scene, q=None, *, trajectory=None, times=None, loop: bool = True) -> list:
    """The meshcat commands that draw ``scene`` at ``q`` and, optionally, animate a trajectory.

    Args:
        scene: The scene to draw.
        q: Configuration shown (nq,); default the first of ``trajectory``, else the reference.
        trajectory: Configurations to animate, (N, nq), or None.
        times: Time of each configuration [s], (N,), strictly increasing; default ``arange(N) / 30``.
        loop: Whether the animation repeats forever (else it plays once).

    Returns:
        A list of ``meshcat.commands`` objects (``SetProperty``, ``SetTransform``, ``SetObject``,
        ``SetAnimation``): the viewer set-up first (meshcat's own axes and grid hidden, the grid
        moved to the mechanism's z = 0 plane should it be shown again, the mechanism's node
        shifted so that its centre sits at meshcat's origin, where the camera looks, and the
        camera placed to frame it), then one ``SetObject`` and one ``SetTransform`` per body
        (its world placement, under that node), then the animation.
    """
    mc, _ = _meshcat()
    mech = scene.mechanism
    traj = tm = None
    if trajectory is not None:
        traj, tm = _check_trajectory(mech, trajectory, times)
    elif times is not None:
        raise InvalidInputError("times", "times were given without a trajectory; pass trajectory=(N, nq) too", times)
    if q is None:
        q = traj[0] if traj is not None else mech.q_reference
    q = mech.check_q(q)

    views = [q] if traj is None else [q, *traj[:: max(1, len(traj) // 50)], traj[-1]]
    centre, _ = scene.bounds(views)
    shift = np.eye(4)
    shift[:3, 3] = -centre
    direction = scene.view_direction(q)
    d = direction * scene.camera_distance(views, direction)
    cmds = [
        mc.commands.SetProperty("visible", False, _path(mc, "/Axes")),
        mc.commands.SetProperty("visible", False, _path(mc, "/Grid")),
        # a light grey background, against which every colour of the legend stands out (meshcat's is sky blue)
        mc.commands.SetProperty("top_color", list(BACKGROUND[0]), _path(mc, "/Background")),
        mc.commands.SetProperty("bottom_color", list(BACKGROUND[1]), _path(mc, "/Background")),
        mc.commands.SetTransform(shift, _path(mc, "/Grid")),
        # the camera hangs in a frame turned by +90 deg about x (its y is the world z)
        mc.commands.SetProperty("position", [float(d[0]), float(d[2]), float(-d[1])],
                                _path(mc, "/Cameras/default/rotated/<object>")),
        mc.commands.SetTransform(shift, _path(mc, scene.root)),
    ]
    for body, m in zip(scene.bodies, scene.transforms(q).values()):
        cmds.append(mc.commands.SetObject(_primitive(mc, body), path=_path(mc, body.path)))
        cmds.append(mc.commands.SetTransform(m, _path(mc, body.path)))
    if traj is not None:
        anim = mc.animation.Animation(default_framerate=FPS)
        clips = {b.path: mc.animation.AnimationClip(fps=FPS) for b in scene.bodies}
        assert tm is not None  # given with the trajectory
        for qk, tk in zip(traj, tm):
            frame = float(tk * FPS)
            for path, m in scene.transforms(qk).items():
                quat = pin.Quaternion(m[:3, :3]).coeffs()  # x y z w, as three.js
                clips[path].set_property(frame, "position", "vector3", [float(v) for v in m[:3, 3]])
                clips[path].set_property(frame, "quaternion", "quaternion", [float(v) for v in quat])
        anim.clips = {_path(mc, p): c for p, c in clips.items()}
        cmds.append(mc.commands.SetAnimation(anim, play=True, repetitions=math.inf if loop else 1))
    return cmds


# ----------------------------------------------------------------------------------------- html
_PAGE = """<!DOCTYPE html>
<html>
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
body {{ margin: 0; }}
#meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}
#pkm-legend {{ position: absolute; left: 8px; bottom: 8px; padding: 6px 8px; border-radius: 4px;
  background: rgba(255, 255, 255, 0.85); font: 11px sans-serif; color: #222; line-height: 1.45; }}
#pkm-legend b {{ display: block; margin-bottom: 2px; }}
#pkm-legend i {{ display: inline-block; width: 10px; height: 10px; margin-right: 5px; vertical-align: -1px;
  border: 1px solid #555; }}
</style>
</head>
<body>
<div id="meshcat-pane"></div>
{legend}
<script>
{viewer_js}
</script>
<script type="application/json" id="pkm-meshcat-commands">
{commands}
</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
(function () {{
  // each entry: one meshcat command, msgpack-encoded then base64, applied in order
  var commands = JSON.parse(document.getElementById("pkm-meshcat-commands").textContent);
  for (var i = 0; i < commands.length; i++) {{
    var raw = atob(commands[i]);
    var bytes = new Uint8Array(raw.length);
    for (var k = 0; k < raw.length; k++) bytes[k] = raw.charCodeAt(k);
    viewer.handle_command_bytearray(bytes);
  }}
}})();
</script>
</body>
</html>
"""


def pack_commands(cmds: list) -> list[str]:
    """Each command lowered, msgpack-encoded as meshcat's server sends it, then base64 (ASCII)."""
    _, umsgpack = _meshcat()
    return [base64.b64encode(umsgpack.packb(c.lower())).decode("ascii") for c in cmds]


def _viewer_js(mc) -> str:
    path = Path(mc.__file__).parent / "viewer" / "dist" / "main.min.js"
    try:
        return path.read_text(encoding="utf-8")
    except OSError as exc:
        raise VizDependencyError(f"meshcat viewer ({path}: {exc.strerror})") from None


def snapshot_html(mech: Mechanism, q=None, *, trajectory=None, times=None, loop: bool = True,
                  legend: bool = True) -> str:
    """A self-contained HTML page showing ``mech`` at ``q``, and animating ``trajectory`` if given.

    The page inlines meshcat's viewer and carries the drawing commands itself; it needs no
    meshcat server and no network. No process is started.

    Args:
        mech: The mechanism.
        q: Configuration shown (nq,); default ``mech.q_reference`` (or the first of ``trajectory``).
        trajectory: Configurations to animate, (N, nq), or None.
        times: Time of each configuration [s], (N,); default 30 configurations per second.
        loop: Whether the animation repeats forever.
        legend: Whether the page shows the legend of the colours (:meth:`Scene.legend`) in its lower left corner.

    Returns:
        The HTML text. The commands are a JSON list of base64 strings in the element
        ``<script id="pkm-meshcat-commands">``, each a msgpack-encoded meshcat command.

    Raises:
        InvalidInputError: ``q``, ``trajectory`` or ``times`` is malformed.
        VizDependencyError: meshcat is not installed.
    """
    mc, _ = _meshcat()
    scene = Scene.from_mechanism(mech)
    packed = pack_commands(scene_commands(scene, q, trajectory=trajectory, times=times, loop=loop))
    return _PAGE.format(title=html.escape(f"pkm: {mech.name}"), viewer_js=_viewer_js(mc),
                        legend=_legend_html(scene) if legend else "",
                        commands="[\n" + ",\n".join(json.dumps(p) for p in packed) + "\n]")


def _legend_html(scene: Scene) -> str:
    """The ``<div id="pkm-legend">`` listing :meth:`Scene.legend`: a swatch and a label per colour."""
    rows = "".join("<div>" + "".join(f'<i style="background:#{c:06x}"></i>' for c in colors)
                   + f"{html.escape(label)}</div>" for label, colors in scene.legend())
    return f'<div id="pkm-legend"><b>{html.escape(scene.mechanism.name)}</b>{rows}</div>'


def read_commands(page: str) -> list[dict]:
    """The meshcat commands embedded in a page written by :func:`snapshot_html`, decoded."""
    _, umsgpack = _meshcat()
    start = page.find('id="pkm-meshcat-commands">')
    if start < 0:
        raise InvalidInputError("page", "not a pkm.viz snapshot: no pkm-meshcat-commands element", None)
    start = page.index(">", start) + 1
    end = page.index("</script>", start)
    return [umsgpack.unpackb(base64.b64decode(s)) for s in json.loads(page[start:end])]


def write_html(path, mech: Mechanism, q=None, **kw) -> Path:
    """Write :func:`snapshot_html` of ``mech`` to ``path`` (UTF-8); keywords go to it. Returns the path."""
    page = snapshot_html(mech, q, **kw)
    out = Path(path)
    try:
        out.write_text(page, encoding="utf-8")
    except OSError as exc:
        raise InvalidInputError("path", f"cannot write {str(out)!r}: {exc.strerror}", path) from None
    return out


def show(mech: Mechanism, q=None, *, trajectory=None, times=None, vis=None):
    """Draw ``mech`` at ``q`` (and animate ``trajectory``) in a live meshcat viewer.

    Args:
        mech: The mechanism.
        q: Configuration shown (nq,); default ``mech.q_reference`` (or the first of ``trajectory``).
        trajectory: Configurations to animate, (N, nq), or None.
        times: Time of each configuration [s], (N,); default 30 configurations per second.
        vis: A ``meshcat.Visualizer``; None starts one (a meshcat server process; open ``vis.url()``).

    Returns:
        The visualizer. The mechanism is drawn under ``<vis path>/pkm``, replacing an earlier drawing.
    """
    mc, _ = _meshcat()
    if vis is None:
        import meshcat.visualizer

        with contextlib.redirect_stdout(io.StringIO()):  # it prints its URL
            vis = meshcat.visualizer.Visualizer()
    root = vis.path.append("pkm")
    scene = Scene.from_mechanism(mech, root=root.lower())
    cmds = scene_commands(scene, q, trajectory=trajectory, times=times)
    vis.window.send(mc.commands.Delete(root))
    for c in cmds:
        vis.window.send(c)
    return vis


class Viewer:
    """A live meshcat view of a mechanism with Pinocchio's visualizer interface: ``display(q)`` and
    ``play(q_trajectory, dt)`` (as ``pinocchio.visualize.MeshcatVisualizer``), drawn from pkm's scene.

    Args:
        mech: The mechanism.
        vis: A ``meshcat.Visualizer``; None starts one (a server process: :meth:`close` stops it).
    """

    def __init__(self, mech: Mechanism, vis=None):
        self.mech = mech
        self.vis = show(mech, vis=vis)
        self.scene = Scene.from_mechanism(mech, root=self.vis.path.append("pkm").lower())  # where show() drew it

    def url(self) -> str:
        """The viewer's web address."""
        return self.vis.url()

    def display(self, q=None) -> None:
        """Move every body to configuration ``q`` (default the reference); the geometry is sent once, here
        only the placements."""
        mc, _ = _meshcat()
        q = self.mech.q_reference if q is None else q
        for body, T in zip(self.scene.bodies, self.scene.transforms(q).values()):
            self.vis.window.send(mc.commands.SetTransform(T, _path(mc, body.path)))

    def play(self, q_trajectory, dt: float) -> None:
        """Display the configurations of ``q_trajectory`` (N, nq) one after the other, ``dt`` [s] apart."""
        import time

        dt = as_scalar(dt, "dt", low=0.0, unit="s")
        Q = _check_trajectory(self.mech, q_trajectory, None)[0]
        for q in Q:
            t0 = time.perf_counter()
            self.display(q)
            time.sleep(max(0.0, dt - (time.perf_counter() - t0)))

    def close(self) -> None:
        """Stop the viewer's server if this viewer started it (see :func:`close`)."""
        close(self.vis)


def close(vis, timeout: float = 5.0) -> None:
    """Stop the meshcat server process that :func:`show` started for ``vis`` and wait for it.

    meshcat starts its server in a session of its own and stops it only from an ``atexit`` hook,
    which a process ended by a signal never runs: without this call the server outlives its
    parent and keeps its ports (7000 on), and the next viewer silently moves to 7001. Safe to
    call twice, and on a visualizer connected to a server it did not start (then it does nothing).
    """
    proc = getattr(getattr(vis, "window", None), "server_proc", None)
    if proc is None or proc.poll() is not None:
        return
    proc.terminate()
    try:
        proc.wait(timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


__all__ = [
    "ACTUATED_COLOR", "FPS", "MIMIC_COLOR", "PASSIVE_COLOR", "ROOT", "Body", "Scene", "Viewer", "VizDependencyError", "close",
    "pack_commands", "read_commands", "scene_commands", "show", "snapshot_html", "write_html",
]
