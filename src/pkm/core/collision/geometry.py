"""A mechanism's collision geometry: the ``<collision>`` elements of its URDF text as Pinocchio's ``GeometryModel``
(coal shapes), and the pairs of bodies whose distance is checked.

**Where it comes from.** Every format pkm reads is imported as URDF text (:mod:`pkm.core.formats.base`), and the
collision geometry travels in it as URDF ``<collision>`` elements on the links: a URDF's own, an MJCF file's geoms
(:mod:`pkm.core.formats.mjcf`), an SDF file's ``<collision>`` elements (:mod:`pkm.core.formats.sdf`), the shipped
designs' primitives (:meth:`pkm.core.model.urdf.UrdfBuilder.collision`). pkm reads them itself (urdfdom, Pinocchio's
URDF parser, knows no capsule): ``<box size="x y z">`` (full side lengths), ``<cylinder radius length>`` and
``<capsule radius length>`` (along the local z axis, centred; a capsule's length between its hemispheres' centres,
Gazebo's and pkm's extension of URDF), ``<sphere radius>``, ``<ellipsoid radii="a b c">`` (pkm's, for MJCF's
ellipsoids), ``<mesh filename scale>``: its convex hull (as MuJoCo collides meshes), the file found as given
(absolute), relative to the model file's folder, or ``package://NAME/rest`` in a folder ``NAME`` above the model
file's or on ``ROS_PACKAGE_PATH`` (``package:///rest``: the model file's folder). A mesh that cannot be found or
loaded is left out with a note (:attr:`CollisionModel.notes`) and a :class:`~pkm.errors.PkmWarning` naming the link
and the file; a malformed primitive is a :class:`~pkm.errors.SpecError`.

Each shape is attached to the Pinocchio joint that moves its link, placed by the link's frame (a link on fixed
joints is a frame of the joint Pinocchio merges it into) times the ``<collision>``'s ``<origin>``.

**The pairs checked.** Every pair of bodies (links with collision geometry) except, each with its reason
(:attr:`CollisionModel.excluded`):

* ``"rigid"``: two links of one rigid body (fixed joints between them): their distance never changes;
* ``"neighbours"``: a body and its parent in the tree, the nearest body with geometry up the tree (a joint joins
  them; massless links between, a universal joint's cross, do not separate them);
* ``"closure"``: the bodies a loop closure joins (they touch at the joint), the nearest with geometry at or above
  each of its frames;
* ``"contact at the reference"``: the pairs whose distance at :attr:`~pkm.core.Mechanism.q_reference` is at most
  :data:`CONTACT_RTOL` times the mechanism's characteristic length (touching or penetrating by design: a pin in its
  bore);
* ``"filtered"``: bodies none of whose shapes may collide by the file's ``contype`` and ``conaffinity`` (an MJCF
  file's bit masks, MuJoCo's rule: ``contype`` of one and ``conaffinity`` of the other share a bit; written as
  attributes of ``<collision>``; a pair of bodies checked compares only the shapes that may collide);
* ``"spec"``: the closure spec's ``[collision] exclude = [["body_a", "body_b"], ...]``.

A spec's ``[collision] include = [...]`` checks a pair the rules above would leave out (not one it excludes).
"""

from __future__ import annotations

import math
import os
import re
import threading
import warnings
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

import numpy as np
import pinocchio as pin

from pkm._derived import derived
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.urdf import floats, parse_xml
from pkm.errors import NoCollisionGeometryError, NonFiniteError, PkmWarning, SpecError, UnknownNameError

#: A pair of bodies whose distance at the reference configuration is at most this times the characteristic length
#: is in contact by design and not checked (scale-free: 0.1 mm on a robot of 1 m, 5 µm on one of 5 cm).
CONTACT_RTOL = 1e-4
#: coal's GJK and EPA tolerances, the precision of a distance (coal's are in metres), are this times the
#: characteristic length (scale-free): distances to about 1e-12 of the mechanism's size (a cylinder's, which GJK
#: approaches iteratively, to 3e-12 of it; the time is the same as at 1e-10).
GJK_RTOL = 1e-12
#: coal answers a pair whose GJK failed with ``-DBL_MAX``; a distance at or below this [m] is that failure.
FAILED = -1e300
#: The tolerances (times the characteristic length) a pair whose GJK failed at :data:`GJK_RTOL` is computed again at,
#: in turn (the 3-RRR's crossing distal cylinders converge at 1e-6 of the size only: 12 mm deep to 1e-6 m).
FALLBACK_RTOLS = (1e-9, 1e-6)
#: The primitive shapes ``<collision>`` elements state and their attributes.
PRIMITIVES: dict[str, tuple[tuple[str, int], ...]] = {
    "box": (("size", 3),), "cylinder": (("radius", 1), ("length", 1)), "capsule": (("radius", 1), ("length", 1)),
    "sphere": (("radius", 1),), "ellipsoid": (("radii", 3),)}


