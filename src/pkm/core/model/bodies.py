"""A mechanism's bodies and their ten standard inertial parameters: the names the regressor, the identification and
the design inputs share.

A body is what one Pinocchio joint moves (its link, with the links fixed to it merged in), named after that link.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pinocchio as pin

BODY_FIELDS = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
"""The ten standard parameters of a body, Pinocchio's order (``Inertia.toDynamicParameters``): the mass, its first
moments ``m c``, the inertia about the joint frame's origin."""
BODY_UNITS = ("kg", "kg m", "kg m", "kg m", "kg m^2", "kg m^2", "kg m^2", "kg m^2", "kg m^2", "kg m^2")


def body_names(model: pin.Model) -> tuple[str, ...]:
    """One name per Pinocchio joint (1 to ``njoints - 1``): the first link it moves (its body frame), else the
    joint's name."""
    import pinocchio as pin  # (here: the names above are read by the command line, which does not load Pinocchio)

    names = []
    for j in range(1, model.njoints):
        link = next((f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == j),
                    model.names[j])
        names.append(link)
    return tuple(names)


__all__ = ["BODY_FIELDS", "BODY_UNITS", "body_names"]
