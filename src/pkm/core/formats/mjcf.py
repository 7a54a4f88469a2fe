"""MuJoCo's MJCF: a ``<mujoco>`` file whose ``<equality>`` section closes the loops.

Pinocchio parses the tree, the inertias (including those MuJoCo computes from geoms) and the
equality constraints (:func:`pinocchio.buildModelAndConstraintsFromMJCF`); pkm reads what Pinocchio
does not keep, from the file itself:

* ``<connect>`` gives a ``point`` closure and ``<weld>`` a ``frame`` closure, named by the equality's
  ``name`` (else ``connect1``, ``weld2``...); their anchors become frames ``<name>_a`` (on ``body1``)
  and ``<name>_b`` (on ``body2``, the world when it is omitted); an equality between two sites
  (``site1``, ``site2``) closes those sites' frames (origins for a connect, frames for a weld; a site whose name
  a body or a joint shares, as MJCF allows, on a frame of its own, ``<site>_site``, that a lookup by name cannot
  confuse with them);
  an equality with ``active="false"`` is left out (a note says so); a weld is read as MuJoCo reads it,
  ``X1 relpose = X2 T(anchor)``: ``relpose`` (body2's pose in body1's frame, position then quaternion ``w x y
  z``; without it the pose at ``qpos0``), ``anchor`` (the point of body2 it holds), ``torquescale="0"`` (the
  orientation free: a ``point`` closure); a free body it ties is moved where its ``relpose`` puts it;
* ``<equality><joint joint1 joint2 polycoef="a0 a1 a2 a3 a4">`` (MuJoCo:
  ``q1 - q1_0 = a0 + a1 (q2 - q2_0) + a2 (q2 - q2_0)^2 + ...``, ``q_0`` the joint's ``ref``): a linear one
  (``a2 = a3 = a4 = 0``) is a mimic joint, ``q1 = a1 q2 + a0 + q1_0 - a1 q2_0`` (Pinocchio's
  ``JointModelMimic``, a URDF ``<mimic>``; the follower is whichever of the two comes second in Pinocchio's
  traversal, chains resolved to one leader); without ``joint2`` (or with ``a1 = 0``) the joint is locked at
  ``q1_0 + a0`` (a fixed joint). A non-linear polynomial is refused;
* the actuated joints: the ``joint`` of each ``<actuator>`` element (``motor``, ``position``,
  ``general``...), in file order; a mimic joint's actuator drives its leader; an actuator on a
  ``<tendon><fixed>`` drives the one independent joint the tendon's length is an affine function of, once
  the mimic couplings are substituted (Robotiq's ``0.5 right + 0.5 left`` with ``right = left`` drives
  ``left`` with factor 1). A tendon of several independent joints is a differential: those joints are
  actuated and each motor on it a ``[motors]`` entry (:attr:`Imported.motors`, :mod:`pkm.core.model.motors`), its
  coordinate the tendon length times the actuator's ``gear``, ``u = sum_j gear c_j q_j`` (the mimic couplings
  substituted), its effort acting on the joints as ``tau_j = gear c_j f``; the motors that share joints must be as
  many as those joints, their map invertible, and a joint in a differential has no actuator of its own (else
  refused); their force ranges bound the motors, not a joint (a note). A ``<spatial>`` tendon is refused; actuators
  on sites or bodies (forces, not joint inputs) are left out with a note;
* the drive of each actuated joint (:attr:`Imported.actuators`, a spec's ``[actuators.<joint>]`` tables: the URDF
  text cannot carry them; :mod:`pkm.core.model.actuators`), class defaults included (MuJoCo's actuator elements
  share one default per class): the joint's ``armature`` (MuJoCo's is the reflected inertia) -> ``armature``,
  ``damping`` -> ``viscous``, ``frictionloss`` -> ``coulomb``; ``effort_limit``, in the joint's units, is what the
  actuators apply at full control: each one's ``forcerange`` when it limits (``forcelimited="true"``, or ``auto`` with
  lower < upper), for a ``<motor>`` its ``ctrlrange`` too (a motor's force is its control), times the first
  ``gear`` and the tendon's coefficient or the mimic scale; several actuators on one joint add; the joint's
  ``actuatorfrcrange`` caps the sum. An asymmetric range reads as its smaller magnitude, a one-sided one as its
  larger (a note says so), ``1e6`` or more as none. What is not stated stays at the defaults (no friction, no
  limit); the servo gains (``kp``, ``kv``) and the armature and friction of joints no actuator moves are not read
  (notes);
* joint springs and dampers (:attr:`Imported.springs`, a spec's ``[springs.<joint>]`` tables:
  :mod:`pkm.core.model.springs`): a hinge's or slide's ``stiffness`` and ``springref`` (MuJoCo's rest position, in
  degrees for a hinge as ``ref``), and the ``damping`` of a joint no actuator drives; named in the notes, applied
  by pkm's dynamics (a damping as the joint's viscous friction); a ball's and a coupled joint's are not read (a note);
* joint names and position limits (``range``, in degrees unless ``<compiler angle="radian">``, for
  hinges only; a slide's range is a length), with ``<default>`` classes and ``childclass``; a body with
  several joints keeps each one's name (Pinocchio joins them into one composite joint). ``q`` is MuJoCo's
  ``qpos`` (a joint's ``ref`` is where its body has the pose the file states, as in MuJoCo). Joints and
  bodies without a name (MuJoCo's are optional) are named from their body: ``<body>_free``,
  ``<body>_hinge``, ``<body>_hinge_2`` (the second), ``<body>_slide``, ``<body>_ball``; a body
  ``<parent>_child`` (``_child_2``...); a derived name never takes one the file uses;
* the reference configuration: the ``<keyframe><key name="reference">`` (the one :func:`pkm.save` writes), held
  (a ``qpos`` of another length is refused naming its line, as in every key); without it, the first key whose
  hinges and slides lie inside their ranges (MuJoCo Menagerie's ``home``: a pose MuJoCo's soft equalities leave
  open by a millimetre or so): its floating base held, its free bodies and actuated joints held where the loops allow
  (:attr:`Imported.hold`: redundant motors whose key values disagree are moved, a note and a warning say by how much),
  the loops closed by moving the other joints from it (a note names the key, the keys passed over, and how far the
  closing moved them); without any, assembled
  starting from MuJoCo's ``qpos0`` (hinges and slides at their ``ref``, free bodies where the file puts them), where
  a ``<connect>``'s second anchor is taken (also for the connects pkm re-anchors: those to free bodies). An
  assembled reference outside a joint's range is assembled again inside it, else said
  (:func:`pkm.core.model.builder.build`);
* ``euler`` angles in any ``<compiler eulerseq>`` (three of ``xyzXYZ``: lower case about the moving axes,
  upper case about the fixed ones, mixed allowed): pkm writes each ``euler`` (bodies, geoms, sites,
  inertials, cameras, default classes...) as the ``quat`` MuJoCo computes, in the copy Pinocchio reads;
* ``ball`` joints become Pinocchio spherical joints, ``<freejoint>`` a free-flyer: on the root body that
  carries every other joint, the mechanism's floating base (``spec.floating_base``).

What Pinocchio 4.1's parser gets wrong is worked around, each by a test: it reads only the first body
under ``<worldbody>`` (pkm wraps them all in one fixed body), ignores the sites of bodies without
joints (pkm adds them from the file), drops the equalities' names, converts a slide's range as
an angle, and crashes on equalities between sites (pkm takes them out of its copy and closes them
itself); it reads only the first top-level ``<default>`` element, so a ``class`` defined in a second one
(onshape-to-robot's Reachy Mini has three) makes it throw ``unordered_map::at`` (pkm merges them into
one); it reads an upper-case (fixed-axes) ``eulerseq`` letter as a lower-case one (pkm hands it
quaternions); it loses the bodies inside a MuJoCo 3 ``<frame>`` (pkm moves them out, composing the
frame's pose) and the unnamed bodies (it names them all ``<parent>Bis``; pkm names them); it returns the
equalities in the order of their names (or of ``<body1>_<body2>_constraint``), keeping one of those that share
a name (pkm names them in file order in its copy); it drops the
``pos`` a default class gives a joint (Robotiq 2F-85's followers), a geom or a site (pkm writes every class
attribute on the joints, geoms and sites of its copy). Refused with a
:class:`~pkm.errors.SpecError`: ``<include>`` (pkm reads one self-contained file), equalities other than
``connect``/``weld``/``joint``, joint types other than hinge, slide, ball, free, a drive's negative or non-numeric
value, a limited range whose lower bound is not below its upper, a gear of 0. What the reader interprets
or leaves out (tendons read as joints, contacts, sensors...) is listed in :attr:`Imported.notes`. Meshes are
not read (kinematics and dynamics need none).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterable
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pinocchio as pin
from lxml import etree

from pkm.core.formats.base import Imported
from pkm.core.model.actuators import UNLIMITED, Actuator
from pkm.core.model.motors import linear_text, motor_map
from pkm.core.model.spec import Closure
from pkm.core.model.springs import describe, parse_springs
from pkm.core.model.urdf import floats, num, parse_xml, urdf_from_model
from pkm.errors import InvalidInputError, SpecError, SpecNameError

_ACTUATORS = ("motor", "position", "velocity", "general", "intvelocity", "damper", "cylinder", "muscle",
              "adhesion")
_JOINT_TYPES = ("hinge", "slide", "ball", "free")
_WORLD = "world"  # the fixed body pkm wraps the worldbody's children in (Pinocchio reads only one): MuJoCo's name
# for the world body, which equalities may name (body2="world") and no body of the file may take
_UNREAD = ("contact", "sensor", "keyframe", "visual", "option", "size", "statistic", "custom", "extension",
           "deformable")  # top-level sections kinematics and dynamics need nothing from
_ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")
_SMALL = 1e-12  # a coefficient below this is zero (a tendon's factor on a joint, a redundant coupling's misfit)


def _floats(text: str | None, n: int, what: str, source: str) -> np.ndarray:
    return np.array(floats(text, n, what, source))


class _Defaults:
    """MJCF attribute defaults: ``<default>`` classes (nested), ``class`` and ``childclass``."""

    def __init__(self, root: etree._Element):
        self.parent: dict[str, str | None] = {}
        self.attrs: dict[tuple[str, str], dict[str, str]] = {}
        for top in root.findall("default"):
            self._walk(top, None)

    def _walk(self, el: etree._Element, parent: str | None) -> None:
        name = el.get("class", "main")
        self.parent[name] = parent
        for child in el:
            if child.tag == "default":
                self._walk(child, name)
            elif isinstance(child.tag, str):
                self.attrs.setdefault((name, child.tag), {}).update(child.attrib)
                if child.tag in _ACTUATORS:  # MuJoCo's actuator shortcuts share one default per class
                    self.attrs.setdefault((name, "<actuator>"), {}).update(child.attrib)

    def chain(self, el: etree._Element) -> list[dict[str, str]]:
        """The attributes the classes give ``el``, its own class (or the nearest ``childclass``) first (an
        actuator: those any actuator element of the class gives, as MuJoCo shares them)."""
        tag = "<actuator>" if el.tag in _ACTUATORS and el.getparent() is not None \
            and el.getparent().tag == "actuator" else el.tag
        cls = el.get("class")
        node = el.getparent()
        while cls is None and node is not None:
            cls = node.get("childclass")
            node = node.getparent()
        out, at = [], cls or "main"
        while at is not None:
            out.append(self.attrs.get((at, tag), {}))
            at = self.parent.get(at)
        return out

    def get(self, el: etree._Element, key: str, default: str | None = None) -> str | None:
        if el.get(key) is not None:
            return el.get(key)
        return next((attrs[key] for attrs in self.chain(el) if key in attrs), default)

    def materialize(self, world: etree._Element) -> None:
        """Every attribute the classes give a joint, geom or site written on it (Pinocchio 4.1 drops a class's
        ``pos``; an orientation or a ``pos``/``fromto`` the element states keeps the class's out)."""
        groups = (set(_ORIENTATIONS), {"pos", "fromto"})
        for el in world.iter("joint", "geom", "site"):
            for attrs in self.chain(el):
                for key, value in attrs.items():
                    group = next((g for g in groups if key in g), {key})
                    if key != "class" and not any(el.get(k) is not None for k in group):
                        el.set(key, value)


def _unit(x: np.ndarray, what: str, source: str) -> np.ndarray:
    n = float(np.linalg.norm(x))
    if n < 1e-12:
        raise SpecError(source, f"{what}: a zero vector gives no direction")
    return x / n


def euler_matrix(angles: Iterable[float], seq: str = "xyz") -> np.ndarray:
    """The rotation of MuJoCo's ``euler`` attribute, ``angles`` [rad] in the sequence ``seq`` (``<compiler
    eulerseq>``): one rotation per letter, about the moving axes for a lower-case letter (``R = R R_i``), about
    the fixed (parent) axes for an upper-case one (``R = R_i R``), as MuJoCo composes them."""
    R = np.eye(3)
    for axis, angle in zip(seq, angles):
        Ri = pin.AngleAxis(float(angle), np.eye(3)["xyz".index(axis.lower())]).matrix()
        R = R @ Ri if axis.islower() else Ri @ R
    return R


def _rotation(el: etree._Element, degrees: bool, source: str, seq: str = "xyz") -> np.ndarray:
    """The orientation an MJCF element states (quat, axisangle, euler in ``seq``, xyaxes, zaxis)."""
    what = f"<{el.tag} name={el.get('name')!r}>"
    if el.get("quat") is not None:
        w, x, y, z = _unit(_floats(el.get("quat"), 4, f"{what} quat", source), f"{what} quat", source)
        return pin.Quaternion(w, x, y, z).matrix()
    if el.get("axisangle") is not None:
        a = _floats(el.get("axisangle"), 4, f"{what} axisangle", source)
        return pin.AngleAxis(np.deg2rad(a[3]) if degrees else a[3], _unit(a[:3], f"{what} axisangle", source)).matrix()
    if el.get("euler") is not None:
        e = _floats(el.get("euler"), 3, f"{what} euler", source)
        return euler_matrix(np.deg2rad(e) if degrees else e, seq)
    if el.get("xyaxes") is not None:
        a = _floats(el.get("xyaxes"), 6, f"{what} xyaxes", source)
        x = _unit(a[:3], f"{what} xyaxes", source)
        y = _unit(a[3:] - x * (x @ a[3:]), f"{what} xyaxes", source)
        return np.column_stack([x, y, np.cross(x, y)])
    if el.get("zaxis") is not None:
        z = _floats(el.get("zaxis"), 3, f"{what} zaxis", source)
        return pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), _unit(z, f"{what} zaxis", source)).matrix()
    return np.eye(3)


