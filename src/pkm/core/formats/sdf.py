r"""SDFormat: a ``<model>`` whose joints form loops (a link with several parent joints).

Pinocchio's SDF parser needs SDFormat, which the PyPI wheel of Pinocchio 4.1 is built without
(``pinocchio.WITH_SDFORMAT`` is False), so pkm reads the subset closed-loop mechanisms use itself, with
SDFormat's pose semantics (1.6 to 1.11):

* ``<link>``: ``<pose>`` in the model frame, or ``relative_to`` another link or frame;
  ``<inertial>`` with its ``<pose>`` (in the link frame), ``<mass>``, ``<inertia>`` (about the centre of
  mass, in the inertial frame's axes);
* ``<joint>`` of type ``revolute``, ``continuous``, ``prismatic``, ``ball`` or ``fixed``: ``<parent>``,
  ``<child>`` (``world`` for the ground), ``<pose>`` in the child link's frame (or ``relative_to``),
  ``<axis><xyz>`` in the joint frame (or ``expressed_in``; SDFormat 1.6's ``use_parent_model_frame``),
  ``<limit><lower><upper>`` (SDFormat's default ±1e16 means none); an actuated joint's drive
  (:class:`~pkm.core.model.actuators.Actuator`) from ``<limit><effort><velocity>`` (SDFormat's default -1: none)
  and ``<dynamics><damping><friction>``;
* ``<frame name attached_to>`` with a ``<pose>``: named frames (an end effector, a tool point);
* ``<pose degrees="true">`` (SDFormat 1.9);
* ``<joint type="gearbox">`` (below);
* SDFormat 1.11's ``<axis><mimic joint="LEADER" axis="axis">`` with ``<multiplier>`` (required), ``<offset>``,
  ``<reference>``: ``follower = offset + multiplier (leader - reference)``, a URDF ``<mimic>`` (both joints
  revolute, continuous or prismatic, in the tree);
* pkm's own custom elements (namespace ``urn:pkm:sdf``, :mod:`pkm.core.formats.to_sdf` writes them; other SDFormat
  readers ignore them): ``<pkm:position>`` in a tree joint, its coordinate at the model's pose (an angle, a length, a
  ball's quaternion ``x y z w``): the joint's zero is put where that coordinate places the link, and its limits and a
  mimic's offset (counted from the model's pose in SDFormat) are shifted by it; ``<pkm:free_joint>NAME`` in a link
  without a parent joint: a free body (SDFormat's reading of such a link), on a free-flyer joint ``NAME`` (its
  ``<pkm:position>``: ``x y z`` and the quaternion ``x y z w``), every joint whose child it is cutting a loop.

The tree: each link's parent joint is the first joint in the file that has it as child; every other
joint cuts a loop, between frames ``<joint>_parent`` and ``<joint>_child`` at the joint: a cut ``ball``
is a ``point`` closure, a cut ``fixed`` joint a ``frame`` closure, a cut revolute two ``point`` closures,
``<joint>`` and ``<joint>_axis`` (at the joint and 0.1 m along its axis: exactly a revolute, five
independent equations). A cut prismatic joint stays in the tree, from its parent to a massless link
``<joint>_cut`` tied to ``<joint>_child`` by a ``frame`` closure: exact too, but the massless link makes
the tree's mass matrix singular, so Pinocchio's ``constraintDynamics`` cannot run on it (pkm's inverse
dynamics can). A link that
no joint has as child is the base, fixed to the world at its pose (SDFormat would leave it free). Every
SDF link and ``<frame>`` keeps its name and pose as a frame (a URDF link's frame is at its joint: where the
SDF link's pose differs, the URDF link is named ``<link>__joint``).
SDFormat names no actuators: a closure spec whose ``urdf`` is the SDF file says which joints are.

A ``gearbox`` joint is no tree joint and no loop: it couples the angles of its ``<parent>`` and ``<child>``
links, :math:`\theta_2 = -r\,\theta_1` with :math:`r` its ``<gearbox_ratio>``, where :math:`\theta_1` is the
angle of the parent link about ``<axis>`` and :math:`\theta_2` that of the child link about ``<axis2>``, both
relative to its ``<gearbox_reference_body>`` (SDFormat's definition; Gazebo's gear joints, and Cassie's motor
rotors). pkm requires each of the two links to hang on a revolute (or continuous) joint from the reference body
about that axis (parallel, either sense; its angle zero at the model's pose, as SDFormat's are), with only fixed
joints besides it between them (a rotor in a housing fixed to the reference body; the reference body anywhere in
the tree: the angles are relative to it), and writes the
coupling as a URDF ``<mimic>``, which Pinocchio models exactly: the slower link's joint (the output: the child
when :math:`|r| \le 1`) keeps its coordinate, the faster one (the motor's rotor) follows it with multiplier
:math:`-s_1 s_2 / r` (or :math:`-s_1 s_2 r` when the parent is the slower), :math:`s_i = \pm 1` the sense of
joint :math:`i`'s axis along the gearbox's, offset 0. The rotor has no coordinate of its own, but its inertia
counts: at an output rate :math:`\omega` it spins at :math:`\omega / r`, so it adds :math:`I_\mathrm{rotor}/r^2`
to the output's inertia about the axis. Pinocchio adds a mimic joint only after the joint it follows, in its
traversal of the URDF, which visits the children of a link in the order of their joints' names: when the rotor's
joint name sorts first (Cassie's ``left-knee-ip`` before ``left-knee-op``), pkm hangs the rotor's joint from a
massless link ``<gearbox>__rotor_mount``, fixed to the reference body by a joint ``<output joint>__<gearbox>``,
which sorts after the output's (a workaround of that Pinocchio 4.1 restriction, pinned by a test). The rotor's
SDF position limits, if any, are dropped: its coordinate is the output's. A revolute's or prismatic's
``<spring_stiffness>`` and ``<spring_reference>`` are its ``[springs]`` entry (:mod:`pkm.core.model.springs`: read
and applied by pkm's dynamics; the reference counts from the model's pose, as the limits do, its ``<pkm:position>``
added; its ``<damping>`` is the joint's friction, as above). Each gearbox so read, and the
springs, are listed in :attr:`Imported.notes <pkm.core.formats.base.Imported.notes>`. SDFormat booleans (``use_parent_model_frame``) are ``true`` or ``1``.

Refused with a :class:`~pkm.errors.SpecError`: nested models, ``<include>``, universal and screw joints, a mimic
without a multiplier or not between two tree joints, ``<pkm:position>`` on a joint cutting a loop, a
gearbox whose links do not hang on revolutes about its axes from its reference body (or with a zero or
non-finite ratio, or a link geared twice), poses relative to what is not a link or frame, several base links,
a cycle of parents.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pinocchio as pin
from lxml import etree

from pkm.core.formats.base import Imported
from pkm.core.model.spec import Closure
from pkm.core.model.springs import parse_springs, spring_notes
from pkm.core.model.urdf import check_urdf, floats, num, origin, parse_xml
from pkm.errors import SpecError

_TYPES = ("revolute", "continuous", "prismatic", "ball", "fixed", "gearbox")
_PARALLEL = 1e-6  # |sin| of the angle between a gearbox's axis and its joint's axis above which they differ
_NO_LIMIT = 1e6  # |bound| above this (SDFormat writes 1e16) is no bound
_AXIS_POINT = 0.1  # m: a cut revolute is two point closures, at the joint and this far along its axis
_PKM = "{urn:pkm:sdf}"  # pkm's custom elements (pkm.core.formats.to_sdf.PKM_NS)


def _numbers(text: str | None, n: int, what: str, source: str) -> np.ndarray:
    return np.array(floats(text, n, what, source, bound=np.inf))  # (SDFormat writes 1e16 for no limit)


def _pose(el: etree._Element | None, what: str, source: str) -> tuple[pin.SE3, str | None]:
    """The ``<pose>`` child of ``el`` (identity when absent) and its ``relative_to``."""
    pose = el.find("pose") if el is not None else None
    if pose is None:
        return pin.SE3.Identity(), None
    v = _numbers(pose.text or "0 0 0 0 0 0", 6, f"{what} pose", source)
    rpy = np.deg2rad(v[3:]) if pose.get("degrees", "false") == "true" else v[3:]
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), v[:3]), pose.get("relative_to") or None


def _text(el: etree._Element, path: str, default: str | None = None) -> str | None:
    found = el.find(path)
    return found.text.strip() if found is not None and found.text else default


def _end(joint: etree._Element, role: str) -> str:
    """A joint's ``parent`` or ``child`` link name (``""`` when it has none)."""
    return _text(joint, role) or ""


