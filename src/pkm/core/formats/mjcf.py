"""MuJoCo's MJCF: a ``<mujoco>`` file whose ``<equality>`` section closes the loops.

Pinocchio parses the tree, the inertias (including those MuJoCo computes from geoms) and the
equality constraints (:func:`pinocchio.buildModelAndConstraintsFromMJCF`); pkm reads what Pinocchio
does not keep, from the file itself:

* ``<connect>`` gives a ``point`` closure and ``<weld>`` a ``frame`` closure, named by the equality's
  ``name`` (else ``connect1``, ``weld2``...); their anchors become frames ``<name>_a`` (on ``body1``)
  and ``<name>_b`` (on ``body2``, the world when it is omitted); an equality between two sites
  (``site1``, ``site2``) closes those sites' frames (origins for a connect, frames for a weld);
* the actuated joints: the ``joint`` of each ``<actuator>`` element (``motor``, ``position``,
  ``general``...), in file order; actuators on tendons or sites are not joint inputs and are skipped;
* joint names and position limits (``range``, in degrees unless ``<compiler angle="radian">``, for
  hinges only; a slide's range is a length), with ``<default>`` classes and ``childclass``; a body with
  several joints keeps each one's name (Pinocchio joins them into one composite joint);
* ``ball`` joints become Pinocchio spherical joints, ``<freejoint>`` a free-flyer: on the root body that
  carries every other joint, the mechanism's floating base (``spec.floating_base``).

What Pinocchio 4.1's parser gets wrong is worked around, each by a test: it reads only the first body
under ``<worldbody>`` (pkm wraps them all in one fixed body), ignores the sites of bodies without
joints (pkm adds them from the file), drops the equalities' names, converts a slide's range as
an angle, and crashes on equalities between sites (pkm takes them out of its copy and closes them itself). Refused with a :class:`~pkm.errors.SpecError`: ``<include>`` (pkm reads one self-contained
file), equalities other than ``connect``/``weld``, joint types other than hinge, slide, ball, free.
Meshes are not read (kinematics and dynamics need none).
"""

from __future__ import annotations

import os
import tempfile
from typing import NamedTuple

import numpy as np
import pinocchio as pin
from lxml import etree

from pkm.core.formats.imported import Imported
from pkm.core.spec import Closure
from pkm.core.urdf import floats, parse_xml, urdf_from_model
from pkm.errors import SpecError

_ACTUATORS = ("motor", "position", "velocity", "general", "intvelocity", "damper", "cylinder", "muscle",
              "adhesion")
_JOINT_TYPES = ("hinge", "slide", "ball", "free")
_WORLD = "world"  # the fixed body pkm wraps the worldbody's children in (Pinocchio reads only one): MuJoCo's name
# for the world body, which equalities may name (body2="world") and no body of the file may take


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
                self.attrs[(name, child.tag)] = dict(child.attrib)

    def get(self, el: etree._Element, key: str, default: str | None = None) -> str | None:
        if el.get(key) is not None:
            return el.get(key)
        cls = el.get("class")
        node = el.getparent()
        while cls is None and node is not None:
            cls = node.get("childclass")
            node = node.getparent()
        cls = cls or "main"
        while cls is not None:
            value = self.attrs.get((cls, el.tag), {}).get(key)
            if value is not None:
                return value
            cls = self.parent.get(cls)
        return default


def _unit(x: np.ndarray, what: str, source: str) -> np.ndarray:
    n = float(np.linalg.norm(x))
    if n < 1e-12:
        raise SpecError(source, f"{what}: a zero vector gives no direction")
    return x / n


def _rotation(el: etree._Element, degrees: bool, source: str) -> np.ndarray:
    """The orientation an MJCF element states (quat, axisangle, euler xyz, xyaxes, zaxis)."""
    what = f"<{el.tag} name={el.get('name')!r}>"
    if el.get("quat") is not None:
        w, x, y, z = _unit(_floats(el.get("quat"), 4, f"{what} quat", source), f"{what} quat", source)
        return pin.Quaternion(w, x, y, z).matrix()
    if el.get("axisangle") is not None:
        a = _floats(el.get("axisangle"), 4, f"{what} axisangle", source)
        return pin.AngleAxis(np.deg2rad(a[3]) if degrees else a[3], _unit(a[:3], f"{what} axisangle", source)).matrix()
    if el.get("euler") is not None:
        e = _floats(el.get("euler"), 3, f"{what} euler", source)
        e = np.deg2rad(e) if degrees else e
        R = np.eye(3)
        for axis, angle in zip("xyz", e):  # MuJoCo's default eulerseq "xyz": rotations about the moving axes
            R = R @ pin.AngleAxis(angle, np.eye(3)["xyz".index(axis)]).matrix()
        return R
    if el.get("xyaxes") is not None:
        a = _floats(el.get("xyaxes"), 6, f"{what} xyaxes", source)
        x = _unit(a[:3], f"{what} xyaxes", source)
        y = _unit(a[3:] - x * (x @ a[3:]), f"{what} xyaxes", source)
        return np.column_stack([x, y, np.cross(x, y)])
    if el.get("zaxis") is not None:
        z = _floats(el.get("zaxis"), 3, f"{what} zaxis", source)
        return pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), _unit(z, f"{what} zaxis", source)).matrix()
    return np.eye(3)


