"""A mechanism written as USD (``usd-core``, the ``usd`` extra): its tree as a UsdPhysics articulation, its loops as
joints excluded from it, its drives as ``PhysicsDriveAPI``, the grammar :mod:`pkm.core.formats.usd` reads back.

The stage is in SI (``metersPerUnit = 1``, ``kilogramsPerUnit = 1``, ``upAxis = "Z"``); angles are USD's degrees.
Under the default prim ``/<mechanism>`` (``PhysicsArticulationRootAPI``, and a ``physicsScene`` with the model's
gravity):

* ``bodies/<body>``: one rigid body (``PhysicsRigidBodyAPI``, ``PhysicsMassAPI``) per Pinocchio joint (its body: the
  body frame on it at the identity, else ``<joint>_body``), posed (``xformOp:translate``, ``xformOp:orient``, double)
  at its world placement in the closed reference configuration (:attr:`~pkm.core.Mechanism.q_reference`); its mass,
  centre of mass, principal moments and axes (``physics:diagonalInertia``, ``physics:principalAxes``);
* ``joints/<joint>``: ``PhysicsRevoluteJoint`` / ``PhysicsPrismaticJoint`` (axis ``X``, ``Y`` or ``Z`` of the joint
  frame, a frame rotated onto it for another axis), ``PhysicsSphericalJoint``, from its parent body
  (``physics:body0``; none: the world) to its body (``physics:body1``), ``localPos0/localRot0`` the joint frame in the
  parent body, ``localPos1/localRot1`` in the child: the joint's zero is pkm's. Limits ``physics:lowerLimit``,
  ``physics:upperLimit`` (degrees, metres);
* a free-flyer joint (a platform closed by loops, a floating base): no joint; the body is free (UsdPhysics' reading of a
  body no joint holds) and ``pkm:freeJoint`` names pkm's joint;
* ``loops/<closure>``: a ``point`` closure as a ``PhysicsSphericalJoint``, a ``frame`` closure as a
  ``PhysicsFixedJoint``, between the bodies of its two frames (``body0``: ``frame_a``'s), at those frames, with
  ``physics:excludeFromArticulation = true``;
* each actuated joint's drive: ``PhysicsDriveAPI:angular`` (``linear``) of type ``force``, ``damping`` the viscous
  friction, ``stiffness`` the servo stiffness (0 for a rigid drive: pkm's ``inf``), both per degree for an angular
  drive as UsdPhysics states them, ``maxForce`` the peak effort (else the continuous; unbounded: not authored),
  ``targetPosition`` the reference; the reflected inertia as ``newton:armature`` and ``physxJoint:armature`` (Newton's
  and PhysX's joint armature), the speed limit as ``physxJoint:maxJointVelocity`` (degrees per second);
* the body and operational frames (the end effector, the task's, the closures') as ``Xform`` children of their body
  marked ``pkm:frame = true``, but those named as a closure or a joint (one namespace when read back).

UsdPhysics' joint frames, masses and limits are single precision (``point3f``, ``quatf``, ``float``): pkm writes the
same values in double beside them (``pkm:localPos0``, ``pkm:localRot0``, ... ``pkm:mass``, ``pkm:centerOfMass``,
``pkm:inertia`` the whole tensor, ``pkm:lowerLimit`` ... in SI, every drive field as ``pkm:actuator:<field>``, the
actuated joints' order as the default prim's ``pkm:actuated``), which pkm's reader takes where they agree with the
standard ones to single precision, so that the mechanism reads back to 1e-12; other readers (Newton, Isaac) read the
standard attributes. A mimic joint is a joint of its own with ``pkm:mimic:joint``, ``pkm:mimic:multiplier``,
``pkm:mimic:offset`` (other readers see an independent joint); a universal joint two revolutes ``<name>__1``,
``<name>__2`` through a massless body ``<name>__cross`` (the MJCF and SDF writers' convention).

Left out (said in :attr:`~pkm.core.formats.writers.Written.dropped`): the joint springs, the Coulomb friction (pkm's
own attribute only), the task and working modes (write pkm's spec for them). Refused by name
(:class:`~pkm.errors.SpecError`): planar and other composite joints, an actuated or task universal joint, a closure
whose two frames are on one body.

:func:`serial_usd` writes a serial-equivalent model (:func:`pkm.serial_equivalent`): the serial tree as a plain
articulation, each output joint's ΔM diagonal as its armature, and the transmissions' parameters as custom attributes
(``pkm:transmissions``: :meth:`~pkm.core.transmissions.serial.SerialEquivalent.data` as JSON on the default prim,
``pkm:transmission`` naming each output joint's transmission).
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from pkm.core.formats.to_mjcf import joint_axis, mimic_leader
from pkm.core.formats.to_sdf import SCALAR_KINDS, closed_reference
from pkm.core.model.actuators import NUMBERS, Actuator
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.urdf import unique_name
from pkm.errors import SpecError

if TYPE_CHECKING:
    from pkm.core.transmissions.serial import SerialEquivalent

#: The optional extra that installs ``pxr`` (usd-core).
EXTRA = "usd"
_BASIS = {"X": np.array([1.0, 0.0, 0.0]), "Y": np.array([0.0, 1.0, 0.0]), "Z": np.array([0.0, 0.0, 1.0])}
_ALIGNED = 1e-12  # |a - e_k| below this: the joint's axis is a frame axis (no frame rotated onto it)


def pxr(what: str) -> Any:
    """The ``pxr`` modules pkm uses (``Gf``, ``Sdf``, ``Tf``, ``Usd``, ``UsdGeom``, ``UsdPhysics``), after the ``usd``
    extra's check (:func:`pkm._optional.require`)."""
    import importlib
    from types import SimpleNamespace

    from pkm import _optional

    _optional.require(EXTRA, what)
    return SimpleNamespace(**{m: importlib.import_module(f"pxr.{m}") for m in
                              ("Gf", "Sdf", "Tf", "Usd", "UsdGeom", "UsdPhysics")})


