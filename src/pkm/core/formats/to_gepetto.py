"""Any mechanism pkm loads written as URDF + YAML in the convention of Gepetto's toolbox-parallel-robots: the file
pair :mod:`pkm.core.formats.gepetto` reads.

:func:`gepetto_from_mechanism` gives the YAML: ``closed_loop`` (each closure's two frames, in the spec's order),
``type`` (``"3d"`` for a point closure, ``"6d"`` for a frame closure), ``name_mot`` (the actuated joints' exact
names) and, when the spec retypes joints, ``joint_name`` / ``joint_type`` (``SPHERICAL``, ``CARDAN`` for pkm's
``universal``, ``UJOINT_AB`` for ``universal_ab``, ``FIXED``); the URDF is the mechanism's own
(:attr:`~pkm.core.Mechanism.urdf`: links, inertias, limits, mimic couplings and each joint's ``<limit effort
velocity>`` travel in it).

What the format cannot hold is written as a comment at the top of the YAML (the toolbox and pkm's reader skip it)
and listed in what :func:`gepetto_from_mechanism` returns, so that a caller (:func:`pkm.save`, ``pkm convert``) says
so; read back, the mechanism lacks it:

* the end effector and the task (the reader's task is the actuated joints);
* the reference configuration (the reader assembles the mechanism from the neutral configuration, which may find
  another assembly mode, or none);
* the closures' names (the reader names them ``loop1``, ``loop2``...);
* the drives stated in the spec (``[actuators.<joint>]``: rotor inertia, gear ratio, friction...; the URDF keeps
  only each joint's effort and velocity limits);
* the working modes (``[branches]``) and the design parameters (``[parameters]``);
* the actuators' order when it is not the URDF's (the reader takes them in the order of the URDF's ``<joint>`` elements).

Refused (a :class:`~pkm.errors.SpecError` naming what): a mechanism built from a Pinocchio model without URDF text,
and one with a floating base (a free-flyer the spec adds to the URDF's tree: the format has no place for it).
"""

from __future__ import annotations

import json

import numpy as np

from pkm.core.formats.gepetto import JOINT_TYPES
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.urdf import check_urdf
from pkm.errors import SpecError

#: pkm's joint types and the toolbox's ``joint_type`` for them (the inverse of
#: :data:`pkm.core.formats.gepetto.JOINT_TYPES`, ``CARDAN`` for ``universal``).
GEPETTO_TYPES = {kind: name for name, kind in JOINT_TYPES.items()}


def _list(values: list) -> str:
    return json.dumps(values, ensure_ascii=False)  # (JSON's flow lists and strings are YAML)


def gepetto_from_mechanism(mech: Mechanism) -> tuple[str, tuple[str, ...]]:
    """The YAML text of ``mech`` in Gepetto's convention (its URDF is :attr:`~pkm.core.Mechanism.urdf`), and what the
    format cannot hold, one line each (written as comments in the YAML; see the module doc).

    Raises:
        SpecError: no URDF text, or a floating base (see the module doc).
    """
    mech = check_mechanism(mech)
    spec = mech.spec
    if mech.urdf is None:
        raise SpecError(mech.source, "Gepetto's URDF + YAML: the mechanism was built from a Pinocchio model, not URDF "
                                     "text: no URDF to write")
    if spec.floating_base is not None:
        raise SpecError(mech.source, f"Gepetto's URDF + YAML cannot hold the floating base {spec.floating_base!r} "
                                     "(a free-flyer the spec adds to the URDF's tree); write a pkm spec or MJCF")
    dropped: list[str] = []
    actuated = list(mech.actuated_names)
    if not spec.task_is_actuated:
        task = " ".join(spec.task.components) or "-"
        dropped.append(f"task: end effector {spec.end_effector!r}, components {task}, frames "
                       f"{dict(spec.task.frames) or '-'}, joints {list(spec.task.joints) or '-'} (read back, the task is "
                       "the actuated joints)")
    reference = {k: [float(x) for x in np.atleast_1d(v)] for k, v in mech.q_to_dict(mech.q_reference).items()}
    dropped.append(f"reference configuration (read back, the mechanism is assembled from the neutral one): "
                   f"{json.dumps(reference)}")
    names = [c.name for c in spec.closures]
    if names != [f"loop{k + 1}" for k in range(len(names))]:
        dropped.append(f"closure names {names} (read back: loop1, loop2, ...)")
    if spec.actuators:
        dropped.append(f"drives stated in the spec ([actuators]): {json.dumps({k: dict(v) for k, v in spec.actuators.items()})}")
    if spec.motors:
        dropped.append(f"the differentials' motors ([motors]): {json.dumps({k: dict(v) for k, v in spec.motors.items()})}"
                       " (read back, each actuated joint has a motor of its own)")
    if spec.branches:
        dropped.append(f"working modes ([branches]): {sorted(spec.branches)}, default {spec.default_branch!r}")
    if spec.parameters:
        dropped.append(f"design parameters ([parameters]): {json.dumps(dict(spec.parameters))}")
    in_file = [str(j.get("name")) for j in check_urdf(mech.urdf, mech.source).findall("joint")]
    order = sorted(actuated, key=in_file.index)  # (pkm's reader takes them in the URDF's order of <joint> elements)
    if order != actuated:
        dropped.append(f"actuator order {actuated} (read back in the URDF's order: {order})")
    lines = [f"# {spec.mechanism}: written by pkm in the convention of Gepetto's toolbox-parallel-robots"]
    if spec.description:
        lines.append("# " + " ".join(spec.description.split()))
    if dropped:
        lines.append("# Not expressible in this format (kept here as comments only; read back, the mechanism lacks it):")
        lines += [f"#   {d}" for d in dropped]
    lines += [f"closed_loop: {_list([[c.frame_a, c.frame_b] for c in spec.closures])}",
              f"type: {_list(['3d' if c.type == 'point' else '6d' for c in spec.closures])}",
              f"name_mot: {_list(actuated)}"]
    if spec.joint_types:
        lines += [f"joint_name: {_list(list(spec.joint_types))}",
                  f"joint_type: {_list([GEPETTO_TYPES[k] for k in spec.joint_types.values()])}"]
    return "\n".join(lines) + "\n", tuple(dropped)


__all__ = ["GEPETTO_TYPES", "gepetto_from_mechanism"]