def read_mjcf(text: str, source: str = "<mjcf>") -> Imported:
    """Read MJCF text (see the module doc).

    Raises:
        SpecError: malformed XML, a refused feature, or a file Pinocchio rejects.
    """
    root = parse_xml(text, source, "mujoco", "MJCF")
    if root.find(".//include") is not None:
        raise SpecError(source, "<include> is refused: pkm reads one self-contained MJCF file; merge the included "
                                "files into it")
    compiler = root.find("compiler")
    degrees = compiler is None or compiler.get("angle", "degree") != "radian"
    if compiler is not None and compiler.get("eulerseq", "xyz") != "xyz":
        raise SpecError(source, f"<compiler eulerseq={compiler.get('eulerseq')!r}>: pkm reads the default 'xyz' only")
    defaults = _Defaults(root)
    world = root.find("worldbody")
    if world is None:
        raise SpecError(source, "no <worldbody>")

    body_joints: dict[str, list[str]] = {}  # a composite's first joint -> the names of all its parts
    limits: dict[str, tuple[float, float]] = {}
    for body in world.iter("body"):
        joints = [j for j in body if j.tag in ("joint", "freejoint")]
        names = []
        for j in joints:
            kind = "free" if j.tag == "freejoint" else defaults.get(j, "type", "hinge")
            if kind not in _JOINT_TYPES:
                raise SpecError(source, f"joint {j.get('name')!r}: type {kind!r} is not one of {list(_JOINT_TYPES)}")
            if not j.get("name"):
                raise SpecError(source, f"a {kind} joint of body {body.get('name')!r} has no name; name every joint")
            names.append(j.get("name"))
            rng, limited = defaults.get(j, "range"), defaults.get(j, "limited", "auto")
            if kind in ("hinge", "slide") and rng is not None and limited != "false":
                lo, hi = _floats(rng, 2, f"joint {j.get('name')!r} range", source)
                limits[j.get("name")] = tuple(np.deg2rad([lo, hi])) if kind == "hinge" and degrees else (lo, hi)
        if names:
            body_joints[names[0]] = names

    equalities = [el for el in root.findall("equality/*") if isinstance(el.tag, str)]
    for el in equalities:
        if el.tag not in ("connect", "weld"):
            raise SpecError(source, f"<equality><{el.tag}> is not a loop closure pkm reads (connect and weld are)")
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
    for el in equalities:
        counts[el.tag] += 1
        eq_names.append((el.tag, el.get("name") or f"{el.tag}{counts[el.tag]}",
                         (el.get("site1"), el.get("site2")) if el in on_sites else None))
    body_based = {t: counts[t] - sum(1 for el in on_sites if el.tag == t) for t in counts}
    actuated = []
    for el in root.findall("actuator/*"):
        joint = el.get("joint") or el.get("jointinparent")
        if isinstance(el.tag, str) and el.tag in _ACTUATORS and joint and joint not in actuated:
            actuated.append(joint)

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
    if free:
        if any(el.tag == "weld" and el.get("relpose") is not None for el in equalities):
            raise SpecError(source, "a weld's relpose with free bodies is not read: leave relpose out (the bodies are "
                                    "then welded as they are at qpos0)")
        points, welds = _anchored(model, free, points), _anchored(model, free, welds)
    taken = set(model.names) | {f.name for f in model.frames}
    extra: list[tuple[str, int, pin.SE3]] = []
    for site in world.iter("site"):  # the sites Pinocchio dropped (those of bodies without joints)
        if site.get("name") and site.get("name") not in taken:
            body = site.getparent().get("name")
            if not model.existFrame(body, pin.FrameType.BODY):
                continue
            bf = model.frames[model.getFrameId(body, pin.FrameType.BODY)]
            pos = _floats(defaults.get(site, "pos", "0 0 0"), 3, f"site {site.get('name')!r} pos", source)
            extra.append((site.get("name"), bf.parentJoint, bf.placement * pin.SE3(_rotation(site, degrees, source),
                                                                                     pos)))
            taken.add(site.get("name"))
    closures = []
    iters = {"connect": iter(points), "weld": iter(welds)}
    for tag, name, on in eq_names:
        if on is not None:  # the two sites coincide (connect: their origins; weld: their frames)
            for site_name in on:
                if site_name not in taken:
                    raise SpecError(source, f"<equality><{tag} name={name!r}>: no site {site_name!r} on a body")
            closures.append(Closure(name, "point" if tag == "connect" else "frame", *on))
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
        closures.append(Closure(name, "point" if tag == "connect" else "frame", *frames))

    joint_names = {f"Composite_{first}": parts for first, parts in body_joints.items() if len(parts) > 1}
    name = root.get("model", "mjcf")
    urdf, types = urdf_from_model(model, name=name, joint_names=joint_names, limits=limits, frames=extra,
                                  skip_frames=(_WORLD,), source=source)
    known = {p for parts in body_joints.values() for p in parts}
    for a in actuated:
        if a not in known:
            raise SpecError(source, f"an actuator drives joint {a!r}, which the file does not define")
    reference = {model.names[j]: tuple(map(float, pin.SE3ToXYZQUAT(X))) for j, X in free.items()}
    return Imported(urdf, tuple(closures), types, tuple(actuated), name, "mjcf", _floating_base(model), reference)


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


def _anchored(model: pin.Model, free: dict[int, pin.SE3], constraints):
    """The constraints with their second end re-anchored where the first is at qpos0 (free bodies at their poses)."""
    q0 = pin.neutral(model)
    for jid, X in free.items():
        jm = model.joints[jid]
        q0[jm.idx_q:jm.idx_q + 7] = pin.SE3ToXYZQUAT(X)
    d = model.createData()
    pin.forwardKinematics(model, d, q0)
    out = []
    for cm in constraints:
        world_a = d.oMi[cm.joint1_id] * cm.joint1_placement
        out.append(_Anchors(cm.joint1_id, cm.joint1_placement, cm.joint2_id, d.oMi[cm.joint2_id].actInv(world_a)))
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
