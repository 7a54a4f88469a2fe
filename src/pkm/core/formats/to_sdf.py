"""A mechanism written as SDFormat (1.11): its tree as links and joints, its loops as cut joints, the grammar
:mod:`pkm.core.formats.sdf` reads, with a closure spec beside it for what SDFormat does not say (the actuated joints,
the task, the drives, working modes and parameters).

SDFormat places every link by its pose in the model, and every joint's position is zero at those poses; a cut joint
is closed there. So the file is written at the mechanism's closed reference configuration
(:attr:`~pkm.core.Mechanism.q_reference`): each link's ``<pose>`` is its joint frame's world placement there, each
joint's ``<pose>`` the identity in its child link (Pinocchio's body frame is its joint's frame). For any SDFormat
reader the joint positions count from that reference: position limits are written as ``lower - q_ref``, ``upper -
q_ref``. pkm keeps its own coordinates with a custom element (SDFormat's ``xmlns:pkm`` extension mechanism, which
other readers ignore), ``<pkm:position>`` in each moving joint: its coordinate at the model's pose (an angle [rad], a
length [m], a ball's quaternion ``x y z w``, a free body's ``x y z`` and quaternion); pkm's reader puts the joint's
zero back where it was and adds it to the limits, so the mechanism reads back with its own coordinates.

* revolute, continuous (an unbounded revolute, written as ``continuous``: pkm's reader makes it a bounded-type
  revolute without limits, the same kinematics and one coordinate instead of cos/sin), prismatic and spherical
  (``ball``) joints as themselves; a universal joint as two revolute joints ``<name>__1``, ``<name>__2`` through a
  massless link ``<name>__cross`` (the MJCF writer's convention: the same FK, Jacobians and dynamics; said);
* a free-flyer (a platform closed by loops): SDFormat has no free joint, but a link without a parent joint is a free
  body; ``<pkm:free_joint>NAME</pkm:free_joint>`` in the link names pkm's joint (pkm's reader otherwise fixes a
  parentless link to the world as the model's base);
* a mimic joint: SDFormat 1.11's ``<axis><mimic joint="LEADER"><multiplier>`` (offset and reference 0: at the
  model's pose both joints are at their reference values);
* a ``point`` closure: a cut ``ball`` joint named after it, from the link of its first frame (``<parent>``) to the
  link of its second (``<child>``), at the second frame; a ``frame`` closure: a cut ``fixed`` joint. pkm's reader
  makes of each the closure of that name and type between frames ``<closure>_parent`` and ``<closure>_child``;
* every other body and operational frame of the model as a ``<frame attached_to>`` (the end effector, the task frames,
  the closures' own frames), but those named as a closure (SDFormat gives links, joints and frames one namespace)
  or as the frames the reader makes for the cut joints;
* inertias as ``<inertial>`` (a massless body with ``<mass>0</mass>``: SDFormat's default inertial is 1 kg);
  actuated joints' effort and speed limits and friction as ``<limit><effort><velocity>`` and ``<dynamics>`` (their
  whole drives are in the spec beside);
* the joint springs (:attr:`Mechanism.springs <pkm.core.model.mechanism.Mechanism.springs>`, ``[springs]``) as
  ``<axis><dynamics>``: ``<spring_stiffness>``, ``<spring_reference>`` (counted from the written pose, as the limits
  are: ``rest - q_ref``; pkm's reader adds its ``<pkm:position>`` back), and the joint's whole viscous damping (a
  drive's and a spring's) as ``<damping>``; a continuous joint's spring is left out (said: SDFormat's would act on
  the unwrapped angle) and kept in the spec beside, which states every spring too;
* the collision geometry (the URDF text's ``<collision>`` elements, :mod:`pkm.core.collision.geometry`) as
  ``<collision>`` elements of the link of the joint that moves it; what it cannot hold (shapes on the world, meshes
  not found) said.

Refused by name (:class:`~pkm.errors.SpecError`): planar and other composite joints, a floating base (the spec's
``floating_base``: pkm's SDF reader fixes the base), an actuated or task universal joint, a closure whose two
frames are on one body, a task frame named as a closure.
"""

