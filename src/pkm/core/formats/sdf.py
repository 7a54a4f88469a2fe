"""SDFormat: a ``<model>`` whose joints form loops (a link with several parent joints).

Pinocchio's SDF parser needs SDFormat, which the PyPI wheel of Pinocchio 4.1 is built without
(``pinocchio.WITH_SDFORMAT`` is False), so pkm reads the subset closed-loop mechanisms use itself, with
SDFormat's pose semantics (1.6 to 1.11):

* ``<link>``: ``<pose>`` in the model frame, or ``relative_to`` another link or frame;
  ``<inertial>`` with its ``<pose>`` (in the link frame), ``<mass>``, ``<inertia>`` (about the centre of
  mass, in the inertial frame's axes);
* ``<joint>`` of type ``revolute``, ``continuous``, ``prismatic``, ``ball`` or ``fixed``: ``<parent>``,
  ``<child>`` (``world`` for the ground), ``<pose>`` in the child link's frame (or ``relative_to``),
  ``<axis><xyz>`` in the joint frame (or ``expressed_in``; SDFormat 1.6's ``use_parent_model_frame``),
  ``<limit><lower><upper>`` (SDFormat's default ±1e16 means none);
* ``<frame name attached_to>`` with a ``<pose>``: named frames (an end effector, a tool point);
* ``<pose degrees="true">`` (SDFormat 1.9).

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

Refused with a :class:`~pkm.errors.SpecError`: nested models, ``<include>``, universal, screw and
gearbox joints, poses relative to what is not a link or frame, several base links, a cycle of
parents.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from lxml import etree

from pkm.core.formats.imported import Imported
from pkm.core.spec import Closure
from pkm.core.urdf import check_urdf, floats, num, origin, parse_xml
from pkm.errors import SpecError

_TYPES = ("revolute", "continuous", "prismatic", "ball", "fixed")
_NO_LIMIT = 1e6  # |bound| above this (SDFormat writes 1e16) is no bound
_AXIS_POINT = 0.1  # m: a cut revolute is two point closures, at the joint and this far along its axis


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

    parent_joint: dict[str, etree._Element] = {}
    cuts = []
    for j in joints:
        child = _end(j, "child")
        if child in parent_joint or child == "world":
            cuts.append(j)
        else:
            parent_joint[child] = j
    bases = [n for n in links if n not in parent_joint]
    if len(bases) > 1:
        raise SpecError(source, f"links {bases} have no parent joint: a model for pkm has one base (join the others "
                                "with joints)")
    for name in links:  # every link reaches the base or the world
        seen: list[str] = []
        node = name
        while node in parent_joint:
            if node in seen:
                raise SpecError(source, f"links {seen} are each other's parents: no base")
            seen.append(node)
            node = _end(parent_joint[node], "parent")

    def joint_frame(j: etree._Element) -> pin.SE3:
        M, rel = _pose(j, f"joint {j.get('name')!r}", source)
        return pose_of(rel or _end(j, "child")) * M

    def axis(j: etree._Element, X: pin.SE3) -> np.ndarray:
        ax = j.find("axis/xyz")
        if ax is None:
            raise SpecError(source, f"joint {j.get('name')!r} ({j.get('type')}) needs <axis><xyz>")
        a = _numbers(ax.text, 3, f"joint {j.get('name')!r} axis", source)
        if np.linalg.norm(a) < 1e-9:
            raise SpecError(source, f"joint {j.get('name')!r} has a zero axis")
        frame = ax.get("expressed_in")
        if frame is None and _text(j, "axis/use_parent_model_frame", "false") == "true":
            frame = "__model__"
        return a if frame is None else X.rotation.T @ pose_of(frame).rotation @ a

    names = set(links) | {j.get("name") for j in joints} | set(frames)
    robot = etree.Element("robot", name=model.get("name") or "sdf")
    urdf_frame: dict[str, pin.SE3] = {"world": pin.SE3.Identity()}  # the URDF frame of each link (at its joint)

    def add_link(name: str, el: etree._Element | None = None) -> None:
        lel = etree.SubElement(robot, "link", name=ulink.get(name, name))
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

    def add_joint(name: str, kind: str, parent: str, child: str, X: pin.SE3, j: etree._Element | None = None):
        jel = etree.SubElement(robot, "joint", name=name, type=kind)
        origin(jel, urdf_frame[parent].inverse() * X)
        etree.SubElement(jel, "parent", link=ulink.get(parent, parent))
        etree.SubElement(jel, "child", link=ulink.get(child, child))
        if j is not None and j.get("type") == "ball":  # a placeholder that [joint_types] makes spherical
            etree.SubElement(jel, "axis", xyz="0 0 1")
            etree.SubElement(jel, "limit", effort="0", velocity="0")
        elif j is not None and kind in ("revolute", "prismatic"):
            etree.SubElement(jel, "axis", xyz=num(axis(j, X)))
            lo, hi = _text(j, "axis/limit/lower"), _text(j, "axis/limit/upper")
            bounds = {}
            if lo is not None and hi is not None and j.get("type") != "continuous":
                b = _numbers(f"{lo} {hi}", 2, f"joint {name!r} limits", source)
                if np.abs(b).max() < _NO_LIMIT:
                    bounds = {"lower": repr(float(b[0])), "upper": repr(float(b[1]))}
            etree.SubElement(jel, "limit", effort="0", velocity="0", **bounds)

    def fixed_frame(name: str, parent: str, X: pin.SE3) -> None:
        if name in names:
            raise SpecError(source, f"pkm names a frame {name!r}, which the model already uses; rename it")
        names.add(name)
        urdf_frame[name] = X
        etree.SubElement(robot, "link", name=name)
        add_joint(f"{name}_fixed", "fixed", parent, name, X)

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
        if j is None:
            add_joint(f"{name}_base", "fixed", robot_root, name, urdf_frame[name])
            continue
        parent = robot_root if _end(j, "parent") == "world" else _end(j, "parent")
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
    return Imported(urdf, tuple(closures), types, (), robot.get("name"), "sdf")


__all__ = ["read_sdf"]
