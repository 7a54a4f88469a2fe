"""Building, validating and loading the URDF trees of mechanisms.

The generators build each tree with :class:`UrdfBuilder` (yourdfpy objects,
validated by yourdfpy), and :func:`load_model` turns URDF text into a Pinocchio
model after pkm's own checks, so that a malformed file yields a
:class:`~pkm.errors.SpecError` that says what is wrong instead of Pinocchio's
bare ``ValueError``.

What the loaders refuse
-----------------------

:func:`check_urdf` (run by :func:`load_model`, hence by every ``Mechanism`` constructor)
raises :class:`~pkm.errors.SpecError` for:

* text that is not a ``str``/``bytes``, that cannot be encoded as UTF-8, or that is larger
  than 16 MiB; a document that is not well-formed XML (truncated files included) or nests
  deeper than libxml2's default limit (256);
* any ``DOCTYPE``, hence any entity declaration: internal entity expansion ("billion
  laughs") and external entities (``<!ENTITY x SYSTEM "file:///etc/passwd">``) are refused
  by a scan of the text before the parser runs, so nothing is expanded or opened. The parser
  runs with entity resolution, DTD loading and network access off; XInclude elements are
  refused too; nothing but the given text is ever read (meshes are not loaded);
* a root element other than ``<robot>``; more than 10,000 links or joints;
* links or joints without a name or with a duplicate name, a joint whose parent or child is
  not a link, a link with two parents, a tree with several roots (or none), an unknown joint
  type;
* a zero axis; a revolute or prismatic joint without ``<limit>`` (URDF requires one), or whose
  ``<limit>`` states only one of ``lower`` and ``upper``, or ``lower > upper`` (position limits are optional: without them a joint has none;
  with them :meth:`pkm.core.Mechanism.outside_limits` and every solver result report violations);
* a number that is not finite or absurd (``|x| > 1e6`` in SI units, taken for a unit error):
  origins, axes, masses, inertias, mimic coefficients; a non-finite limit. A joint limit of magnitude
  ``>= 1e6`` (:data:`UNLIMITED`: exporters write ``velocity="1e8"`` or ``effort="1e30"`` for "unlimited") is
  read as no limit: an effort or velocity limit of any sign, a lower limit ``<= -1e6``, an upper limit
  ``>= 1e6`` (:func:`position_limits` gives that side as infinite); :func:`limit_notes` says which were read so;
  a lower limit ``>= 1e6`` or an upper one ``<= -1e6`` is refused;
* a negative mass. An inertia tensor with a negative principal moment, or one that breaks the triangle inequality,
  loads (the kinematics needs no inertia): :mod:`pkm.core.model.plausibility` warns and the dynamics refuses it;
* a ``<mimic>`` naming an unknown joint.

Whatever Pinocchio or yourdfpy still reject after these checks is reported as a
:class:`~pkm.errors.SpecError` too, never as their own exception types.
yourdfpy drops ``<mimic>`` when it writes, so the builder puts those elements back itself.
"""

from __future__ import annotations

import copy
import io
import math
import re
import threading
from collections.abc import Container, Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin
from lxml import etree
from numpy.typing import ArrayLike

from pkm.core.model.joints import copy_limits
from pkm.errors import InvalidInputError, SpecError
from pkm.validation import ABSURD

if TYPE_CHECKING:  # (imported where used: yourdfpy brings trimesh, scipy and networkx, a second of CPU a process
    # that only reads a tree, as a sweep's worker evaluating a closed-form map, never pays)
    import yourdfpy

_JOINT_TYPES = {"revolute", "continuous", "prismatic", "fixed", "floating", "planar"}
_MAX_BYTES = 16 * 1024 * 1024
_MAX_ELEMENTS = 10_000  # links + joints


def _origin(xyz: ArrayLike = (0.0, 0.0, 0.0), rotation: ArrayLike | None = None) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = xyz
    if rotation is not None:
        T[:3, :3] = rotation
    return T


def unique_name(base: str, taken: set[str], reserved: Container[str] = ()) -> str:
    """``base``, else ``base_1``, ``base_2``...: the first name not ``taken`` (a numbered one not ``reserved``
    either), added to ``taken``; the writers' names for bodies, joints and frames."""
    out, k = base, 1
    while out in taken or (out != base and out in reserved):
        out, k = f"{base}_{k}", k + 1
    taken.add(out)
    return out


#: The collision primitives :meth:`UrdfBuilder.collision` writes, and their sizes' names [m].
COLLISION_SHAPES: dict[str, tuple[str, ...]] = {"box": ("x", "y", "z"), "cylinder": ("radius", "length"),
                                                "capsule": ("radius", "length"), "sphere": ("radius",)}