from __future__ import annotations

import dataclasses as dc
from pathlib import Path

import numpy as np
import pinocchio as pin
from lxml import etree

from pkm.core.collision.geometry import Collision, model_folders, placed_collisions, resolve_mesh
from pkm.core.formats.to_mjcf import geometry_omissions, joint_axis, mimic_leader
from pkm.core.model.actuators import NUMBERS
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.spec import ClosureSpec
from pkm.core.model.urdf import unique_name
from pkm.errors import SpecError

#: The namespace of pkm's custom SDFormat elements (``<pkm:position>``, ``<pkm:free_joint>``).
PKM_NS = "urn:pkm:sdf"
#: The Pinocchio joints of one coordinate written as a revolute, continuous or prismatic joint (the USD writer's too).
SCALAR_KINDS = ("RX", "RY", "RZ", "PX", "PY", "PZ", "RUBX", "RUBY", "RUBZ", "RevoluteUnaligned", "PrismaticUnaligned",
                "RevoluteUnboundedUnaligned", "Mimic")
_P = f"{{{PKM_NS}}}"


def _text(parent: etree._Element, tag: str, value: str) -> etree._Element:
    el = etree.SubElement(parent, tag)
    el.text = value
    return el


def _num(x: object) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(np.asarray(x, dtype=float)))


def _pose(parent: etree._Element, M: pin.SE3) -> None:
    _text(parent, "pose", _num([*M.translation, *pin.rpy.matrixToRpy(M.rotation)]))


def closed_reference(mech: Mechanism) -> np.ndarray:
    """The reference configuration, its loops closed to the last bit where the solver gets there from it within
    1e-9 (the file's poses place each cut joint's two frames at one point: the residual left in the reference, 5e-13
    on the acceptance set's 3-RPR, would move them apart by as much; the polish moves it by 2.5e-12 there), else the
    reference itself."""
    from pkm.core.kinematics.solve import close_loops

    q = mech.q_reference
    polished = close_loops(mech, mech.actuated_q(q), q, tol=1e-15, raise_on_failure=False)
    near = polished.converged and float(np.abs(pin.difference(mech.model, q, polished.q)).max(initial=0.0)) <= 1e-9
    return polished.q if near else q