@dataclass(frozen=True)
class Collision:
    """One ``<collision>`` element of a link.

    Attributes:
        link: The link that carries it.
        name: A name unique among the mechanism's shapes (``<link>/<k>``, its ``k``-th on the link).
        kind: ``box``, ``cylinder``, ``capsule``, ``sphere``, ``ellipsoid`` or ``mesh``.
        size: The primitive's sizes [m] (box: x y z; cylinder and capsule: radius, length; sphere: radius;
            ellipsoid: its three radii); a mesh's scale.
        origin: Its placement in the link's frame.
        filename: A mesh's file name as the model states it (else None).
        contype: MuJoCo's ``contype`` bit mask (an MJCF geom's; pkm's ``<collision contype>`` attribute), 1 by default.
        conaffinity: MuJoCo's ``conaffinity``: two shapes may collide where ``contype`` of either and ``conaffinity``
            of the other share a bit (MuJoCo's rule), 1 by default.
    """

    link: str
    name: str
    kind: str
    size: tuple[float, ...]
    origin: pin.SE3
    filename: str | None = None
    contype: int = 1
    conaffinity: int = 1

    def may_collide(self, other: Collision) -> bool:
        """MuJoCo's filter: ``contype`` of one and ``conaffinity`` of the other share a bit, either way."""
        return bool(self.contype & other.conaffinity or other.contype & self.conaffinity)


def read_collisions(urdf: str, source: str = "<urdf>") -> list[Collision]:
    """The ``<collision>`` elements of URDF text, in file order (the module doc says what is read).

    Raises:
        SpecError: a primitive without its sizes, a size not positive and finite, an unknown geometry.
    """
    root = parse_xml(urdf, source)
    out: list[Collision] = []
    for lel in root.findall("link"):
        link = str(lel.get("name"))
        for k, cel in enumerate(lel.findall("collision")):
            where = f"link {link!r} <collision> {k + 1}"
            org = cel.find("origin")
            xyz = floats(org.get("xyz", "0 0 0") if org is not None else "0 0 0", 3, f"{where} origin xyz", source)
            rpy = floats(org.get("rpy", "0 0 0") if org is not None else "0 0 0", 3, f"{where} origin rpy", source)
            geometry = cel.find("geometry")
            shapes = [el for el in (geometry if geometry is not None else ()) if isinstance(el.tag, str)]
            if len(shapes) != 1:
                raise SpecError(source, f"{where}: <geometry> must hold one shape, it holds {len(shapes)}")
            el = shapes[0]
            origin = pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz))
            mask: dict[str, int] = {}
            for key in ("contype", "conaffinity"):
                if cel.get(key) is not None:
                    v = floats(cel.get(key), 1, f"{where} {key}", source)[0]
                    if v != int(v) or v < 0:
                        raise SpecError(source, f"{where}: {key} must be a non-negative integer (a bit mask)")
                    mask[key] = int(v)
            if el.tag == "mesh":
                filename = el.get("filename")
                if not filename:
                    raise SpecError(source, f"{where}: <mesh> without a filename")
                scale = floats(el.get("scale", "1 1 1"), 3, f"{where} mesh scale", source)
                out.append(Collision(link, f"{link}/{k}", "mesh", tuple(scale), origin, filename,
                                     mask.get("contype", 1), mask.get("conaffinity", 1)))
                continue
            if el.tag not in PRIMITIVES:
                raise SpecError(source, f"{where}: <{el.tag}> is not a shape pkm reads ({', '.join(PRIMITIVES)}, "
                                        "mesh)")
            size: list[float] = []
            for attr, n in PRIMITIVES[el.tag]:
                if el.get(attr) is None:
                    raise SpecError(source, f"{where}: <{el.tag}> needs {attr}=")
                size += floats(el.get(attr), n, f"{where} {el.tag} {attr}", source)
            if not all(v > 0.0 for v in size):
                raise SpecError(source, f"{where}: <{el.tag}> sizes must be positive [m], got {size}")
            out.append(Collision(link, f"{link}/{k}", el.tag, tuple(size), origin, None, mask.get("contype", 1),
                                 mask.get("conaffinity", 1)))
    return out