def _turning_joint(link: str, ref: str, parent_joint: dict[str, etree._Element]) -> etree._Element | None:
    """The one revolute (or continuous) joint on the path from ``ref`` down to ``link``, the others fixed, or None
    (``ref`` is not above ``link``, or the path has no moving joint, or another)."""
    moving: list[etree._Element] = []
    node = link
    while node != ref:
        j = parent_joint.get(node)
        if j is None:  # the base (fixed to the world) or the world itself
            if ref != "world" or node == "world":
                return None
            break
        if j.get("type") != "fixed":
            moving.append(j)
        node = _end(j, "parent")
    if link == ref or len(moving) != 1 or moving[0].get("type") not in ("revolute", "continuous"):
        return None
    return moving[0]


def _gears(gearboxes: list[etree._Element], parent_joint: dict[str, etree._Element],
           joint_frame: Callable[[etree._Element], pin.SE3], axis: Callable[..., np.ndarray],
           source: str) -> dict[str, tuple[str, float, str]]:
    """The mimic couplings of the ``gearbox`` joints (see the module doc): ``{rotor joint: (output joint,
    multiplier, gearbox)}``.

    Raises:
        SpecError: a gearbox whose links do not hang on revolutes about its axes from its reference body, a zero
            or non-finite ratio, a joint geared twice.
    """
    out: dict[str, tuple[str, float, str]] = {}
    for g in gearboxes:
        name = g.get("name")
        ref = _text(g, "gearbox_reference_body")
        if not ref:
            raise SpecError(source, f"gearbox {name!r} needs a <gearbox_reference_body>")
        ratio = float(_numbers(_text(g, "gearbox_ratio", "1"), 1, f"gearbox {name!r} ratio", source)[0])
        if not np.isfinite(ratio) or ratio == 0.0:
            raise SpecError(source, f"gearbox {name!r}: gearbox_ratio {ratio!r} must be finite and nonzero")
        Xg = joint_frame(g)
        ends = []
        for role, tag in (("parent", "axis"), ("child", "axis2")):
            link = _end(g, role)
            j = _turning_joint(link, ref, parent_joint)
            if j is None:
                raise SpecError(source, f"gearbox {name!r}: its {role} link {link!r} must hang on a revolute joint from "
                                        f"its gearbox_reference_body {ref!r} (with fixed joints only between them)")
            a = Xg.rotation @ axis(g, Xg, tag)
            Xj = joint_frame(j)
            b = Xj.rotation @ axis(j, Xj)
            a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
            if np.linalg.norm(np.cross(a, b)) > _PARALLEL:
                raise SpecError(source, f"gearbox {name!r}: its <{tag}> {np.round(a, 6).tolist()} is not the axis "
                                        f"{np.round(b, 6).tolist()} of joint {j.get('name')!r}, on which its {role} link "
                                        f"{link!r} turns")
            ends.append((j.get("name"), 1.0 if a @ b > 0 else -1.0))
        (j1, s1), (j2, s2) = ends
        if j1 == j2:
            raise SpecError(source, f"gearbox {name!r} gears link {_end(g, 'child')!r} to itself")
        # theta_2 = -ratio theta_1, q_i = s_i theta_i: the slower side (the output) leads
        rotor, output, mult = (j1, j2, -s1 * s2 / ratio) if abs(ratio) <= 1.0 else (j2, j1, -s1 * s2 * ratio)
        geared = {k for k in out} | {v[0] for v in out.values()}
        if rotor in geared or output in geared:
            raise SpecError(source, f"gearbox {name!r}: joint {rotor if rotor in geared else output!r} is already "
                                    "geared by another gearbox; pkm reads one gearbox per joint")
        out[rotor] = (output, mult, name)
    return out