def sdf_from_mechanism(mech: Mechanism) -> tuple[str, tuple[str, ...]]:
    """``mech`` as SDFormat text (module doc) and what it leaves out, one line each.

    Raises:
        SpecError: a joint SDFormat cannot hold, a floating base, an actuated or task universal joint, a closure on
            one body (module doc).
    """
    mech = check_mechanism(mech)
    model, spec, source = mech.model, mech.spec, mech.source
    if spec.floating_base:
        raise SpecError(source, f"SDFormat (as pkm reads it) has no floating base ({spec.floating_base!r}): pkm's "
                                "reader fixes the base link; write pkm's spec or MJCF")
    data = model.createData()
    q = closed_reference(mech)
    pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    names = {model.names[j] for j in range(model.njoints)}
    frame_names = {f.name for f in model.frames}
    taken: set[str] = {"world", "__model__"}
    cut_frames = {f"{c.name}_{side}" for c in spec.closures for side in ("parent", "child")}
    cut_frames |= {f"{n}_fixed" for n in cut_frames}

    reserved = frame_names | names

    def unique(base: str) -> str:
        return unique_name(base, taken, reserved)

    taken |= names | cut_frames
    root = etree.Element("sdf", nsmap={"pkm": PKM_NS}, version="1.11")
    sdf_model = etree.SubElement(root, "model", name=spec.mechanism)
    links = ["world"]  # the SDF link of each Pinocchio joint
    geometry, _ = placed_collisions(mech)
    folders = model_folders(mech)
    primary: set[str] = set()
    universals: list[str] = []
    joints: list[etree._Element] = []
    at: dict[str, float] = {}  # a one-coordinate joint's coordinate at the written pose (SDFormat's zero)
    for j in range(1, model.njoints):
        jm, jname = model.joints[j], model.names[j]
        kind = jm.shortname().removeprefix("JointModel")
        body = next((f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == j
                     and f.placement.isIdentity(1e-12) and f.name not in taken), None)
        lname = body if body is not None else unique(f"{jname}_body")
        taken.add(lname)
        if body is not None:
            primary.add(body)
        links.append(lname)
        link = etree.SubElement(sdf_model, "link", name=lname)
        _pose(link, data.oMi[j])
        inertia = model.inertias[j]
        inertial = etree.SubElement(link, "inertial")
        _pose(inertial, pin.SE3(np.eye(3), inertia.lever))
        _text(inertial, "mass", repr(float(inertia.mass)))
        iel = etree.SubElement(inertial, "inertia")
        I = inertia.inertia
        for key, value in (("ixx", I[0, 0]), ("ixy", I[0, 1]), ("ixz", I[0, 2]), ("iyy", I[1, 1]), ("iyz", I[1, 2]),
                           ("izz", I[2, 2])):
            _text(iel, key, repr(float(value)))
        for shape, joint_of, M in geometry:
            if joint_of == j:
                _collision(link, shape, M, folders)
        seg = q[jm.idx_q:jm.idx_q + jm.nq]
        parent = links[int(model.parents[j])]
        if kind == "FreeFlyer":
            link.insert(0, el := etree.Element(f"{_P}free_joint"))
            el.text = jname
            _text(link, f"{_P}position", _num(seg))
            continue
        if kind == "Spherical":
            joints.append(_joint(jname, "ball", parent, lname, _num(seg)))
            continue
        if kind == "Universal":
            if jname in spec.actuated or jname in spec.task.joints:
                raise SpecError(source, f"universal joint {jname!r} is actuated or a task joint: SDFormat writes it as "
                                        "two revolute joints; write pkm's spec or MJCF")
            u = jm.extract()
            a1, a2 = (np.asarray(a, dtype=float) / np.linalg.norm(a) for a in (u.axis1, u.axis2))
            cross = unique(f"{jname}__cross")
            cel = etree.Element("link", name=cross)
            _pose(cel, data.oMi[j] * pin.SE3(pin.AngleAxis(float(seg[1]), a2).matrix(), np.zeros(3)).inverse())
            sdf_model.insert(sdf_model.index(link), cel)
            for k, (p, c, a) in enumerate(((parent, cross, a1), (cross, lname, a2))):
                joints.append(_joint(f"{jname}__{k + 1}", "revolute", p, c, _num(seg[k]), a,
                                     mech.limits.get(jname), float(seg[k])))
            universals.append(jname)
            continue
        if kind not in SCALAR_KINDS:
            raise SpecError(source, f"joint {jname!r}: SDFormat has no {jm.shortname()} (pkm writes revolute, "
                                    "continuous, prismatic, ball, universal, free-flyer and mimic joints)")
        revolute, axis = joint_axis(jm)
        axis = axis / np.linalg.norm(axis)
        if kind == "Mimic":
            mimic = jm.extract()
            value = float(mimic.offset + mimic.scaling * q[jm.idx_q])
        elif kind.startswith("RUB"):
            value = float(np.arctan2(seg[1], seg[0]))
        else:
            value = float(seg[0])
        sdf_kind = "continuous" if "Unbounded" in kind or kind.startswith("RUB") else \
            "revolute" if revolute else "prismatic"
        at[jname] = value
        jel = _joint(jname, sdf_kind, parent, lname, repr(value), axis,
                     mech.limits.get(jname) if sdf_kind != "continuous" else None, value)
        if kind == "Mimic":
            m = etree.SubElement(jel.find("axis"), "mimic", joint=model.names[mimic_leader(model, j)], axis="axis")
            _text(m, "multiplier", repr(float(jm.extract().scaling)))
            _text(m, "offset", "0.0")
            _text(m, "reference", "0.0")
        joints.append(jel)
    for a in mech.actuators:  # SDFormat's own drive fields, for other readers (the spec beside has the whole drive)
        jel = next(el for el in joints if el.get("name") == a.joint)
        limit = jel.find("axis/limit")
        if limit is None:  # (SDFormat's own "no limit")
            limit = etree.SubElement(jel.find("axis"), "limit")
            _text(limit, "lower", "-1e16")
            _text(limit, "upper", "1e16")
        for key, value in (("effort", a.effort_limit), ("velocity", a.velocity_limit)):
            if np.isfinite(value):
                _text(limit, key, repr(value))
    unsprung = _dynamics(mech, joints, at)
    sdf_model.extend(joints)
    for c, (fa, fb) in zip(spec.closures, mech.closure_frames, strict=True):
        ja, jb = model.frames[fa].parentJoint, model.frames[fb].parentJoint
        if ja == jb:
            raise SpecError(source, f"closure {c.name!r}: both frames are on one body ({links[ja]!r}); SDFormat's cut "
                                    "joint needs two")
        cut = _joint(c.name, "ball" if c.type == "point" else "fixed", links[ja], links[jb])
        cut.find("pose").text = _num([*model.frames[fb].placement.translation,
                                      *pin.rpy.matrixToRpy(model.frames[fb].placement.rotation)])
        sdf_model.append(cut)
    cuts = {c.name for c in spec.closures}
    needed = {f for f in (spec.end_effector, *spec.task.frames) if f is not None} - names
    clash = sorted(needed & (cuts | cut_frames))
    if clash:
        raise SpecError(source, f"frame {clash[0]!r} (the task's) has the name of a closure, or of the frame pkm's "
                                "reader makes for one: SDFormat's joints and frames share their names; rename it")
    skip = primary | cut_frames | names | set(links) | cuts  # (SDFormat: one name per link, joint or frame)
    for f in model.frames[1:]:
        if f.type not in (pin.FrameType.BODY, pin.FrameType.OP_FRAME) or f.name in skip:
            continue
        skip.add(f.name)
        fel = etree.SubElement(sdf_model, "frame", name=f.name)
        if f.parentJoint:
            fel.set("attached_to", links[f.parentJoint])
        _pose(fel, f.placement)
    etree.indent(root, space="  ")
    dropped = []
    if spec.closures:
        dropped.append("the closures' frames: read back as <closure>_parent, <closure>_child, at the same places (the "
                       "original frames are kept as <frame>s, but those named as a closure: SDFormat's joints and "
                       "frames share names)")
    if universals:
        dropped.append(f"universal joints {universals}: written as two revolute joints <name>__1, <name>__2 through a "
                       "massless link <name>__cross (read back as two revolute joints of those names)")
    unbounded = [model.names[j] for j in range(1, model.njoints)
                 if model.joints[j].shortname().removeprefix("JointModel").startswith(("RUB", "RevoluteUnbounded"))]
    if unbounded:
        dropped.append(f"unbounded revolute joints {unbounded}: written as continuous joints, read back as revolute "
                       "joints without limits (one coordinate, not cos/sin)")
    if unsprung:
        dropped.append(f"the springs of the continuous joints {unsprung}: SDFormat's <spring_stiffness> of a continuous "
                       "joint is not pkm's (kept in the spec beside)")
    dropped += geometry_omissions(mech, world=True)
    return etree.tostring(root, xml_declaration=True, encoding="utf-8", pretty_print=True).decode(), tuple(dropped)