def placed_collisions(mech: Mechanism) -> tuple[list[tuple[Collision, int, pin.SE3]], list[str]]:
    """Each ``<collision>`` of ``mech``'s URDF text with the Pinocchio joint that moves it and its placement in that
    joint's frame (the link's frame times its origin); and the links the model has no body of (their geometry left
    out). What :class:`CollisionModel` builds on, and the writers of other formats write."""
    model = mech.model
    out, missing = [], []
    for c in read_collisions(mech.urdf, mech.source) if mech.urdf is not None else []:
        if not model.existFrame(c.link, pin.FrameType.BODY):
            missing.append(c.link)
            continue
        f = model.frames[model.getFrameId(c.link, pin.FrameType.BODY)]
        out.append((c, int(f.parentJoint), f.placement * c.origin))
    return out, list(dict.fromkeys(missing))


def model_folders(mech: Mechanism) -> list[Path]:
    """The folders a mechanism's relative mesh paths are read from: its model file's (and the spec's) folder."""
    source = mech.source
    m = re.search(r"\((.*)\)$", source)  # (a package's model: "name (path)")
    candidates = [Path(m.group(1)) if m else Path(source)]
    out: list[Path] = []
    for path in candidates:
        if path.is_file():
            out.append(path.parent)
            if path.suffix == ".toml":
                out.append(path.parent / PurePosixPath(mech.spec.urdf).parent)
    return list(dict.fromkeys(out))


