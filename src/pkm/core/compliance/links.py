r"""Compliant links as virtual six-dimensional springs (the virtual-joint method of Pashkevich, Klimchik and Chablat).

A compliant link is a straight beam from its own frame's origin (where its parent joint is) to each of its
*attachments*: the joints it carries (its child joints), the closure frames and the end-effector frame on it (through
fixed joints). At each attachment ``a`` a virtual twist :math:`\xi_a = (\delta p, \delta\theta)` (world axes, at the
attachment's point :math:`o_a`) moves everything beyond it rigidly: the subtree of a child joint, or the closure or
end-effector frame itself; its stiffness is the inverse of the cantilever's tip compliance :math:`C_a` (the beam
clamped at the link's origin, loaded at the attachment). Each attachment is its own cantilever from the link's
origin: a link with several attachments (a platform) is modelled as that many beams.

A frame :math:`F` at :math:`p_F` beyond :math:`a` moves with the world-aligned twist
:math:`X(p_F - o_a)\,\xi_a`, :math:`X(r) = \begin{bmatrix} I & -[r]_\times \\ 0 & I \end{bmatrix}`: those are
the virtual coordinates' columns of the closure and end-effector Jacobians (:mod:`pkm.core.kinematics.constraints`'
conventions: world-aligned linear rows for a point closure, local rows for a frame closure).

**The beam** (:class:`Beam`): a circular or tubular section of Young's modulus ``E`` and shear modulus ``G``;
Euler-Bernoulli (``shear=False``, default) or Timoshenko (``shear=True``, Cowper's shear coefficient of a circular
or tubular section). Its tip compliance, with :math:`x` along the beam of length :math:`l`:
axial :math:`l/EA`, torsion :math:`l/GJ`, bending :math:`l^3/3EI` (+ :math:`l/\kappa G A` in shear),
:math:`l^2/2EI` coupling a tip force to the tip rotation, :math:`l/EI` a tip moment. A link may instead be given its
own 6 x 6 compliance at each attachment, in the link's frame's axes (``(dp, dtheta)`` per ``(f, m)``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pkm._derived import derived
from pkm.core.collision.geometry import Collision, placed_collisions
from pkm.core.model.mechanism import Mechanism
from pkm.errors import InvalidInputError, UnknownNameError
from pkm.validation import as_array, as_scalar, symmetric_positive_definite


@dataclass(frozen=True)
class Beam:
    """A straight beam of circular (``inner = 0``) or tubular section (module doc).

    Attributes:
        E: Young's modulus [Pa] (steel 2.1e11, aluminium 7e10, CFRP tube 1e11 along its axis).
        radius: The section's outer radius [m].
        inner: The inner radius of a tube [m] (0: solid).
        G: The shear modulus [Pa]; default ``E / 2.6`` (Poisson's ratio 0.3).
        shear: Timoshenko's shear deflection (Cowper's coefficient) on top of Euler-Bernoulli's bending.
    """

    E: float
    radius: float
    inner: float = 0.0
    G: float | None = None
    shear: bool = False

    def __post_init__(self) -> None:
        as_scalar(self.E, "Beam.E", low=0.0, strict_low=True, unit="Pa")
        as_scalar(self.radius, "Beam.radius", low=0.0, strict_low=True, unit="m")
        as_scalar(self.inner, "Beam.inner", low=0.0, high=self.radius, unit="m")
        if self.inner >= self.radius:
            raise InvalidInputError("Beam.inner", f"a tube's inner radius is below its outer ({self.radius:g} m)",
                                    self.inner)
        if self.G is not None:
            as_scalar(self.G, "Beam.G", low=0.0, strict_low=True, unit="Pa")

    def compliance(self, length: float) -> np.ndarray:
        """The cantilever's tip compliance (6 x 6) of a beam of ``length`` [m], ``x`` along it: ``(dp, dtheta)``
        per tip ``(f, m)``, about the tip."""
        E, l = float(self.E), float(length)
        G = float(self.G) if self.G is not None else E / 2.6
        r, ri = float(self.radius), float(self.inner)
        A = math.pi * (r**2 - ri**2)
        I = math.pi * (r**4 - ri**4) / 4.0
        J = 2.0 * I
        C = np.zeros((6, 6))
        C[0, 0] = l / (E * A)
        C[3, 3] = l / (G * J)
        bend = l**3 / (3.0 * E * I)
        if self.shear:
            nu, m = E / (2.0 * G) - 1.0, ri / r
            kappa = 6.0 * (1 + nu) * (1 + m**2) ** 2 / ((7 + 6 * nu) * (1 + m**2) ** 2 + (20 + 12 * nu) * m**2)
            bend += l / (kappa * G * A)
        for u, t, sign in ((1, 5, 1.0), (2, 4, -1.0)):  # (a force along y turns the tip about +z; along z, about -y)
            C[u, u] = bend
            C[u, t] = C[t, u] = sign * l**2 / (2.0 * E * I)
            C[t, t] = l / (E * I)
        return C


@dataclass(frozen=True)
class Material:
    """A linear elastic isotropic material: the links as beams of their collision primitive's section
    (``pkm.stiffness(mech, q, links=Material(...))``, :func:`beams_from_collisions`).

    Attributes:
        E: Young's modulus [Pa].
        G: The shear modulus [Pa]; default ``E / 2.6`` (Poisson's ratio 0.3, as :class:`Beam`).
        shear: Timoshenko's shear deflection on top of Euler-Bernoulli's bending (:class:`Beam`).
    """

    E: float
    G: float | None = None
    shear: bool = False

    def __post_init__(self) -> None:
        as_scalar(self.E, "Material.E", low=0.0, strict_low=True, unit="Pa")
        if self.G is not None:
            as_scalar(self.G, "Material.G", low=0.0, strict_low=True, unit="Pa")

    def beam(self, radius: float) -> Beam:
        """A solid circular beam of this material and ``radius`` [m]."""
        return Beam(E=self.E, radius=radius, G=self.G, shear=self.shear)


#: Structural steel (E 210 GPa, G 81 GPa).
STEEL = Material(E=2.1e11, G=8.1e10)
#: Aluminium alloy (E 70 GPa, G 26 GPa).
ALUMINIUM = Material(E=7.0e10, G=2.6e10)
#: The materials named by :func:`as_links` (the command line's ``--links``, the service's ``links``).
MATERIALS = {"steel": STEEL, "aluminium": ALUMINIUM, "aluminum": ALUMINIUM}


def as_links(value: object) -> str | Material | None:
    """A faces' ``links`` (the command line, the service) as :func:`pkm.stiffness` takes it: ``None`` or
    ``"spec"`` (the spec's ``[links]``), ``"rigid"``, a name of :data:`MATERIALS`, or ``{"E": Pa, "G": Pa}`` (``G``
    optional) a :class:`Material`.

    Raises:
        InvalidInputError: anything else, saying what is read.
    """
    if value is None or isinstance(value, Material):
        return value
    if isinstance(value, str) and value in ("spec", "rigid", *MATERIALS):
        return None if value == "spec" else "rigid" if value == "rigid" else MATERIALS[value]
    if isinstance(value, Mapping) and "E" in value and set(value) <= {"E", "G"}:
        return Material(E=as_scalar(value["E"], "links E", unit="Pa"),
                        G=as_scalar(value["G"], "links G", unit="Pa") if value.get("G") is not None else None)
    raise InvalidInputError("links", "spec, rigid, " + ", ".join(MATERIALS) + ", or the moduli E [Pa] and optionally "
                                     "G [Pa]", value)


def law_fields(law: object) -> dict[str, object]:
    """A compliant link's law as the faces answer it: a :class:`Beam`'s ``radius``, ``inner`` [m], ``E``, ``G``
    [Pa] (``G`` as used) and ``shear``; else its 6 x 6 ``compliance``."""
    if isinstance(law, Beam):
        return {"radius": law.radius, "inner": law.inner, "E": law.E,
                "G": law.G if law.G is not None else law.E / 2.6, "shear": law.shear}
    return {"compliance": np.asarray(law, dtype=float)}


#: The largest angle between a cylinder's or capsule's axis and a span of its link for the primitive's radius to be
#: taken as that beam's section [deg].
AXIS_TOL_DEG = 5.0


def _shapes(mech: Mechanism) -> dict[str, list[Collision]]:
    """``{link: its collision shapes}`` (:func:`~pkm.core.collision.geometry.placed_collisions`), read once a
    mechanism."""
    out: dict[str, list[Collision]] = {}
    for c, _, _ in placed_collisions(mech)[0]:
        out.setdefault(c.link, []).append(c)
    return out


def beams_from_collisions(mech: Mechanism, data: pin.Data, material: Material) \
        -> tuple[dict[str, Beam], dict[str, str]]:
    """``({link: Beam}, {link: why it is taken rigid})``: each link that carries something (a joint, a closure or
    the end-effector frame) as a solid circular :class:`Beam` of ``material``, its radius its collision geometry's
    (:mod:`pkm.core.collision.geometry`) where that is one cylinder or capsule, at least as long as its diameter (a
    disc is no beam), whose axis lies within :data:`AXIS_TOL_DEG` of each of the link's spans (from its origin to
    what it carries, at the placements in ``data``); every other link that carries something is rigid, with the
    reason."""
    m = mech.model
    shapes = derived(mech, _shapes)
    beams: dict[str, Beam] = {}
    rigid: dict[str, str] = {}
    cos_tol = math.cos(math.radians(AXIS_TOL_DEG))
    for fid in derived(mech, _carriers):
        f = m.frames[fid]
        carried = _carried(mech, data, fid)
        own = shapes.get(f.name, [])
        if not own:
            rigid[f.name] = "no collision geometry"
            continue
        if len(own) > 1 or own[0].kind not in ("cylinder", "capsule"):
            rigid[f.name] = f"its collision geometry is {', '.join(c.kind for c in own)}, not one cylinder or capsule"
            continue
        c = own[0]
        radius, length = c.size
        if length < 2.0 * radius:
            rigid[f.name] = f"its {c.kind} is shorter ({length:.3g} m) than its diameter ({2 * radius:.3g} m): no beam"
            continue
        root = data.oMf[fid]
        axis = root.rotation @ c.origin.rotation[:, 2]
        spans = [(label, point - root.translation) for _, label, _, _, point in carried]
        short = [label for label, d in spans if np.linalg.norm(d) == 0.0]
        if short:
            rigid[f.name] = f"its {', '.join(short)} at its origin: a beam of no length"
            continue
        across = [label for label, d in spans if abs(float(axis @ d)) < cos_tol * float(np.linalg.norm(d))]
        if across:
            rigid[f.name] = (f"its {c.kind}'s axis is more than {AXIS_TOL_DEG:g} deg off its span to "
                             f"{', '.join(across)}")
            continue
        beams[f.name] = material.beam(radius)
    return beams, rigid


@dataclass(frozen=True)
class Attachment:
    """One virtual spring: where a compliant link carries something (module doc).

    Attributes:
        link: The compliant link's name.
        what: The joint or frame it carries.
        point: The attachment's point ``o_a`` (world) [m].
        stiffness: The virtual spring's 6 x 6 stiffness, world axes, about ``o_a``.
        beyond: The joints whose every frame moves with the virtual twist (a child joint's subtree; empty for a
            frame attachment).
        frame: The frame that moves with it where the attachment is a frame (closure or end effector), else -1.
    """

    link: str
    what: str
    point: np.ndarray
    stiffness: np.ndarray
    beyond: frozenset[int]
    frame: int


def _carried_by(model: pin.Model, fid: int, link: int) -> bool:
    """Whether frame ``fid`` hangs on the link of BODY frame ``link`` through fixed joints and merged links (up its
    ``parentFrame`` chain without crossing a joint); a JOINT frame from its parent frame (the link that carries the
    joint). A link does not carry its own frame."""
    cur = model.frames[fid].parentFrame if model.frames[fid].type == pin.FrameType.JOINT else fid
    if cur == link and fid == link:
        return False
    while True:
        if cur == link:
            return True
        if cur == 0 or model.frames[cur].type == pin.FrameType.JOINT:
            return False
        cur = model.frames[cur].parentFrame


def attachments(mech: Mechanism, data: pin.Data, links: Mapping[str, object]) -> list[Attachment]:
    """The virtual springs of ``links`` (``{link: Beam or 6 x 6 compliance}``) at the placements in ``data``
    (frames updated)."""
    m = mech.model
    bodies = {f.name: i for i, f in enumerate(m.frames) if f.type == pin.FrameType.BODY}
    out: list[Attachment] = []
    for name, law in links.items():
        if name not in bodies:
            raise UnknownNameError("link", str(name), bodies, mech.name)
        fid = bodies[name]
        if not isinstance(law, Beam):
            law = as_array(law, f"links[{name!r}]", "a Beam, or a 6 x 6 compliance [m/N, m/(N m); rad/N, rad/(N m)]")
            if law.shape != (6, 6) or not symmetric_positive_definite(law):
                raise InvalidInputError(f"links[{name!r}]", "a 6 x 6 compliance is symmetric positive definite", law)
        carried = _carried(mech, data, fid)
        if not carried:
            raise InvalidInputError(f"links[{name!r}]", "the link carries no joint, closure or end effector: its "
                                                        "compliance would move nothing", name)
        root = data.oMf[fid]
        for what, label, beyond, frame, point in carried:
            C = law.compliance(_length(root.translation, point, name, label)) if isinstance(law, Beam) else None
            R = _beam_axes(root.translation, point) if C is not None else root.rotation
            R6 = np.kron(np.eye(2), R)
            C_world = R6 @ (C if C is not None else law) @ R6.T
            out.append(Attachment(name, what, point.copy(), np.linalg.inv(0.5 * (C_world + C_world.T)), beyond,
                                  frame))
    return out


def _carriers(mech: Mechanism) -> dict[int, list[tuple[str, str, frozenset[int], int, int]]]:
    """``{BODY frame: [(what, label, beyond, frame, joint), ...]}``: what each link carries (module doc; ``frame``
    -1 for a joint, ``joint`` -1 for a frame), the links that carry nothing left out: the tree's, made once a
    mechanism (:func:`pkm._derived.derived`)."""
    m = mech.model
    frames = {f for pair in mech.closure_frames for f in pair} | {mech.ee_frame}
    out: dict[int, list[tuple[str, str, frozenset[int], int, int]]] = {}
    for fid, f in enumerate(m.frames):
        if f.type != pin.FrameType.BODY:
            continue
        carried = [(m.names[j], f"joint {m.names[j]}", frozenset(m.subtrees[j]), -1, j) for j in range(1, m.njoints)
                   if _carried_by(m, m.getFrameId(m.names[j], pin.FrameType.JOINT), fid)]
        carried += [(m.frames[g].name, f"frame {m.frames[g].name}", frozenset(), g, -1)
                    for g in sorted(frames) if _carried_by(m, g, fid)]
        if carried:
            out[fid] = carried
    return out


def _carried(mech: Mechanism, data: pin.Data, fid: int) -> list[tuple[str, str, frozenset[int], int, np.ndarray]]:
    """``(what, label, beyond, frame, point)`` of each joint, closure or end-effector frame the link of BODY frame
    ``fid`` carries (module doc), at the placements in ``data``."""
    return [(what, label, beyond, frame, data.oMf[frame].translation if frame >= 0 else data.oMi[j].translation)
            for what, label, beyond, frame, j in derived(mech, _carriers).get(fid, [])]


def _length(root: np.ndarray, point: np.ndarray, link: str, label: str) -> float:
    length = float(np.linalg.norm(point - root))
    if length == 0.0:
        raise InvalidInputError(f"links[{link!r}]", f"its {label} lies at the link's origin: a beam of no length", link)
    return length


def _beam_axes(root: np.ndarray, point: np.ndarray) -> np.ndarray:
    """A rotation whose x axis runs from ``root`` to ``point`` (the other two any: the section is round)."""
    x = (point - root) / np.linalg.norm(point - root)
    y = np.cross(x, [0.0, 0.0, 1.0] if abs(x[2]) < 0.9 else [1.0, 0.0, 0.0])
    y /= np.linalg.norm(y)
    return np.column_stack([x, y, np.cross(x, y)])


def _carry(r: np.ndarray) -> np.ndarray:
    """``X(r)``: the world-aligned twist at a point ``r`` away from a twist's reference point (6 x 6)."""
    X = np.eye(6)
    X[:3, 3:] = -pin.skew(r)
    return X