@dataclass
class _Body:
    name: str
    placement: pin.SE3
    inertia: pin.Inertia
    free_joint: str | None = None
    frames: list[tuple[str, pin.SE3]] = field(default_factory=list)


@dataclass
class _Joint:
    name: str
    kind: str  # revolute, prismatic, spherical, fixed
    body0: str | None
    body1: str
    local0: pin.SE3
    local1: pin.SE3
    axis: str = "X"
    limits: tuple[float, float] | None = None
    exclude: bool = False
    mimic: tuple[str, float, float] | None = None
    custom: dict[str, object] = field(default_factory=dict)


def _onto(axis: np.ndarray) -> tuple[str, np.ndarray]:
    """A USD axis token and the rotation of the joint frame that puts that axis on ``axis`` (unit)."""
    a = axis / np.linalg.norm(axis)
    for token, e in _BASIS.items():
        if np.abs(a - e).max() <= _ALIGNED:
            return token, np.eye(3)
    return "X", pin.Quaternion.FromTwoVectors(_BASIS["X"], a).matrix()


def _tree(model: pin.Model, q: np.ndarray, limits: Mapping[str, tuple[float, float]], taken: set[str],
          source: str, refuse_universal: set[str]) -> tuple[list[str], list[_Body], list[_Joint]]:
    """The bodies and joints of ``model`` at ``q``: ``(body name of each Pinocchio joint, bodies, joints)``."""
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    names = {model.names[j] for j in range(model.njoints)}

    def unique(base: str) -> str:
        return unique_name(base, taken, names)

    links: list[str] = [""]  # the body of each joint ("" : the world)
    bodies: list[_Body] = []
    joints: list[_Joint] = []
    for j in range(1, model.njoints):
        jm, jname = model.joints[j], model.names[j]
        kind = jm.shortname().removeprefix("JointModel")
        frame = next((f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == j
                      and f.placement.isIdentity(1e-12) and f.name not in taken), None)
        body = unique(frame if frame is not None else f"{jname}_body")
        links.append(body)
        bodies.append(_Body(body, data.oMi[j].copy(), model.inertias[j].copy()))
        parent = links[int(model.parents[j])] or None
        X = model.jointPlacements[j]
        seg = q[jm.idx_q:jm.idx_q + jm.nq]
        if kind == "FreeFlyer":
            bodies[-1].free_joint = jname
            continue
        if kind == "Spherical":
            joints.append(_Joint(jname, "spherical", parent, body, X, pin.SE3.Identity()))
            continue
        if kind == "Universal":
            if jname in refuse_universal:
                raise SpecError(source, f"universal joint {jname!r} is actuated or a task joint: USD writes it as two "
                                        "revolute joints; write pkm's spec or MJCF")
            u = jm.extract()
            a1, a2 = (np.asarray(a, dtype=float) / np.linalg.norm(a) for a in (u.axis1, u.axis2))
            cross = unique(f"{jname}__cross")
            R2 = pin.SE3(pin.AngleAxis(float(seg[1]), a2).matrix(), np.zeros(3))
            bodies.insert(len(bodies) - 1, _Body(cross, data.oMi[j] * R2.inverse(), pin.Inertia.Zero()))
            lim = limits.get(jname)
            for k, (p, c, a, L0, L1) in enumerate(((parent, cross, a1, X, pin.SE3.Identity()),
                                                   (cross, body, a2, pin.SE3.Identity(), pin.SE3.Identity()))):
                token, R = _onto(a)
                Rf = pin.SE3(R, np.zeros(3))
                joints.append(_Joint(f"{jname}__{k + 1}", "revolute", p, c, L0 * Rf, L1 * Rf, token,
                                     None if lim is None else (float(lim[0]), float(lim[1]))))
            continue
        if kind not in SCALAR_KINDS:
            raise SpecError(source, f"joint {jname!r}: USD (UsdPhysics) has no {jm.shortname()} (pkm writes revolute, "
                                    "prismatic, spherical, universal, free-flyer and mimic joints)")
        revolute, axis = joint_axis(jm)
        token, R = _onto(axis)
        Rf = pin.SE3(R, np.zeros(3))
        lim = limits.get(jname)
        joint = _Joint(jname, "revolute" if revolute else "prismatic", parent, body, X * Rf, Rf, token,
                       None if lim is None else (float(lim[0]), float(lim[1])))
        if kind == "Mimic":
            m = jm.extract()
            joint.mimic = (model.names[mimic_leader(model, j)], float(m.scaling), float(m.offset))
        joints.append(joint)
    return links, bodies, joints


