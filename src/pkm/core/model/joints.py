"""Joints the URDF cannot state: spherical and universal joints as Pinocchio's own joint models, and locked joints.

URDF has no spherical or universal joint; CAD exporters (onshape-to-robot) write a revolute in their place
and a side file says what it is (Gepetto's toolbox-parallel-robots: ``joint_name`` / ``joint_type`` in
``robot.yaml``). A closure spec says it in its ``[joint_types]`` table, ``name = "spherical"``:

* ``"spherical"``: :class:`pinocchio.JointModelSpherical` at the joint's placement (a unit quaternion,
  three velocity coordinates: no gimbal lock, unlike three revolutes);
* ``"universal_ab"``, ``a`` and ``b`` two distinct axes among ``x``, ``y``, ``z`` (``"universal_zy"``...):
  :class:`pinocchio.JointModelUniversal` about the joint frame's axis ``a``, then about axis ``b`` of the frame
  that first rotation moved, ``R(q) = exp(q_1 [a]) exp(q_2 [b])``, two coordinates ``(q_1, q_2)`` [rad] (the
  toolbox's ``UJOINT_AB``); ``"universal"`` is ``"universal_xy"`` (the toolbox's ``CARDAN``);
* ``"fixed"``: the joint locked at its neutral value (its child body welded to its parent).

The other joints, the bodies' inertias and every frame are kept, with their names. Mimic joints are kept too:
Pinocchio 4.1 neither exposes a mimic joint's own joint model nor reduces a model that has mimic joints
(``buildReducedModel`` fails), so they are rebuilt as plain joints about their axes, the model retyped and
reduced, and each turned back into a mimic (``transformJointIntoMimic``); a mimic joint, or one that a mimic
joint follows, cannot be retyped.

Every reduction goes through :func:`reduced_model`: Pinocchio 4.1's ``buildReducedModel`` looks frames up by name
alone and raises ``ValueError: Several frames match the filter`` on any model where two frames share a name (an MJCF
body and its joint, a URDF link and joint named alike: MuJoCo Menagerie's Cassie).
"""

from __future__ import annotations

import weakref
from collections.abc import Mapping

import numpy as np
import pinocchio as pin

from pkm.errors import SpecError, SpecNameError, closest

_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
#: The universal joint types and their ``(first, second)`` axes, names of the joint frame's axes.
UNIVERSAL_AXES: dict[str, tuple[str, str]] = {"universal": ("x", "y"),
                                              **{f"universal_{a}{b}": (a, b) for a in "xyz" for b in "xyz" if a != b}}
#: Every value ``[joint_types]`` accepts.
JOINT_TYPES = ("spherical", *UNIVERSAL_AXES, "fixed")


def universal_joint(kind: str) -> pin.JointModelUniversal:
    """The :class:`pinocchio.JointModelUniversal` of a universal joint type (a key of :data:`UNIVERSAL_AXES`)."""
    a, b = UNIVERSAL_AXES[kind]
    return pin.JointModelUniversal(np.array(_AXES[a]), np.array(_AXES[b]))