def virtual_columns(mech: Mechanism, data: pin.Data, att: list[Attachment]) -> tuple[np.ndarray, np.ndarray]:
    """The closure Jacobian's (n_constraints x 6k) and the end effector's (6 x 6k) columns of the virtual twists, in
    :mod:`pkm.core.kinematics.constraints`' conventions (module doc)."""
    m = mech.model
    Vc = np.zeros((mech.n_constraints, 6 * len(att)))
    Vee = np.zeros((6, 6 * len(att)))

    def moved(f: int, a: Attachment) -> np.ndarray:
        """The world-aligned twist of frame ``f`` per virtual twist of ``a`` (6 x 6; zeros where ``f`` stays)."""
        if f == a.frame or m.frames[f].parentJoint in a.beyond:
            return _carry(data.oMf[f].translation - a.point)
        return np.zeros((6, 6))

    def local(f: int, X: np.ndarray) -> np.ndarray:
        return np.kron(np.eye(2), data.oMf[f].rotation.T) @ X

    for i, a in enumerate(att):
        cols = slice(6 * i, 6 * i + 6)
        k = 0
        for c, (fa, fb) in zip(mech.spec.closures, mech.closure_frames):
            if c.type == "point":
                Vc[k:k + 3, cols] = moved(fa, a)[:3] - moved(fb, a)[:3]
                k += 3
            else:
                aMb = data.oMf[fa].actInv(data.oMf[fb])
                Vc[k:k + 6, cols] = local(fa, moved(fa, a)) - aMb.toActionMatrix() @ local(fb, moved(fb, a))
                k += 6
        Vee[:, cols] = moved(mech.ee_frame, a)
    return Vc, Vee


__all__ = ["ALUMINIUM", "AXIS_TOL_DEG", "MATERIALS", "STEEL", "Attachment", "Beam", "Material", "as_links",
           "attachments", "beams_from_collisions", "law_fields", "virtual_columns"]