class UrdfBuilder:
    """Collects links and joints, then writes a validated URDF string.

    Lengths in m, masses in kg, inertias in kg m^2 about the centre of mass,
    angles in rad. Rotations are given as 3x3 matrices.
    """

    def __init__(self, name: str):
        self.name = name
        self._links: list[yourdfpy.Link] = []
        self._joints: list[yourdfpy.Joint] = []
        self._mimic: dict[str, tuple[str, float, float]] = {}
        self._collisions: dict[str, list[tuple[str, dict[str, float], np.ndarray]]] = {}

    def link(self, name: str, mass: float = 0.0, com: ArrayLike = (0.0, 0.0, 0.0),
             inertia: ArrayLike | None = None) -> str:
        """Add a link; a massless link gets no ``<inertial>``."""
        import yourdfpy

        inertial = None
        if mass > 0.0:
            I = np.zeros((3, 3)) if inertia is None else np.asarray(inertia, dtype=float)
            inertial = yourdfpy.Inertial(origin=_origin(com), mass=float(mass), inertia=I)
        self._links.append(yourdfpy.Link(name=name, inertial=inertial))
        return name

    def joint(self, name: str, type: str, parent: str, child: str, xyz: ArrayLike = (0.0, 0.0, 0.0),
              rotation: ArrayLike | None = None, axis: ArrayLike = (0.0, 0.0, 1.0), limits: tuple[float, float] | None = None, effort: float = 1e3,
              velocity: float = 1e2, mimic: tuple[str, float, float] | None = None) -> str:
        """Add a joint. ``mimic = (leader, multiplier, offset)`` makes it follow ``leader``."""
        import yourdfpy

        limit = None
        if type in ("revolute", "prismatic"):
            lo, hi = limits if limits is not None else (-math.pi, math.pi)
            limit = yourdfpy.Limit(effort=float(effort), velocity=float(velocity), lower=float(lo), upper=float(hi))
        ax = None if type in ("fixed", "floating") else np.asarray(axis, dtype=float)
        self._joints.append(yourdfpy.Joint(name=name, type=type, parent=parent, child=child,
                                           origin=_origin(xyz, rotation), axis=ax, limit=limit))
        if mimic is not None:
            self._mimic[name] = (mimic[0], float(mimic[1]), float(mimic[2]))
        return name

    def frame(self, name: str, parent: str, xyz: ArrayLike = (0.0, 0.0, 0.0), rotation: ArrayLike | None = None) -> str:
        """Add a massless link ``name`` fixed to ``parent`` (a named frame for closures)."""
        self.link(name)
        self.joint(f"{name}_fixed", "fixed", parent, name, xyz, rotation)
        return name

    def collision(self, link: str, shape: str, xyz: ArrayLike = (0.0, 0.0, 0.0), rotation: ArrayLike | None = None,
                  **size: float) -> str:
        """Add a collision primitive to ``link``: ``shape`` one of :data:`COLLISION_SHAPES` with its sizes [m]
        (``box``: ``size=(x, y, z)`` as ``x=, y=, z=``; ``cylinder``/``capsule``: ``radius=, length=`` along the
        local z axis, a capsule's length between its hemispheres' centres; ``sphere``: ``radius=``), placed at
        ``xyz``/``rotation`` in the link's frame. A capsule is written ``<capsule radius length>``, the element
        Gazebo's URDF reader and pkm's geometry reader take (urdfdom's does not)."""
        if shape not in COLLISION_SHAPES:
            raise InvalidInputError("shape", f"one of {sorted(COLLISION_SHAPES)} expected", shape)
        if set(size) != set(COLLISION_SHAPES[shape]):
            raise InvalidInputError("size", f"a {shape} takes {COLLISION_SHAPES[shape]}", size)
        for k, v in size.items():
            if not (math.isfinite(v) and 0.0 < v <= ABSURD):
                raise InvalidInputError(k, f"a {shape}'s {k} must be positive and finite [m]", v)
        self._collisions.setdefault(link, []).append((shape, {k: float(v) for k, v in size.items()},
                                                      _origin(xyz, rotation)))
        return link

    def to_xml(self) -> str:
        """The URDF text: yourdfpy-validated, ``<mimic>`` and ``<collision>`` restored, pretty-printed."""
        import yourdfpy

        robot = yourdfpy.Robot(name=self.name, links=self._links, joints=self._joints)
        urdf = yourdfpy.URDF(robot=robot, build_scene_graph=False, load_meshes=False)
        if not urdf.validate():
            raise SpecError(f"<generated {self.name}>", "yourdfpy rejects the generated tree")
        root = etree.fromstring(urdf.write_xml_string())
        for jel in root.iter("joint"):
            if jel.get("name") in self._mimic:
                leader, mult, off = self._mimic[jel.get("name")]
                etree.SubElement(jel, "mimic", joint=leader, multiplier=repr(mult), offset=repr(off))
        for lel in root.iter("link"):
            for k, (shape, size, T) in enumerate(self._collisions.get(str(lel.get("name")), ())):
                col = etree.SubElement(lel, "collision", name=f"{lel.get('name')}_{k}")
                rpy = pin.rpy.matrixToRpy(T[:3, :3])
                etree.SubElement(col, "origin", xyz=" ".join(map(repr, map(float, T[:3, 3]))),
                                 rpy=" ".join(map(repr, map(float, rpy))))
                attrs = ({"size": " ".join(repr(size[a]) for a in "xyz")} if shape == "box"
                         else {a: repr(v) for a, v in size.items()})
                etree.SubElement(etree.SubElement(col, "geometry"), shape, **attrs)
        etree.indent(root, space="  ")
        text = etree.tostring(root, xml_declaration=True, encoding="utf-8", pretty_print=True).decode()
        check_urdf(text, f"<generated {self.name}>")
        _passed(text, yourdfpy_too=True)  # (its tree validated above: the <mimic> and <collision> added are checked)
        return text