def _set_rotation(el: etree._Element, R: np.ndarray) -> None:
    """``el``'s orientation written as a ``quat`` (w x y z), its other orientation attributes removed."""
    for key in _ORIENTATIONS:
        el.attrib.pop(key, None)
    x, y, z, w = pin.Quaternion(R).coeffs()
    el.set("quat", num([w, x, y, z]))


def _eulers_to_quats(root: etree._Element, degrees: bool, source: str) -> str:
    """Every ``euler`` of the file (any element, default classes included) written as a ``quat``, in the
    ``<compiler eulerseq>`` of the file, which is then dropped. Returns the sequence."""
    compiler = root.find("compiler")
    seq = "xyz" if compiler is None else compiler.get("eulerseq", "xyz")
    if len(seq) != 3 or any(c not in "xyzXYZ" for c in seq):
        raise SpecError(source, f"<compiler eulerseq={seq!r}>: give three letters of xyzXYZ (lower case: about the "
                                "moving axes, upper case: about the fixed axes)")
    for el in root.iter():
        if isinstance(el.tag, str) and el.get("euler") is not None:
            stated = [k for k in _ORIENTATIONS if el.get(k) is not None]
            if len(stated) > 1:
                raise SpecError(source, f"<{el.tag} name={el.get('name')!r}> states its orientation twice ({stated})")
            _set_rotation(el, _rotation(el, degrees, source, seq))
    if compiler is not None:
        compiler.attrib.pop("eulerseq", None)
    return seq


def _merge_defaults(root: etree._Element) -> int:
    """The top-level ``<default>`` elements merged into the first (Pinocchio reads the first only), placed before the
    ``<worldbody>`` (MuJoCo reads the classes wherever they stand; Pinocchio 4.1 in document order, and a class it has
    not met yet raised ``unordered_map::at``: ToddlerBot's files state them last); their number."""
    tops = root.findall("default")
    world = root.find("worldbody")
    if tops and world is not None and list(root).index(tops[0]) > list(root).index(world):
        root.remove(tops[0])
        root.insert(list(root).index(world), tops[0])
    for extra in tops[1:]:
        for child in list(extra):
            if not isinstance(child.tag, str):
                continue
            same = tops[0].find(child.tag) if child.tag != "default" else None
            if same is not None:
                same.attrib.update(child.attrib)
            else:
                tops[0].append(child)
        root.remove(extra)
    return len(tops)


