"""The Gough-Stewart platform (6-UPS): six legs of adjustable length between universal joints on the base and
spherical joints on the platform; the fifth registered mechanism, with no paper of its own.

Parameters (:class:`GoughStewartParams`): the six base points and the six platform points (m, in the base and
platform frames), the legs' stroke, masses, a reference pose. ``pkm.build("gough_stewart", base=[[x, y, z], ...],
platform=[[x, y, z], ...])``. The actuated coordinates are the six leg lengths; the universal joints are
Pinocchio's ``JointModelUniversal``, the ball joints Pinocchio point constraints (``CONTACT_3D``). Inverse
kinematics in closed form; forward kinematics: every assembly mode by :func:`pkm.assembly_modes` (40 complex for
generic data).
"""

from __future__ import annotations

from pkm.mechanisms.gough_stewart.kinematics import (
    closed_form_configuration,
    closed_form_fk,
    closed_form_ik,
    inverse_kinematics,
    joint_values,
    leg_vectors,
    pose,
    reference_pose,
    task_vector,
)
from pkm.mechanisms.gough_stewart.model import build, closure_spec, urdf_xml
from pkm.mechanisms.gough_stewart.params import BASE, NAME, PLATFORM, GoughStewartParams, Params

__all__ = ["BASE", "NAME", "PLATFORM", "GoughStewartParams", "Params", "build", "closed_form_configuration",
           "closed_form_fk", "closed_form_ik", "closure_spec", "inverse_kinematics", "joint_values", "leg_vectors",
           "pose", "reference_pose", "task_vector", "urdf_xml"]