def retype_joints(model: pin.Model, types: Mapping[str, str], source: str = "<model>") -> pin.Model:
    """``model`` with the joints named in ``types`` replaced (see the module doc); ``model`` itself when empty.

    Raises:
        SpecError: an unknown type, a joint that is not in the model, a mimic joint or one it follows.
    """
    if not types:
        return model
    names = list(model.names)
    for name, kind in types.items():
        if name not in names[1:]:
            raise SpecNameError(source, "joint", name, names[1:], "[joint_types]")
        if kind not in JOINT_TYPES:
            hint = closest(kind, JOINT_TYPES)
            raise SpecError(source, f"joint_types.{name} = {kind!r}: "
                                    + (f"did you mean {hint[0]!r}? " if hint else "") + f"use one of {list(JOINT_TYPES)}")
    mimics = _mimics(model)
    for name, (leader, *_) in mimics.items():
        for n in (name, leader):
            if n in types:
                raise SpecError(source, f"joint_types.{n} = {types[n]!r}: joint {name!r} mimics {leader!r}; "
                                        "neither can be retyped")
    new = pin.Model()
    new.name = model.name
    new.gravity = model.gravity
    ids = {0: 0}
    for jid in range(1, model.njoints):
        name = names[jid]
        retype = types.get(name)
        jm = (pin.JointModelSpherical() if retype == "spherical"
              else universal_joint(retype) if retype in UNIVERSAL_AXES
              else mimics[name][3] if name in mimics else model.joints[jid])
        ids[jid] = new.addJoint(ids[model.parents[jid]], jm, model.jointPlacements[jid], name)
        new.appendBodyToJoint(ids[jid], model.inertias[jid], pin.SE3.Identity())
    # the joints kept as they were keep the file's limits and drives (addJoint leaves Pinocchio's defaults)
    copy_limits(model, new, [(jid, ids[jid]) for jid in range(1, model.njoints)
                             if names[jid] not in types and names[jid] not in mimics])
    for k, f in enumerate(model.frames):
        if k == 0:
            continue  # the universe frame, which every model has
        new.addFrame(pin.Frame(f.name, ids[f.parentJoint], f.parentFrame, f.placement, f.type, f.inertia), False)
    locked = [new.getJointId(n) for n, kind in types.items() if kind == "fixed"]
    new = reduced_model(new, locked, pin.neutral(new)) if locked else new
    for name, (leader, scaling, offset, _) in mimics.items():
        new = pin.transformJointIntoMimic(new, new.getJointId(leader), new.getJointId(name), scaling, offset)
    return new


def reduced_model(model: pin.Model, locked: list[int], q: np.ndarray) -> pin.Model:
    """``pinocchio.buildReducedModel(model, locked, q)`` (the ``locked`` joints fixed at their values in ``q``, their
    bodies welded to their parents) for any model, also one where frames of different types share a name (a body
    and a joint named alike, as MJCF allows): such frames (but the joint's own) are renamed apart in a copy for the
    reduction, whose ``getFrameId`` by name alone would find several, and their names restored in the result. Every
    frame keeps its name and type (a locked joint's frame becomes a ``FIXED_JOINT`` frame of the joint's name)."""
    names = [f.name for f in model.frames]
    shared = {n for n in names if names.count(n) > 1}
    if not shared:
        return pin.buildReducedModel(model, locked, q)
    work, restore = model.copy(), {}
    for k, f in enumerate(work.frames):
        if f.name in shared and f.type != pin.FrameType.JOINT:
            restore[f"{f.name}\x00{k}"] = f.name  # (a NUL no file's name holds)
            f.name = f"{f.name}\x00{k}"
    reduced = pin.buildReducedModel(work, locked, q)
    for f in reduced.frames:
        f.name = restore.get(f.name, f.name)
    return reduced


#: A model's limits and drives per configuration entry (``q``) and per velocity entry (``v``), as Pinocchio names them;
#: ``addJoint`` gives a new joint Pinocchio's defaults (unbounded positions, no effort or speed limit, no friction,
#: damping or armature).
LIMITS_Q = ("lowerPositionLimit", "upperPositionLimit", "positionLimitMargin")
LIMITS_V = ("lowerEffortLimit", "upperEffortLimit", "lowerVelocityLimit", "upperVelocityLimit", "lowerDryFrictionLimit",
            "upperDryFrictionLimit", "effortLimit", "velocityLimit", "damping", "friction", "armature")