def read_sdf(text: str, source: str = "<sdf>") -> Imported:
    """Read SDFormat text (see the module doc).

    Raises:
        SpecError: malformed XML or a refused feature.
    """
    try:
        return _read_sdf(text, source)
    except RecursionError:
        raise SpecError(source, "poses or parent links nested deeper than Python's recursion limit") from None


def _read_sdf(text: str, source: str) -> Imported:
    root = parse_xml(text, source, "sdf", "SDF")
    models = root.findall("model") or root.findall("world/model")
    if len(models) != 1:
        raise SpecError(source, f"an SDF file for pkm holds one <model>, found {len(models)}")
    model = models[0]
    if model.find("model") is not None or model.find("include") is not None:
        raise SpecError(source, "nested models and <include> are refused: pkm reads one flat <model>")
    links = {el.get("name"): el for el in model.findall("link")}
    if not links or any(not n for n in links) or len(links) != len(model.findall("link")):
        raise SpecError(source, "every <link> needs a distinct name")
    frames = {el.get("name"): el for el in model.findall("frame")}
    if any(not n for n in frames) or len(frames) != len(model.findall("frame")):
        raise SpecError(source, "every <frame> needs a distinct name")
    joints = model.findall("joint")
    for j in joints:
        if not j.get("name") or j.get("type") not in _TYPES:
            raise SpecError(source, f"joint {j.get('name')!r}: type {j.get('type')!r} is not one of {list(_TYPES)}")
        for role in ("parent", "child"):
            name = _end(j, role)
            if name != "world" and name not in links:
                raise SpecError(source, f"joint {j.get('name')!r}: {role} {name!r} is not a link of the model")
    if len({j.get("name") for j in joints}) != len(joints):
        raise SpecError(source, "two joints share a name")
    gearboxes = [j for j in joints if j.get("type") == "gearbox"]
    joints = [j for j in joints if j.get("type") != "gearbox"]

    placed: dict[str, pin.SE3] = {}  # world pose of each link and frame (model frame = world)

    def pose_of(name: str, stack: tuple[str, ...] = ()) -> pin.SE3:
        if name in ("world", "__model__"):
            return pin.SE3.Identity()
        if name in placed:
            return placed[name]
        if name in stack:
            raise SpecError(source, f"poses relative to each other in a cycle: {' -> '.join(stack + (name,))}")
        el = links.get(name) if name in links else frames.get(name)
        if el is None:
            raise SpecError(source, f"a pose is relative_to {name!r}, which is no link or frame of the model")
        M, rel = _pose(el, f"{el.tag} {name!r}", source)
        if el.tag == "frame" and rel is None:
            rel = el.get("attached_to") or "__model__"
        placed[name] = pose_of(rel, stack + (name,)) * M if rel else M
        return placed[name]

    free: dict[str, str] = {}  # a link marked free by pkm's writer -> its free-flyer joint's name
    for name, el in links.items():
        mark = el.find(f"{_PKM}free_joint")
        if mark is not None:
            if not (mark.text or "").strip():
                raise SpecError(source, f"link {name!r}: <pkm:free_joint> needs the free-flyer joint's name")
            free[name] = mark.text.strip()
    parent_joint: dict[str, etree._Element] = {}
    cuts = []
    for j in joints:
        child = _end(j, "child")
        if child in parent_joint or child == "world" or child in free:  # (a free link's joints all cut loops)
            cuts.append(j)
        else:
            parent_joint[child] = j
    bases = [n for n in links if n not in parent_joint and n not in free]
    if len(bases) > 1:
        raise SpecError(source, f"links {bases} have no parent joint: a model for pkm has one base (join the others "
                                "with joints)")
    reached: set[str] = set()  # links known to reach the base or the world (each link walked once: linear)
    for name in links:  # every link reaches the base or the world
        seen: dict[str, None] = {}
        node = name
        while node in parent_joint and node not in reached:
            if node in seen:
                raise SpecError(source, f"links {list(seen)} are each other's parents: no base")
            seen[node] = None
            node = _end(parent_joint[node], "parent")
        reached.update(seen)

    def joint_frame(j: etree._Element) -> pin.SE3:
        M, rel = _pose(j, f"joint {j.get('name')!r}", source)
        return pose_of(rel or _end(j, "child")) * M

    def axis(j: etree._Element, X: pin.SE3, tag: str = "axis") -> np.ndarray:
        ax = j.find(f"{tag}/xyz")
        if ax is None:
            raise SpecError(source, f"joint {j.get('name')!r} ({j.get('type')}) needs <{tag}><xyz>")
        a = _numbers(ax.text, 3, f"joint {j.get('name')!r} {tag}", source)
        if np.linalg.norm(a) < 1e-9:
            raise SpecError(source, f"joint {j.get('name')!r} has a zero {tag}")
        frame = ax.get("expressed_in")
        if frame is None and (_text(j, f"{tag}/use_parent_model_frame") or "").lower() in ("true", "1"):
            frame = "__model__"
        return a if frame is None else X.rotation.T @ pose_of(frame).rotation @ a

    mimic = _gears(gearboxes, parent_joint, joint_frame, axis, source)  # {rotor joint: (output joint, multiplier)}
    tree = {j.get("name"): j for j in parent_joint.values()}
    for j in cuts:
        if j.find(f"{_PKM}position") is not None:
            raise SpecError(source, f"joint {j.get('name')!r}: <pkm:position> on a joint that cuts a loop (pkm "
                                    "writes it on tree joints only)")

    def position(j: etree._Element) -> np.ndarray:
        """The joint's ``<pkm:position>`` (its coordinate at the model's pose: 1 number, a ball's quaternion ``x y z
        w``, 0 or the identity when absent)."""
        n = 4 if j.get("type") == "ball" else 1
        el = j.find(f"{_PKM}position")
        if el is None:
            return np.array([0.0, 0.0, 0.0, 1.0]) if n == 4 else np.zeros(1)
        if j.get("type") not in ("revolute", "continuous", "prismatic", "ball"):
            raise SpecError(source, f"joint {j.get('name')!r}: <pkm:position> on a {j.get('type')} joint")
        p = _numbers(el.text, n, f"joint {j.get('name')!r} pkm:position", source)
        if n == 4 and abs(np.linalg.norm(p) - 1.0) > 1e-9:
            raise SpecError(source, f"joint {j.get('name')!r}: <pkm:position> {p.tolist()} is not a unit quaternion")
        return p

    def motion(j: etree._Element, X: pin.SE3) -> pin.SE3:
        """The placement the joint gives its child at its ``<pkm:position>`` (module doc)."""
        p = position(j)
        if j.get("type") == "ball":
            return pin.SE3(pin.Quaternion(p[3], p[0], p[1], p[2]).normalized().matrix(), np.zeros(3))
        if not p[0]:
            return pin.SE3.Identity()
        a = axis(j, X)
        a = a / np.linalg.norm(a)
        if j.get("type") == "prismatic":
            return pin.SE3(np.eye(3), float(p[0]) * a)
        return pin.SE3(pin.AngleAxis(float(p[0]), a).matrix(), np.zeros(3))

    follow: dict[str, tuple[str, float, float]] = {}  # SDFormat 1.11 <mimic>: {follower: (leader, mult, offset)}
    for j in joints:
        el = j.find("axis/mimic")
        if el is None:
            continue
        name, leader = j.get("name"), el.get("joint")
        where = f"joint {name!r} <mimic>"
        if name not in tree or leader not in tree or name in mimic or leader == name:
            raise SpecError(source, f"{where}: follower and leader {leader!r} must be two joints of the tree (not "
                                    "cutting a loop, not geared by a gearbox)")
        if el.get("axis", "axis") != "axis" or {j.get("type"), tree[leader].get("type")} - \
                {"revolute", "continuous", "prismatic"}:
            raise SpecError(source, f"{where}: pkm reads a mimic between the first axes of revolute, continuous or "
                                    "prismatic joints")
        if el.find("multiplier") is None:
            raise SpecError(source, f"{where}: needs a <multiplier>")
        m, off, ref = (float(_numbers(_text(el, key, "0"), 1, f"{where} {key}", source)[0])
                       for key in ("multiplier", "offset", "reference"))
        # SDFormat: follower = offset + m (leader - reference), both counted from the model's pose
        follow[name] = (leader, m, off - m * ref + float(position(j)[0]) - m * float(position(tree[leader])[0]))

    names = set(links) | {j.get("name") for j in joints} | set(frames)
    robot = etree.Element("robot", name=model.get("name") or "sdf")
    urdf_frame: dict[str, pin.SE3] = {"world": pin.SE3.Identity()}  # the URDF frame of each link (at its joint)
    unread: list[str] = []  # the collision shapes not read

    def add_link(name: str, el: etree._Element | None = None) -> None:
        lel = etree.SubElement(robot, "link", name=ulink.get(name, name))
        for k, col in enumerate(el.findall("collision") if el is not None else ()):
            left = _collision(lel, col, urdf_frame[name].inverse() * pose_of(name), f"link {name!r} <collision> "
                              f"{k + 1}", source)
            if left is not None:
                unread.append(f"{name} ({left})")
        inertial = el.find("inertial") if el is not None else None
        if inertial is None:
            return
        mass = float(_numbers(_text(inertial, "mass", "0"), 1, f"link {name!r} mass", source)[0])
        M, rel = _pose(inertial, f"link {name!r} inertial", source)
        if rel is not None:
            raise SpecError(source, f"link {name!r}: an inertial pose relative_to is not read; give it in the link frame")
        iel = etree.SubElement(lel, "inertial")
        origin(iel, urdf_frame[name].inverse() * pose_of(name) * M)
        etree.SubElement(iel, "mass", value=repr(mass))
        keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
        etree.SubElement(iel, "inertia", {k: repr(float(_numbers(_text(inertial, f"inertia/{k}", "0"), 1,
                                                                   f"link {name!r} {k}", source)[0])) for k in keys})

    def add_joint(name: str, kind: str, parent: str, child: str, X: pin.SE3, j: etree._Element | None = None) \
            -> None:
        jel = etree.SubElement(robot, "joint", name=name, type=kind)
        shift = motion(j, X) if j is not None and tree.get(name) is j else pin.SE3.Identity()
        origin(jel, urdf_frame[parent].inverse() * X * shift.inverse())
        etree.SubElement(jel, "parent", link=ulink.get(parent, parent))
        etree.SubElement(jel, "child", link=ulink.get(child, child))
        if j is not None and j.get("type") == "ball":  # a placeholder that [joint_types] makes spherical
            etree.SubElement(jel, "axis", xyz="0 0 1")
            etree.SubElement(jel, "limit", effort="0", velocity="0")
        elif j is not None and kind in ("revolute", "prismatic"):
            etree.SubElement(jel, "axis", xyz=num(axis(j, X)))
            lo, hi = _text(j, "axis/limit/lower"), _text(j, "axis/limit/upper")
            bounds = {}
            at = float(position(j)[0]) if tree.get(name) is j else 0.0
            if name in mimic:  # a gearbox's rotor: no coordinate, no bounds of its own
                output, mult = mimic[name][0], mimic[name][1]
                etree.SubElement(jel, "mimic", joint=output, multiplier=repr(mult),
                                 offset=repr(at - mult * float(position(tree[output])[0])))
            else:
                if name in follow:
                    etree.SubElement(jel, "mimic", joint=follow[name][0], multiplier=repr(follow[name][1]),
                                     offset=repr(follow[name][2]))
                if lo is not None and hi is not None and j.get("type") != "continuous":
                    b = _numbers(f"{lo} {hi}", 2, f"joint {name!r} limits", source)
                    if np.abs(b).max() < _NO_LIMIT:
                        bounds = {"lower": repr(float(b[0]) + at), "upper": repr(float(b[1]) + at)}
            drive = {}
            for key in ("effort", "velocity"):  # (SDF's default -1: no limit, read as none)
                text = _text(j, f"axis/limit/{key}")
                value = float(_numbers(text, 1, f"joint {name!r} {key} limit", source)[0]) if text else -1.0
                drive[key] = repr(value) if value > 0.0 and name not in mimic else "0"
            etree.SubElement(jel, "limit", **drive, **bounds)
            damping, friction = _text(j, "axis/dynamics/damping"), _text(j, "axis/dynamics/friction")
            if (damping or friction) and name not in mimic:
                values = {k: float(_numbers(t, 1, f"joint {name!r} {k}", source)[0])
                          for k, t in (("damping", damping), ("friction", friction)) if t}
                if any(v < 0.0 for v in values.values()):
                    raise SpecError(source, f"joint {name!r}: a negative dynamics value {values}")
                etree.SubElement(jel, "dynamics", {k: repr(v) for k, v in values.items()})

    def fixed_frame(name: str, parent: str, X: pin.SE3, joint: str | None = None) -> None:
        for n in (name, joint or f"{name}_fixed"):
            if n in names:
                raise SpecError(source, f"pkm names a frame {n!r}, which the model already uses; rename it")
            names.add(n)
        urdf_frame[name] = X
        etree.SubElement(robot, "link", name=name)
        add_joint(joint or f"{name}_fixed", "fixed", parent, name, X)

    robot_root = "world" if "world" not in names else "world_"
    if robot_root != "world":
        urdf_frame[robot_root] = urdf_frame.pop("world")
    etree.SubElement(robot, "link", name=robot_root)
    kinds = {"ball": "revolute", "continuous": "revolute"}  # a ball is a placeholder [joint_types] makes spherical
    order: list[str] = []

    def visit(name: str) -> None:  # parents before children (URDF order does not matter; frames do)
        if name in urdf_frame:
            return
        j = parent_joint.get(name)
        parent = robot_root if j is None or _end(j, "parent") == "world" else _end(j, "parent")
        if parent != robot_root:
            visit(parent)
        urdf_frame[name] = joint_frame(j) if j is not None else pose_of(name)
        order.append(name)

    for name in links:
        visit(name)
    # a URDF link's frame is its joint's; where an SDF link's pose differs, the URDF link is <name>__joint and a
    # frame <name> marks the SDF link's own pose
    ulink: dict[str, str] = {}
    for name in order:
        if not urdf_frame[name].isApprox(pose_of(name), 1e-12):
            ulink[name] = f"{name}__joint"
            if ulink[name] in names:
                raise SpecError(source, f"pkm names a link {ulink[name]!r}, which the model already uses; rename it")
            names.add(ulink[name])
    types: dict[str, str] = {}
    for name in order:
        add_link(name, links[name])
        j = parent_joint.get(name)
        if j is None and name in free:
            if free[name] in names:
                raise SpecError(source, f"link {name!r}: its <pkm:free_joint> {free[name]!r} names another element")
            names.add(free[name])
            el = links[name].find(f"{_PKM}position")
            X = pin.XYZQUATToSE3(_numbers(el.text, 7, f"link {name!r} pkm:position", source)) if el is not None \
                else pin.SE3.Identity()
            add_joint(free[name], "floating", robot_root, name, urdf_frame[name] * X.inverse())
            continue
        if j is None:
            add_joint(f"{name}_base", "fixed", robot_root, name, urdf_frame[name])
            continue
        parent = robot_root if _end(j, "parent") == "world" else _end(j, "parent")
        if j.get("name") in mimic and j.get("name") < mimic[j.get("name")][0]:  # Pinocchio needs the output first
            output, _, gear = mimic[j.get("name")]
            mount = f"{gear}__rotor_mount"
            fixed_frame(mount, parent, urdf_frame[parent], f"{output}__{gear}")
            parent = mount
        add_joint(j.get("name"), kinds.get(j.get("type"), j.get("type")), parent, name, urdf_frame[name], j)
        if j.get("type") == "ball":
            types[j.get("name")] = "spherical"
    for name, urdf_name in ulink.items():
        etree.SubElement(robot, "link", name=name)
        jel = etree.SubElement(robot, "joint", name=f"{name}_fixed", type="fixed")
        origin(jel, urdf_frame[name].inverse() * pose_of(name))
        etree.SubElement(jel, "parent", link=urdf_name)
        etree.SubElement(jel, "child", link=name)
    closures = []
    for j in cuts:
        jname, X = j.get("name"), joint_frame(j)
        parent = robot_root if _end(j, "parent") == "world" else _end(j, "parent")
        child = robot_root if _end(j, "child") == "world" else _end(j, "child")
        fixed_frame(f"{jname}_child", child, X)
        if j.get("type") in ("ball", "fixed"):
            fixed_frame(f"{jname}_parent", parent, X)
            closures.append(Closure(jname, "point" if j.get("type") == "ball" else "frame", f"{jname}_parent",
                                    f"{jname}_child"))
        elif j.get("type") in ("revolute", "continuous"):  # two points of the axis, _AXIS_POINT apart
            fixed_frame(f"{jname}_parent", parent, X)
            Y = X * pin.SE3(np.eye(3), _AXIS_POINT * axis(j, X) / np.linalg.norm(axis(j, X)))
            fixed_frame(f"{jname}_axis_parent", parent, Y)
            fixed_frame(f"{jname}_axis_child", child, Y)
            closures += [Closure(jname, "point", f"{jname}_parent", f"{jname}_child"),
                         Closure(f"{jname}_axis", "point", f"{jname}_axis_parent", f"{jname}_axis_child")]
        else:
            cut = f"{jname}_cut"
            if cut in names:
                raise SpecError(source, f"pkm names a link {cut!r}, which the model already uses; rename it")
            names.add(cut)
            urdf_frame[cut] = X
            etree.SubElement(robot, "link", name=cut)
            add_joint(jname, kinds.get(j.get("type"), j.get("type")), parent, cut, X, j)
            closures.append(Closure(jname, "frame", cut, f"{jname}_child"))
    for name, el in frames.items():
        attached = el.get("attached_to") or "__model__"
        if attached not in links and attached != "__model__":
            raise SpecError(source, f"frame {name!r} is attached_to {attached!r}, which is not a link")
        names.discard(name)
        fixed_frame(name, robot_root if attached == "__model__" else attached, pose_of(name))
    etree.indent(robot, space="  ")
    urdf = etree.tostring(robot, xml_declaration=True, encoding="utf-8", pretty_print=True).decode()
    check_urdf(urdf, source)
    notes = [f"gearbox {gear!r} read as a mimic joint: {rotor} = {mult:.6g} {output}"
             for rotor, (output, mult, gear) in mimic.items()]
    if unread:
        notes.append(f"collision shapes not read (pkm reads box, sphere, cylinder, capsule, ellipsoid, mesh): "
                     f"{', '.join(unread)}")
    springs = {}
    for j in joints:
        name = str(j.get("name"))
        stiffness, rest = (floats(_text(j, f"axis/dynamics/{key}", "0"), 1, f"joint {name!r} {key}", source, np.inf)[0]
                           for key in ("spring_stiffness", "spring_reference"))
        if stiffness != 0.0 and (j.get("type") not in ("revolute", "prismatic") or name in mimic):
            raise SpecError(source, f"joint {name!r}: a spring on a {j.get('type')} joint"
                                    + (" that a gearbox drives" if name in mimic else "") + " (pkm reads the springs "
                                    "of revolute and prismatic joints)")
        if stiffness != 0.0:  # (the reference counts from the model's pose, as the limits: pkm's zero put back)
            springs[name] = {"stiffness": stiffness, "rest": rest + (float(position(j)[0]) if tree.get(name) is j
                                                                     else 0.0)}
    notes += spring_notes(parse_springs(springs, source))
    return Imported(urdf, tuple(closures), types, (), robot.get("name"), "sdf", notes=tuple(notes), springs=springs)


