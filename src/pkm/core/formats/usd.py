"""USD: a UsdPhysics articulation whose loops are joints excluded from it (``usd-core``, the ``usd`` extra).

pkm reads, from a stage (``.usda`` text, ``.usd``/``.usdc`` binary, with its sublayers and references):

* every prim with ``PhysicsRigidBodyAPI``: a body, named after its prim (or its ``pkm:name``), at its world pose
  (unscaled: a scaled body is refused), with ``PhysicsMassAPI``'s ``mass``, ``centerOfMass`` (in the body frame),
  ``diagonalInertia`` and ``principalAxes`` (a body without an authored mass is massless: pkm does not compute masses
  from collision shapes, a note says which);
* ``PhysicsRevoluteJoint``, ``PhysicsPrismaticJoint``, ``PhysicsSphericalJoint``, ``PhysicsFixedJoint``: ``physics:body0``
  and ``body1`` (none, or a prim that is no body and under none: the world; a prim under a body: that body, the
  frames moved to it), ``localPos0/localRot0`` and ``localPos1/localRot1`` (the joint frame in each body: the joint is
  at zero where they coincide, pkm's zero too), ``physics:axis`` (``X``, ``Y``, ``Z`` of the joint frame),
  ``physics:lowerLimit``/``upperLimit`` (degrees for a revolute: read in radians; infinite: none); a joint with
  ``physics:jointEnabled = false`` is skipped (a note);
* the tree: from the world through the joints not excluded from the articulation; a joint with
  ``physics:excludeFromArticulation = true``, or one that closes a cycle of the others (a note), cuts a loop, between
  frames ``<joint>_parent`` (on body0, at its local frame) and ``<joint>_child`` (body1): a spherical joint is a
  ``point`` closure, a fixed joint a ``frame`` closure, a revolute two ``point`` closures ``<joint>`` and
  ``<joint>_axis`` (at the joint and 0.1 m along its axis: exactly a revolute, as pkm's SDF reader does); a joint the
  tree walks from body1 to body0 is reversed (its axis negated: the same coordinate). A body no joint of the tree holds
  is free (UsdPhysics' reading): a free-flyer joint, named by the body's ``pkm:freeJoint`` (else ``<body>_free``),
  carries it at its pose; it is the floating base when every other body hangs below it;
* a drive (``PhysicsDriveAPI:angular``, ``:linear``) makes its joint actuated (in the default prim's ``pkm:actuated``
  order where it names them, else the stage's): ``damping`` the viscous friction, ``stiffness`` the servo stiffness
  (per degree for an angular drive, read per radian; 0: a rigid drive), ``maxForce`` the effort limit; the armature
  (``newton:armature``, else ``physxJoint:armature``, else ``mjc:armature``) and ``physxJoint:maxJointVelocity``
  (degrees per second) the drive's armature and speed limit;
* ``Xform`` prims marked ``pkm:frame = true``: frames (an end effector, a task frame) on the body above them.

Units are converted at the edge: lengths by the stage's ``metersPerUnit`` (USD's fallback 0.01 when it is not
authored: a note says so), masses by ``kilogramsPerUnit``, inertias, efforts, gains and armatures by their products.

pkm's own double-precision attributes (:mod:`pkm.core.formats.to_usd` writes them: ``pkm:localPos0`` ...,
``pkm:mass``, ``pkm:inertia``, ``pkm:lowerLimit`` ..., ``pkm:actuator:<field>``, ``pkm:mimic:*``) are taken where they
agree with the standard single-precision ones (to 1e-6 of their size), else the standard ones are, and a note says
which disagree.

Not read: collision and visual shapes, materials, joint friction (but pkm's ``pkm:actuator:coulomb``), spherical cone
limits and the D6 joint's limits (a note), springs. Refused with a :class:`~pkm.errors.SpecError` naming the prim:
a malformed stage, a plain ``PhysicsJoint`` (D6) or a distance joint, a joint naming several bodies or a missing one,
a joint between a body and itself, a scaled body, a prismatic loop joint, a drive on a loop joint or on a joint with
no single coordinate, two prims of one name; a stage given as text (an upload) that names other files (sublayers,
references, payloads: those are read from a file's path only).
"""