def _flatten_frames(world: etree._Element, degrees: bool, source: str) -> int:
    """MuJoCo 3's ``<frame>`` elements removed, their pose composed into their children's (Pinocchio 4.1 loses
    what they hold); their number."""
    frames = list(world.iter("frame"))
    for fr in reversed(frames):  # the innermost first
        if fr.get("childclass") is not None:
            raise SpecError(source, f"<frame name={fr.get('name')!r} childclass=...>: put the class on its children")
        X = pin.SE3(_rotation(fr, degrees, source), _floats(fr.get("pos", "0 0 0"), 3, "<frame> pos", source))
        parent, at = fr.getparent(), fr.getparent().index(fr)
        for child in list(fr):
            if isinstance(child.tag, str) and child.get("fromto") is not None:
                ends = _floats(child.get("fromto"), 6, f"<{child.tag}> fromto", source).reshape(2, 3)
                child.set("fromto", num([X.act(p) for p in ends]))
            elif isinstance(child.tag, str):
                M = X * pin.SE3(_rotation(child, degrees, source),
                                _floats(child.get("pos", "0 0 0"), 3, f"<{child.tag}> pos", source))
                child.set("pos", num(M.translation))
                _set_rotation(child, M.rotation)
            parent.insert(at, child)
            at += 1
        parent.remove(fr)
    return len(frames)


def _fresh(base: str, used: set[str]) -> str:
    """``base``, else ``base_2``, ``base_3``...: the first that ``used`` lacks (added to it)."""
    name, k = base, 1
    while name in used:
        k += 1
        name = f"{base}_{k}"
    used.add(name)
    return name


class _Affine(NamedTuple):
    """A joint coordinate as ``scale * q[root] + offset`` (a leader's own: scale 1, offset 0)."""

    root: str
    scale: float
    offset: float


class _Couplings:
    """The joint equalities: groups of joints tied by linear couplings, each joint affine in its group's root;
    locked groups hold constants."""

    def __init__(self, source: str):
        self.source = source
        self.of: dict[str, _Affine] = {}
        self.locked: dict[str, float] = {}  # root -> its locked value

    def get(self, j: str) -> _Affine:
        return self.of.get(j, _Affine(j, 1.0, 0.0))

    def members(self, root: str) -> list[str]:
        return [j for j, a in self.of.items() if a.root == root] + ([] if root in self.of else [root])

    def tie(self, where: str, j1: str, j2: str, a1: float, c: float) -> None:
        """``q[j1] = a1 q[j2] + c`` (``a1 != 0``), stated by the equality ``where`` names."""
        r1, r2 = self.get(j1), self.get(j2)
        if r1.root == r2.root:  # a redundant (or contradicting) coupling
            if abs(r1.scale - a1 * r2.scale) > _SMALL or abs(r1.offset - (a1 * r2.offset + c)) > _SMALL:
                raise SpecError(self.source, f"{where} contradicts the couplings before it")
            return
        # r1.root = (q[j1] - r1.offset) / r1.scale, with q[j1] = a1 (r2.scale q[r2.root] + r2.offset) + c
        s, o = a1 * r2.scale / r1.scale, (a1 * r2.offset + c - r1.offset) / r1.scale
        for j in self.members(r1.root):
            a = self.get(j)
            self.of[j] = _Affine(r2.root, a.scale * s, a.scale * o + a.offset)
        if r1.root in self.locked:
            self.lock(where, r2.root, (self.locked.pop(r1.root) - o) / s)

    def lock(self, where: str, j: str, value: float) -> None:
        a = self.get(j)
        root_value = (value - a.offset) / a.scale
        if a.root in self.locked and abs(self.locked[a.root] - root_value) > _SMALL:
            raise SpecError(self.source, f"{where} locks joint {j!r} at another value than "
                                         "the couplings before it")
        self.locked[a.root] = root_value

    def value(self, j: str) -> float | None:
        """The constant a locked joint holds, else None."""
        a = self.get(j)
        return a.scale * self.locked[a.root] + a.offset if a.root in self.locked else None

    def lead(self, order: dict[str, int]) -> None:
        """Each free group re-rooted at its member that comes first in ``order`` (Pinocchio's traversal: a mimic
        joint's leader must come before it)."""
        for root in {a.root for a in self.of.values()} - set(self.locked):
            first = min(self.members(root), key=order.__getitem__)
            f = self.get(first)
            for j in self.members(root):
                a = self.get(j)
                self.of[j] = _Affine(first, a.scale / f.scale, a.offset - a.scale * f.offset / f.scale)
            self.of.pop(first)

    def followers(self) -> dict[str, tuple[str, float, float]]:
        """``{joint: (leader, multiplier, offset)}`` for the joints of free groups but their roots."""
        return {j: (a.root, a.scale, a.offset) for j, a in self.of.items() if a.root not in self.locked}