#: SDFormat's shapes and the URDF ``<collision>`` they are written as (:mod:`pkm.core.collision.geometry`):
#: ``{sdf shape: (urdf shape, ((sdf element, urdf attribute, numbers), ...))}``.
_SHAPES = {"box": ("box", (("size", "size", 3),)), "sphere": ("sphere", (("radius", "radius", 1),)),
           "cylinder": ("cylinder", (("radius", "radius", 1), ("length", "length", 1))),
           "capsule": ("capsule", (("radius", "radius", 1), ("length", "length", 1))),
           "ellipsoid": ("ellipsoid", (("radii", "radii", 3),))}


def _collision(lel: etree._Element, col: etree._Element, X: pin.SE3, what: str, source: str) -> str | None:
    """An SDF link's ``<collision>`` written on its URDF link ``lel`` (whose frame is ``X`` in the SDF link's):
    its ``<pose>`` (in the link frame) and ``<geometry>`` (box, sphere, cylinder, capsule, ellipsoid: their sizes;
    mesh: its ``<uri>``, relative to the file's folder, ``model://`` read as ``package://``, and ``<scale>``);
    a plane, a height map or another shape is not collision geometry pkm reads: left out, its tag returned."""
    M, rel = _pose(col, what, source)
    if rel is not None:
        raise SpecError(source, f"{what}: a pose relative_to is not read; give it in the link frame")
    geometry = col.find("geometry")
    shapes = [el for el in (geometry if geometry is not None else ()) if isinstance(el.tag, str)]
    if len(shapes) != 1 or (shapes[0].tag not in _SHAPES and shapes[0].tag != "mesh"):
        return ", ".join(str(el.tag) for el in shapes) or "no shape"
    el = shapes[0]
    out = etree.SubElement(lel, "collision", name=str(col.get("name") or ""))
    origin(out, X * M)
    g = etree.SubElement(out, "geometry")
    if el.tag == "mesh":
        uri = (_text(el, "uri") or "").strip()
        if uri.startswith("model://"):
            uri = "package://" + uri[len("model://"):]
        elif uri and "://" not in uri and not Path(uri).is_absolute() and Path(source).is_file():
            uri = str(Path(source).parent / uri)
        scale = _numbers(_text(el, "scale", "1 1 1"), 3, f"{what} mesh scale", source)
        etree.SubElement(g, "mesh", filename=uri, scale=num(scale))
        return None
    tag, fields = _SHAPES[el.tag]
    etree.SubElement(g, tag, {attr: num(_numbers(_text(el, key), n, f"{what} {el.tag} {key}", source))
                              for key, attr, n in fields})
    return None


__all__ = ["read_sdf"]