#: A joint limit of at least this magnitude (SI: m, rad, m/s, rad/s, N, N m) is read as no limit.
UNLIMITED = 1e6
_LIMIT_SIGN = {"lower": -1.0, "upper": 1.0, "effort": 0.0, "velocity": 0.0}  # the side a limit opens (0: either)

_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?|[+-]?(nan|inf|infinity)", re.IGNORECASE)


def floats(text: str | None, n: int, what: str, source: str, bound: float = ABSURD) -> list[float]:
    """``n`` finite numbers of magnitude <= ``bound`` from whitespace-separated text (the model formats share it)."""
    words = (text or "").split()
    vals: list[float] | None = None
    if (text or "").isascii() and "_" not in (text or ""):  # (the words float() takes are then _NUMBER's: 4x faster)
        try:
            vals = [float(v) for v in words]
        except ValueError:
            pass
    if vals is None:
        if not all(_NUMBER.fullmatch(w) for w in words):  # float() would also take "1_000" and non-ASCII digits
            raise SpecError(source, f"{what}: {text!r} is not a list of numbers")
        vals = [float(v) for v in words]
    if len(vals) != n:
        raise SpecError(source, f"{what}: expected {n} numbers, got {text!r}")
    for v in vals:
        if not math.isfinite(v) or abs(v) > bound:
            raise SpecError(source, f"{what}: value {v!r} is not finite or absurdly large (SI units expected)")
    return vals


def limit_value(text: str | None, key: str, what: str, source: str) -> float | None:
    """A joint ``<limit>`` attribute (``key``: ``lower``, ``upper``, ``effort`` or ``velocity``) as a number, or
    None when it states no limit: magnitude ``>= UNLIMITED`` (a lower limit ``<= -1e6``, an upper ``>= 1e6``, an
    effort or velocity of either sign).

    Raises:
        SpecError: not a finite number; a lower limit ``>= 1e6`` or an upper one ``<= -1e6`` (no joint moves
            there: a unit error).
    """
    v = floats(text, 1, what, source, bound=math.inf)[0]
    if abs(v) < UNLIMITED:
        return v
    side = _LIMIT_SIGN[key]
    if side and v * side < 0:
        raise SpecError(source, f"{what}: value {v!r} is absurd for a {key} limit (SI units expected)")
    return None


def limit_notes(root: etree._Element) -> tuple[str, ...]:
    """One sentence per limit value a checked URDF states that :func:`limit_value` reads as none, the joints
    that state it named: ``"joint 'j': velocity limit 1e8 read as none"``."""
    found: dict[tuple[str, str], list[str]] = {}
    for el in root.findall("joint"):
        lim = el.find("limit")
        if lim is None:
            continue
        keys = tuple(_LIMIT_SIGN) if el.get("type") in ("revolute", "prismatic") else ("effort", "velocity")
        for key in keys:  # (the position limits of other joints are neither checked nor read)
            text = lim.get(key)
            if text is not None and abs(float(text)) >= UNLIMITED:
                found.setdefault((key, text.strip()), []).append(str(el.get("name")))
    out = []
    for (key, text), joints in found.items():
        shown = ", ".join(repr(j) for j in joints[:6]) + (f", ... ({len(joints)} joints)" if len(joints) > 6 else "")
        out.append(f"joint{'s' if len(joints) > 1 else ''} {shown}: {key} limit {text} read as none "
                   f"(|x| >= {UNLIMITED:g})")
    return tuple(out)


def parse_xml(text: str | bytes, source: str = "<string>", root_tag: str = "robot", what: str = "URDF") \
        -> etree._Element:
    """Parse XML text safely (no DOCTYPE, entities, DTD, network or XInclude; at most 16 MiB) and check that its
    root element is ``<root_tag>``; the model formats (URDF, MJCF, SDF) share it.

    Raises:
        SpecError: the text is not UTF-8, too large, not well-formed, or refused as above.
    """
    if not isinstance(text, (str, bytes)):
        raise InvalidInputError("text", f"expected the {what} text as a str, got {type(text).__name__}", text)
    if len(text) > _MAX_BYTES:
        raise SpecError(source, f"{what} larger than {_MAX_BYTES} bytes")
    try:
        data = text.encode() if isinstance(text, str) else text.decode("utf-8").encode()
    except UnicodeEncodeError as exc:
        raise SpecError(source, f"{what} text cannot be encoded as UTF-8 (character {exc.start})") from None
    except UnicodeDecodeError as exc:
        raise SpecError(source, f"{what} bytes are not UTF-8 (byte {exc.start})") from None
    if b"<!DOCTYPE" in data or b"<!ENTITY" in data:  # refused before the parser sees (and expands) anything
        raise SpecError(source, f"{what} with a DOCTYPE (entity declarations) is refused; remove the <!DOCTYPE ...> "
                                f"block ({what} needs none)")
    if len(data) > _MAX_BYTES:
        raise SpecError(source, f"{what} larger than {_MAX_BYTES} bytes")
    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False,
                             dtd_validation=False)
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        raise SpecError(source, f"not well-formed XML: {exc}") from None
    if root.getroottree().docinfo.doctype:
        raise SpecError(source, f"{what} with a DOCTYPE (entity declarations) is refused")
    if root.tag != root_tag:
        raise SpecError(source, f"root element is <{root.tag}>, expected <{root_tag}>")
    if any(isinstance(el.tag, str) and el.tag.startswith("{http://www.w3.org/2001/XInclude}") for el in root.iter()):
        raise SpecError(source, f"XInclude elements are refused (pkm reads one self-contained {what}; expand it first)")
    return root