def read_mjcf(text: str, source: str = "<mjcf>") -> Imported:
    """Read MJCF text (see the module doc).

    Raises:
        SpecError: malformed XML, a refused feature, or a file Pinocchio rejects.
    """
    root = parse_xml(text, source, "mujoco", "MJCF")
    if root.find(".//include") is not None:
        raise SpecError(source, "<include> is refused: pkm reads one self-contained MJCF file; merge the included "
                                "files into it")
    notes: list[str] = []
    compiler = root.find("compiler")
    degrees = compiler is None or compiler.get("angle", "degree") != "radian"
    world = root.find("worldbody")
    if world is None:
        raise SpecError(source, "no <worldbody>")
    if _merge_defaults(root) > 1:
        notes.append("the top-level <default> elements were merged into one (as MuJoCo reads them)")
    _eulers_to_quats(root, degrees, source)
    defaults = _Defaults(root)
    defaults.materialize(world)
    if _flatten_frames(world, degrees, source):
        notes.append("the <frame> elements' poses were composed into their children's")
    used = {str(el.get("name")) for el in root.iter() if isinstance(el.tag, str) and el.get("name")} | {_WORLD}
    derived = []
    for body in world.iter("body"):
        if not body.get("name"):
            parent = body.getparent()
            body.set("name", _fresh(f"{parent.get('name') if parent.tag == 'body' else _WORLD}_child", used))
            derived.append(f"body {body.get('name')}")

    body_joints: dict[str, list[str]] = {}  # a composite's first joint -> the names of all its parts
    limits: dict[str, tuple[float, float]] = {}
    kinds: dict[str, str] = {}
    refs: dict[str, float] = {}
    for body in world.iter("body"):
        joints = [j for j in body if j.tag in ("joint", "freejoint")]
        names = []
        for j in joints:
            kind = "free" if j.tag == "freejoint" else defaults.get(j, "type", "hinge")
            if kind not in _JOINT_TYPES:
                raise SpecError(source, f"joint {j.get('name')!r}: type {kind!r} is not one of {list(_JOINT_TYPES)}")
            if not j.get("name"):
                j.set("name", _fresh(f"{body.get('name')}_{kind}", used))
                derived.append(f"{kind} joint {j.get('name')}")
            name = str(j.get("name"))
            names.append(name)
            kinds[name] = kind
            if kind in ("hinge", "slide"):
                ref = _floats(defaults.get(j, "ref", "0"), 1, f"joint {name!r} ref", source)[0]
                refs[name] = float(np.deg2rad(ref)) if kind == "hinge" and degrees else float(ref)
            rng, limited = defaults.get(j, "range"), defaults.get(j, "limited", "auto")
            if kind in ("hinge", "slide") and rng is not None and limited != "false":
                lo, hi = _floats(rng, 2, f"joint {name!r} range", source)
                limits[name] = tuple(np.deg2rad([lo, hi])) if kind == "hinge" and degrees else (lo, hi)
        if names:
            body_joints[names[0]] = names
    if derived:
        notes.append(f"names derived for what the file leaves unnamed: {', '.join(derived)}")
    stray = next((j for j in world.iter("joint", "freejoint") if j.getparent().tag != "body"), None)
    if stray is not None:  # (MuJoCo refuses it too: a joint moves the body it is in)
        raise SpecError(source, f"<{stray.tag}> (line {stray.sourceline}) is in <{stray.getparent().tag}>, not in a "
                                "<body>: a joint moves the body it is in")
    keys = _keyframes(root, world, kinds, source)
    key_name, key_qpos = _key_chosen(keys, limits, notes)

    equalities = []
    for el in [el for el in root.findall("equality/*") if isinstance(el.tag, str)]:
        if el.get("active", "true") == "false":
            notes.append(f"the inactive equality <{el.tag} name={el.get('name')!r}> is left out")
            el.getparent().remove(el)
        elif el.tag not in ("connect", "weld", "joint"):
            raise SpecError(source, f"<equality><{el.tag}> is not a constraint pkm reads (connect, weld and joint are)")
        else:
            equalities.append(el)
    couplings = _joint_equalities([el for el in equalities if el.tag == "joint"], kinds, refs, notes, source)
    equalities = [el for el in equalities if el.tag != "joint"]
    on_sites = []
    for el in equalities:
        sites = (el.get("site1"), el.get("site2"))
        if any(sites) and not all(sites):
            raise SpecError(source, f"<equality><{el.tag} name={el.get('name')!r}>: give both site1 and site2, or "
                                    "body1 (optional body2)")
        if not any(sites) and not el.get("body1"):
            raise SpecError(source, f"<equality><{el.tag} name={el.get('name')!r}>: no body1 and no sites")
        if all(sites):  # Pinocchio 4.1 crashes on site-based equalities: pkm closes them itself, on the sites
            on_sites.append(el)
            el.getparent().remove(el)
    counts = {"connect": 0, "weld": 0}
    eq_names = []
    bodies = [str(b.get("name")) for b in world.iter("body") if b.get("name")]
    for el in equalities:
        counts[el.tag] += 1
        eq_name = el.get("name") or f"{el.tag}{counts[el.tag]}"
        for key in ("body1", "body2"):
            if el.get(key) not in (None, "world", *bodies):
                raise SpecNameError(source, "body", str(el.get(key)), bodies,
                                    f"<equality><{el.tag} name={eq_name!r}> (line {el.sourceline}) {key}")
        point = el.tag == "connect" or _torquescale(el, eq_name, defaults, source) == 0.0
        eq_names.append((el.tag, eq_name, (el.get("site1"), el.get("site2")) if el in on_sites else None,
                         "point" if point else "frame", el.sourceline))
    body_based = {t: counts[t] - sum(1 for el in on_sites if el.tag == t) for t in counts}
    for k, el in enumerate(el for el in equalities if el not in on_sites):  # Pinocchio returns them by name
        el.set("name", f"pkm{k:06d}")
    unread = [el.tag for el in root if isinstance(el.tag, str) and el.tag in _UNREAD
              and not (el.tag == "keyframe" and key_qpos)]  # (the keys not read: noted by _key_chosen)
    for el in root.findall("keyframe"):  # (Pinocchio checks their sizes; pkm reads the reference key itself)
        root.remove(el)
    if unread:
        notes.append(f"{', '.join(f'<{t}>' for t in dict.fromkeys(unread))} not read (kinematics and dynamics need "
                     "none of it)")

    collisions = _geoms(root, world, defaults, degrees, notes, source)
    # Pinocchio reads one body under <worldbody>: wrap everything in one fixed body at the origin
    wrapper = etree.Element("body", name=_WORLD)
    for child in list(world):
        wrapper.append(child)
    world.append(wrapper)
    with tempfile.TemporaryDirectory(prefix="pkm-mjcf-") as tmp:
        path = os.path.join(tmp, "model.xml")
        with open(path, "wb") as fh:
            fh.write(etree.tostring(root))
        try:
            model, points, welds = pin.buildModelAndConstraintsFromMJCF(path)
        except Exception as exc:  # Pinocchio's own exception types must not leak
            raise SpecError(source, f"Pinocchio rejects the MJCF: {exc}") from None
    if len(points) != body_based["connect"] or len(welds) != body_based["weld"]:
        raise SpecError(source, f"Pinocchio read {len(points)} connect and {len(welds)} weld constraints, the file "
                                f"states {body_based['connect']} and {body_based['weld']} between bodies")

    free = _free_bodies(model, world, degrees, source)
    points = _connects(model, free, refs, [(el, eq[1]) for el, eq in zip(equalities, eq_names)
                                           if el.tag == "connect" and el not in on_sites], defaults, source)
    welds = _welds(model, free, refs, [(el, eq[1]) for el, eq in zip(equalities, eq_names)
                                       if el.tag == "weld" and el not in on_sites], defaults, source)
    taken = set(model.names) | {f.name for f in model.frames}
    extra: list[tuple[str, int, pin.SE3]] = []
    site_els = {str(site.get("name")): site for site in world.iter("site") if site.get("name")}

    def site_placement(site: etree._Element) -> tuple[int, pin.SE3] | None:
        """A site's joint and placement in it: Pinocchio's frame of the site, else from its body (None: a site of
        a body Pinocchio does not have)."""
        name = str(site.get("name"))
        if model.existFrame(name, pin.FrameType.OP_FRAME):
            f = model.frames[model.getFrameId(name, pin.FrameType.OP_FRAME)]
            return f.parentJoint, f.placement
        body = site.getparent().get("name")
        if not model.existFrame(body, pin.FrameType.BODY):
            return None
        bf = model.frames[model.getFrameId(body, pin.FrameType.BODY)]
        pos = _floats(defaults.get(site, "pos", "0 0 0"), 3, f"site {name!r} pos", source)
        return bf.parentJoint, bf.placement * pin.SE3(_rotation(site, degrees, source), pos)

    for sname, site in site_els.items():  # the sites Pinocchio dropped (those of bodies without joints)
        if sname not in taken and (at := site_placement(site)) is not None:
            extra.append((sname, *at))
            taken.add(sname)
    aliases: dict[str, str] = {}

    def site_frame(sname: str) -> str:
        """The frame a closure on site ``sname`` names: the site's own, else (its name shared by a body or a joint,
        as MJCF allows, where a lookup by name would find those) a frame of a fresh name at the site."""
        if sname in aliases:
            return aliases[sname]
        same = [f for f in model.frames if f.name == sname]
        if [f.type for f in same] in ([pin.FrameType.OP_FRAME], []) and not model.existJointName(sname):
            return sname
        at = site_placement(site_els[sname])
        assert at is not None  # (a site in taken: its body is in the model)
        aliases[sname] = _fresh(f"{sname}_site", taken)
        extra.append((aliases[sname], *at))
        return aliases[sname]

    closures = []
    iters = {"connect": iter(points), "weld": iter(welds)}
    site_names = sorted(n for n in site_els if n in taken)
    for tag, name, on, kind, line in eq_names:
        if on is not None:  # the two sites coincide (connect: their origins; weld: their frames)
            for key, site_name in zip(("site1", "site2"), on):
                if site_name not in taken:
                    raise SpecNameError(source, "site", str(site_name), site_names,
                                        f"<equality><{tag} name={name!r}> (line {line}) {key}")
            closures.append(Closure(name, kind, *(site_frame(str(s)) for s in on)))
            continue
        cm = next(iters[tag])
        frames = []
        for end, jid, M in (("a", cm.joint1_id, cm.joint1_placement), ("b", cm.joint2_id, cm.joint2_placement)):
            fname = f"{name}_{end}"
            while fname in taken:
                fname += "_"
            taken.add(fname)
            extra.append((fname, jid, M))
            frames.append(fname)
        closures.append(Closure(name, kind, *frames))

    if aliases:
        notes.append(f"sites whose names a body or a joint shares are closed on frames of their own: "
                     f"{', '.join(f'{s} -> {a}' for s, a in aliases.items())}")
    joint_names = {f"Composite_{first}": parts for first, parts in body_joints.items() if len(parts) > 1}
    name = root.get("model", "mjcf")
    locked = {j: v for j in kinds if (v := couplings.value(j)) is not None}
    kwargs = dict(name=name, joint_names=joint_names, frames=extra, skip_frames=(_WORLD,), locked=locked,
                  source=source)
    if couplings.of:  # the leaders: first in Pinocchio's traversal of the URDF (which a mimic needs)
        plain, _ = urdf_from_model(model, limits=limits, **kwargs)
        order = {n: k for k, n in enumerate(pin.buildModelFromXML(plain).names)}
        couplings.lead(order)
    drives, motors = _actuated(root, defaults, kinds, couplings, notes, source)
    actuated = [d.joint for d in drives]
    motor_map(list(dict.fromkeys(actuated)), motors, source)  # (a differential of as many motors as joints)
    actuators = _drives(drives, defaults, world, notes, source)
    mimic = couplings.followers()
    for j, (lead, m, c) in mimic.items():  # a follower's range bounds its leader; Pinocchio gives a mimic none
        if j in limits:
            lo, hi = sorted(((limits[j][0] - c) / m, (limits[j][1] - c) / m))
            own = limits.get(lead, (-np.inf, np.inf))
            limits[lead] = (max(lo, own[0]), min(hi, own[1]))
            del limits[j]
    for j in locked:
        limits.pop(j, None)
    urdf, types = urdf_from_model(model, limits=limits, mimic=mimic, collisions=collisions, **kwargs)
    reference = {model.names[j]: tuple(map(float, pin.SE3ToXYZQUAT(X))) for j, X in free.items()}
    dependent = set(mimic) | set(locked)
    continuous = {str(j.get("name")) for j in etree.fromstring(urdf.encode()).iter("joint")
                  if j.get("type") == "continuous"}
    keyed = _pinocchio_values(key_qpos, kinds, dependent, continuous)
    seed = {} if keyed else {j: _value(v, j in continuous) for j, v in refs.items() if v != 0.0 and j not in dependent}
    hold: tuple[str, ...] = ()
    base = _floating_base(model)
    if keyed and key_name == _KEY:
        reference = keyed
        notes.append(f"the reference configuration is the <keyframe><key name={_KEY!r}> (the one pkm writes)")
    elif keyed:  # another key (Menagerie's "home"): its free bodies and motors held, the passive joints closed from it
        reference = {j: keyed[j] for j in keyed if j == base}  # (the others held where the loops allow: redundant
        hold = tuple(j for j in keyed if j != base and (kinds[j] == "free" or j in actuated))  # motors may disagree)
        seed = {j: v for j, v in keyed.items() if j != base}
        notes.append(f"the reference configuration is the <keyframe><key name={key_name!r}>, the first key inside "
                     "every joint limit, its loops closed by moving the joints no actuator drives (its free bodies "
                     "and actuated joints held)")
    elif seed:
        notes.append(f"assembled from the joints' ref (MuJoCo's qpos0, where the file's poses hold): "
                     f"{', '.join(seed)}")
    direct = [d.joint for d in drives if d.motor is None]
    if len(set(direct)) < len(direct):
        notes.append("several actuators drive the same joint: it is one input")
    springs = _springs(world, defaults, kinds, set(actuated), dependent, degrees, notes, source)
    return Imported(urdf, tuple(closures), types, tuple(dict.fromkeys(actuated)), name, "mjcf", base,
                    reference, tuple(notes), actuators, seed, springs, motors, hold)