from __future__ import annotations

import math
import re
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
from lxml import etree

from pkm.core.formats.base import Imported
from pkm.core.formats.sdf import _AXIS_POINT
from pkm.core.formats.to_usd import pxr
from pkm.core.model.actuators import NUMBERS
from pkm.core.model.spec import Closure
from pkm.core.model.urdf import check_urdf, num, origin
from pkm.errors import SpecError

_AGREE = 1e-6  # pkm's double attribute agrees with the standard float one within this, relative to its size
_TYPES = {"PhysicsRevoluteJoint": "revolute", "PhysicsPrismaticJoint": "prismatic",
          "PhysicsSphericalJoint": "spherical", "PhysicsFixedJoint": "fixed"}
_AXES = {"X": np.array([1.0, 0.0, 0.0]), "Y": np.array([0.0, 1.0, 0.0]), "Z": np.array([0.0, 0.0, 1.0])}


@dataclass
class _Body:
    name: str
    path: str
    pose: pin.SE3  # in the world [m]
    inertia: pin.Inertia  # in the body frame [SI]
    root: bool = False  # PhysicsArticulationRootAPI on it
    free_joint: str | None = None


@dataclass
class _Joint:
    name: str
    path: str
    kind: str
    body0: str | None
    body1: str | None
    local0: pin.SE3
    local1: pin.SE3
    axis: np.ndarray
    limits: tuple[float, float] | None
    exclude: bool
    drive: dict[str, float] | None = None
    mimic: tuple[str, float, float] | None = None
    reversed: bool = False
    extra: dict[str, Any] = field(default_factory=dict)


def _open(p: Any, text: str, source: str) -> Any:
    """The stage of ``text`` (parsed from it), or of the file ``source`` when ``text`` is empty."""
    try:
        if text:
            layer = p.Sdf.Layer.CreateAnonymous(".usda")
            if not layer.ImportFromString(text):
                raise SpecError(source, "not a USD layer pkm can parse (usda text)")
            named = sorted(layer.GetCompositionAssetDependencies())
            if named:  # (text given, an upload: it may not make pkm open files of this machine)
                raise SpecError(source, f"a USD stage given as text names other files ({named[:3]}): sublayers, "
                                        "references and payloads are read from files only (pkm.load of the path)")
            return p.Usd.Stage.Open(layer)
        layer = p.Sdf.Layer.Find(str(source))
        if layer is not None:  # (one this process holds: read the file as it is now)
            layer.Reload(True)
        stage = p.Usd.Stage.Open(str(source))
    except p.Tf.ErrorException as exc:
        detail = re.sub(r"Error in '[^']*' at line \d+ in file \S+ : |pxrInternal_v\w*?__pxrReserved__::", "",
                        " ".join(str(exc).split()))[:300]
        raise SpecError(source, f"not a USD stage pkm can open: {detail}") from None
    if stage is None:
        raise SpecError(source, "not a USD stage pkm can open")
    return stage


def read_usd(text: str, source: str = "<usd>") -> Imported:
    """Read a USD stage (see the module doc): ``text`` (usda), or the file ``source`` when ``text`` is empty (a
    binary crate file is opened from its path).

    Raises:
        MissingDependencyError: ``usd-core`` is not installed (the ``usd`` extra).
        SpecError: a malformed stage, or a refused feature (module doc), naming the prim.
    """
    p = pxr("reading USD")
    stage = _open(p, text, source)
    try:
        return _read(p, stage, source)
    except RecursionError:
        raise SpecError(source, "prims nested deeper than Python's recursion limit") from None


def _vec(value: Any, n: int) -> np.ndarray:
    return np.array([float(value[i]) for i in range(n)])