#: The latest URDF texts :func:`check_urdf` passed (a text -> whether yourdfpy took it too), most recent last: a
#: mechanism's build checks its text three times (written, loaded, its limits read) and a sweep's designs share
#: theirs with their tests; checking is a pure function of the text, so a text met again is only parsed.
_CHECKED: dict[str | bytes, bool] = {}
_CHECKED_KEPT = 16
_CHECKED_LOCK = threading.Lock()  # (the service loads models from several threads)


def _passed(text: str | bytes, *, yourdfpy_too: bool = False) -> None:
    """Remember that ``text`` passed :func:`check_urdf` (and yourdfpy's validation, ``yourdfpy_too``)."""
    with _CHECKED_LOCK:
        seen = _CHECKED.pop(text, False)
        _CHECKED[text] = seen or yourdfpy_too
        while len(_CHECKED) > _CHECKED_KEPT:
            del _CHECKED[next(iter(_CHECKED))]


def check_urdf(text: str | bytes, source: str = "<string>") -> etree._Element:
    """Parse and check URDF text (see the module docstring); returns the root element (a fresh tree each call)."""
    root = parse_xml(text, source)
    if text in _CHECKED:
        return root
    if len(root) > _MAX_ELEMENTS:
        raise SpecError(source, f"more than {_MAX_ELEMENTS} elements under <robot>")
    links = [el.get("name") for el in root.findall("link")]
    if any(not n for n in links):
        raise SpecError(source, "a <link> has no name")
    if len(set(links)) != len(links):
        raise SpecError(source, "two links share a name")
    joints = root.findall("joint")
    jnames = [el.get("name") for el in joints]
    if any(not n for n in jnames) or len(set(jnames)) != len(jnames):
        raise SpecError(source, "a <joint> has no name or two joints share a name")
    parent_of: dict[str, str] = {}
    for el in joints:
        name, typ = el.get("name"), el.get("type")
        if typ not in _JOINT_TYPES:
            raise SpecError(source, f"joint {name!r}: unknown type {typ!r}; URDF types are {sorted(_JOINT_TYPES)}")
        par, chi = el.find("parent"), el.find("child")
        if par is None or chi is None:
            raise SpecError(source, f"joint {name!r} lacks <parent> or <child>")
        for role, link in (("parent", par.get("link")), ("child", chi.get("link"))):
            if link not in links:
                raise SpecError(source, f"joint {name!r}: {role} link {link!r} does not exist")
        if chi.get("link") in parent_of:
            raise SpecError(source, f"link {chi.get('link')!r} has two parents (URDF is a tree; "
                                    "put loops in the closure spec)")
        parent_of[chi.get("link")] = par.get("link")
        org = el.find("origin")
        if org is not None:
            floats(org.get("xyz", "0 0 0"), 3, f"joint {name!r} origin xyz", source)
            floats(org.get("rpy", "0 0 0"), 3, f"joint {name!r} origin rpy", source)
        if typ in ("revolute", "continuous", "prismatic"):
            ax = el.find("axis")
            axis = floats(ax.get("xyz") if ax is not None else "1 0 0", 3, f"joint {name!r} axis", source)
            if np.linalg.norm(axis) < 1e-9:
                raise SpecError(source, f"joint {name!r} has a zero axis")
        if typ in ("revolute", "prismatic"):
            lim = el.find("limit")  # position limits are optional (onshape-to-robot writes effort and velocity only)
            if lim is None:
                raise SpecError(source, f"joint {name!r} ({typ}) needs a <limit> element (URDF requires one; "
                                        "effort and velocity suffice, lower and upper are optional)")
            stated = [] if lim is None else [k for k in ("lower", "upper") if lim.get(k) is not None]
            if len(stated) == 1:
                raise SpecError(source, f"joint {name!r} ({typ}) states only its {stated[0]} limit; give both "
                                        "lower and upper, or neither (no position limits)")
            if stated:
                lo, hi = (limit_value(lim.get(k), k, f"joint {name!r} {k} limit", source) for k in ("lower", "upper"))
                if lo is not None and hi is not None and lo > hi:
                    raise SpecError(source, f"joint {name!r}: lower limit {lo} > upper limit {hi}")
        lim = el.find("limit")
        if lim is not None:
            for key in ("effort", "velocity"):
                if lim.get(key) is not None:
                    limit_value(lim.get(key), key, f"joint {name!r} limit {key}", source)
        mim = el.find("mimic")
        if mim is not None and mim.get("joint") not in jnames:
            raise SpecError(source, f"joint {name!r} mimics unknown joint {mim.get('joint')!r}")
        if mim is not None:
            for key in ("multiplier", "offset"):
                if mim.get(key) is not None:
                    floats(mim.get(key), 1, f"joint {name!r} mimic {key}", source)
    roots = [n for n in links if n not in parent_of]
    if len(roots) != 1:
        raise SpecError(source, f"a URDF tree has one root link; found {roots}")
    for lel in root.findall("link"):
        inertial = lel.find("inertial")
        if inertial is None:
            continue
        mass = inertial.find("mass")
        lname = lel.get("name")
        m = floats(mass.get("value") if mass is not None else None, 1, f"link {lname!r} mass", source)[0]
        if m < 0:
            raise SpecError(source, f"link {lname!r} has negative mass {m}")
        org = inertial.find("origin")
        if org is not None:
            floats(org.get("xyz", "0 0 0"), 3, f"link {lname!r} inertial origin xyz", source)
            floats(org.get("rpy", "0 0 0"), 3, f"link {lname!r} inertial origin rpy", source)
        iel = inertial.find("inertia")
        if iel is None:
            raise SpecError(source, f"link {lname!r}: <inertial> needs <inertia ixx=... ixy=... ixz=... iyy=... "
                                    "iyz=... izz=...>")
        if iel is not None:
            keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
            floats(" ".join(iel.get(k, "0") for k in keys), 6, f"link {lname!r} inertia {'/'.join(keys)}", source)
    _passed(text)
    return root