def resolve_mesh(filename: str, folders: Iterable[Path]) -> Path | None:
    """The file a ``<mesh filename>`` names (module doc), or None where it is nowhere to be found."""
    folders = list(folders)
    if filename.startswith("file://"):
        filename = filename[len("file://"):]
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://"):].partition("/")
        roots = [f for f in folders] if not package else \
            [a for f in folders for a in (f, *f.parents) if a.name == package] \
            + [Path(p) / package for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
        return next((r / rest for r in roots if (r / rest).is_file()), None)
    path = Path(filename)
    if path.is_absolute():
        return path if path.is_file() else None
    return next((f / path for f in folders if (f / path).is_file()), None)


def shape(c: Collision, folders: Iterable[Path]) -> tuple[object | None, str]:
    """The coal shape of ``c`` and, for a mesh, the file read (``(None, reason)`` where it cannot be loaded)."""
    import coal  # type: ignore[import-untyped]  # (Pinocchio's collision library: no type information)

    s = c.size
    if c.kind == "box":
        return coal.Box(*s), ""
    if c.kind == "cylinder":
        return coal.Cylinder(s[0], s[1]), ""
    if c.kind == "capsule":
        return coal.Capsule(s[0], s[1]), ""
    if c.kind == "sphere":
        return coal.Sphere(s[0]), ""
    if c.kind == "ellipsoid":
        return coal.Ellipsoid(*s), ""
    assert c.filename is not None
    path = resolve_mesh(c.filename, folders)
    if path is None:
        return None, f"mesh {c.filename!r} not found"
    try:
        bvh = coal.MeshLoader().load(str(path), np.array(s))
        bvh.buildConvexHull(True, "Qt")
        return bvh.convex, str(path)
    except Exception as exc:  # coal's loader raises ValueError/RuntimeError with assimp's words
        return None, f"mesh {str(path)!r} cannot be loaded ({str(exc).strip().splitlines()[-1][:120]})"


class CollisionModel:
    """A mechanism's collision geometry and the pairs of bodies checked (module doc), made once per mechanism:
    :meth:`of`.

    Attributes:
        geometry: Pinocchio's ``GeometryModel``: one object per shape, on the joint that moves it; its collision
            pairs are the checked bodies' pairs of shapes.
        shapes: The :class:`Collision` read, in the order of ``geometry``'s objects.
        bodies: The bodies (links) with collision geometry, in the order of their first shape.
        pairs: The pairs of bodies checked, ``(body_a, body_b)`` with ``body_a`` first in :attr:`bodies`.
        excluded: ``{(body_a, body_b): reason}``: the pairs not checked (module doc), the reason a sentence that
            starts with its rule (``"neighbours: ..."``).
        notes: What was left out (meshes not found) or read so, one sentence each.
        pair_of: For each of ``geometry``'s collision pairs, the index of its pair of bodies in :attr:`pairs`.
        body_joints: ``{body: the Pinocchio joint that moves it}``.
    """

    def __init__(self, mech: Mechanism):
        mech = check_mechanism(mech)
        self.mech = mech
        self._local = threading.local()
        model = mech.model
        placed, missing = placed_collisions(mech)
        notes = [f"link {link!r}: its collision geometry is left out (no body of the model)" for link in missing]
        folders = model_folders(mech)
        gm = pin.GeometryModel()
        shapes: list[Collision] = []
        joint_of: dict[str, int] = {}
        lost: list[str] = []
        for c, joint, placement in placed:
            geom, what = shape(c, folders)
            if geom is None:
                lost.append(f"link {c.link!r}: {what}")
                continue
            fid = model.getFrameId(c.link, pin.FrameType.BODY)
            gm.addGeometryObject(pin.GeometryObject(c.name, joint, fid, placement, geom))
            shapes.append(c)
            joint_of[c.link] = joint
        if lost:  # (one sentence and one warning for them all: a file may name a hundred meshes not shipped)
            said = (f"{len(lost)} collision shape{'s' if len(lost) > 1 else ''} left out: " + "; ".join(lost[:5])
                    + (f"; and {len(lost) - 5} more" if len(lost) > 5 else ""))
            notes.append(said)
            warnings.warn(f"{mech.source}: {said}", PkmWarning, stacklevel=3)
        self.geometry = gm
        self.shapes: tuple[Collision, ...] = tuple(shapes)
        self.bodies: tuple[str, ...] = tuple(dict.fromkeys(c.link for c in shapes))
        self.notes: tuple[str, ...] = tuple(notes)
        self.body_joints: dict[str, int] = joint_of
        self.excluded: dict[tuple[str, str], str] = {}
        self.pairs: tuple[tuple[str, str], ...] = ()
        self.pair_of = np.zeros(0, dtype=int)
        self.flipped = np.zeros(0, dtype=bool)
        #: ``(joint, start in q)`` of each quaternion of ``q`` (free-flyers', spherical joints'): the map's checks.
        self.quaternions = tuple((j.name, j.idx_q + 3 if j.kind == "JointModelFreeFlyer" else j.idx_q)
                                 for j in mech.joints.values() if j.kind in ("JointModelFreeFlyer",
                                                                             "JointModelSpherical"))
        self._choose_pairs()  # (the spec's pairs checked even where there are fewer than two bodies)

    @classmethod
    def of(cls, mech: Mechanism) -> CollisionModel:
        """The collision model of ``mech``, made on first use and kept with it (remade when its reference
        configuration changes: the pairs in contact there are decided at it)."""
        return derived(check_mechanism(mech), cls)

    # ------------------------------------------------------------------ the pairs
    def _structural(self) -> dict[tuple[str, str], str]:
        """The pairs the tree and the closures exclude, with their reasons."""
        mech, model = self.mech, self.mech.model
        carriers = set(self.body_joints.values())

        def owner(j: int) -> int | None:  # the nearest joint at or above j that carries geometry
            while j not in carriers:
                if j == 0:
                    return None
                j = model.parents[j]
            return j

        parent = {j: owner(model.parents[j]) if j else None for j in carriers}
        closures: dict[frozenset[int | None], str] = {}
        for c, (fa, fb) in zip(mech.spec.closures, mech.closure_frames):
            ends = {owner(model.frames[fa].parentJoint), owner(model.frames[fb].parentJoint)}
            if None not in ends and len(ends) == 2:
                closures.setdefault(frozenset(ends), c.name)
        out = {}
        for i, a in enumerate(self.bodies):
            for b in self.bodies[i + 1:]:
                ja, jb = self.body_joints[a], self.body_joints[b]
                if ja == jb:
                    out[(a, b)] = f"rigid: one body (joint {model.names[ja]!r}), their distance never changes"
                elif parent[jb] == ja or parent[ja] == jb:
                    child = jb if parent[jb] == ja else ja
                    out[(a, b)] = f"neighbours: joint {model.names[child]!r} joins them"
                elif frozenset((ja, jb)) in closures:
                    out[(a, b)] = f"closure: the loop closure {closures[frozenset((ja, jb))]!r} joins them"
                elif not any(sa.may_collide(sb) for sa in self.shapes if sa.link == a
                             for sb in self.shapes if sb.link == b):
                    out[(a, b)] = "filtered: the file's contype and conaffinity let none of their shapes collide"
        return out

    def _named(self, pairs: Iterable[Iterable[str]], key: str) -> list[tuple[str, str]]:
        out = []
        for pair in pairs:
            a, b = pair
            for name in (a, b):
                if name not in self.bodies:
                    raise UnknownNameError("body with collision geometry", name, self.bodies,
                                           f"{self.mech.name} ([collision] {key})")
            if a == b:
                raise SpecError(self.mech.source, f"[collision] {key} pairs {a!r} with itself")
            out.append(self._ordered(a, b))
        return out

    def _ordered(self, a: str, b: str) -> tuple[str, str]:
        return (a, b) if self.bodies.index(a) < self.bodies.index(b) else (b, a)

    def _choose_pairs(self) -> None:
        spec = self.mech.spec
        exclude = set(self._named(spec.collision_exclude, "exclude"))
        include = set(self._named(spec.collision_include, "include"))
        both = exclude & include
        if both:
            raise SpecError(self.mech.source, f"[collision] both excludes and includes the pair {sorted(both)[0]}")
        excluded = {p: r for p, r in self._structural().items() if p not in include}
        excluded.update({p: "spec: the closure spec's [collision] exclude" for p in exclude})
        candidates = [(a, b) for i, a in enumerate(self.bodies) for b in self.bodies[i + 1:] if (a, b) not in excluded]
        self._set_pairs(candidates, include)
        if candidates:
            L = self.mech.characteristic_length
            d = self.body_distances(self.mech.q_reference)
            for (a, b), dist in zip(candidates, d):
                if dist <= CONTACT_RTOL * L and (a, b) not in include:
                    excluded[(a, b)] = (f"contact at the reference: {dist:.3g} m apart, at most {CONTACT_RTOL:g} of "
                                        f"the size {L:.3g} m")
        self.excluded = {p: excluded[p] for i, a in enumerate(self.bodies) for b in self.bodies[i + 1:]
                         if (p := (a, b)) in excluded}
        self._set_pairs([p for p in candidates if p not in excluded], include)

    def _set_pairs(self, pairs: list[tuple[str, str]], include: set[tuple[str, str]] | None = None) -> None:
        """Check ``pairs``: every pair of their shapes that may collide (MuJoCo's filter), all of those ``include``
        names."""
        include = include or set()
        self.pairs = tuple(pairs)
        index = {p: k for k, p in enumerate(pairs)}
        gm = self.geometry
        gm.removeAllCollisionPairs()
        pair_of, flipped = [], []
        for i in range(gm.ngeoms):
            for j in range(i + 1, gm.ngeoms):
                p = self._ordered(self.shapes[i].link, self.shapes[j].link) \
                    if self.shapes[i].link != self.shapes[j].link else None
                if p in index and (p in include or self.shapes[i].may_collide(self.shapes[j])):
                    gm.addCollisionPair(pin.CollisionPair(i, j))
                    pair_of.append(index[p])
                    flipped.append(self.shapes[i].link != p[0])
        self.pair_of = np.array(pair_of, dtype=int)
        #: For each collision pair, whether its first shape is on the second body of its pair in :attr:`pairs`.
        self.flipped = np.array(flipped, dtype=bool)
        self._local = threading.local()  # (the data follow the pairs)

    # ------------------------------------------------------------------ evaluation
    @property
    def data(self) -> pin.GeometryData:
        """This thread's ``GeometryData``: signed distances (negative: penetration), to :data:`GJK_RTOL` of the
        characteristic length, each configuration's independent of those computed before (GJK from coal's default
        guess, not the pair's last result)."""
        try:
            return self._local.data
        except AttributeError:
            gd = self.geometry.createData()
            tol = GJK_RTOL * self.mech.characteristic_length
            with warnings.catch_warnings():  # (coal deprecates the flag for gjk_initial_guess, which it overrides)
                warnings.simplefilter("ignore", DeprecationWarning)
                for r in gd.distanceRequests:
                    r.enable_signed_distance = True
                    r.gjk_tolerance = tol
                    r.epa_tolerance = tol
                    # Pinocchio's requests start each GJK from the pair's last result: on the Delta's thin parallel
                    # forearms that warm start returned -1.8e308 or a distance 1 cm off, depending on the
                    # configurations computed before; every configuration from coal's default guess instead
                    r.enable_cached_gjk_guess = False
            self._local.data = gd
            return gd

    def compute(self, q: np.ndarray) -> int:
        """Every collision pair's signed distance at ``q`` (nq, not checked) into :attr:`data`'s results; the index
        of the closest pair. Where coal's GJK fails on a pair (it answers ``-DBL_MAX``: the Delta's base disc and a
        forearm 5 mm thick at 1e-12 of the size), that pair again with Nesterov's acceleration, then at each of
        :data:`FALLBACK_RTOLS` of the size (plain, then accelerated), until one converges.

        Raises:
            NonFiniteError: a pair fails every way (named).
        """
        gd, model, data, gm = self.data, self.mech.model, self.mech.data, self.geometry
        results = gd.distanceResults
        k = pin.computeDistances(model, data, gm, gd, q)
        if results[k].min_distance > FAILED:  # (a failure is the smallest: its result alone is read)
            return int(k)
        import coal  # type: ignore[import-untyped]

        L, tol = self.mech.characteristic_length, GJK_RTOL * self.mech.characteristic_length
        nesterov, plain = coal.GJKVariant.NesterovAcceleration, coal.GJKVariant.DefaultGJK
        bad = [i for i, r in enumerate(results) if not r.min_distance > FAILED]
        try:
            for variant, rtol in ((nesterov, GJK_RTOL), *((v, t) for t in FALLBACK_RTOLS for v in (plain, nesterov))):
                for i in bad:
                    r = gd.distanceRequests[i]
                    r.gjk_variant, r.gjk_tolerance, r.epa_tolerance = variant, rtol * L, rtol * L
                k = pin.computeDistances(model, data, gm, gd, q)
                if results[k].min_distance > FAILED:
                    return int(k)
        finally:
            for i in bad:
                r = gd.distanceRequests[i]
                r.gjk_variant, r.gjk_tolerance, r.epa_tolerance = plain, tol, tol
        pair = gm.collisionPairs[k]
        raise NonFiniteError(f"the distance of {gm.geometryObjects[pair.first].name} and "
                             f"{gm.geometryObjects[pair.second].name}", results[k].min_distance,
                             f"coal's GJK failed at {GJK_RTOL:g} and {FALLBACK_RTOLS} of the size, with and without "
                             "Nesterov's acceleration")

    def distances(self, q: np.ndarray) -> np.ndarray:
        """The signed distance [m] of each of ``geometry``'s collision pairs at ``q`` (nq, not checked; as
        :meth:`compute`); the results (witness points, normals) are left in :attr:`data`."""
        self.compute(q)
        return np.array([r.min_distance for r in self.data.distanceResults])

    def body_distances(self, q: np.ndarray) -> np.ndarray:
        """The signed distance [m] of each pair of :attr:`pairs` at ``q``: its shapes' closest."""
        out = np.full(len(self.pairs), math.inf)
        np.minimum.at(out, self.pair_of, self.distances(q))
        return out

    def require(self) -> CollisionModel:
        """Itself, where it has pairs to check; else :class:`~pkm.errors.NoCollisionGeometryError` saying why."""
        if not self.bodies:
            raise NoCollisionGeometryError(self.mech.name, "no_geometry", (
                f"{self.mech.name}: " + (f"none of its collision geometry could be read ({'; '.join(self.notes)})"
                                         if self.notes else "its files carry no collision geometry")
                + ": add <collision> elements to the URDF's links (box, cylinder, sphere, <capsule radius length>, "
                  "mesh), geoms to an MJCF file's bodies, <collision> to an SDF file's links, or, for a shipped "
                  "design, UrdfBuilder.collision in its generator"))
        if not self.pairs:
            raise NoCollisionGeometryError(self.mech.name, "no_pairs", (
                f"{self.mech.name}: no pair of bodies to check: "
                + "; ".join(f"{a}-{b}: {r}" for (a, b), r in self.excluded.items())
                + ". A closure spec's [collision] include = [[\"body_a\", \"body_b\"]] checks one"))
        return self


__all__ = ["CONTACT_RTOL", "PRIMITIVES", "Collision", "CollisionModel", "model_folders", "placed_collisions",
           "read_collisions", "resolve_mesh", "shape"]