_GEOM_SKIPPED = ("plane", "hfield", "sdf")  # geom types that bound no body (a floor, a terrain) or pkm cannot read


def _geoms(root: etree._Element, world: etree._Element, defaults: _Defaults, degrees: bool, notes: list[str],
           source: str) -> dict[str, list[etree._Element]]:
    """The collision geometry of the bodies, ``{body: [URDF <collision> element]}`` (the geoms directly in
    ``<worldbody>`` under :data:`_WORLD`), placed in the body's frame: a geom's ``pos`` and orientation, or its
    ``fromto`` (the axis from one point to the other); sizes from MuJoCo's half-sizes (a box's ``size`` its
    half-extents, a capsule's and a cylinder's its radius and half-length), a mesh its ``<asset><mesh>``'s file
    (``<compiler meshdir>``, relative to the file's folder) and ``scale``. Geoms with ``contype`` and ``conaffinity``
    both 0 never collide in MuJoCo: left out (a note), unless every geom of the file is so (the file turns contacts
    off for its simulation: its geoms are still its bodies' shapes, read so, a note says). The others' ``contype`` and
    ``conaffinity`` (other than 1) are written on their ``<collision>`` (pkm's attributes): the geometry checks a pair
    of shapes only where MuJoCo would collide them (:mod:`pkm.core.collision.geometry`). Planes, height fields and
    SDF geoms are left out (a note)."""
    geoms = [g for g in world.iter("geom") if g.getparent().tag in ("body", "worldbody")]
    if not geoms:
        return {}
    masks = {g: tuple(int(_floats(defaults.get(g, key, "1"), 1, f"<geom> {key}", source)[0])
                      for key in ("contype", "conaffinity")) for g in geoms}
    off = [g for g in geoms if masks[g] == (0, 0)]
    filtered = len(off) < len(geoms)  # (all off: the shapes read without MuJoCo's filter)
    if off and len(off) == len(geoms):
        notes.append("every geom has contype and conaffinity 0 (contacts off in MuJoCo): their shapes are read as "
                     "the bodies' collision geometry")
        off = []
    elif off:
        notes.append(f"{len(off)} geoms with contype and conaffinity 0 (never colliding in MuJoCo) are not "
                     "collision geometry")
    compiler = root.find("compiler")
    folder = Path(source).parent if Path(source).is_file() else None
    meshdir = (compiler.get("meshdir") or compiler.get("assetdir") or "") if compiler is not None else ""
    meshes = {str(m.get("name") or Path(str(m.get("file", ""))).stem): m for m in root.findall("asset/mesh")}
    out: dict[str, list[etree._Element]] = {}
    skipped: dict[str, int] = {}
    for g in geoms:
        if g in off:
            continue
        kind = defaults.get(g, "type", "sphere") or "sphere"
        what = f"<geom name={g.get('name')!r}> (line {g.sourceline})"
        size = [float(v) for v in (defaults.get(g, "size", "") or "").split()]
        fromto = defaults.get(g, "fromto")
        if kind in _GEOM_SKIPPED or kind not in ("sphere", "capsule", "cylinder", "box", "ellipsoid", "mesh"):
            skipped[kind] = skipped.get(kind, 0) + 1
            continue
        if fromto is not None and kind in ("capsule", "cylinder", "box", "ellipsoid"):
            a, b = _floats(fromto, 6, f"{what} fromto", source).reshape(2, 3)
            axis = b - a
            half = float(np.linalg.norm(axis)) / 2.0
            if half <= 0.0:
                raise SpecError(source, f"{what}: fromto gives two equal points")
            M = pin.SE3(pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), axis / (2 * half)).matrix(),
                        (a + b) / 2.0)
            size = size[:1] + ([size[0]] if kind in ("box", "ellipsoid") else []) + [half]
        else:
            M = pin.SE3(_rotation(g, degrees, source), _floats(defaults.get(g, "pos", "0 0 0"), 3, f"{what} pos",
                                                               source))
        need = {"sphere": 1, "capsule": 2, "cylinder": 2, "box": 3, "ellipsoid": 3, "mesh": 0}[kind]
        if len(size) < need or not all(v > 0.0 for v in size[:need]):
            raise SpecError(source, f"{what}: a {kind} needs {need} positive size values, got {size}")
        col = etree.Element("collision", name=str(g.get("name") or f"geom_{g.sourceline}"))
        if filtered and masks[g] != (1, 1):  # (pkm's attributes: MuJoCo's filter of the pairs, read by the geometry)
            col.set("contype", str(masks[g][0]))
            col.set("conaffinity", str(masks[g][1]))
        etree.SubElement(col, "origin", xyz=num(M.translation), rpy=num(pin.rpy.matrixToRpy(M.rotation)))
        geometry = etree.SubElement(col, "geometry")
        if kind == "sphere":
            etree.SubElement(geometry, "sphere", radius=repr(size[0]))
        elif kind in ("capsule", "cylinder"):
            etree.SubElement(geometry, kind, radius=repr(size[0]), length=repr(2.0 * size[1]))
        elif kind == "box":
            etree.SubElement(geometry, "box", size=num(2.0 * np.array(size[:3])))
        elif kind == "ellipsoid":
            etree.SubElement(geometry, "ellipsoid", radii=num(size[:3]))
        else:
            asset = meshes.get(str(g.get("mesh")))
            if asset is None or not asset.get("file"):
                raise SpecNameError(source, "mesh", str(g.get("mesh")), sorted(meshes), f"{what} mesh")
            path = Path(meshdir) / str(asset.get("file"))
            if folder is not None and not path.is_absolute():
                path = folder / path
            etree.SubElement(geometry, "mesh", filename=str(path), scale=asset.get("scale", "1 1 1"))
        parent = g.getparent()
        out.setdefault(_WORLD if parent.tag == "worldbody" else str(parent.get("name")), []).append(col)
    if skipped:
        notes.append("geoms not read as collision geometry: "
                     + ", ".join(f"{n} {kind}{'s' if n > 1 else ''}" for kind, n in skipped.items()))
    return out


#: The ``<keyframe><key>`` read as the reference configuration (:func:`pkm.save` writes it).
_KEY = "reference"
_QPOS = {"free": 7, "ball": 4, "hinge": 1, "slide": 1}  # MuJoCo's qpos width of each joint type


def _value(angle: float, continuous: bool) -> tuple[float, ...]:
    """A one-coordinate joint's value in Pinocchio's coordinates (an unbounded revolute's: cos, sin)."""
    return (float(np.cos(angle)), float(np.sin(angle))) if continuous else (float(angle),)