def position_limits(text: str | bytes, source: str = "<string>") -> dict[str, tuple[float, float]]:
    """``{joint: (lower, upper)}`` [m or rad] for the revolute and prismatic joints whose ``<limit>`` states both
    (checked URDF text; the others have none: Pinocchio's parser gives them ``[0, 0]``, which pkm does not read).
    A side stated beyond :data:`UNLIMITED` is infinite (``-inf`` or ``inf``); a joint with neither side bounded
    has no entry."""
    out: dict[str, tuple[float, float]] = {}
    for el in check_urdf(text, source).findall("joint"):
        lim = el.find("limit")
        if el.get("type") in ("revolute", "prismatic") and lim is not None and lim.get("lower") is not None \
                and lim.get("upper") is not None:
            lo, hi = (limit_value(lim.get(k), k, f"joint {el.get('name')!r} {k} limit", source)
                      for k in ("lower", "upper"))
            if lo is not None or hi is not None:
                out[str(el.get("name"))] = (-math.inf if lo is None else lo, math.inf if hi is None else hi)
    return out


def load_model(text: str, source: str = "<string>") -> pin.Model:
    """Check URDF text and build the Pinocchio model (mimic joints honoured, in whatever order the file gives
    them: where Pinocchio's parser meets a mimic joint before its leader, :func:`mimics_first`).

    Raises:
        SpecError: see the module docstring for what is refused.
    """
    root = check_urdf(text, source)
    given, validated = text, _CHECKED.get(text, False)
    if isinstance(text, bytes):
        text = text.decode("utf-8", errors="replace")
    if without_geometry(root):  # (the tree needs none of it; urdfdom prints errors for a <capsule>)
        text = etree.tostring(root, encoding="unicode")
    if not validated:  # (a text yourdfpy took already, as UrdfBuilder.to_xml's: not again)
        import yourdfpy

        try:
            yourdfpy.URDF.load(io.BytesIO(text.encode()), build_scene_graph=False, load_meshes=False)
        except Exception as exc:  # yourdfpy raises a variety of types
            raise SpecError(source, f"yourdfpy rejects the URDF: {exc}") from None
        _passed(given, yourdfpy_too=True)
    mimics = {str(el.get("name")): (str(m.get("joint")), float(m.get("multiplier", 1.0)), float(m.get("offset", 0.0)))
              for el in root.findall("joint") if el.get("type") != "fixed" for m in el.findall("mimic")[:1]}
    try:
        return pin.buildModelFromXML(text, mimic=bool(mimics))
    except Exception as exc:  # Pinocchio's own exception types must not leak
        if not mimics:
            raise SpecError(source, f"Pinocchio rejects the URDF: {exc}") from None
    try:  # (a mimic met before its leader in Pinocchio's traversal: pkm orders the tree itself)
        model = pin.buildModelFromXML(text)
    except Exception as exc:
        raise SpecError(source, f"Pinocchio rejects the URDF: {exc}") from None
    return mimics_first(model, mimics, source)


def without_geometry(root: etree._Element) -> bool:
    """Remove the ``<collision>`` and ``<visual>`` elements of a URDF tree (in place): the kinematic and dynamic
    model needs none of them (the collision geometry is :mod:`pkm.core.collision`'s, read from the text), and
    urdfdom, Pinocchio's parser, prints errors for a ``<capsule>``. Whether there were any."""
    found = [el for lel in root.findall("link") for el in lel if el.tag in ("collision", "visual")]
    for el in found:
        lel = el.getparent()
        lel.remove(el)
    return bool(found)