def _frames(model: pin.Model, links: list[str], bodies: list[_Body], skip: set[str]) -> None:
    """The body and operational frames of ``model`` (but ``skip``) as ``pkm:frame`` children of their bodies (the
    world's are not written)."""
    by_name = {b.name: b for b in bodies}
    for f in model.frames[1:]:
        if f.type not in (pin.FrameType.BODY, pin.FrameType.OP_FRAME) or f.name in skip or not f.parentJoint:
            continue
        skip.add(f.name)
        by_name[links[f.parentJoint]].frames.append((f.name, f.placement))


def _drive(joint: _Joint, drive: Actuator, reference: float) -> None:
    """The standard drive values of ``drive`` (module doc) and its whole fields as pkm's attributes."""
    angular = joint.kind == "revolute"
    per = math.pi / 180.0 if angular else 1.0  # (UsdPhysics' angular gains are per degree)
    joint.custom["drive"] = {
        "stiffness": drive.stiffness * per if math.isfinite(drive.stiffness) else 0.0,
        "damping": drive.viscous * per,
        "maxForce": drive.max_effort,
        "targetPosition": math.degrees(reference) if angular else reference,
    }
    joint.custom["armature"] = drive.reflected_inertia
    if math.isfinite(drive.velocity_limit):
        joint.custom["physxJoint:maxJointVelocity"] = math.degrees(drive.velocity_limit) if angular \
            else drive.velocity_limit
    for f in NUMBERS:
        joint.custom[f"pkm:actuator:{f}"] = float(getattr(drive, f))