def _keyframes(root: etree._Element, world: etree._Element, kinds: dict[str, str],
               source: str) -> list[tuple[str, dict[str, list[float]]]]:
    """``[(name, {joint: its qpos})]`` of the ``<keyframe><key>`` elements that state a ``qpos`` (MuJoCo's order: the
    joints as the file nests them), in file order; an unnamed key is named ``key <k>`` (its rank).

    Raises:
        SpecError: a ``qpos`` of the wrong length, or not numbers (naming the key's line).
    """
    joints = [str(j.get("name")) for j in world.iter("joint", "freejoint")]
    width = sum(_QPOS[kinds[j]] for j in joints)
    out = []
    for rank, key in enumerate(root.findall("keyframe/key"), 1):
        if key.get("qpos") is None:
            continue
        name = key.get("name") or f"key {rank}"
        qpos = _floats(key.get("qpos"), width, f"<keyframe><key name={name!r}> (line {key.sourceline}) qpos", source)
        values, k = {}, 0
        for j in joints:
            values[j] = [float(x) for x in qpos[k:k + _QPOS[kinds[j]]]]
            k += _QPOS[kinds[j]]
        out.append((name, values))
    return out


def _key_chosen(keys: list[tuple[str, dict[str, list[float]]]], limits: dict[str, tuple[float, float]],
                notes: list[str]) -> tuple[str | None, dict[str, list[float]]]:
    """The key the reference comes from: ``reference`` (pkm's, whatever its values), else the first key whose hinges
    and slides lie inside their ranges (Menagerie's ``home``), else none; notes name the keys passed over (those
    outside a range, with the joints) and those not read."""
    chosen = next((k for k, (name, _) in enumerate(keys) if name == _KEY), None)
    chosen_by_name = chosen is not None
    skipped: list[str] = []
    for k, (name, values) in enumerate(keys if chosen is None else ()):
        outside = [j for j, (lo, hi) in limits.items() if j in values and not lo - 1e-9 <= values[j][0] <= hi + 1e-9]
        if not outside:
            chosen = k
            break
        skipped.append(f"{name!r} ({', '.join(outside)})")
    if skipped:
        notes.append(f"keys outside the joint limits not taken for the reference: {'; '.join(skipped)}")
    unread = [name for k, (name, _) in enumerate(keys) if chosen is not None and k != chosen
              and (chosen_by_name or k > chosen)]
    if unread:
        notes.append(f"keys not read (the reference is one key): {', '.join(map(repr, unread))}")
    return (None, {}) if chosen is None else keys[chosen]


def _pinocchio_values(qpos: dict[str, list[float]], kinds: dict[str, str], dependent: set[str],
                      continuous: set[str]) -> dict[str, tuple[float, ...]]:
    """MuJoCo's ``{joint: qpos}`` in Pinocchio's coordinates (``[reference]``), the dependent (mimic, locked) joints
    left out: a free body's position and quaternion ``w x y z`` as ``x y z qx qy qz qw``, a ball's quaternion as
    ``qx qy qz qw``, an unbounded hinge's angle as its cosine and sine."""
    out: dict[str, tuple[float, ...]] = {}
    for j, seg in qpos.items():
        if j in dependent:
            continue
        if kinds[j] == "free":
            out[j] = (*seg[:3], *seg[4:], seg[3])
        elif kinds[j] == "ball":
            out[j] = (*seg[1:], seg[0])
        else:
            out[j] = _value(seg[0], j in continuous)
    return out


def _joint_equalities(els: list[etree._Element], kinds: dict[str, str], refs: dict[str, float], notes: list[str],
                      source: str) -> _Couplings:
    """The ``<equality><joint>`` elements as couplings (linear: mimic joints; no ``joint2``: locked joints), in
    ``qpos`` (the polynomial is MuJoCo's, about the joints' ``ref``); taken out of Pinocchio's copy."""
    couplings = _Couplings(source)
    for k, el in enumerate(els, 1):
        name = el.get("name")  # (an unnamed one by its rank: "joint1" may name a joint of the file, as xArm7's)
        where = f"<equality><joint name={name!r}>" if name else f"<equality><joint> {k} (unnamed)"
        j1, j2 = el.get("joint1"), el.get("joint2")
        if not j1:
            raise SpecError(source, f"{where}: no joint1")
        for j in (j1, j2):
            if j is not None and j not in kinds:
                raise SpecNameError(source, "joint", j, list(kinds), where)
            if j is not None and kinds[j] not in ("hinge", "slide"):
                raise SpecError(source, f"{where}: joint {j!r} is a {kinds[j]} joint (MuJoCo couples hinges and "
                                        "slides only)")
        a = _floats(el.get("polycoef", "0 1 0 0 0"), 5, f"{where} polycoef", source)
        if j2 is not None and np.any(a[2:] != 0.0):
            raise SpecError(source, f"{where}: polycoef {el.get('polycoef')!r} makes {j1} a polynomial of degree "
                                    f"{int(np.flatnonzero(a)[-1])} in {j2}; pkm represents only the linear coupling "
                                    "(a2 = a3 = a4 = 0), a mimic joint")
        if j2 is None or a[1] == 0.0:
            couplings.lock(where, j1, refs[j1] + a[0])
            notes.append(f"{where} read as joint {j1} locked at {refs[j1] + a[0]:.6g}")
        else:
            c = a[0] + refs[j1] - a[1] * refs[j2]
            couplings.tie(where, j1, j2, float(a[1]), float(c))
            notes.append(f"{where} read as a mimic coupling: {j1} = {a[1]:.6g} {j2} + {c:.6g}")
        el.getparent().remove(el)
    return couplings


def _tendons(root: etree._Element, source: str) -> dict[str, list[tuple[str, float]] | None]:
    """``{tendon: [(joint, coef)...]}`` for the fixed tendons, ``None`` for the spatial ones."""
    out: dict[str, list[tuple[str, float]] | None] = {}
    for t in root.findall("tendon/*"):
        if isinstance(t.tag, str) and t.get("name"):
            out[t.get("name")] = None if t.tag != "fixed" else [
                (str(j.get("joint")), _floats(j.get("coef", "1"), 1, f"tendon {t.get('name')!r} coef", source)[0])
                for j in t if j.tag == "joint"]
    return out


class _Drive(NamedTuple):
    """An ``<actuator>`` element on an independent joint (a differential's: one per joint it moves)."""

    joint: str  # the independent joint it drives
    factor: float  # the effort on ``joint`` per unit of the transmission's effort (a mimic's scale, a tendon's coef)
    el: etree._Element
    label: str
    motor: str | None = None  # the differential's motor (``[motors]``) it is a part of, else None


def _actuated(root: etree._Element, defaults: _Defaults, kinds: dict[str, str], couplings: _Couplings,
              notes: list[str], source: str) -> tuple[list[_Drive], dict[str, dict[str, float]]]:
    """The ``<actuator>`` elements that drive independent joints, in file order (see the module doc), and the motors
    of the differentials (``{motor: {joint: coefficient}}``, :mod:`pkm.core.model.motors`)."""
    tendons = _tendons(root, source)
    driven = {el.get("tendon") for el in root.findall("actuator/*") if isinstance(el.tag, str)}
    if set(tendons) - driven:
        notes.append(f"tendons no actuator drives ({', '.join(sorted(set(tendons) - driven))}) not read")
    out: list[_Drive] = []
    motors: dict[str, dict[str, float]] = {}
    used = set(kinds)
    for k, el in enumerate(root.findall("actuator/*"), 1):
        if not isinstance(el.tag, str):
            continue
        label = f"<{el.tag} name={el.get('name')!r}>" if el.get("name") else f"actuator {k} (<{el.tag}>)"
        if el.tag not in _ACTUATORS:
            notes.append(f"{label} is not an actuator pkm reads: left out")
            continue
        joint, tendon = el.get("joint") or el.get("jointinparent"), el.get("tendon")
        if joint:
            if joint not in kinds:
                raise SpecNameError(source, "joint", joint, list(kinds), f"{label}, an actuator")
            if couplings.value(joint) is not None:
                raise SpecError(source, f"{label} drives joint {joint!r}, which an <equality><joint> locks")
            a = couplings.get(joint)
            if a.root != joint:
                notes.append(f"{label} drives {joint} = {a.scale:.6g} {a.root} + {a.offset:.6g}: read as actuated "
                             f"joint {a.root}")
            out.append(_Drive(a.root, a.scale, el, label))
        elif tendon:
            moving = _tendon_joints(label, tendon, tendons, kinds, couplings, notes, source)
            if len(moving) == 1:
                out.append(_Drive(*next(iter(moving.items())), el, label))
                continue
            gear = _gear(el, defaults, label, source)
            motor = _fresh(el.get("name") or tendon, used)
            motors[motor] = {j: gear * f for j, f in moving.items()}
            out += [_Drive(j, f, el, label, motor) for j, f in moving.items()]
            notes.append(f"{label} on tendon {tendon!r} read as motor {motor!r} of a differential, its coordinate "
                         + linear_text(motors[motor].items()) + " (gear included; [motors]: its effort f acts on the joints as coef * f; its force range "
                           "bounds the motor, not read as a joint's effort limit)")
        else:
            target = next((f"{key} {el.get(key)!r}" for key in ("site", "body", "refsite") if el.get(key)), "nothing")
            notes.append(f"{label} acts on {target}, not on a joint coordinate: left out")
    differential = {j for coefs in motors.values() for j in coefs}
    both = sorted({d.joint for d in out if d.motor is None} & differential)
    if both:
        raise SpecError(source, f"joint {both[0]!r} is driven both by an actuator of its own and through a "
                                "differential's tendon: pkm reads a differential's joints as driven by its motors only")
    return out, motors