def mimics_first(model: pin.Model, mimics: Mapping[str, tuple[str, float, float]], source: str) -> pin.Model:
    """``model`` (plain joints) with the joints ``mimics`` names made mimic joints, ``{joint: (leader, multiplier,
    offset)}``: ``q_joint = multiplier q_leader + offset`` (URDF's ``<mimic>``).

    Pinocchio's URDF parser visits the tree depth first, sibling joints in name order, and refuses a mimic joint
    met before its leader ("The parent joint of the mimic joint is not in the kinematic tree") though the file is
    valid URDF: here the tree is visited depth first with, under each body, the subtrees holding a leader before
    those holding the joints that mimic it (else in the parser's order), and each mimic joint made so
    (``transformJointIntoMimic``). Joint names, placements, inertias, limits and frames are kept.

    Raises:
        SpecError: a mimic joint's leader is not a 1-coordinate joint, is below it in the tree, or the leaders
            cross between sibling subtrees (no depth-first order visits every leader first).
    """
    names = list(model.names)
    for name, (leader, _, _) in mimics.items():
        if leader not in names[1:] or model.joints[model.getJointId(leader)].nq != 1 \
                or model.joints[model.getJointId(name)].nq != 1:
            raise SpecError(source, f"joint {name!r}: <mimic joint={leader!r}> needs two joints of one coordinate "
                                    "each")
    children: dict[int, list[int]] = {j: [] for j in range(model.njoints)}
    for j in range(1, model.njoints):
        children[model.parents[j]].append(j)
    subtree = {j: {j} for j in range(model.njoints)}
    for j in range(model.njoints - 1, 0, -1):
        subtree[model.parents[j]] |= subtree[j]
    pairs = [(model.getJointId(leader), model.getJointId(name)) for name, (leader, _, _) in mimics.items()]
    order: list[int] = []

    def visit(j: int) -> None:
        order.append(j)
        kids, ordered = list(children[j]), []
        while kids:  # the first sibling no other pending sibling must precede (a leader of a mimic in it)
            ready = [k for k in kids if not any(lead in subtree[o] and mim in subtree[k]
                                                for o in kids if o != k for lead, mim in pairs)]
            if not ready:
                raise SpecError(source, f"the mimic joints below {names[j]!r} follow leaders across sibling branches "
                                        "both ways: no depth-first order visits each leader first")
            ordered.append(ready[0])
            kids.remove(ready[0])
        for k in ordered:
            visit(k)

    visit(0)
    rank = {j: n for n, j in enumerate(order)}
    for lead, mim in pairs:
        if rank[lead] > rank[mim]:
            raise SpecError(source, f"joint {names[mim]!r} mimics {names[lead]!r}, a joint below it in the tree: "
                                    "Pinocchio cannot model that coupling")
    new = pin.Model()
    new.name, new.gravity = model.name, model.gravity
    ids = {0: 0}
    for j in order[1:]:
        ids[j] = new.addJoint(ids[model.parents[j]], model.joints[j], model.jointPlacements[j], names[j])
        new.appendBodyToJoint(ids[j], model.inertias[j], pin.SE3.Identity())
    copy_limits(model, new, [(j, ids[j]) for j in order[1:]], extra_v=("rotorInertia", "rotorGearRatio"))
    for k, f in enumerate(model.frames):
        if k:  # (the universe frame: every model has it)
            new.addFrame(pin.Frame(f.name, ids[f.parentJoint], f.parentFrame, f.placement, f.type, f.inertia), False)
    for name, (leader, multiplier, offset) in sorted(mimics.items(), key=lambda item: rank[model.getJointId(item[0])]):
        new = pin.transformJointIntoMimic(new, new.getJointId(leader), new.getJointId(name), multiplier, offset)
    return new


_AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


def num(x: ArrayLike) -> str:
    """Numbers as URDF attribute text, each written exactly (``repr``)."""
    return " ".join(repr(float(v)) for v in np.ravel(x))


def origin(el: etree._Element, M: pin.SE3) -> None:
    """An ``<origin xyz rpy>`` child of ``el`` for the placement ``M``."""
    etree.SubElement(el, "origin", xyz=num(M.translation), rpy=num(pin.rpy.matrixToRpy(M.rotation)))


def _urdf_joint_kind(jm: pin.JointModel, where: str, source: str) -> tuple[str, np.ndarray | None, str | None]:
    """``(URDF type, axis, pkm joint type or None)`` of one (non-composite) Pinocchio joint model."""
    kind = jm.shortname().removeprefix("JointModel")
    if kind in ("RX", "RY", "RZ", "PX", "PY", "PZ"):
        return ("revolute" if kind[0] == "R" else "prismatic"), np.array(_AXES[kind[1]]), None
    if kind in ("RevoluteUnaligned", "PrismaticUnaligned"):
        return ("revolute" if kind[0] == "R" else "prismatic"), np.asarray(jm.extract().axis, dtype=float), None
    if kind in ("RUBX", "RUBY", "RUBZ"):
        return "continuous", np.array(_AXES[kind[3]]), None
    if kind == "Spherical":  # URDF has none: a revolute placeholder that [joint_types] makes spherical
        return "revolute", np.array(_AXES["Z"]), "spherical"
    if kind == "FreeFlyer":
        return "floating", None, None
    if kind == "Universal":
        uj = jm.extract()
        names = [next((a for a in "XYZ" if np.allclose(axis, _AXES[a], atol=1e-12)), None)
                 for axis in (uj.axis1, uj.axis2)]
        if names == ["X", "Y"]:
            return "revolute", np.array(_AXES["Z"]), "universal"
        if None not in names and names[0] != names[1]:  # (about two of the frame's axes: [joint_types] says which)
            return "revolute", np.array(_AXES["Z"]), f"universal_{names[0]}{names[1]}".lower()
    raise SpecError(source, f"{where}: a Pinocchio {jm.shortname()} cannot be written as URDF (pkm writes revolute, "
                            "prismatic, continuous, spherical, universal about two of the joint frame's axes, and "
                            "free-flyer joints)")


def _joint_motion(jm: pin.JointModel, value: float, where: str, source: str) -> pin.SE3:
    """The placement a revolute or prismatic joint model gives its child at ``q = value`` (rad or m)."""
    kind, axis, pkm_type = _urdf_joint_kind(jm, where, source)
    if kind not in ("revolute", "prismatic") or pkm_type is not None or axis is None:
        raise SpecError(source, f"{where}: only a revolute or prismatic joint can be locked at a value")
    if kind == "revolute":
        return pin.SE3(pin.AngleAxis(float(value), axis / np.linalg.norm(axis)).matrix(), np.zeros(3))
    return pin.SE3(np.eye(3), float(value) * axis / np.linalg.norm(axis))