def _dynamics(mech: Mechanism, joints: list[etree._Element], at: dict[str, float]) -> list[str]:
    """SDFormat's ``<axis><dynamics>`` of each actuated or sprung joint (``[springs]``): its whole viscous damping
    (the drive's and the spring's, Pinocchio's ``damping``), its friction and its spring, the ``<spring_reference>``
    counted from the written pose (``at``: the joint's coordinate there) as the limits are; the continuous joints
    whose spring it leaves out (returned)."""
    model = mech.model
    damping, friction = np.asarray(model.damping, dtype=float), np.asarray(model.friction, dtype=float)
    sprung = dict(zip(mech.springs.names, zip(mech.springs.stiffness.tolist(), mech.springs.rest.tolist())))
    by_name = {str(el.get("name")): el for el in joints}
    left: list[str] = []
    for name in dict.fromkeys([*mech.actuated_names, *mech.spec.springs]):
        jel = by_name.get(name)
        if jel is None or jel.find("axis") is None or name not in at:
            continue
        iv = mech.joints[name].idx_v
        k, rest = sprung.get(name, (0.0, 0.0))
        if k and jel.get("type") == "continuous":
            left.append(name)
            k = 0.0
        if not (damping[iv] or friction[iv] or k):
            continue
        dyn = etree.SubElement(jel.find("axis"), "dynamics")
        _text(dyn, "damping", repr(float(damping[iv])))
        _text(dyn, "friction", repr(float(friction[iv])))
        if k:
            _text(dyn, "spring_reference", repr(rest - at[name]))
            _text(dyn, "spring_stiffness", repr(k))
    return left