def _rot(quat: Any) -> np.ndarray:
    """The rotation matrix of a Gf quaternion (identity for a zero one: USD's unauthored)."""
    w, v = float(quat.GetReal()), _vec(quat.GetImaginary(), 3)
    if w == 0.0 and not v.any():
        return np.eye(3)
    return pin.Quaternion(w, *v).normalized().matrix()


def _read(p: Any, stage: Any, source: str) -> Imported:
    Usd, UsdGeom, UsdPhysics = p.Usd, p.UsdGeom, p.UsdPhysics
    notes: list[str] = []
    mpu = float(UsdGeom.GetStageMetersPerUnit(stage))
    kpu = float(UsdPhysics.GetStageKilogramsPerUnit(stage))
    if not stage.HasAuthoredMetadata("metersPerUnit"):
        notes.append(f"metersPerUnit not authored: USD's fallback {mpu:g} m per unit read")
    if not (math.isfinite(mpu) and mpu > 0 and math.isfinite(kpu) and kpu > 0):
        raise SpecError(source, f"metersPerUnit {mpu!r} and kilogramsPerUnit {kpu!r} must be finite and > 0")
    time = Usd.TimeCode.Default()
    disagree: list[str] = []

    def attr(prim: Any, name: str) -> Any:
        a = prim.GetAttribute(name)
        return a.Get() if a and a.HasAuthoredValue() else None

    def exact(prim: Any, name: str, standard: np.ndarray, value: Any) -> np.ndarray:
        """pkm's double value of ``name`` where it agrees with ``standard`` (module doc), else ``standard``."""
        if value is None:
            return standard
        x = np.asarray(value, dtype=float)
        finite = np.isfinite(standard)
        if np.array_equal(np.isfinite(x), finite) and np.array_equal(x[~finite], standard[~finite]) and \
                np.abs(x[finite] - standard[finite]).max(initial=0.0) <= \
                _AGREE * max(np.abs(standard[finite]).max(initial=0.0), 1e-300):
            return x
        disagree.append(f"{prim.GetPath()}.{name}")
        return standard

    def world(prim: Any) -> pin.SE3:
        """A prim's world pose [m]; refused if scaled or sheared."""
        M = np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(time), dtype=float).T  # (row vectors)
        R = M[:3, :3]
        if np.abs(R @ R.T - np.eye(3)).max() > 1e-6 or np.linalg.det(R) < 0:
            raise SpecError(source, f"prim {prim.GetPath()}: a scaled or mirrored transform (pkm reads rigid "
                                    "placements: put the scale on the geometry below the body)")
        U, _, Vt = np.linalg.svd(R)
        return pin.SE3(U @ Vt, M[:3, 3] * mpu)

    def name_of(prim: Any) -> str:
        n = attr(prim, "pkm:name")
        return str(n) if n else str(prim.GetName())

    def local(prim: Any, a: Any) -> np.ndarray | None:
        return None if a is None else np.array(a, dtype=float).reshape(3, 3).T  # (Gf row-major, row vectors)

    # bodies
    bodies: dict[str, _Body] = {}
    by_path: dict[str, str] = {}
    massless: list[str] = []
    for prim in stage.Traverse():
        if not prim.HasAPI(UsdPhysics.RigidBodyAPI):
            continue
        name = name_of(prim)
        if name in bodies:
            raise SpecError(source, f"prims {bodies[name].path} and {prim.GetPath()} are both bodies named {name!r}: "
                                    "pkm names bodies after their prims; rename one")
        mass_api = UsdPhysics.MassAPI(prim) if prim.HasAPI(UsdPhysics.MassAPI) else None
        m = float(mass_api.GetMassAttr().Get() or 0.0) if mass_api else 0.0
        com = _vec(mass_api.GetCenterOfMassAttr().Get(), 3) if mass_api else np.zeros(3)
        diag = _vec(mass_api.GetDiagonalInertiaAttr().Get(), 3) if mass_api else np.zeros(3)
        axes = _rot(mass_api.GetPrincipalAxesAttr().Get()) if mass_api else np.eye(3)
        if not np.isfinite(com).all():  # (USD's unauthored centre of mass: -inf, "computed")
            com = np.zeros(3)
        m = float(exact(prim, "pkm:mass", np.array(m), attr(prim, "pkm:mass")))
        com = exact(prim, "pkm:centerOfMass", com, attr(prim, "pkm:centerOfMass"))
        I = exact(prim, "pkm:inertia", axes @ np.diag(diag) @ axes.T, local(prim, attr(prim, "pkm:inertia")))
        if not (math.isfinite(m) and m >= 0.0 and np.isfinite(I).all()):
            raise SpecError(source, f"body {prim.GetPath()}: mass {m!r} and inertia must be finite, the mass >= 0")
        if m == 0.0 and attr(prim, "pkm:mass") is None:
            massless.append(name)
        inertia = pin.Inertia(m * kpu, com * mpu, I * kpu * mpu * mpu)
        free = attr(prim, "pkm:freeJoint")
        bodies[name] = _Body(name, str(prim.GetPath()), world(prim), inertia, prim.HasAPI(UsdPhysics.ArticulationRootAPI),
                             str(free) if free else None)
        by_path[str(prim.GetPath())] = name
    if not bodies:
        raise SpecError(source, "no prim with PhysicsRigidBodyAPI: no body to read")
    if massless:
        notes.append(f"bodies {massless} have no authored mass: read as massless (pkm does not compute masses from "
                     "collision shapes)")

    def holder(prim: Any) -> tuple[str | None, pin.SE3]:
        """The body a joint's target belongs to (None: the world) and the target's frame in it."""
        node = prim
        while node and node.GetPath() != node.GetPath().absoluteRootPath:
            if str(node.GetPath()) in by_path:
                body = by_path[str(node.GetPath())]
                return body, pin.SE3.Identity() if node == prim else bodies[body].pose.inverse() * world(prim)
            node = node.GetParent()
        return None, world(prim)

    # joints
    joints: list[_Joint] = []
    for prim in stage.Traverse():
        if not prim.IsA(UsdPhysics.Joint):
            continue
        where = f"joint {prim.GetPath()}"
        kind = _TYPES.get(str(prim.GetTypeName()))
        if kind is None:
            raise SpecError(source, f"{where}: a {prim.GetTypeName()} is not read (pkm reads revolute, prismatic, "
                                    "spherical and fixed joints)")
        joint = UsdPhysics.Joint(prim)
        if joint.GetJointEnabledAttr().Get() is False:
            notes.append(f"{where}: jointEnabled = false, skipped")
            continue
        ends: list[str | None] = []
        frames: list[pin.SE3] = []
        for k in (0, 1):
            targets = getattr(joint, f"GetBody{k}Rel")().GetTargets()
            if len(targets) > 1:
                raise SpecError(source, f"{where}: physics:body{k} names {len(targets)} prims; a joint ties two")
            if targets and not stage.GetPrimAtPath(targets[0]):
                raise SpecError(source, f"{where}: physics:body{k} names {targets[0]}, which is not on the stage")
            body, X = holder(stage.GetPrimAtPath(targets[0])) if targets else (None, pin.SE3.Identity())
            pos = _vec(getattr(joint, f"GetLocalPos{k}Attr")().Get(), 3)
            R = _rot(getattr(joint, f"GetLocalRot{k}Attr")().Get())
            pos = exact(prim, f"pkm:localPos{k}", pos, attr(prim, f"pkm:localPos{k}"))
            dq = attr(prim, f"pkm:localRot{k}")
            R = exact(prim, f"pkm:localRot{k}", R, None if dq is None else _rot(dq))
            L = pin.SE3(R, pos * mpu)
            ends.append(body)
            frames.append(X * L)
        if ends[0] == ends[1]:
            raise SpecError(source, f"{where}: both ends on {ends[0] or 'the world'!r}")
        axis, limits = _AXES["X"], None
        if kind in ("revolute", "prismatic"):
            token = str(prim.GetAttribute("physics:axis").Get() or "X")
            if token not in _AXES:
                raise SpecError(source, f"{where}: axis {token!r} is not X, Y or Z")
            axis = _AXES[token]
            scale = math.pi / 180.0 if kind == "revolute" else mpu
            lo, hi = (float(v if (x := prim.GetAttribute(f"physics:{b}Limit").Get()) is None else x)
                      for b, v in (("lower", -math.inf), ("upper", math.inf)))
            b = exact(prim, "pkm:lowerLimit", np.array([lo, hi]) * scale,
                      None if attr(prim, "pkm:lowerLimit") is None else
                      [attr(prim, "pkm:lowerLimit"), attr(prim, "pkm:upperLimit")])
            if np.isfinite(b).all():
                if b[0] > b[1]:
                    raise SpecError(source, f"{where}: lower limit {lo!r} above the upper {hi!r}")
                limits = (float(b[0]), float(b[1]))
        elif kind == "spherical" and any(float(prim.GetAttribute(f"physics:coneAngle{k}Limit").Get() or -1) >= 0
                                         for k in (0, 1)):
            notes.append(f"{where}: its cone limits are not read")
        exclude = bool(joint.GetExcludeFromArticulationAttr().Get())
        jt = _Joint(name_of(prim), str(prim.GetPath()), kind, ends[0], ends[1], frames[0], frames[1], axis, limits,
                    exclude)
        drives = [d for d in UsdPhysics.DriveAPI.GetAll(prim)]
        if drives:
            jt.drive = _drive(prim, drives[0], kind, mpu, kpu, attr, exact, where, source)
        leader = attr(prim, "pkm:mimic:joint")
        if leader:
            jt.mimic = (str(leader), float(attr(prim, "pkm:mimic:multiplier") or 1.0),
                        float(attr(prim, "pkm:mimic:offset") or 0.0))
        joints.append(jt)
    names = [j.name for j in joints]
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        raise SpecError(source, f"two joint prims are named {dup!r}; pkm names joints after their prims")
    if disagree:
        notes.append(f"pkm's double-precision attributes disagree with the standard ones, which are read: {disagree}")
    marked: list[tuple[str, str | None, pin.SE3]] = []  # pkm:frame prims: (name, body, placement in it)
    for prim in stage.Traverse():
        if prim.GetTypeName() == "Xform" and attr(prim, "pkm:frame") is True:
            body, X = holder(prim)
            marked.append((name_of(prim), body, X))
    root_prim = stage.GetDefaultPrim()
    order = attr(root_prim, "pkm:actuated") if root_prim else None
    title = (attr(root_prim, "pkm:name") if root_prim else None) or \
        (str(root_prim.GetName()) if root_prim else Path(source).stem)
    return _build(str(title), bodies, joints, marked, notes, list(order) if order else None, source)


