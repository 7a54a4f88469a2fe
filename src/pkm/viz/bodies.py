"""The bodies that draw a mechanism, built from its Pinocchio tree and closure spec (see :mod:`pkm.viz`).

Joints as spheres coloured by actuation, bodies as cylinders coloured by leg, the platform and the base as convex
hulls (:mod:`pkm.viz.hull`), closures as a dot in a bubble, world and end-effector triads. Sizes are fractions of
the mechanism's characteristic length.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pkm.core.model.mechanism import Mechanism
from pkm.viz.body import Body
from pkm.viz.colors import (
    AXIS_COLORS,
    BASE_COLOR,
    CLOSURE_COLOR,
    JOINT_COLORS,
    LEG_COLORS,
    LINK_COLOR,
    PLATFORM_COLOR,
)
from pkm.viz.hull import convex_hull, layered_polygons, unique_points

# Sizes relative to the mechanism's characteristic length (diagonal of its bounding box).
JOINT_RADIUS = 0.02
_LINK_RADIUS = 0.4  # of the joint radius
_BASE_BAR = 0.6  # the radius of the bar drawn between two base anchors, of the joint radius
_PLATFORM_FRACTION = 0.15  # largest joint radius, of the platform's diameter
_NESTED_SCALE = 1.35  # radius of a joint's ring around its parent's sphere
_TRIAD_LENGTH = 0.12
_TRIAD_RADIUS = 0.2 * JOINT_RADIUS
CENTRE_OF_MASS = "centre of mass"
"""The name of a link's far end when the link runs to its body's centre of mass (:attr:`Body.ends`)."""


def build_bodies(mech: Mechanism, root: str) -> tuple[list[Body], float, str | None]:
    """The bodies that draw ``mech`` under meshcat path ``root``, its characteristic length [m] and the name of the
    joint that carries its platform (None if the end effector is fixed to the world)."""
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
        if len(unique_points(np.array(verts).reshape(-1, 3), eps)) < 3:
            verts.append(np.zeros(3))  # a leg carries the platform: its joint is a corner too
        hull = convex_hull(np.array(verts), eps)
        if hull is not None:
            bodies.append(Body(f"{root}/platform", "mesh", "platform", joint_frame(pj), eye.copy(),
                               PLATFORM_COLOR, vertices=hull[0], faces=hull[1], joint=model.names[pj]))
    # joint spheres: a fraction of the mechanism's size, small enough to leave the platform visible
    # and the end-effector triad no longer than the platform is wide
    r_joint, ee_triad = JOINT_RADIUS * length, _TRIAD_LENGTH * length
    if bodies:
        v = bodies[0].vertices
        diameter = float(np.max(np.linalg.norm(v[:, None] - v[None], axis=-1)))
        r_joint, ee_triad = min(r_joint, _PLATFORM_FRACTION * diameter), min(ee_triad, diameter)

    # the base: anchors of the joints hung on the world, and closure frames fixed to it
    anchors = [np.array(model.jointPlacements[j].translation) for j in range(1, model.njoints)
               if model.parents[j] == 0 and model.joints[j].shortname() != "JointModelFreeFlyer"]
    anchors += [local(f) for f in closure_ids if model.frames[f].parentJoint == 0]
    hull = layered_polygons(np.array(anchors).reshape(-1, 3), eps)
    if hull is not None:
        bodies.append(Body(f"{root}/base", "mesh", "base", joint_frame(0), eye.copy(), BASE_COLOR, opacity=0.5,
                           vertices=hull[0], faces=hull[1], joint=model.names[0]))
    elif len(ends := unique_points(np.array(anchors).reshape(-1, 3), eps)) >= 2:  # two anchors, or a line: a bar
        far = np.linalg.norm(ends[:, None] - ends[None], axis=-1)
        a, b = np.unravel_index(int(np.argmax(far)), far.shape)
        bodies.append(Body(f"{root}/base", "cylinder", "base", joint_frame(0), _segment(ends[a], ends[b]),
                           BASE_COLOR, (float(far[a, b]), _BASE_BAR * r_joint), joint=model.names[0]))

    # links: cylinders from each joint's origin to its children and to the frames it carries (the platform's body:
    # the polygon draws them, unless its frames make no polygon, as the five-bar's tip), coloured by leg (the tree cut
    # at the platform where there is one drawn); a body with mass that reaches nowhere else: a link to its centre of
    # mass (the cylinder of a Gough-Stewart leg, its piston on a prismatic joint at the same origin)
    platform_drawn = any(b.role == "platform" for b in bodies)
    legs = _legs(mech, pj if platform_drawn else 0)
    rank = {pin.FrameType.BODY: 1, pin.FrameType.OP_FRAME: 2, pin.FrameType.FIXED_JOINT: 3}
    for j in range(1, model.njoints):
        targets = [(model.names[c], np.array(model.jointPlacements[c].translation))
                   for c in range(1, model.njoints) if model.parents[c] == j]
        if j != pj or not platform_drawn:
            frames = [f for f in range(model.nframes) if model.frames[f].parentJoint == j
                      and model.frames[f].type in rank]
            frames.sort(key=lambda f: (rank[model.frames[f].type], f))
            targets += [(model.frames[f].name, local(f)) for f in frames]
            if all(np.linalg.norm(p) <= eps for _, p in targets) and model.inertias[j].mass > 0:
                targets.append((CENTRE_OF_MASS, np.array(model.inertias[j].lever)))
        seen: list[np.ndarray] = []
        for name, p in targets:
            if np.linalg.norm(p) <= eps or any(np.linalg.norm(p - s) <= eps for s in seen):
                continue
            seen.append(p)
            leg, color = legs.get(j, (None, LINK_COLOR))
            end = "centre_of_mass" if name == CENTRE_OF_MASS else _clean(name)
            bodies.append(Body(f"{root}/links/{_clean(model.names[j])}-{end}", "cylinder", "link",
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
