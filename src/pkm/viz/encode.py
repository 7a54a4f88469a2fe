"""A scene as meshcat commands: the viewer set-up, one object and one placement per body, an animation."""

from __future__ import annotations

import base64
import dataclasses
import json
import math
import uuid
from typing import Any

import numpy as np
import pinocchio as pin

from pkm.core.model.mechanism import Mechanism
from pkm.errors import InvalidInputError
from pkm.viz.backend import load_meshcat
from pkm.viz.body import Body
from pkm.viz.colors import BACKGROUND
from pkm.viz.interference import interference_marks
from pkm.viz.scene import Scene

FPS = 30.0
"""Frame rate [1/s] of the animation keys, and of a trajectory given without times."""

_UUID_NAMESPACE = uuid.UUID("6f1b4c1e-8d4a-4e0b-9a51-7c6d2f3e9b10")


def check_trajectory(mech: Mechanism, trajectory, times) -> tuple[np.ndarray, np.ndarray]:
    """``trajectory`` (N, nq), each row checked, and its ``times`` [s] (default ``arange(N) / FPS``)."""
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


def meshcat_path(mc, path: str):
    """The ``meshcat.path.Path`` of an absolute meshcat ``path`` such as ``/meshcat/pkm/joints/a``."""
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


def scene_commands(scene: Scene, q=None, *, trajectory=None, times=None, loop: bool = True,
                   collisions: bool = True) -> list:
    """The meshcat commands that draw ``scene`` at ``q`` and, optionally, animate a trajectory.

    Args:
        scene: The scene to draw.
        q: Configuration shown (nq,); default the first of ``trajectory``, else the reference.
        trajectory: Configurations to animate, (N, nq), or None.
        times: Time of each configuration [s], (N,), strictly increasing; default ``arange(N) / 30``.
        loop: Whether the animation repeats forever (else it plays once).
        collisions: At one configuration (no trajectory), where the mechanism has collision geometry, colour the
            bodies that interpenetrate and mark the witness points (:func:`~pkm.viz.interference.interference_marks`);
            False: not.

    Returns:
        A list of ``meshcat.commands`` objects (``SetProperty``, ``SetTransform``, ``SetObject``,
        ``SetAnimation``): the viewer set-up first (meshcat's own axes and grid hidden, the grid
        moved to the mechanism's z = 0 plane should it be shown again, the mechanism's node
        shifted so that its centre sits at meshcat's origin, where the camera looks, and the
        camera placed to frame it), then one ``SetObject`` and one ``SetTransform`` per body
        (its world placement, under that node), then the interference marks, then the animation.
    """
    mc, _ = load_meshcat()
    mech = scene.mechanism
    traj = tm = None
    if trajectory is not None:
        traj, tm = check_trajectory(mech, trajectory, times)
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
        mc.commands.SetProperty("visible", False, meshcat_path(mc, "/Axes")),
        mc.commands.SetProperty("visible", False, meshcat_path(mc, "/Grid")),
        # a light grey background, against which every colour of the legend stands out (meshcat's is sky blue)
        mc.commands.SetProperty("top_color", list(BACKGROUND[0]), meshcat_path(mc, "/Background")),
        mc.commands.SetProperty("bottom_color", list(BACKGROUND[1]), meshcat_path(mc, "/Background")),
        mc.commands.SetTransform(shift, meshcat_path(mc, "/Grid")),
        # the camera hangs in a frame turned by +90 deg about x (its y is the world z)
        mc.commands.SetProperty("position", [float(d[0]), float(d[2]), float(-d[1])],
                                meshcat_path(mc, "/Cameras/default/rotated/<object>")),
        mc.commands.SetTransform(shift, meshcat_path(mc, scene.root)),
    ]
    marks = interference_marks(scene, q) if collisions and traj is None else None
    colors = {} if marks is None else marks.colors
    placed = list(zip(scene.bodies, scene.transforms(q).values()))
    placed += [(b, b.offset) for b in (marks.bodies if marks is not None else ())]  # (on the world frame)
    for body, m in placed:
        if body.path in colors:
            body = dataclasses.replace(body, color=colors[body.path])
        cmds.append(mc.commands.SetObject(_primitive(mc, body), path=meshcat_path(mc, body.path)))
        cmds.append(mc.commands.SetTransform(m, meshcat_path(mc, body.path)))
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
        anim.clips = {meshcat_path(mc, p): c for p, c in clips.items()}
        cmds.append(mc.commands.SetAnimation(anim, play=True, repetitions=math.inf if loop else 1))
    return cmds



def pack_commands(cmds: list) -> list[str]:
    """Each command lowered, msgpack-encoded as meshcat's server sends it, then base64 (ASCII)."""
    _, umsgpack = load_meshcat()
    return [base64.b64encode(umsgpack.packb(c.lower())).decode("ascii") for c in cmds]



def read_commands(page: str) -> list[dict]:
    """The meshcat commands embedded in a page written by :func:`snapshot_html`, decoded."""
    _, umsgpack = load_meshcat()
    start = page.find('id="pkm-meshcat-commands">')
    if start < 0:
        raise InvalidInputError("page", "not a pkm.viz snapshot: no pkm-meshcat-commands element", None)
    start = page.index(">", start) + 1
    end = page.index("</script>", start)
    return [umsgpack.unpackb(base64.b64decode(s)) for s in json.loads(page[start:end])]
