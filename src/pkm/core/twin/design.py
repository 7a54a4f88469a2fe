"""Designs as kernel inputs: which of a mechanism's numbers a twin takes as symbols, so that one compiled library
serves every design of a family.

A design parameter is named as the sweeps name it (:mod:`pkm.sweeps.family`):

* ``JOINT.x``, ``JOINT.y``, ``JOINT.z`` [m], ``JOINT.roll``, ``JOINT.pitch``, ``JOINT.yaw`` [rad]: the origin of a
  URDF joint in its parent link (where a link's length and a base joint's position live). A moving joint's placement
  in the twin becomes ``F * origin(p)``, ``F`` its parent link's frame in the parent joint (the fixed links merged
  between them); a fixed joint's origin moves the frames it carries (:meth:`Twin.frame_local
  <pkm.core.twin.tree.Twin.frame_local>`), and the moving joints hanging from them. Only the varied components are
  symbols (an origin whose angles stay fixed keeps a constant rotation: no trigonometry is added). A fixed joint
  that carries mass moves it within the body it merges into: that body's ten inertial parameters must be inputs
  too (:func:`with_merged_bodies` adds them), or the twin would keep the file's.
* ``BODY.m``, ``BODY.mx`` ... ``BODY.Izz`` (:data:`~pkm.core.model.bodies.BODY_FIELDS`, the
  regressor's names and Pinocchio's ``toDynamicParameters`` order: the mass, its first moments, the inertia about
  the joint frame's origin) [kg, kg m, kg m^2]: a body's inertial parameters.

What stays structural (fixed by the file the twin was built from: :func:`structure`): the joints' kinds and axes,
the tree, the closures, the task, and the choices a twin makes numerically at its reference: the linear solves' pivot orders
(:mod:`~pkm.core.twin.linear`), the idle motions' coordinates. A design far from the file's may therefore hit the
pivot floor sooner; the kernels report the pivot and the callers fall back as for any state.

:func:`design_mechanism` builds the :class:`~pkm.core.Mechanism` of one design (the URDF with its origins set, the
inertias set, the actuators held at the file's reference and the other joints assembled from it): the generic core's
route, against which the parametric kernels are checked, and what their fallbacks use.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import casadi as cs
import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm._derived import SLOT
from pkm.core.model.bodies import BODY_FIELDS, body_names
from pkm.core.model.mechanism import Mechanism
from pkm.core.model.origins import ORIGIN, joint_elements, origins_set
from pkm.core.twin.spatial import SE3, Expr
from pkm.errors import InvalidInputError, UnknownNameError


@dataclass(frozen=True)
class Design:
    """The design parameters of a twin (see the module doc).

    Attributes:
        names: The parameters, in the order of the kernels' ``design`` input.
        base: Their values in the mechanism the twin was built from (SI).
        joints: URDF joint name -> ``(component, index in names)`` of its varied origin components.
        bodies: Pinocchio joint id -> ``(field, index in names)`` of its body's varied inertial parameters.
        urdf: URDF joint name -> ``(xyz, rpy, parent link)`` of every URDF joint (geometry varied), else empty.
    """

    names: tuple[str, ...]
    base: np.ndarray
    joints: Mapping[str, tuple[tuple[int, int], ...]]
    bodies: Mapping[int, tuple[tuple[int, int], ...]]
    urdf: Mapping[str, tuple[np.ndarray, np.ndarray, str]]

    def __len__(self) -> int:
        return len(self.names)

    def vector(self, values: Mapping[str, float] | ArrayLike | None = None) -> np.ndarray:
        """The ``design`` input of the kernels: ``values`` by name (the others at :attr:`base`) or a whole vector."""
        from pkm.validation import as_array, as_scalar

        if values is None:
            return self.base.copy()
        if isinstance(values, Mapping):
            out = self.base.copy()
            for name, value in values.items():
                if name not in self.names:
                    raise UnknownNameError("design parameter", name, self.names, "the twin's design inputs")
                out[self.names.index(name)] = as_scalar(value, name)
        else:
            out = as_array(values, "design", f"{len(self.names)} values (SI): {', '.join(self.names)}")
            if out.shape != (len(self.names),) or not np.all(np.isfinite(out)):
                raise InvalidInputError("design", f"expected {len(self.names)} finite values "
                                                  f"({', '.join(self.names)})", values)
        for k in (i for fields in self.bodies.values() for f, i in fields if f == 0):  # (the masses)
            if not out[k] > 0.0:
                raise InvalidInputError(self.names[k], "a body's mass must be positive", float(out[k]))
        return out

    def origin(self, joint: str, p: Expr) -> SE3:
        """URDF joint ``joint``'s origin (its placement in its parent link) with its varied components the symbols
        ``p``: a constant rotation where no angle varies (no trigonometry added)."""
        xyz0, rpy0, _ = self.urdf[joint]
        xyz, rpy = [cs.SX(float(v)) for v in xyz0], [cs.SX(float(v)) for v in rpy0]
        turned = False
        for comp, k in self.joints.get(joint, ()):
            attr, i = ORIGIN[list(ORIGIN)[comp]]
            (xyz if attr == "xyz" else rpy)[i] = p[k]
            turned = turned or attr == "rpy"
        R = _rpy_matrix(*rpy) if turned else cs.DM(pin.rpy.rpyToMatrix(*rpy0))
        return SE3(R, cs.vertcat(*xyz))

    def theta(self, jid: int, values: np.ndarray, p: Expr) -> Expr:
        """Body ``jid``'s ten inertial parameters (``values``: the model's) with its varied ones the symbols ``p``."""
        out = [cs.SX(float(v)) for v in values]
        for field, k in self.bodies[jid]:
            out[field] = p[k]
        return cs.vertcat(*out)


def design_of(mech: Mechanism, names: Sequence[str] | None) -> Design:
    """The :class:`Design` of ``mech`` whose parameters are ``names`` (none: a twin of constants).

    Raises:
        UnknownNameError: a name is neither a URDF joint's origin component nor a body's inertial parameter (the
            error lists them).
        InvalidInputError: ``mech`` was not built from URDF text (origins need it), a name repeats, or a fixed
            joint's origin varies with mass below it without the ten inertial parameters of the body it merges
            into (:func:`with_merged_bodies`; else the merged inertia would stay the file's).
    """
    if isinstance(names, str) or not all(isinstance(n, str) for n in names or ()):
        raise InvalidInputError("design", "expected a list of parameter names (JOINT.x, BODY.m, ...)", names)
    names = tuple(names or ())
    if len(set(names)) != len(names):
        raise InvalidInputError("design", "a parameter is named twice", names)
    model = mech.model
    bodies = body_names(model) if names else ()
    urdf = _urdf_joints(mech) if any(n.rpartition(".")[2] in ORIGIN for n in names) else {}
    base: list[float] = []
    joints: dict[str, list[tuple[int, int]]] = {}
    body_fields: dict[int, list[tuple[int, int]]] = {}
    for k, name in enumerate(names):
        owner, _, comp = name.rpartition(".")
        if comp in ORIGIN and owner in urdf:
            joints.setdefault(owner, []).append((list(ORIGIN).index(comp), k))
            attr, i = ORIGIN[comp]
            base.append(float(urdf[owner][0 if attr == "xyz" else 1][i]))
        elif comp in BODY_FIELDS and owner in bodies:
            jid = bodies.index(owner) + 1
            body_fields.setdefault(jid, []).append((BODY_FIELDS.index(comp), k))
            base.append(float(model.inertias[jid].toDynamicParameters()[BODY_FIELDS.index(comp)]))
        else:
            choices = [f"{j}.{c}" for j in urdf or _urdf_joints(mech) for c in ORIGIN]
            choices += [f"{b}.{f}" for b in bodies or body_names(model) for f in BODY_FIELDS]
            raise UnknownNameError("design parameter", name, choices,
                                   f"{mech.name}: URDF joints' origins and bodies' inertial parameters")
    for joint, body in _merged(mech, joints).items():  # (a fixed joint carrying mass moves it in its body)
        jid = bodies.index(body) + 1
        if len(body_fields.get(jid, ())) != len(BODY_FIELDS):
            carried = _carried_mass(mech.urdf or "", joint)
            raise InvalidInputError("design", f"the fixed joint {joint!r} carries {carried:g} kg merged into body "
                                              f"{body!r}: its ten inertial parameters vary with it ({body}.m ... "
                                              f"{body}.Izz; with_merged_bodies adds them), or keep the origin fixed",
                                    names)
    return Design(names, np.array(base, dtype=float), {j: tuple(v) for j, v in joints.items()},
                  {j: tuple(v) for j, v in body_fields.items()}, urdf)


def with_merged_bodies(mech: Mechanism, names: Sequence[str]) -> tuple[str, ...]:
    """``names`` and, for each varied fixed-joint origin that carries mass, the ten inertial parameters of the body
    it merges into (what :func:`design_of` requires; their values are the design mechanism's, which Pinocchio merges
    from its files: :func:`read_design`)."""
    joints = {n.rpartition(".")[0] for n in names if n.rpartition(".")[2] in ORIGIN}
    extra = [f"{b}.{f}" for b in dict.fromkeys(_merged(mech, joints).values()) for f in BODY_FIELDS]
    return tuple(names) + tuple(n for n in extra if n not in names)


def _merged(mech: Mechanism, joints: Iterable[str]) -> dict[str, str]:
    """``{fixed joint: body}`` of the URDF fixed joints among ``joints`` that carry mass into a moving body (mass
    welded to the world moves nothing)."""
    model, out = mech.model, {}
    for joint in joints:
        if model.existJointName(joint) or not model.existFrame(joint, pin.FrameType.FIXED_JOINT):
            continue
        jid = model.frames[model.getFrameId(joint, pin.FrameType.FIXED_JOINT)].parentJoint
        if jid and _carried_mass(mech.urdf or "", joint) > 0.0:
            out[joint] = body_names(model)[jid - 1]
    return out


def design_mechanism(mech: Mechanism, values: Mapping[str, float]) -> Mechanism:
    """The mechanism of one design of ``mech``: its URDF's joint origins and its bodies' inertial parameters set to
    ``values`` (names as in the module doc); the actuators held at the file's reference, the other joints assembled
    from their former values (the same assembly mode). The inertias live in the model only: pickled (to a Dask
    worker), the mechanism is rebuilt from its files with the file's inertias; send the values instead.

    Raises:
        InvalidInputError: ``mech`` was not built from URDF text.
        UnknownNameError: as :func:`design_of`.
        SpecError: the design does not assemble at the held actuators.
    """
    from pkm.core.model.builder import from_strings
    from pkm.core.model.spec import ClosureSpec

    design_of(mech, with_merged_bodies(mech, tuple(values)))  # (the names checked, with the choices listed)
    inertial = {k: v for k, v in values.items() if k.rpartition(".")[2] in BODY_FIELDS}
    origins = {k: v for k, v in values.items() if k not in inertial}
    spec = ClosureSpec.from_toml(mech.spec.to_toml(), mech.source)
    held = {n: v for n, v in spec.reference.items() if n in spec.actuated}
    out = from_strings(origins_set(_urdf(mech), origins), dataclasses.replace(spec, reference=held),
                       source=mech.source, seed=spec.reference)
    bodies = body_names(mech.model) if inertial else ()
    for name, value in inertial.items():  # (the mechanism's own model, fresh: set in place)
        body, _, field = name.rpartition(".")
        jid = bodies.index(body) + 1
        theta = np.array(out.model.inertias[jid].toDynamicParameters())
        theta[BODY_FIELDS.index(field)] = value
        out.model.inertias[jid] = pin.Inertia.FromDynamicParameters(theta)
    if inertial:
        out.__dict__.pop(SLOT, None)  # (what was derived from the inertias, plausibility.nonphysical: made again)
    return out


def read_design(mech: Mechanism, names: Sequence[str] | None = None) -> dict[str, float]:
    """The design values of ``mech`` by name: ``names``, or every URDF joint's origin components and every body's
    inertial parameters (what :func:`design_of` can take). The design of a mechanism built by other means (a
    registered mechanism's ``build``) read back, so that one twin with design inputs serves its family."""
    out: dict[str, float] = {}
    if mech.urdf is not None:
        for joint, (xyz, rpy, _) in _urdf_joints(mech).items():
            for comp, (attr, i) in ORIGIN.items():
                out[f"{joint}.{comp}"] = float((xyz if attr == "xyz" else rpy)[i])
    for j, body in enumerate(body_names(mech.model), start=1):
        theta = mech.model.inertias[j].toDynamicParameters()
        for k, field in enumerate(BODY_FIELDS):
            out[f"{body}.{field}"] = float(theta[k])
    if names is None:
        return out
    missing = [n for n in names if n not in out]
    if missing:
        raise UnknownNameError("design parameter", missing[0], list(out), mech.name)
    return {n: out[n] for n in names}


def structure(mech: Mechanism) -> str:
    """What a twin with design inputs fixes of ``mech``, as text: its URDF without origins, inertials, limits and
    geometry (collision and visual elements), its spec without reference, parameters and description, its model's
    joint kinds. Designs of one family that share it can share a twin (the kernels read no position, effort or speed
    limit and no geometry: a design whose limits or link radii move with its lengths shares it too)."""
    from lxml import etree

    parts = [dataclasses.replace(mech.spec, reference={}, parameters={}, description="").to_toml(),
             " ".join(j.shortname() for j in mech.model.joints)]
    if mech.urdf is not None:
        root, _ = joint_elements(mech.urdf)
        for el in list(root.iter("origin", "inertial", "limit", "safety_controller", "collision", "visual")):
            if el.getparent() is not None:
                el.getparent().remove(el)
        parts.append(etree.tostring(root, encoding="unicode"))
    return "\n".join(parts)


def _urdf(mech: Mechanism) -> str:
    if mech.urdf is None:
        raise InvalidInputError("mechanism", "built from a Pinocchio model without URDF text: its joint origins "
                                             "cannot vary (load it from files)", mech.source)
    return mech.urdf


def _urdf_joints(mech: Mechanism) -> dict[str, tuple[np.ndarray, np.ndarray, str]]:
    """``{joint: (xyz, rpy, parent link)}`` of every URDF joint of ``mech``'s file."""
    out = {}
    for name, j in joint_elements(_urdf(mech))[1].items():
        origin, parent = j.find("origin"), j.find("parent")
        xyz, rpy = ((np.array([float(v) for v in ((origin.get(a) if origin is not None else None) or "0 0 0").split()]))
                    for a in ("xyz", "rpy"))
        out[name] = (xyz, rpy, parent.get("link") if parent is not None else "")
    return out


def _carried_mass(urdf: str, joint: str) -> float:
    """The mass of the links URDF joint ``joint`` carries through fixed joints (what merges into one body)."""
    return _carried(urdf).get(joint, 0.0)


@functools.lru_cache(maxsize=16)
def _carried(urdf: str) -> dict[str, float]:
    """:func:`_carried_mass` of every joint of the URDF text (read once per text: a sweep asks at every design)."""
    root, joints = joint_elements(urdf)
    masses = {}
    for link in root.iter("link"):
        m = link.find("inertial/mass")
        masses[link.get("name")] = float(m.get("value", 0.0)) if m is not None else 0.0
    children: dict[str, list] = {}
    for j in joints.values():
        children.setdefault(j.find("parent").get("link"), []).append(j)
    out = {}
    for name, j in joints.items():
        total, todo = 0.0, [j.find("child").get("link")]
        while todo:
            link = todo.pop()
            total += masses.get(link, 0.0)
            todo += [c.find("child").get("link") for c in children.get(link, []) if c.get("type") == "fixed"]
        out[name] = total
    return out


def _rpy_matrix(roll: Expr, pitch: Expr, yaw: Expr) -> Expr:
    """URDF's ``Rz(yaw) Ry(pitch) Rx(roll)`` of symbols."""
    cr, sr, cp, sp, cy, sy = cs.cos(roll), cs.sin(roll), cs.cos(pitch), cs.sin(pitch), cs.cos(yaw), cs.sin(yaw)
    return cs.vertcat(cs.horzcat(cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
                      cs.horzcat(sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
                      cs.horzcat(-sp, cp * sr, cp * cr))


__all__ = ["Design", "design_mechanism", "design_of", "read_design", "structure", "with_merged_bodies"]