def _gear(el: etree._Element, defaults: _Defaults, label: str, source: str) -> float:
    """An actuator's (first) ``gear``, MuJoCo's default 1."""
    return float(floats(((defaults.get(el, "gear") or "").split() or ["1"])[0], 1, f"{label} gear", source,
                        np.inf)[0])


def _tendon_joints(label: str, tendon: str, tendons: dict[str, list[tuple[str, float]] | None],
                   kinds: dict[str, str], couplings: _Couplings, notes: list[str], source: str) -> dict[str, float]:
    """The independent joints a fixed tendon's length is an affine function of, once the mimic couplings are
    substituted, with the length's rate per unit of each joint's (one joint: a note says so)."""
    if tendon not in tendons:
        raise SpecNameError(source, "tendon", tendon, list(tendons), label)
    parts = tendons[tendon]
    if parts is None:
        raise SpecError(source, f"{label} acts on the spatial tendon {tendon!r}: its length is not a joint "
                                "coordinate (pkm reads actuators on joints and on fixed tendons)")
    factors: dict[str, float] = {}
    for j, coef in parts:
        if j not in kinds:
            raise SpecNameError(source, "joint", j, list(kinds), f"tendon {tendon!r}")
        if couplings.value(j) is None:
            a = couplings.get(j)
            factors[a.root] = factors.get(a.root, 0.0) + coef * a.scale
    moving = {j: f for j, f in factors.items() if abs(f) > _SMALL}
    text = linear_text(parts)
    if not moving:
        raise SpecError(source, f"{label} acts on tendon {tendon!r} ({text}), whose length no joint moves")
    if len(moving) == 1:
        (joint, factor), = moving.items()
        notes.append(f"tendon {tendon!r} ({text}) of {label} read as actuated joint {joint} (length = {factor:.6g} "
                     f"{joint} + constant)")
    return moving


_DRIVE_KEYS = (("armature", "armature"), ("damping", "viscous"), ("frictionloss", "coulomb"))  # MJCF -> Actuator
_SERVOS = ("position", "velocity", "intvelocity", "damper")  # actuators whose gains make the force of a target


def _range(el: etree._Element, defaults: _Defaults, key: str, what: str, source: str) -> tuple[float, float] | None:
    """A ``forcerange``, ``ctrlrange`` or ``actuatorfrcrange`` when it limits (MuJoCo: ``<...>limited="true"``, or
    ``"auto"`` and the range's lower bound below its upper), else None."""
    text = defaults.get(el, key)
    limited = defaults.get(el, key.replace("range", "limited"), "auto")
    lo, hi = floats(text, 2, what, source, bound=np.inf) if text is not None else (0.0, 0.0)
    if limited == "true" and not lo < hi:
        stated = repr(text) if text is not None else "not given"
        raise SpecError(source, f"{what} {stated}: a limited range needs lower < upper (MuJoCo refuses it)")
    return (lo, hi) if limited != "false" and lo < hi else None


def _magnitude(bounds: tuple[float, float], what: str, notes: list[str]) -> float:
    """The symmetric limit pkm reads from ``(lower, upper)``: the smaller magnitude (a one-sided range: the larger),
    ``inf`` from ``UNLIMITED`` on; a note says when the range is not symmetric."""
    lo, hi = bounds
    small, large = sorted((abs(lo), abs(hi)))
    if small == 0.0:
        notes.append(f"{what} [{lo:g}, {hi:g}] is one-sided: read as the symmetric limit {large:g}")
        small = large
    elif lo != -hi:
        notes.append(f"{what} [{lo:g}, {hi:g}] is not symmetric: read as the smaller magnitude, {small:g}")
    return np.inf if small >= UNLIMITED else small


def _drives(drives: list[_Drive], defaults: _Defaults, world: etree._Element, notes: list[str],
            source: str) -> dict[str, dict[str, float]]:
    """``{joint: {field: value}}`` (:mod:`pkm.core.model.actuators`) of the driven joints, the values the file
    states only: the joint's ``armature``, ``damping``, ``frictionloss``, and the effort limit of its actuators
    (see the module doc).

    Raises:
        SpecError: a value that is not a number, a negative one, a limited range with lower >= upper, a gear of 0.
    """
    elements = {str(j.get("name")): j for j in world.iter("joint", "freejoint")}
    efforts: dict[str, float] = {}
    for d in drives:
        gear = _gear(d.el, defaults, d.label, source)
        scale = abs(gear * d.factor)
        if scale == 0.0:
            raise SpecError(source, f"{d.label} on joint {d.joint!r}: gear 0 transmits no effort")
        if d.motor is not None:  # (a differential's motor: its force range bounds the motor, not one joint)
            efforts[d.joint] = np.inf
            continue
        limit = np.inf
        force = _range(d.el, defaults, "forcerange", f"{d.label} forcerange", source)
        if force is not None:
            limit = _magnitude(force, f"{d.label} forcerange", notes)
        ctrl = _range(d.el, defaults, "ctrlrange", f"{d.label} ctrlrange", source) if d.el.tag == "motor" else None
        if ctrl is not None and (m := _magnitude(ctrl, f"{d.label} ctrlrange", notes)) < limit:
            limit = m
            notes.append(f"{d.label}: a motor's force is its control: its ctrlrange bounds joint {d.joint}'s effort")
        if scale != 1.0 and np.isfinite(limit):
            by = f"gear {gear:g}" + (f" x coupling {d.factor:g}" if d.factor != 1.0 else "")
            notes.append(f"{d.label}: force limit {limit:g} x {by} read as joint {d.joint}'s effort limit "
                         f"{limit * scale:g}")
        efforts[d.joint] = efforts.get(d.joint, 0.0) + limit * scale  # several actuators on one joint: they add
    servos = [d.label for d in drives if d.el.tag in _SERVOS]
    if servos:
        notes.append(f"the gains of {', '.join(servos)} are not read: pkm's input is the joint effort (their force "
                     "range bounds it)")
    out: dict[str, dict[str, float]] = {}
    for joint, effort in efforts.items():
        el, values = elements[joint], {}
        for key, field in _DRIVE_KEYS:
            value = floats(defaults.get(el, key, "0"), 1, f"joint {joint!r} {key}", source, np.inf)[0]
            if value != 0.0:
                values[field] = value
        own = _range(el, defaults, "actuatorfrcrange", f"joint {joint!r} actuatorfrcrange", source)
        if own is not None:
            effort = min(effort, _magnitude(own, f"joint {joint!r} actuatorfrcrange", notes))
        if np.isfinite(effort):
            values["effort_limit"] = float(effort)
        try:
            Actuator(joint, **values)
        except InvalidInputError as exc:
            raise SpecError(source, f"joint {joint!r}: {exc}") from None
        if values:
            out[joint] = values
    passive = [n for n, el in elements.items() if n not in efforts
               and any((defaults.get(el, key) or "0").strip() not in ("0", "0.0") for key in ("armature", "frictionloss"))]
    if passive:
        notes.append(f"armature and frictionloss of joints no actuator drives are not read (their damping is a "
                     f"[springs] entry): {', '.join(passive)}")
    return out


def _springs(world: etree._Element, defaults: _Defaults, kinds: dict[str, str], actuated: set[str],
             dependent: set[str], degrees: bool, notes: list[str], source: str) -> dict[str, dict[str, float]]:
    """``{joint: {"stiffness", "rest", "damping": value}}`` (:mod:`pkm.core.model.springs`) of the hinges and slides
    whose ``stiffness`` or (for a joint no actuator drives: a driven joint's damping is its drive's) ``damping`` is not
    zero: ``rest`` is MuJoCo's ``springref`` (in degrees for a hinge unless ``<compiler angle="radian">``, as ``ref``).
    A note names them; the springs of ball joints and of joints an
    ``<equality><joint>`` ties are not read (a note)."""
    out: dict[str, dict[str, float]] = {}
    unread = []
    for el in world.iter("joint"):
        name = str(el.get("name"))
        stiffness, damping, rest = (floats(defaults.get(el, key, "0"), 1, f"joint {name!r} {key}", source, np.inf)[0]
                                    for key in ("stiffness", "damping", "springref"))
        if name in actuated:
            damping = 0.0
        if stiffness == 0.0 and damping == 0.0:
            continue
        if kinds[name] not in ("hinge", "slide") or name in dependent:
            unread.append(name)
            continue
        values = {"stiffness": stiffness, "rest": float(np.deg2rad(rest)) if kinds[name] == "hinge" and degrees
                  else rest} if stiffness != 0.0 else {}
        if damping != 0.0:
            values["damping"] = damping
        out[name] = values
    if out:
        notes.append(f"joint springs and dampers read into [springs] (applied by pkm's dynamics): "
                     f"{describe(parse_springs(out, source))}")
    if unread:
        notes.append(f"the stiffness and damping of ball joints and of joints an <equality><joint> ties are not "
                     f"read: {', '.join(unread)}")
    return out


