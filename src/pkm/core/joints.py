"""Joints the URDF cannot state: spherical and universal joints as Pinocchio's own joint models, and locked joints.

URDF has no spherical or universal joint; CAD exporters (onshape-to-robot) write a revolute in their place
and a side file says what it is (Gepetto's toolbox-parallel-robots: ``joint_name`` / ``joint_type`` in
``robot.yaml``). A closure spec says it in its ``[joint_types]`` table, ``name = "spherical"``:

* ``"spherical"``: :class:`pinocchio.JointModelSpherical` at the joint's placement (a unit quaternion,
  three velocity coordinates: no gimbal lock, unlike three revolutes);
* ``"universal"``: :class:`pinocchio.JointModelUniversal` about the joint frame's x then y axes (the
  toolbox's ``CARDAN``, two coordinates);
* ``"fixed"``: the joint locked at its neutral value (its child body welded to its parent).

The other joints, the bodies' inertias and every frame are kept, with their names.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pinocchio as pin

from pkm.errors import SpecError, SpecNameError

JOINT_TYPES = ("spherical", "universal", "fixed")


def retype_joints(model: pin.Model, types: Mapping[str, str], source: str = "<model>") -> pin.Model:
    """``model`` with the joints named in ``types`` replaced (see the module doc); ``model`` itself when empty.

    Raises:
        SpecError: an unknown type, a joint that is not in the model, or a model with mimic joints.
    """
    if not types:
        return model
    names = list(model.names)
    for name, kind in types.items():
        if name not in names[1:]:
            raise SpecNameError(source, "joint", name, names[1:], "[joint_types]")
        if kind not in JOINT_TYPES:
            raise SpecError(source, f"joint_types.{name} = {kind!r}: use one of {list(JOINT_TYPES)}")
    if any(jm.shortname() == "JointModelMimic" for jm in model.joints):
        raise SpecError(source, "[joint_types] cannot yet retype joints of a model with mimic joints")
    new = pin.Model()
    new.name = model.name
    new.gravity = model.gravity
    ids = {0: 0}
    for jid in range(1, model.njoints):
        name = names[jid]
        retype = types.get(name)
        jm = (pin.JointModelSpherical() if retype == "spherical"
              else pin.JointModelUniversal(np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])) if retype == "universal"
              else model.joints[jid])
        ids[jid] = new.addJoint(ids[model.parents[jid]], jm, model.jointPlacements[jid], name)
        new.appendBodyToJoint(ids[jid], model.inertias[jid], pin.SE3.Identity())
    for k, f in enumerate(model.frames):
        if k == 0:
            continue  # the universe frame, which every model has
        new.addFrame(pin.Frame(f.name, ids[f.parentJoint], f.parentFrame, f.placement, f.type, f.inertia), False)
    locked = [new.getJointId(n) for n, kind in types.items() if kind == "fixed"]
    return pin.buildReducedModel(new, locked, pin.neutral(new)) if locked else new


__all__ = ["JOINT_TYPES", "retype_joints"]