def _drive(prim: Any, drive: Any, kind: str, mpu: float, kpu: float, attr: Any, exact: Any, where: str,
           source: str) -> dict[str, float]:
    """The actuator fields of a joint's drive (module doc), SI."""
    if kind not in ("revolute", "prismatic"):
        raise SpecError(source, f"{where}: a drive on a {kind} joint (pkm actuates joints of one coordinate)")
    angular = kind == "revolute"
    effort = kpu * mpu * mpu if angular else kpu * mpu  # N m or N per file unit
    per = 180.0 / math.pi if angular else 1.0 / mpu  # per degree -> per rad; per unit -> per m
    out: dict[str, float] = {}
    damping = float(drive.GetDampingAttr().Get() or 0.0) * effort * per
    stiffness = float(drive.GetStiffnessAttr().Get() or 0.0) * effort * per
    max_force = float(drive.GetMaxForceAttr().Get() if drive.GetMaxForceAttr().HasAuthoredValue() else math.inf)
    armature = next((float(v) for v in (attr(prim, k) for k in ("newton:armature", "physxJoint:armature",
                                                                  "mjc:armature")) if v is not None), 0.0)
    speed = attr(prim, "physxJoint:maxJointVelocity")
    standard = {"viscous": damping, "stiffness": stiffness if stiffness > 0 else math.inf,
                "effort_limit": max_force * effort if 0 < max_force < math.inf else math.inf,
                "armature": armature * (kpu * mpu * mpu if angular else kpu),
                "velocity_limit": float(speed) * (math.pi / 180.0 if angular else mpu)
                if speed is not None and 0 < float(speed) < math.inf else math.inf}
    ours = {f: attr(prim, f"pkm:actuator:{f}") for f in NUMBERS}
    if all(v is not None for v in ours.values()):  # pkm's whole drive, where it agrees with the standard values
        mine = {f: float(v) for f, v in ours.items()}
        checks = {"viscous": mine["viscous"], "stiffness": mine["stiffness"],
                  "effort_limit": mine["peak_effort"] if math.isfinite(mine["peak_effort"]) else mine["effort_limit"],
                  "armature": mine["rotor_inertia"] * mine["gear_ratio"] ** 2 + mine["armature"],
                  "velocity_limit": mine["velocity_limit"]}
        if all(exact(prim, f"pkm:actuator:{f}", np.array(standard[f]), checks[f]) == checks[f] for f in checks):
            return {f: v for f, v in mine.items()}
    for f, v in standard.items():
        if v != 0.0 and math.isfinite(v):
            out[f] = v
    return out


