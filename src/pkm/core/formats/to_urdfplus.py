"""A mechanism written as URDF+ (arXiv 2411.19753): its URDF tree and one ``<loop>`` per cut joint, the grammar
:mod:`pkm.core.formats.urdfplus` reads (and documents), so that :func:`pkm.load` reads it back.

* a ``frame`` closure: a ``<loop type="fixed">`` between the links its two frames hang on, each ``<origin>`` the
  frame's placement in its link;
* a ``point`` closure ``X`` with a ``point`` closure ``X_axis`` whose frames hang on the same two links at the
  same distance (> 0) from ``X``'s on each side: a ``<loop type="revolute">`` about that line, its ``<axis>`` z
  of the loop frame (pkm's reader makes of it the same two closures, so a URDF+ file comes back as it was read);
* any other ``point`` closure: a ``<loop type="spherical">``. URDF+ has no spherical loop joint: this is a pkm
  extension, which pkm's reader reads and other URDF+ readers refuse; the writer says so (:class:`~pkm.core.formats.writers.Written`'s
  ``dropped``, a :class:`~pkm.errors.PkmWarning` from :func:`pkm.save`);
* the actuated joints: a ``<transmission>`` each (ROS's ``SimpleTransmission``);
* the joint springs (``[springs]``): URDF+ (and URDF) has no spring, so they are written with Gazebo's URDF extension,
  ``<gazebo reference="JOINT"><springStiffness><springReference>`` (:func:`~pkm.core.model.urdf.gazebo_springs`,
  which pkm's URDF readers read: Gazebo's converter makes SDFormat's springs of them), a spring's damping as the
  joint's ``<dynamics damping>`` (its whole viscous damping, a drive's with it);
* the closures' frames that are massless leaf links fixed to their parent (and not the end effector or a task
  frame) are left out of the tree: the loop's origins place them, and the reader adds them back.

Refused by name: ``[joint_types]`` (URDF cannot state a spherical or universal joint in the tree) and a floating
base. Left out, and said (:class:`~pkm.core.formats.writers.Written`'s ``dropped``): the closures' frame names
(read back as ``<loop>_predecessor``, ``<loop>_successor``), the task and end effector, the reference
configuration (the reader assembles), the spec's drives, working modes and parameters.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from lxml import etree

from pkm.core.model.mechanism import Mechanism
from pkm.core.model.urdf import origin, write_gazebo_springs
from pkm.errors import SpecError

_TOL = 1e-9  # relative tolerance on the two sides' axis lengths (they are written by a reader to 1e-16)


def damping_of(mech: Mechanism) -> dict[str, float]:
    """``{joint: its whole viscous damping}`` (Pinocchio's ``damping``: a drive's and a spring's) of each joint of
    ``mech``'s ``[springs]`` that the model has."""
    return {n: float(mech.model.damping[mech.joints[n].idx_v]) for n in mech.spec.springs if n in mech.joints}


def _link_of(mech: Mechanism, frame_id: int, cut: set[str]) -> tuple[str, pin.SE3]:
    """The URDF link a frame moves with (a body frame of its parent joint, at the joint, not one of the closures'
    frames ``cut``, which the writer leaves out) and the frame's placement there."""
    f = mech.model.frames[frame_id]
    link = next(g.name for g in mech.model.frames if g.type == pin.FrameType.BODY and g.parentJoint == f.parentJoint
                and g.placement.isIdentity(1e-14) and g.name not in cut)
    return link, f.placement


def urdfplus_from_mechanism(mech: Mechanism) -> tuple[str, tuple[str, ...]]:
    """``mech`` as URDF+ text and what it leaves out (module doc).

    Raises:
        SpecError: ``[joint_types]``, a floating base; no URDF text.
    """
    spec = mech.spec
    if mech.urdf is None:
        raise SpecError(mech.source, "built from a Pinocchio model, not URDF text: no URDF to write as URDF+")
    if spec.joint_types:
        raise SpecError(mech.source, f"URDF+ cannot state the joint types {dict(spec.joint_types)} (URDF has no "
                                     "spherical or universal joint); write pkm's spec or MJCF")
    if spec.floating_base:
        raise SpecError(mech.source, f"URDF+ has no floating base ({spec.floating_base!r}); write pkm's spec or MJCF")
    root = etree.fromstring(mech.urdf.encode())
    ids = dict(zip((c.name for c in spec.closures), mech.closure_frames, strict=True))
    cut: set[str] = set()
    kept = {spec.end_effector, *spec.task.frames}
    for fid in (i for pair in mech.closure_frames for i in pair):
        name = mech.model.frames[fid].name
        link = next((el for el in root.findall("link") if el.get("name") == name), None)
        joint = next((j for j in root.findall("joint") if j.find("child") is not None
                      and j.find("child").get("link") == name), None)
        leaf = not any(j.find("parent") is not None and j.find("parent").get("link") == name
                       for j in root.findall("joint"))
        if link is not None and len(link) == 0 and joint is not None and joint.get("type") == "fixed" and leaf \
                and name not in kept:
            root.remove(link)
            root.remove(joint)
            cut.add(name)
    loops: list[etree._Element] = []
    used: set[str] = set()
    balls: list[str] = []
    for c in spec.closures:
        if c.name in used:
            continue
        (la, Xa), (lb, Xb) = (_link_of(mech, i, cut) for i in ids[c.name])
        loop = etree.Element("loop", name=c.name, type="fixed")
        axis = next((d for d in spec.closures if d.name == f"{c.name}_axis" and d.type == "point"
                     and d.name not in used), None) if c.type == "point" else None
        if axis is not None:  # a revolute cut if the two pairs of frames are on one line of the same two links
            (la2, Xa2), (lb2, Xb2) = (_link_of(mech, i, cut) for i in ids[axis.name])
            ua, ub = Xa2.translation - Xa.translation, Xb2.translation - Xb.translation
            na, nb = float(np.linalg.norm(ua)), float(np.linalg.norm(ub))
            if (la2, lb2) == (la, lb) and na > 0.0 and abs(na - nb) <= _TOL * na:
                z = np.array([0.0, 0.0, 1.0])  # the loop frame's z along the axis on each side
                Xa = pin.SE3(pin.Quaternion.FromTwoVectors(z, ua / na).matrix(), Xa.translation)
                Xb = pin.SE3(pin.Quaternion.FromTwoVectors(z, ub / nb).matrix(), Xb.translation)
                loop.set("type", "revolute")
                used.add(axis.name)
            else:
                axis = None
        if c.type == "point" and axis is None:
            loop.set("type", "spherical")
            balls.append(c.name)
        for role, link, X in (("predecessor", la, Xa), ("successor", lb, Xb)):
            origin(etree.SubElement(loop, role, link=link), X)
        if loop.get("type") == "revolute":
            etree.SubElement(loop, "axis", xyz="0 0 1")
        loops.append(loop)
        used.add(c.name)
    for el in root.findall("transmission"):
        root.remove(el)
    root.extend(loops)
    write_gazebo_springs(root, spec.springs, damping_of(mech))
    for j in spec.actuated:
        tr = etree.SubElement(root, "transmission", name=f"{j}_transmission")
        etree.SubElement(tr, "type").text = "transmission_interface/SimpleTransmission"
        jel = etree.SubElement(tr, "joint", name=j)
        etree.SubElement(jel, "hardwareInterface").text = "hardware_interface/EffortJointInterface"
        etree.SubElement(etree.SubElement(tr, "actuator", name=f"{j}_actuator"), "mechanicalReduction").text = "1"
    etree.indent(root, space="  ")
    dropped = ["the reference configuration (the reader assembles)"]
    if spec.closures:
        dropped.append("the closures' frame names (read back as <loop>_predecessor, <loop>_successor)")
    if balls:
        dropped.append(f"URDF+ has no spherical loop joint: the point closures {balls} are written as "
                       '<loop type="spherical">, a pkm extension that other URDF+ readers refuse')
    if not spec.task_is_actuated:
        dropped.append("the task and end effector")
    if spec.actuators:
        dropped.append(f"the drives of {sorted(spec.actuators)}")
    if spec.motors:
        dropped.append(f"the differentials' motors {sorted(spec.motors)} (read back, each actuated joint has a motor "
                       "of its own)")
    if spec.branches or spec.parameters:
        dropped.append("working modes and parameters")
    return etree.tostring(root, encoding="unicode") + "\n", tuple(dropped)


__all__ = ["urdfplus_from_mechanism"]