def urdf_from_model(model: pin.Model, *, name: str | None = None, joint_names: dict[str, list[str]] | None = None,
                    limits: dict[str, tuple[float, float]] | None = None,
                    frames: Sequence[tuple[str, int, pin.SE3]] = (), skip_frames: tuple[str, ...] = (),
                    mimic: Mapping[str, tuple[str, float, float]] | None = None,
                    locked: Mapping[str, float] | None = None,
                    collisions: Mapping[str, Sequence[etree._Element]] | None = None,
                    source: str = "<model>") -> tuple[str, dict[str, str]]:
    """The URDF text of a Pinocchio tree, and the ``[joint_types]`` that URDF cannot state.

    The other formats (MJCF, SDF) reach pkm through this: one representation downstream. Each joint
    becomes a URDF joint of its name, its child link carrying the joint's inertia and named after the body
    frame at the joint's origin (``<joint>_link`` when there is none); a composite joint (a MuJoCo body
    with several joints) becomes a chain through massless links, its parts named by ``joint_names``;
    every other body and operational frame, and each of ``frames`` (``(name, parent joint id,
    placement in that joint's frame)``), becomes a massless link on a fixed joint ``<frame>_fixed``.
    ``limits`` gives the position limits ``{joint: (lower, upper)}`` to state; the other revolute and
    prismatic joints get a ``<limit>`` without bounds. ``mimic`` makes joints followers,
    ``{joint: (leader, multiplier, offset)}``: a URDF ``<mimic>``, ``q_joint = multiplier q_leader + offset``
    (:func:`load_model` builds Pinocchio's mimic joints, in any order).
    ``locked`` welds one-coordinate joints at a value, ``{joint: q [rad or m]}``: a fixed joint at the
    placement the joint has there. ``collisions`` gives bodies their ``<collision>`` elements, ``{frame name:
    [element]}``, each placed in that frame (a body's, an operational frame's, or the root link's by its name):
    written on the link made for it. :func:`load_model` and :func:`pkm.core.model.joints.retype_joints` give the
    same tree back (same ``q`` layout but for the mimic and locked joints, frames, inertias).

    Raises:
        SpecError: a joint kind URDF and ``[joint_types]`` cannot express (planar, helical...), mimic joints
            in ``model``, a locked joint with more than one coordinate.
    """
    joint_names = joint_names or {}
    limits = limits or {}
    mimic = mimic or {}
    locked = locked or {}
    fnames = {f.name for f in model.frames}
    taken: set[str] = set()

    def unique(base: str) -> str:
        return unique_name(base, taken, fnames)

    robot = etree.Element("robot", name=name or model.name or "robot")

    collisions = collisions or {}

    def link(lname: str, inertia: pin.Inertia | None = None, frame: str | None = None) -> None:
        lel = etree.SubElement(robot, "link", name=lname)
        for col in collisions.get(frame, ()) if frame is not None else ():
            lel.append(copy.deepcopy(col))
        if inertia is not None and inertia.mass > 0.0:
            iel = etree.SubElement(lel, "inertial")
            origin(iel, pin.SE3(np.eye(3), inertia.lever))
            etree.SubElement(iel, "mass", value=repr(float(inertia.mass)))
            I = inertia.inertia
            etree.SubElement(iel, "inertia", ixx=num(I[0, 0]), ixy=num(I[0, 1]), ixz=num(I[0, 2]),
                             iyy=num(I[1, 1]), iyz=num(I[1, 2]), izz=num(I[2, 2]))

    def joint(jname: str, kind: str, parent: str, child: str, M: pin.SE3, axis: ArrayLike | None = None) -> None:
        jel = etree.SubElement(robot, "joint", name=jname, type=kind)
        origin(jel, M)
        etree.SubElement(jel, "parent", link=parent)
        etree.SubElement(jel, "child", link=child)
        if axis is not None:
            etree.SubElement(jel, "axis", xyz=num(axis))
        if kind in ("revolute", "prismatic"):
            bounds = {"lower": repr(float(limits[jname][0])), "upper": repr(float(limits[jname][1]))} \
                if jname in limits else {}
            etree.SubElement(jel, "limit", effort="0", velocity="0", **bounds)

    root = unique("world")
    taken.update(skip_frames)
    link(root, frame=root)
    link_of = {0: root}
    primary = set()
    types: dict[str, str] = {}
    for jid in range(1, model.njoints):
        jm, jname = model.joints[jid], model.names[jid]
        if jm.shortname() == "JointModelMimic":
            raise SpecError(source, f"joint {jname!r}: mimic joints cannot be written as URDF by pkm yet")
        if jm.shortname() == "JointModelComposite":
            comp = jm.extract()
            parts = list(zip(comp.joints, comp.jointPlacements))
            names = joint_names.get(jname) or [f"{jname}_{k}" for k in range(len(parts))]
            if len(names) != len(parts):
                raise SpecError(source, f"joint {jname!r} has {len(parts)} parts but {len(names)} names")
        else:
            parts, names = [(jm, pin.SE3.Identity())], [jname]
        body = next((f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == jid
                     and f.placement.isIdentity(1e-12) and f.name not in taken), None)
        parent = link_of[model.parents[jid]]
        for k, ((part, placement), pname) in enumerate(zip(parts, names)):
            kind, axis, pkm_type = _urdf_joint_kind(part, f"joint {pname!r}", source)
            last = k == len(parts) - 1
            child = (unique(body) if body is not None else unique(f"{pname}_link")) if last else unique(f"{pname}_link")
            link(child, model.inertias[jid] if last else None, body if last else None)
            M = model.jointPlacements[jid] * placement if k == 0 else placement
            if pname in locked:
                M, kind, axis, pkm_type = M * _joint_motion(part, locked[pname], f"joint {pname!r}", source), \
                    "fixed", None, None
            joint(pname, kind, parent, child, M, axis)
            if pname in mimic:
                leader, mult, off = mimic[pname]
                etree.SubElement(robot[-1], "mimic", joint=leader, multiplier=repr(float(mult)), offset=repr(float(off)))
            if pkm_type:
                types[pname] = pkm_type
            parent = child
        link_of[jid] = parent
        if body is not None:
            primary.add(body)
    extra = [(f.name, f.parentJoint, f.placement) for f in model.frames[1:]
             if f.type in (pin.FrameType.BODY, pin.FrameType.OP_FRAME) and f.name not in primary
             and f.name not in skip_frames]
    for fname, _, _ in frames:
        if fname in taken or fname in fnames:
            raise SpecError(source, f"frame {fname!r} to add is already a name of the model")
    for fname, jid, M in extra + list(frames):
        child = unique(fname)
        link(child, frame=fname)
        joint(unique(f"{child}_fixed"), "fixed", link_of[jid], child, M)
    etree.indent(robot, space="  ")
    text = etree.tostring(robot, xml_declaration=True, encoding="utf-8", pretty_print=True).decode()
    check_urdf(text, source)
    return text, types