def _collision(link: etree._Element, c: Collision, M: pin.SE3, folders: list[Path]) -> None:
    """A ``<collision>`` of ``link`` (at its joint's frame): ``c``'s shape at ``M``; a mesh's file as found (one not
    found is left out: said by the writer)."""
    shape = etree.Element("geometry")
    if c.kind == "mesh":
        path = resolve_mesh(str(c.filename), folders)
        if path is None:
            return
        mesh = etree.SubElement(shape, "mesh")
        _text(mesh, "uri", str(path.resolve()))
        _text(mesh, "scale", _num(c.size))
    else:
        el = etree.SubElement(shape, c.kind)
        keys = {"box": ("size",), "sphere": ("radius",), "cylinder": ("radius", "length"),
                "capsule": ("radius", "length"), "ellipsoid": ("radii",)}[c.kind]
        values = [c.size] if c.kind in ("box", "ellipsoid") else [[v] for v in c.size]
        for key, v in zip(keys, values):
            _text(el, key, _num(v))
    col = etree.Element("collision", name=c.name.replace("/", "_"))
    _pose(col, M)
    col.append(shape)
    inertial = link.find("inertial")
    link.insert(list(link).index(inertial) if inertial is not None else len(link), col)


def _joint(name: str, kind: str, parent: str, child: str, position: str | None = None,
           axis: np.ndarray | None = None, limits: tuple[float, float] | None = None, at: float = 0.0) \
        -> etree._Element:
    """A ``<joint>`` at its child link's frame; ``position``: its ``<pkm:position>``; ``limits`` [rad or m] in pkm's
    coordinates, written from the model's pose (``at``: the coordinate there)."""
    jel = etree.Element("joint", name=name, type=kind)
    _text(jel, "pose", "0 0 0 0 0 0")
    _text(jel, "parent", parent)
    _text(jel, "child", child)
    if axis is not None:
        ax = etree.SubElement(jel, "axis")
        _text(ax, "xyz", _num(axis))
        if limits is not None:
            limit = etree.SubElement(ax, "limit")
            _text(limit, "lower", repr(float(limits[0]) - at))
            _text(limit, "upper", repr(float(limits[1]) - at))
    if position is not None:
        _text(jel, f"{_P}position", position)
    return jel


def sdf_spec(mech: Mechanism, sdf_name: str) -> ClosureSpec:
    """The closure spec written beside the SDF file ``sdf_name``: ``mech``'s spec without what the SDF states (the
    closures, the joint types), with the reference configuration (a universal's two angles under its hinges'
    names) and every actuated joint's whole drive (:class:`~pkm.core.model.actuators.Actuator`'s fields)."""
    mech = check_mechanism(mech)
    reference: dict[str, tuple[float, ...]] = {}
    for name, value in mech.q_to_dict(closed_reference(mech)).items():
        v = tuple(float(x) for x in np.atleast_1d(value))
        if mech.model.joints[mech.joints[name].id].shortname() == "JointModelUniversal":
            reference[f"{name}__1"], reference[f"{name}__2"] = (v[0],), (v[1],)
        else:
            reference[name] = v
    drives = {a.joint: {f: float(getattr(a, f)) for f in NUMBERS} for a in mech.actuators}
    return dc.replace(mech.spec, urdf=sdf_name, closures=(), joint_types={}, reference=reference, actuators=drives)


__all__ = ["PKM_NS", "SCALAR_KINDS", "sdf_from_mechanism", "sdf_spec"]
