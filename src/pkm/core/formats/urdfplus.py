r"""Closed loops written inside a URDF: MIT's URDF+ ``<loop>`` and the ``<constraint>`` element proposed to urdfdom.

A URDF stays a tree; both formats add, under ``<robot>``, elements that cut a loop between two links of the tree.
:func:`read_urdf` reads a URDF with neither as before (:func:`pkm.core.formats.imported.read_urdf`) and one with
either as a closed mechanism. The grammar pkm implements, element by element, with its source:

**URDF+** (Chignoli et al., "URDF+: An Enhanced URDF for Robots with Kinematic Loops", arXiv 2411.19753; the
element and field names as in its reference parser's ``LoopConstraint``/``CouplingConstraint`` (``urdf_model/
constraint.h`` of the authors' urdfdom fork used by ROAM-Lab-ND/generalized_rbda) and in ACDC4Robot's URDF+
exporter)::

    <loop name="L" type="revolute|continuous|fixed|spherical">
      <predecessor link="A"> <origin xyz="x y z" rpy="r p y"/> </predecessor>
      <successor link="B"> <origin xyz="x y z" rpy="r p y"/> </successor>
      <axis xyz="ax ay az"/>
    </loop>

The loop frame is ``origin`` in link A's frame and ``origin`` in link B's frame (each defaults to the identity,
as URDF's); ``axis`` (URDF's default ``1 0 0``) is in the loop frame; ``type`` is URDF's joint type of the cut.
``<coupling name ratio>`` (a gear relation between two links' velocities) is refused by name: pkm's closures
are positions; its ``prismatic`` and ``planar`` loop types are refused too (below). URDF+ has no spherical loop
joint: ``type="spherical"`` is a pkm extension (what :mod:`pkm.core.formats.to_urdfplus` writes for a ball cut,
the Delta's), which other URDF+ readers refuse.

**urdfdom ``<constraint>``** (ros/urdfdom_headers PR #108, "Add constraints to describe closed loops", and
ros/urdfdom PR #264, both from 2026-06: the grammar of the PR's description)::

    <constraint name="C" type="revolute|continuous|fixed|spherical">
      <parent link="A"/> <parent_origin xyz="..." rpy="..."/> <parent_axis xyz="..."/>
      <child link="B"/>  <child_origin xyz="..." rpy="..."/>  <child_axis xyz="..."/>
    </constraint>

Two frames, ``parent_origin`` in link A and ``child_origin`` in link B, which the cut joint ties; ``parent_axis``
and ``child_axis`` are the joint's axis in each (the PR adds two so that a universal joint can be written).
The PR's description names no list of types ("similar to joints"): pkm reads URDF's ``revolute``,
``continuous`` and ``fixed`` and, a pkm extension, ``spherical`` (the ball joints of the delta robots the PR
motivates); ``universal`` is refused (a universal cut is 4 equations, pkm's closures are 3 or 6).

**What pkm makes of them.** Each cut joint becomes frames fixed to its two links and closures that are exactly
that joint, as :mod:`pkm.core.formats.sdf` does for a cut SDF joint: ``fixed`` one ``frame`` closure;
``spherical`` one ``point`` closure; ``revolute``/``continuous`` two ``point`` closures, at the joint and
0.1 m along its axis (five independent equations). The frames are ``<name>_<role>`` and, for a revolute,
``<name>_axis_<role>``, with roles ``predecessor``/``successor`` (URDF+) and ``parent``/``child``
(``<constraint>``); the closures are ``<name>`` and ``<name>_axis``. The actuated joints are the ``<joint
name>`` of the file's ROS ``<transmission>`` elements, in file order (neither format names actuators
otherwise); a file with none loads with ``actuated=`` given in code (:class:`pkm.core.formats.load.Given`).

Refused with a :class:`~pkm.errors.SpecError` naming the file, the element and its line: a cut joint naming a
link the tree lacks (:class:`~pkm.errors.SpecNameError`), an unknown or unsupported type, a missing
``name``/``link``, a malformed number, a zero axis, two elements of one name, a name pkm's frames would clash
with, a transmission naming a missing joint.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from lxml import etree

from pkm.core.formats.base import Imported
from pkm.core.formats.sdf import _AXIS_POINT
from pkm.core.model.spec import Closure
from pkm.core.model.springs import spring_notes
from pkm.core.model.urdf import check_urdf, gazebo_springs, limit_notes, origin, parse_xml
from pkm.errors import SpecError, SpecNameError

#: The elements under ``<robot>`` that make a URDF closed, and the format each marks.
ELEMENTS = {"loop": "urdfplus", "coupling": "urdfplus", "constraint": "urdfdom"}

_TYPES = ("revolute", "continuous", "fixed", "spherical")  # (spherical: a pkm extension in both, module doc)
_REFUSED = {"prismatic": "a cut prismatic joint", "planar": "a cut planar joint",
            "universal": "a universal cut (4 equations; pkm's closures state 3 or 6)",
            "floating": "a floating cut (no equation)"}


@dataclass(frozen=True)
class _Cut:
    """One cut joint read from either element: its two sides (link, frame in it, axis in that frame)."""

    name: str
    type: str
    roles: tuple[str, str]
    links: tuple[str, str]
    frames: tuple[pin.SE3, pin.SE3]
    axes: tuple[np.ndarray, np.ndarray]


def _where(el: etree._Element) -> str:
    return f"<{el.tag} name={el.get('name')!r}> at line {el.sourceline}"


def _vector(el: etree._Element | None, attr: str, default: str, source: str, where: str) -> np.ndarray:
    text = default if el is None or el.get(attr) is None else str(el.get(attr))
    try:
        v = np.array([float(t) for t in text.split()], dtype=float)
    except ValueError:
        v = np.array([])
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise SpecError(source, f"{where}: {attr}={text!r} is not three finite numbers")
    return v


def _origin(el: etree._Element | None, source: str, where: str) -> pin.SE3:
    """A URDF ``<origin xyz rpy>`` (rpy: about fixed x, y, z in turn, as URDF's), identity when absent."""
    return pin.SE3(pin.rpy.rpyToMatrix(*_vector(el, "rpy", "0 0 0", source, where)),
                   _vector(el, "xyz", "0 0 0", source, where))


def _axis(el: etree._Element | None, source: str, where: str) -> np.ndarray:
    a = _vector(el, "xyz", "1 0 0", source, where)
    n = float(np.linalg.norm(a))
    if n == 0.0:
        raise SpecError(source, f"{where}: a zero axis")
    return a / n


def _link(el: etree._Element | None, links: list[str], source: str, where: str, role: str) -> str:
    name = el.get("link") if el is not None else None
    if not name:
        raise SpecError(source, f"{where}: no <{role} link=...>")
    if name not in links:
        raise SpecNameError(source, "link", name, links, where)
    return str(name)


def _cut(el: etree._Element, links: list[str], source: str) -> _Cut:
    where = _where(el)
    name, typ = el.get("name"), el.get("type")
    if el.tag == "coupling":
        raise SpecError(source, f"{where}: URDF+ couplings (velocity ratios between links) are not read; pkm's "
                                "closures tie positions (write the gear as a URDF <mimic>)")
    if not name:
        raise SpecError(source, f"<{el.tag}> at line {el.sourceline}: no name")
    if typ in _REFUSED:
        raise SpecError(source, f"{where}: {_REFUSED[typ]} is not read")
    if typ not in _TYPES:
        raise SpecError(source, f"{where}: type {typ!r} unknown; pkm reads {list(_TYPES)}")
    if el.tag == "loop":
        pred, succ = el.find("predecessor"), el.find("successor")
        axis = _axis(el.find("axis"), source, where)
        return _Cut(str(name), str(typ), ("predecessor", "successor"),
                    (_link(pred, links, source, where, "predecessor"), _link(succ, links, source, where, "successor")),
                    (_origin(pred.find("origin") if pred is not None else None, source, where),
                     _origin(succ.find("origin") if succ is not None else None, source, where)), (axis, axis))
    return _Cut(str(name), str(typ), ("parent", "child"),
                (_link(el.find("parent"), links, source, where, "parent"),
                 _link(el.find("child"), links, source, where, "child")),
                (_origin(el.find("parent_origin"), source, where), _origin(el.find("child_origin"), source, where)),
                (_axis(el.find("parent_axis"), source, where), _axis(el.find("child_axis"), source, where)))


def _actuated(root: etree._Element, joints: list[str], source: str) -> tuple[str, ...]:
    names: list[str] = []
    for tr in root.findall("transmission"):
        for jel in tr.findall("joint"):
            name = jel.get("name")
            if name not in joints:
                raise SpecNameError(source, "joint", str(name), joints,
                                    f"<transmission name={tr.get('name')!r}> at line {jel.sourceline}")
            if name not in names:
                names.append(str(name))
    return tuple(names)


def read_urdf(text: str, source: str = "<urdf>") -> Imported:
    """A URDF file: with URDF+ ``<loop>`` or urdfdom ``<constraint>`` elements a closed mechanism (see the module
    doc), else as a plain URDF (:func:`pkm.core.formats.imported.read_urdf`).

    Raises:
        SpecError: as the module doc says (a :class:`~pkm.errors.SpecNameError` for a missing link or joint).
    """
    from pkm.core.formats.imported import read_urdf as read_plain

    if not any(f"<{tag}" in text for tag in ELEMENTS):  # (a plain URDF, parsed once)
        return read_plain(text, source)
    root = parse_xml(text, source)
    marked = [el for el in root if isinstance(el.tag, str) and el.tag in ELEMENTS]
    if not marked:
        return read_plain(text, source)
    kind = ELEMENTS[marked[0].tag]
    other = next((el for el in marked if ELEMENTS[el.tag] != kind), None)
    if other is not None:
        raise SpecError(source, f"{_where(marked[0])} and {_where(other)}: URDF+ and urdfdom constraints in one "
                                "file; write one kind")
    links = [str(el.get("name")) for el in root.findall("link")]
    cuts = [_cut(el, links, source) for el in marked]
    for el in marked:
        root.remove(el)
    tree = check_urdf(etree.tostring(root, encoding="unicode"), source)
    joints = [str(el.get("name")) for el in tree.findall("joint")]
    names = set(links) | set(joints)
    closures: list[Closure] = []

    def frame(name: str, link: str, X: pin.SE3, where: str) -> str:
        for n in (name, f"{name}_fixed"):
            if n in names:
                raise SpecError(source, f"{where}: pkm names a frame {n!r}, which the model already uses; rename it")
            names.add(n)
        etree.SubElement(tree, "link", name=name)
        jel = etree.SubElement(tree, "joint", name=f"{name}_fixed", type="fixed")
        origin(jel, X)
        etree.SubElement(jel, "parent", link=link)
        etree.SubElement(jel, "child", link=name)
        return name

    seen: set[str] = set()
    for cut, el in zip(cuts, marked, strict=True):
        where = _where(el)
        if cut.name in seen:
            raise SpecError(source, f"{where}: a second cut joint of that name")
        seen.add(cut.name)
        a, b = (frame(f"{cut.name}_{role}", link, X, where)
                for role, link, X in zip(cut.roles, cut.links, cut.frames, strict=True))
        closures.append(Closure(cut.name, {"fixed": "frame", "spherical": "point"}.get(cut.type, "point"), a, b))
        if cut.type in ("revolute", "continuous"):  # two points of the axis, _AXIS_POINT apart
            a, b = (frame(f"{cut.name}_axis_{role}", link, X * pin.SE3(np.eye(3), _AXIS_POINT * axis), where)
                    for role, link, X, axis in zip(cut.roles, cut.links, cut.frames, cut.axes, strict=True))
            closures.append(Closure(f"{cut.name}_axis", "point", a, b))
    springs = gazebo_springs(tree, source)
    return Imported(etree.tostring(tree, encoding="unicode"), tuple(closures), {}, _actuated(tree, joints, source),
                    str(root.get("name") or "robot"), kind, notes=limit_notes(tree) + spring_notes(springs),
                    springs=springs)


__all__ = ["ELEMENTS", "read_urdf"]