def _free_bodies(model: pin.Model, world: etree._Element, degrees: bool, source: str) -> dict[int, pin.SE3]:
    """``{free-flyer joint: the body's pose at qpos0}`` for MuJoCo's free bodies. Pinocchio 4.1 misplaces them
    (the body's pose is applied twice), so their joints are reset to the world origin here (``model`` edited) and
    their pose moves into the reference."""
    out = {}
    for body in world.iter("body"):
        free = [j for j in body if j.tag == "freejoint" or (j.tag == "joint" and j.get("type") == "free")]
        if not free or not model.existJointName(free[0].get("name")):
            continue
        jid = model.getJointId(free[0].get("name"))
        pos = _floats(body.get("pos", "0 0 0"), 3, f"body {body.get('name')!r} pos", source)
        out[jid] = pin.SE3(_rotation(body, degrees, source), pos)
        model.jointPlacements[jid] = pin.SE3.Identity()
    return out


def _qpos0(model: pin.Model, free: dict[int, pin.SE3], refs: dict[str, float]) -> np.ndarray:
    """MuJoCo's ``qpos0`` in Pinocchio's coordinates: free bodies at their poses, hinges and slides at their ``ref``."""
    q0 = pin.neutral(model)
    for jid, X in free.items():
        q0[model.joints[jid].idx_q:model.joints[jid].idx_q + 7] = pin.SE3ToXYZQUAT(X)
    for joint, value in refs.items():
        if model.existJointName(joint) and model.joints[model.getJointId(joint)].nq == 1:
            q0[model.joints[model.getJointId(joint)].idx_q] = value
    return q0


def _torquescale(el: etree._Element, name: str, defaults: _Defaults, source: str) -> float:
    """A weld's ``torquescale`` (MuJoCo's default 1); 0 makes it position-only."""
    where = f"<equality><weld name={name!r}> (line {el.sourceline}) torquescale"
    value = float(_floats(defaults.get(el, "torquescale", "1"), 1, where, source)[0])
    if value < 0.0:
        raise SpecError(source, f"{where} = {value:g}: MuJoCo's scale of the angular residual is >= 0")
    return value


def _welds(model: pin.Model, free: dict[int, pin.SE3], refs: dict[str, float],
           welds: list[tuple[etree._Element, str]], defaults: _Defaults, source: str) -> list[_Anchors]:
    """The two ends of the body-based ``<weld>`` elements (with their names), read from the file as MuJoCo reads
    them (pkm does not rely on Pinocchio 4.1's parser for them: it misplaces free bodies).

    MuJoCo's weld holds ``X1 relpose = X2 T(anchor)``: the frame ``relpose`` (position, then quaternion ``w x y
    z``) of ``body1`` on the point ``anchor`` of ``body2`` (in its frame), their axes aligned with ``body2``'s.
    Without ``relpose`` (its quaternion all zeros, MuJoCo's default) the relative pose is the one at ``qpos0``
    (free bodies where the file puts them, hinges and slides at their ``ref``). With it, a free body at either end
    (body2 first) is moved where the weld puts it (``free`` edited: the reference pkm assembles from holds it);
    MuJoCo would pull it there. ``torquescale = 0`` leaves the
    orientation free: a ``point`` closure (as ``<connect>``), else a ``frame`` one (another scale weights the
    angular residual in MuJoCo's soft solver, the closed configuration is the same).
    """
    q0 = _qpos0(model, free, refs)
    data = model.createData()
    pin.framesForwardKinematics(model, data, q0)
    out, moved = [], set()
    for el, name in welds:
        where = f"<equality><weld name={name!r}> (line {el.sourceline})"
        (j1, P1, X1), (j2, P2, X2) = _ends(model, data, el, where, source)
        anchor = pin.SE3(np.eye(3), _floats(defaults.get(el, "anchor", "0 0 0"), 3, f"{where} anchor", source))
        relpose = _floats(defaults.get(el, "relpose", "0 1 0 0 0 0 0"), 7, f"{where} relpose", source)
        if np.linalg.norm(relpose[3:]) < 1e-15:  # (MuJoCo's mjMINVAL: no relpose, the pose at qpos0)
            rel = X1.actInv(X2 * anchor)
        else:
            w, x, y, z = relpose[3:] / np.linalg.norm(relpose[3:])
            rel = pin.SE3(pin.Quaternion(w, x, y, z).matrix(), relpose[:3])
            for jid, target in ((j2, X1 * rel * anchor.inverse() * P2.inverse()),
                                (j1, X2 * anchor * rel.inverse() * P1.inverse())):
                if jid in free and jid not in moved:  # a free body where the weld puts it (the reference holds it)
                    free[jid] = target
                    moved.add(jid)
                    q0[model.joints[jid].idx_q:model.joints[jid].idx_q + 7] = pin.SE3ToXYZQUAT(target)
                    pin.framesForwardKinematics(model, data, q0)
                    break
        out.append(_Anchors(j1, P1 * rel, j2, P2 * anchor))
    return out


def _ends(model: pin.Model, data: pin.Data, el: etree._Element, where: str, source: str
          ) -> list[tuple[int, pin.SE3, pin.SE3]]:
    """The two bodies of a body-based equality: each its joint, its frame's placement in the joint and its pose at
    the configuration ``data`` holds (the world: joint 0, identity)."""
    ends = []
    for key in ("body1", "body2"):
        body = el.get(key)
        if body in (None, "world", _WORLD):
            ends.append((0, pin.SE3.Identity(), pin.SE3.Identity()))
        elif model.existFrame(body, pin.FrameType.BODY):
            fid = model.getFrameId(body, pin.FrameType.BODY)
            ends.append((model.frames[fid].parentJoint, model.frames[fid].placement, data.oMf[fid]))
        else:
            bodies = [f.name for f in model.frames if f.type == pin.FrameType.BODY and f.name != _WORLD]
            raise SpecNameError(source, "body", str(body), bodies, f"{where} {key}")
    return ends


def _connects(model: pin.Model, free: dict[int, pin.SE3], refs: dict[str, float],
              connects: list[tuple[etree._Element, str]], defaults: _Defaults, source: str) -> list[_Anchors]:
    """The two ends of the body-based ``<connect>`` elements (with their names), read from the file as MuJoCo reads
    them: ``anchor`` in ``body1``'s frame, and the same point at ``qpos0`` (:func:`_qpos0`) in ``body2``'s.
    Pinocchio 4.1's parser puts the anchor in body1's *joint* frame, off by the joint's ``pos`` where the file
    states one (Robotiq 2F-85's followers: 19 mm, the loop then closing elsewhere than MuJoCo's), and misplaces
    free bodies."""
    q0 = _qpos0(model, free, refs)
    data = model.createData()
    pin.framesForwardKinematics(model, data, q0)
    out = []
    for el, name in connects:
        where = f"<equality><connect name={name!r}> (line {el.sourceline})"
        (j1, P1, X1), (j2, P2, X2) = _ends(model, data, el, where, source)
        anchor = pin.SE3(np.eye(3), _floats(defaults.get(el, "anchor", "0 0 0"), 3, f"{where} anchor", source))
        out.append(_Anchors(j1, P1 * anchor, j2, P2 * pin.SE3(np.eye(3), X2.actInv(X1 * anchor).translation)))
    return out


class _Anchors(NamedTuple):
    """The two ends of an equality: each a joint and a placement in its frame (as Pinocchio's constraint models)."""

    joint1_id: int
    joint1_placement: pin.SE3
    joint2_id: int
    joint2_placement: pin.SE3


def _floating_base(model: pin.Model) -> str | None:
    """The root free-flyer joint when every other joint hangs below it (a floating base), else None."""
    if model.njoints < 2 or model.joints[1].shortname() != "JointModelFreeFlyer" or model.parents[1] != 0:
        return None
    return model.names[1] if all(model.parents[j] != 0 for j in range(2, model.njoints)) else None


__all__ = ["read_mjcf"]