def _quat(R: np.ndarray) -> tuple[float, float, float, float]:
    qt = pin.Quaternion(R)
    qt.normalize()
    return float(qt.w), float(qt.x), float(qt.y), float(qt.z)


def save(stage: Any, path: str | os.PathLike[str]) -> Path:
    """Write ``stage`` at ``path`` (``.usda`` text, ``.usd`` and ``.usdc`` binary), replacing any file there.

    Raises:
        SpecError: the file cannot be written (naming it).
    """
    p = pxr("writing USD")
    out = Path(path)
    try:
        ok = stage.GetRootLayer().Export(str(out))
    except p.Tf.ErrorException as exc:
        raise SpecError(str(out), f"cannot write USD: {' '.join(str(exc).split())[:300]}") from None
    if not ok:
        raise SpecError(str(out), "cannot write USD")
    return out


def _stage(name: str, gravity: np.ndarray, bodies: list[_Body], joints: list[_Joint],
           actuated: Sequence[str], extra: Mapping[str, str] | None = None) -> Any:
    """The stage (in memory) of these bodies and joints (module doc)."""
    p = pxr("writing USD")
    Gf, Sdf, Usd, UsdGeom, UsdPhysics, Tf = p.Gf, p.Sdf, p.Usd, p.UsdGeom, p.UsdPhysics, p.Tf
    stage = Usd.Stage.CreateInMemory()  # (written at path by save(): no layer registry entry for it)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    UsdPhysics.SetStageKilogramsPerUnit(stage, 1.0)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    prim_names: dict[str, str] = {}

    def ident(n: str) -> str:
        if n not in prim_names:
            base, k = Tf.MakeValidIdentifier(n), 1
            out = base
            while out in prim_names.values():
                out, k = f"{base}_{k}", k + 1
            prim_names[n] = out
        return prim_names[n]

    root = UsdGeom.Xform.Define(stage, f"/{Tf.MakeValidIdentifier(name)}")
    stage.SetDefaultPrim(root.GetPrim())
    rp = root.GetPrim()
    UsdPhysics.ArticulationRootAPI.Apply(rp)
    rp.CreateAttribute("pkm:name", Sdf.ValueTypeNames.String, custom=True).Set(name)
    rp.CreateAttribute("pkm:actuated", Sdf.ValueTypeNames.StringArray, custom=True).Set(list(actuated))
    for key, value in (extra or {}).items():
        rp.CreateAttribute(key, Sdf.ValueTypeNames.String, custom=True).Set(value)
    g = float(np.linalg.norm(gravity))
    scene = UsdPhysics.Scene.Define(stage, f"{rp.GetPath()}/physicsScene")
    scene.CreateGravityMagnitudeAttr(g)
    scene.CreateGravityDirectionAttr(Gf.Vec3f(*(gravity / g if g else np.array([0.0, 0.0, -1.0]))))
    base = rp.GetPath()
    where: dict[str, str] = {}
    for b in bodies:
        bp = f"{base}/bodies/{ident(b.name)}"
        where[b.name] = bp
        xf = UsdGeom.Xform.Define(stage, bp)
        xf.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*b.placement.translation))
        w, x, y, z = _quat(b.placement.rotation)
        xf.AddOrientOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Quatd(w, x, y, z))
        prim = xf.GetPrim()
        UsdPhysics.RigidBodyAPI.Apply(prim)
        mass = UsdPhysics.MassAPI.Apply(prim)
        I = np.asarray(b.inertia.inertia, dtype=float)
        moments, axes = np.linalg.eigh(I)
        if np.linalg.det(axes) < 0:
            axes[:, 0] = -axes[:, 0]
        mass.CreateMassAttr(float(b.inertia.mass))
        mass.CreateCenterOfMassAttr(Gf.Vec3f(*b.inertia.lever))
        mass.CreateDiagonalInertiaAttr(Gf.Vec3f(*np.maximum(moments, 0.0)))
        w, x, y, z = _quat(axes)
        mass.CreatePrincipalAxesAttr(Gf.Quatf(w, x, y, z))
        prim.CreateAttribute("pkm:mass", Sdf.ValueTypeNames.Double, custom=True).Set(float(b.inertia.mass))
        prim.CreateAttribute("pkm:centerOfMass", Sdf.ValueTypeNames.Double3, custom=True).Set(
            Gf.Vec3d(*b.inertia.lever))
        prim.CreateAttribute("pkm:inertia", Sdf.ValueTypeNames.Matrix3d, custom=True).Set(Gf.Matrix3d(*I.ravel()))
        if ident(b.name) != b.name:
            prim.CreateAttribute("pkm:name", Sdf.ValueTypeNames.String, custom=True).Set(b.name)
        if b.free_joint is not None:
            prim.CreateAttribute("pkm:freeJoint", Sdf.ValueTypeNames.String, custom=True).Set(b.free_joint)
        for fname, M in b.frames:
            fx = UsdGeom.Xform.Define(stage, f"{bp}/{ident(fname)}")
            fx.AddTranslateOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Vec3d(*M.translation))
            w, x, y, z = _quat(M.rotation)
            fx.AddOrientOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Quatd(w, x, y, z))
            fp = fx.GetPrim()
            fp.CreateAttribute("pkm:frame", Sdf.ValueTypeNames.Bool, custom=True).Set(True)
            if ident(fname) != fname:
                fp.CreateAttribute("pkm:name", Sdf.ValueTypeNames.String, custom=True).Set(fname)
    schema = {"revolute": UsdPhysics.RevoluteJoint, "prismatic": UsdPhysics.PrismaticJoint,
              "spherical": UsdPhysics.SphericalJoint, "fixed": UsdPhysics.FixedJoint}
    for jt in joints:
        jp = f"{base}/{'loops' if jt.exclude else 'joints'}/{ident(jt.name)}"
        joint = schema[jt.kind].Define(stage, jp)
        prim = joint.GetPrim()
        if jt.body0 is not None:
            joint.CreateBody0Rel().SetTargets([Sdf.Path(where[jt.body0])])
        joint.CreateBody1Rel().SetTargets([Sdf.Path(where[jt.body1])])
        for k, L in ((0, jt.local0), (1, jt.local1)):
            w, x, y, z = _quat(L.rotation)
            getattr(joint, f"CreateLocalPos{k}Attr")(Gf.Vec3f(*L.translation))
            getattr(joint, f"CreateLocalRot{k}Attr")(Gf.Quatf(w, x, y, z))
            prim.CreateAttribute(f"pkm:localPos{k}", Sdf.ValueTypeNames.Double3, custom=True).Set(
                Gf.Vec3d(*L.translation))
            prim.CreateAttribute(f"pkm:localRot{k}", Sdf.ValueTypeNames.Quatd, custom=True).Set(Gf.Quatd(w, x, y, z))
        if ident(jt.name) != jt.name:
            prim.CreateAttribute("pkm:name", Sdf.ValueTypeNames.String, custom=True).Set(jt.name)
        if jt.exclude:
            joint.CreateExcludeFromArticulationAttr(True)
        if jt.kind in ("revolute", "prismatic"):
            joint.CreateAxisAttr(jt.axis)
            if jt.limits is not None:
                lo, hi = jt.limits
                scale = 180.0 / math.pi if jt.kind == "revolute" else 1.0
                joint.CreateLowerLimitAttr(lo * scale)
                joint.CreateUpperLimitAttr(hi * scale)
                prim.CreateAttribute("pkm:lowerLimit", Sdf.ValueTypeNames.Double, custom=True).Set(lo)
                prim.CreateAttribute("pkm:upperLimit", Sdf.ValueTypeNames.Double, custom=True).Set(hi)
        if jt.mimic is not None:
            leader, mult, offset = jt.mimic
            prim.CreateAttribute("pkm:mimic:joint", Sdf.ValueTypeNames.String, custom=True).Set(leader)
            prim.CreateAttribute("pkm:mimic:multiplier", Sdf.ValueTypeNames.Double, custom=True).Set(mult)
            prim.CreateAttribute("pkm:mimic:offset", Sdf.ValueTypeNames.Double, custom=True).Set(offset)
        custom = dict(jt.custom)
        drive = custom.pop("drive", None)
        if isinstance(drive, dict):
            api = UsdPhysics.DriveAPI.Apply(prim, "angular" if jt.kind == "revolute" else "linear")
            api.CreateTypeAttr("force")
            api.CreateStiffnessAttr(float(drive["stiffness"]))
            api.CreateDampingAttr(float(drive["damping"]))
            api.CreateTargetPositionAttr(float(drive["targetPosition"]))
            if math.isfinite(drive["maxForce"]):
                api.CreateMaxForceAttr(float(drive["maxForce"]))
        armature = custom.pop("armature", None)
        if armature is not None:
            for name_ in ("newton:armature", "physxJoint:armature"):
                prim.CreateAttribute(name_, Sdf.ValueTypeNames.Float, custom=True).Set(float(armature))  # type: ignore[arg-type]
        for key, v in custom.items():
            kind: Any = Sdf.ValueTypeNames.String if isinstance(v, str) else \
                Sdf.ValueTypeNames.Double if key.startswith("pkm:") else Sdf.ValueTypeNames.Float
            prim.CreateAttribute(key, kind, custom=True).Set(v)
    return stage


