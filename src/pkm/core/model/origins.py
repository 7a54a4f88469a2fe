"""URDF joint origins as named numbers: ``JOINT.x``, ``JOINT.y``, ``JOINT.z`` [m], ``JOINT.roll``, ``JOINT.pitch``,
``JOINT.yaw`` [rad] (the joint's placement in its parent link), read and set in the URDF text. What the sweeps vary
and the twin's design inputs take (:mod:`pkm.core.twin.design`); light to import (the command line reads it).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from pkm.errors import UnknownNameError

#: Origin components: name -> (URDF attribute, index).
ORIGIN = {"x": ("xyz", 0), "y": ("xyz", 1), "z": ("xyz", 2), "roll": ("rpy", 0), "pitch": ("rpy", 1), "yaw": ("rpy", 2)}


def origins_set(urdf: str, values: Mapping[str, float]) -> str:
    """The URDF text with the joint origins named by ``values`` (``JOINT.x`` ... ``JOINT.yaw``, SI) set."""
    from lxml import etree

    root, joints = joint_elements(urdf)
    for name, value in values.items():
        joint, _, comp = name.rpartition(".")
        if joint not in joints or comp not in ORIGIN:
            raise UnknownNameError("parameter", name, [f"{j}.{c}" for j in joints for c in ORIGIN], "the URDF")
        origin = joints[joint].find("origin")
        if origin is None:
            origin = etree.SubElement(joints[joint], "origin")
        attr, k = ORIGIN[comp]
        parts = (origin.get(attr) or "0 0 0").split()
        parts[k] = repr(float(value))
        origin.set(attr, " ".join(parts))
    return etree.tostring(root, encoding="unicode")


def urdf_joints(urdf: str) -> tuple[str, ...]:
    """The URDF's joint names, in file order."""
    return tuple(joint_elements(urdf)[1])


def joint_elements(urdf: str) -> tuple[Any, dict[str, Any]]:
    """The URDF's root and its joints by name (pkm's hardened parser, :func:`pkm.core.model.urdf.parse_xml`)."""
    from pkm.core.model.urdf import parse_xml

    root = parse_xml(urdf)
    return root, {j.get("name"): j for j in root.iter("joint") if j.get("name") and j.getparent() is root}


__all__ = ["ORIGIN", "joint_elements", "origins_set", "urdf_joints"]