def stated_limits(model: pin.Model, idx: np.ndarray | slice | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The position limits a model's file states, per configuration entry (of ``idx`` only, if given) [rad, m]:
    ``(-inf, inf)`` where the interval is empty or a point (``lower >= upper``), the placeholder Pinocchio's readers
    leave where a file states no limit (URDF's ``lower``/``upper`` default to 0; SDF, Gepetto's robots), which MuJoCo
    also reads as unlimited (``range="0 0"``). Every use of a model's limits reads them here: a placeholder taken as a
    limit made every pose infeasible (:func:`pkm.feasible_region` on a Gepetto robot)."""
    lo = np.array(model.lowerPositionLimit, dtype=float)
    hi = np.array(model.upperPositionLimit, dtype=float)
    if idx is not None:
        lo, hi = lo[idx], hi[idx]
    empty = ~(lo < hi)
    lo[empty], hi[empty] = -np.inf, np.inf
    return lo, hi


def copy_limits(model: pin.Model, new: pin.Model, joints: list[tuple[int, int]],
                extra_v: tuple[str, ...] = ()) -> None:
    """``model``'s limits and drives (:data:`LIMITS_Q`, :data:`LIMITS_V` and ``extra_v``, those this Pinocchio has)
    onto the coordinates of ``new``'s joints: ``joints`` pairs each joint id of ``model`` with its id in ``new``, the
    two of the same kind."""
    per_q = tuple(k for k in LIMITS_Q if hasattr(new, k))
    per_v = tuple(k for k in LIMITS_V + extra_v if hasattr(new, k))
    values = {k: np.array(getattr(new, k), dtype=float) for k in per_q + per_v}
    for old_id, new_id in joints:
        old, kept = model.joints[old_id], new.joints[new_id]
        for k in per_q:
            values[k][kept.idx_q:kept.idx_q + kept.nq] = getattr(model, k)[old.idx_q:old.idx_q + old.nq]
        for k in per_v:
            values[k][kept.idx_v:kept.idx_v + kept.nv] = getattr(model, k)[old.idx_v:old.idx_v + old.nv]
    for k, v in values.items():
        setattr(new, k, v)


#: :func:`has_mimic`'s answers by model: ``id(model) -> (its joint count, the answer)``, an entry dropped when its model
#: is freed (so that no other model takes it over with the id). The scan of the joints (a Python object a joint) took
#: 18 µs, a third of the Delta's joint-space mass matrix, on every dynamics evaluation (a simulation's every stage).
_MIMIC: dict[int, tuple[int, bool]] = {}


def has_mimic(model: pin.Model) -> bool:
    """Whether Pinocchio's ``model`` has a mimic joint (a URDF ``<mimic>``, an MJCF gear ``<equality><joint>``)."""
    key, known = id(model), _MIMIC.get(id(model))
    if known is not None and known[0] == model.njoints:  # (a joint added since: asked again)
        return known[1]
    found = any(jm.shortname() == "JointModelMimic" for jm in model.joints)
    if known is None:
        try:
            weakref.finalize(model, _MIMIC.pop, key, None)
        except TypeError:  # (an object that takes no weak reference: not remembered)
            return found
    _MIMIC[key] = (model.njoints, found)
    return found


def _mimics(model: pin.Model) -> dict[str, tuple[str, float, float, pin.JointModel]]:
    """``{mimic joint: (the joint it follows, scaling, offset, a plain joint about its axis)}`` (revolute or
    prismatic: the axis is its motion subspace over its scaling)."""
    out: dict[str, tuple[str, float, float, pin.JointModel]] = {}
    if not has_mimic(model):
        return out
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    for jid in range(1, model.njoints):
        if model.joints[jid].shortname() != "JointModelMimic":
            continue
        jm = model.joints[jid].extract()
        leader = next(k for k in range(1, model.njoints) if model.joints[k].shortname() != "JointModelMimic"
                      and model.joints[k].nq and model.joints[k].idx_q == jm.idx_q)
        S = np.asarray(data.joints[jid].S).reshape(6) / jm.scaling
        plain = (pin.JointModelRevoluteUnaligned(S[3:]) if np.linalg.norm(S[3:]) > 0
                 else pin.JointModelPrismaticUnaligned(S[:3]))
        out[model.names[jid]] = (model.names[leader], float(jm.scaling), float(jm.offset), plain)
    return out


__all__ = ["JOINT_TYPES", "LIMITS_Q", "LIMITS_V", "UNIVERSAL_AXES", "copy_limits", "has_mimic", "reduced_model",
           "retype_joints", "stated_limits", "universal_joint"]