def _loops(mech: Mechanism, links: list[str]) -> list[_Joint]:
    model, out = mech.model, []
    for c, (fa, fb) in zip(mech.spec.closures, mech.closure_frames, strict=True):
        ja, jb = model.frames[fa].parentJoint, model.frames[fb].parentJoint
        if ja == jb:
            raise SpecError(mech.source, f"closure {c.name!r}: both frames are on one body ({links[ja] or 'the world'!r});"
                                         " a USD joint needs two")
        if not jb:  # (the world as body1: UsdPhysics' body1 is a body)
            ja, jb, fa, fb = jb, ja, fb, fa
        out.append(_Joint(c.name, "spherical" if c.type == "point" else "fixed", links[ja] or None, links[jb],
                          model.frames[fa].placement, model.frames[fb].placement, exclude=True))
    return out


def usd_from_mechanism(mech: Mechanism, path: str | os.PathLike[str] | None = None) -> tuple[Any, tuple[str, ...]]:
    """``mech`` as a USD stage (module doc), written at ``path`` (``.usda`` text, ``.usd``/``.usdc`` binary) or in
    memory, and what it leaves out, one line each.

    Raises:
        MissingDependencyError: ``usd-core`` is not installed (the ``usd`` extra).
        SpecError: a joint USD cannot hold, an actuated or task universal joint, a closure on one body (module doc).
    """
    mech = check_mechanism(mech)
    pxr("writing USD")
    model, spec = mech.model, mech.spec
    q = closed_reference(mech)
    taken = {f"{c.name}_{side}" for c in spec.closures for side in ("parent", "child")}
    links, bodies, joints = _tree(model, q, mech.limits, taken, mech.source, {*spec.actuated, *spec.task.joints})
    skip = {f"{c.name}_{side}" for c in spec.closures for side in ("parent", "child")} | \
        {b.name for b in bodies} | {model.names[j] for j in range(model.njoints)} | {c.name for c in spec.closures}
    _frames(model, links, bodies, skip)
    by_name = {j.name: j for j in joints}
    for a in mech.actuators:
        if a.joint not in by_name or by_name[a.joint].kind not in ("revolute", "prismatic"):
            raise SpecError(mech.source, f"actuated joint {a.joint!r}: USD drives a revolute or prismatic joint")
        _drive(by_name[a.joint], a, float(q[mech.joints[a.joint].idx_q]))
    joints += _loops(mech, links)
    stage = _stage(spec.mechanism, np.asarray(model.gravity.linear), bodies, joints, mech.actuated_names)
    if path is not None:
        save(stage, path)
    dropped = ["the task, working modes and parameters (pkm's spec keeps them); the Coulomb friction in pkm's "
               "pkm:actuator:coulomb only (UsdPhysics has no joint friction torque)"]
    if spec.springs:
        dropped.append(f"the joint springs of {sorted(spec.springs)} (UsdPhysics has no joint spring)")
    if spec.closures:
        dropped.append("the closures' frames: read back as <closure>_parent, <closure>_child, at the same places (the "
                       "other frames are kept as pkm:frame prims, but those named as a closure or a joint)")
    universal = [j.name.removesuffix("__1") for j in joints if j.name.endswith("__1") and j.body1.endswith("__cross")]
    if universal:
        dropped.append(f"universal joints {universal}: written as two revolute joints <name>__1, <name>__2 through a "
                       "massless body <name>__cross (read back as two revolute joints of those names)")
    mimic = [j.name for j in joints if j.mimic is not None]
    if mimic:
        dropped.append(f"mimic joints {mimic}: independent joints for UsdPhysics readers (pkm:mimic:* for pkm)")
    return stage, tuple(dropped)