def _build(title: str, bodies: dict[str, _Body], joints: list[_Joint], marked: list[tuple[str, str | None, pin.SE3]],
           notes: list[str], order: list[str] | None, source: str) -> Imported:
    # the tree: breadth first from the world through the articulation's joints, then from each free body
    edges: dict[str | None, list[_Joint]] = {}
    for j in joints:
        if not j.exclude:
            edges.setdefault(j.body0, []).append(j)
            edges.setdefault(j.body1, []).append(j)
    parent_joint: dict[str, _Joint] = {}
    tree: list[_Joint] = []
    seen: set[str | None] = {None}
    cuts = [j for j in joints if j.exclude]
    used: set[int] = set()
    free: list[str] = []

    def walk(start: str | None) -> None:
        todo = deque([start])
        while todo:
            node = todo.popleft()
            for j in edges.get(node, []):
                if id(j) in used:
                    continue
                used.add(id(j))
                other = j.body1 if j.body0 == node else j.body0
                if other in seen:
                    cuts.append(j)
                    notes.append(f"joint {j.path} closes a loop but is not excluded from the articulation: read as "
                                 "a loop joint")
                    continue
                assert other is not None
                j.reversed = j.body0 != node
                seen.add(other)
                parent_joint[other] = j
                tree.append(j)
                todo.append(other)

    walk(None)
    rest = [b for b in bodies if b not in seen]
    while rest:
        root = next((b for b in rest if bodies[b].root), rest[0])
        free.append(root)
        seen.add(root)
        walk(root)
        rest = [b for b in rest if b not in seen]
    if any(j.kind == "prismatic" for j in cuts):
        j = next(j for j in cuts if j.kind == "prismatic")
        raise SpecError(source, f"joint {j.path}: a prismatic loop joint is not read (pkm reads spherical, fixed and "
                                "revolute loop joints)")
    for j in cuts:
        if j.drive is not None:
            raise SpecError(source, f"joint {j.path}: a drive on a loop joint (pkm actuates joints of the tree)")

    names = set(bodies)  # the URDF's links (its joints': taken)
    taken = {j.name for j in joints}
    robot = etree.Element("robot", name=title)
    world = "world" if "world" not in names else "world_"
    names.add(world)
    etree.SubElement(robot, "link", name=world)
    U: dict[str | None, pin.SE3] = {None: pin.SE3.Identity()}  # body frame in its URDF link's frame
    link: dict[str | None, str] = {None: world}
    pose: dict[str | None, pin.SE3] = {None: pin.SE3.Identity()}
    seed: dict[str, tuple[float, ...]] = {}
    reference: dict[str, tuple[float, ...]] = {}
    types: dict[str, str] = {}

    def claim(n: str, among: set[str] = names) -> str:
        if n in among:
            raise SpecError(source, f"pkm names a {'frame' if among is names else 'joint'} {n!r}, which the stage "
                                    "already uses; rename it")
        among.add(n)
        return n

    def add_link(b: str) -> None:
        body = bodies[b]
        lel = etree.SubElement(robot, "link", name=link[b])
        if body.inertia.mass == 0.0 and not np.asarray(body.inertia.inertia).any():
            return
        I = body.inertia.se3Action(U[b])  # (the inertia in the URDF link's frame)
        iel = etree.SubElement(lel, "inertial")
        etree.SubElement(iel, "origin", xyz=num(I.lever), rpy="0 0 0")
        etree.SubElement(iel, "mass", value=repr(float(I.mass)))
        T = np.asarray(I.inertia, dtype=float)
        etree.SubElement(iel, "inertia", {k: repr(float(T[a, c])) for k, (a, c) in
                                          zip(("ixx", "ixy", "ixz", "iyy", "iyz", "izz"),
                                              ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)))})

    def fixed(n: str, parent: str | None, X: pin.SE3) -> None:
        """A frame ``n`` on body ``parent`` at ``X`` in the body's frame."""
        etree.SubElement(robot, "link", name=claim(n))
        jel = etree.SubElement(robot, "joint", name=claim(f"{n}_fixed", taken), type="fixed")
        origin(jel, U[parent] * X)
        etree.SubElement(jel, "parent", link=link[parent])
        etree.SubElement(jel, "child", link=n)

    free_joints: dict[str, str] = {}
    for b in free:  # a free body's link is its own frame, on a free-flyer joint from the world
        U[b], link[b], pose[b] = pin.SE3.Identity(), b, bodies[b].pose
        add_link(b)
        fj = free_joints[b] = claim(bodies[b].free_joint or f"{b}_free", taken)
        jel = etree.SubElement(robot, "joint", name=fj, type="floating")
        origin(jel, pin.SE3.Identity())
        etree.SubElement(jel, "parent", link=world)
        etree.SubElement(jel, "child", link=b)
        reference[fj] = tuple(float(x) for x in pin.SE3ToXYZQUAT(bodies[b].pose))
    late: list[tuple[str, str]] = []
    pending = deque(tree)
    while pending:
        j = pending.popleft()
        parent, child = (j.body1, j.body0) if j.reversed else (j.body0, j.body1)
        Lp, Lc = (j.local1, j.local0) if j.reversed else (j.local0, j.local1)
        if parent not in link:  # (its parent's joint comes first in the walk: never)
            pending.append(j)
            continue
        assert child is not None
        a = -j.axis if j.reversed else j.axis
        t = Lc.translation
        on_axis = float(np.linalg.norm(t - (t @ (Lc.rotation @ a)) * (Lc.rotation @ a))) <= 1e-12 * max(1.0, float(np.linalg.norm(t)))
        if j.kind == "fixed" or j.kind == "prismatic" or (j.kind == "revolute" and on_axis) or \
                (j.kind == "spherical" and Lc.isIdentity(1e-12)):
            U[child], axis = pin.SE3.Identity(), Lc.rotation @ a  # (the link's frame is the body's)
            X = U[parent] * Lp * Lc.inverse()
        else:
            U[child], axis = Lc.inverse(), a  # (the link's frame is the joint's: the body's is a frame on it)
            X = U[parent] * Lp
        link[child] = child if U[child].isIdentity(1e-15) else claim(f"{child}__joint")
        if link[child] != child:
            late.append((child, link[child]))
        add_link(child)
        urdf_kind = {"spherical": "revolute", "fixed": "fixed"}.get(j.kind, j.kind)
        jel = etree.SubElement(robot, "joint", name=j.name, type=urdf_kind)
        origin(jel, X)
        etree.SubElement(jel, "parent", link=link[parent])
        etree.SubElement(jel, "child", link=link[child])
        if j.kind == "spherical":  # (a placeholder [joint_types] makes spherical)
            etree.SubElement(jel, "axis", xyz="0 0 1")
            etree.SubElement(jel, "limit", effort="0", velocity="0")
            types[j.name] = "spherical"
        elif j.kind in ("revolute", "prismatic"):
            etree.SubElement(jel, "axis", xyz=num(axis))
            bounds = {} if j.limits is None else \
                {"lower": repr(j.limits[0]), "upper": repr(j.limits[1])}
            etree.SubElement(jel, "limit", effort="0", velocity="0", **bounds)
            if j.mimic is not None:
                etree.SubElement(jel, "mimic", joint=j.mimic[0], multiplier=repr(j.mimic[1]), offset=repr(j.mimic[2]))
        # the joint's value where the stage poses its bodies (the assembly's seed)
        wp = (bodies[parent].pose if parent is not None else pin.SE3.Identity()) * Lp
        wc = bodies[child].pose * Lc
        rel = wp.inverse() * wc
        if j.kind == "revolute" and j.mimic is None:
            seed[j.name] = (float(pin.log3(rel.rotation) @ a),)
        elif j.kind == "prismatic" and j.mimic is None:
            seed[j.name] = (float(rel.translation @ a),)
        elif j.kind == "spherical":
            seed[j.name] = tuple(float(x) for x in pin.Quaternion(rel.rotation).normalized().coeffs())
    for child, urdf_name in late:  # the body's own frame, where its link is its joint's
        etree.SubElement(robot, "link", name=claim(child) if child not in bodies else child)
        jel = etree.SubElement(robot, "joint", name=claim(f"{child}_fixed", taken), type="fixed")
        origin(jel, U[child])
        etree.SubElement(jel, "parent", link=urdf_name)
        etree.SubElement(jel, "child", link=child)
    closures: list[Closure] = []
    for j in cuts:
        fixed(f"{j.name}_parent", j.body0, j.local0)
        fixed(f"{j.name}_child", j.body1, j.local1)
        if j.kind == "spherical":
            closures.append(Closure(j.name, "point", f"{j.name}_parent", f"{j.name}_child"))
        elif j.kind == "fixed":
            closures.append(Closure(j.name, "frame", f"{j.name}_parent", f"{j.name}_child"))
        else:  # a revolute: two points of its axis
            step = pin.SE3(np.eye(3), _AXIS_POINT * j.axis)
            fixed(f"{j.name}_axis_parent", j.body0, j.local0 * step)
            fixed(f"{j.name}_axis_child", j.body1, j.local1 * step)
            closures += [Closure(j.name, "point", f"{j.name}_parent", f"{j.name}_child"),
                         Closure(f"{j.name}_axis", "point", f"{j.name}_axis_parent", f"{j.name}_axis_child")]
    for n, body, X in marked:
        fixed(n, body, X)
    etree.indent(robot, space="  ")
    urdf = etree.tostring(robot, xml_declaration=True, encoding="utf-8", pretty_print=True).decode()
    check_urdf(urdf, source)
    driven = [j.name for j in tree if j.drive is not None]
    if order is not None and sorted(order) == sorted(driven):
        driven = list(order)
    actuators = {j.name: j.drive for j in tree if j.drive}
    base = free_joints[free[0]] if len(free) == 1 and not edges.get(None) and not any(
        j.body0 is None or j.body1 is None for j in cuts) else None
    return Imported(urdf, tuple(closures), types, tuple(driven), title, "usd", floating_base=base,
                    reference=reference, notes=tuple(notes), actuators={k: v for k, v in actuators.items() if v},
                    seed=seed)


__all__ = ["read_usd"]