def gazebo_springs(root: etree._Element, source: str) -> dict[str, dict[str, float]]:
    """The joint springs a URDF states with Gazebo's URDF extension, ``<gazebo reference="JOINT">`` holding
    ``<springStiffness>`` and ``<springReference>`` (what the URDF-to-SDFormat converter makes SDFormat's ``<axis>
    <dynamics><spring_stiffness>``, ``<spring_reference>`` of; sdformat's "SDFormat extensions to URDF"):
    ``{joint: {"stiffness", "rest"}}`` as a spec's ``[springs]`` tables (:mod:`pkm.core.model.springs`), checked;
    a ``<gazebo>`` element naming a link, or a stiffness of 0, states none. The joint's damping is URDF's own
    ``<dynamics damping>``.

    Raises:
        SpecError: a value that is not a finite number, a negative stiffness, a spring on a joint neither revolute
            nor prismatic.
    """
    from pkm.core.model.springs import parse_springs

    types = {str(j.get("name")): j.get("type") for j in root.findall("joint")}
    found: dict[str, dict[str, float]] = {}
    for g in root.findall("gazebo"):
        joint, k, rest = g.get("reference"), g.findtext("springStiffness"), g.findtext("springReference")
        if joint not in types or (k is None and rest is None):
            continue
        try:
            values = {"stiffness": float(k or 0.0), "rest": float(rest or 0.0)}
        except ValueError:
            raise SpecError(source, f'<gazebo reference="{joint}"> (line {g.sourceline}): springStiffness '
                                    f"{k!r} or springReference {rest!r} is not a number") from None
        if values["stiffness"] == 0.0:
            continue
        if types[joint] not in ("revolute", "prismatic"):
            raise SpecError(source, f'<gazebo reference="{joint}"> (line {g.sourceline}): a spring on a '
                                    f"{types[joint]} joint (pkm reads the springs of revolute and prismatic joints)")
        found[str(joint)] = values
    return parse_springs(found, source) if found else {}


def write_gazebo_springs(root: etree._Element, springs: Mapping[str, Mapping[str, float]],
                         damping: Mapping[str, float]) -> None:
    """Write ``springs`` (``[springs]`` tables) into the URDF ``root`` as :func:`gazebo_springs` reads them: a
    ``<gazebo reference="JOINT">`` with ``<springStiffness>`` and ``<springReference>`` for each of non-zero
    stiffness, and ``damping`` (``{joint: its whole viscous damping}``, for the tables that state one) as the
    joint's ``<dynamics damping>`` (its friction kept)."""
    joints = {str(j.get("name")): j for j in root.findall("joint")}
    for g in root.findall("gazebo"):  # (a spring the file stated already: replaced, not stated twice)
        if g.get("reference") in springs:
            for el in [*g.findall("springStiffness"), *g.findall("springReference")]:
                g.remove(el)
            if len(g) == 0:
                root.remove(g)
    for name, table in springs.items():
        if name not in joints:
            continue
        if table.get("stiffness", 0.0) != 0.0:
            g = etree.SubElement(root, "gazebo", reference=name)
            etree.SubElement(g, "springStiffness").text = repr(float(table["stiffness"]))
            etree.SubElement(g, "springReference").text = repr(float(table.get("rest", 0.0)))
        if "damping" in table and name in damping:
            dyn = joints[name].find("dynamics")
            if dyn is None:
                dyn = etree.SubElement(joints[name], "dynamics")
            dyn.set("damping", repr(float(damping[name])))