def serial_usd(se: SerialEquivalent, path: str | os.PathLike[str] | None = None) -> Any:
    """The serial-equivalent model ``se`` (:func:`pkm.serial_equivalent`) as a USD stage (module doc), written at
    ``path`` or in memory: the serial tree as a plain articulation, each output joint driven with its ΔM diagonal
    (``se.armature``) as armature and the robot's drive for the rest, ``se.limits`` as limits, and the transmissions'
    parameters as custom attributes (``pkm:transmissions``: :meth:`SerialEquivalent.data` as JSON;
    ``pkm:transmission`` on each output joint). The transmissions' exact ΔM(q), Δh(q, v) are not USD: a simulator
    applies them through pkm's kernels (:mod:`pkm.core.transmissions.targets`).

    Raises:
        MissingDependencyError: ``usd-core`` is not installed (the ``usd`` extra).
        SpecError: a joint USD cannot hold.
    """
    pxr("writing USD")
    model, q = se.model, np.asarray(se.q_reference, dtype=float)
    links, bodies, joints = _tree(model, q, se.limits, set(), se.robot.source, set())
    _frames(model, links, bodies, {b.name for b in bodies} | {model.names[j] for j in range(model.njoints)})
    by_name = {j.name: j for j in joints}
    drives = {a.joint: a for a in se.robot.actuators}
    owner = {o: t.name for t in se.transmissions for o in t.outputs}
    for out in se.outputs:
        j = by_name.get(out)
        if j is None or j.kind not in ("revolute", "prismatic"):
            continue
        base = drives.get(out, Actuator(out))
        _drive(j, Actuator(out, armature=se.armature[out], viscous=base.viscous, coulomb=base.coulomb,
                           effort_limit=base.effort_limit, peak_effort=base.peak_effort,
                           velocity_limit=base.velocity_limit, stiffness=base.stiffness),
               float(q[model.joints[model.getJointId(out)].idx_q]))
        j.custom["pkm:transmission"] = owner.get(out, "")
    actuated = [o for o in se.outputs if o in by_name]
    data = json.dumps(se.data(), default=float)
    stage = _stage(f"{se.robot.name}_serial", np.asarray(model.gravity.linear), bodies, joints, actuated,
                   {"pkm:transmissions": data})
    if path is not None:
        save(stage, path)
    return stage


__all__ = ["EXTRA", "pxr", "save", "serial_usd", "usd_from_mechanism"]
