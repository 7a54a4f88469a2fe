"""Delta robot (Hernández Reyna & Sandoval-Castro, 2018): tree, closures and closed forms.

Geometry (paper eqs. 1-8, SI units): the base frame 0 is at the centre of the
base, Z up. Arm ``i`` (``i = 1, 2, 3``) lies in the plane obtained by rotating the
Y-Z plane by ``phi_i = 0, 120, 240 deg`` about Z; its motor sits at ``A_i = Rz(phi_i)
(0, R, 0)`` and its axis is ``Rz(phi_i) X``: the arm swings in the (rotated) Y-Z plane
as eqs. (1)-(2) say, ``B_i = Rz(phi_i) (0, R + La cos th_i, La sin th_i)``. (The text
says the motor axis is aligned with Y; the equations, which we follow, make it X.)
The forearm of length ``Lb`` joins ``B_i`` to the platform point ``E + Rz(phi_i)(0, r, 0)``.

How the parallelograms are modelled: each parallelogram is represented by its
centre line, a rod of length ``Lb`` hung from the elbow by a universal joint
(``knee_i`` about the motor-axis direction, then ``knee_i_b`` across it) and tied to
the platform by a point closure (the ball joints). What the three parallelograms do
together, keeping the platform's orientation fixed, is represented by a massless
translational guide of the platform (prismatic joints ``platform_x``, ``platform_y``,
``platform_z`` from the base). The positions, velocities and accelerations of the
platform and of the forearm centre lines are exact; the guide carries the moments
that the parallelogram pairs would carry, which do no work and produce no actuator
torque (each couple acts along the motor axis direction).

Working modes: ``knee_i`` is the angle from the arm to the forearm's projection on the
arm's plane; it is 0 or pi when the inverse problem has a double root. ``knee_out`` (the
usual Delta, default) has ``knee_i < 0``; ``knee_in`` has ``knee_i > 0``.

Velocities: ``J = dX/dth`` (eq. 12) in closed form from the sphere equations
(:func:`jacobian`, :func:`jacobian_factors`). Grids of poses: :mod:`pkm.mechanisms.delta.workspace`;
the choice of R: :mod:`pkm.mechanisms.delta.design`.

Masses are not given by the paper; the defaults are illustrative (a light robot
of this size) and only matter for dynamics.
"""

from __future__ import annotations

from pkm.mechanisms.delta.kinematics import (
    arm_angles,
    branch_signs,
    closed_form_configuration,
    closed_form_fk,
    closed_form_ik,
    configuration,
    forward_kinematics,
    inverse_kinematics,
    jacobian,
    jacobian_factors,
    joint_values,
    reference_pose,
    sphere_centres,
)
from pkm.mechanisms.delta.model import (
    build,
    closure_spec,
    urdf_xml,
)
from pkm.mechanisms.delta.params import (
    BRANCHES,
    NAME,
    PHI,
    DeltaParams,
    Params,
)

__all__ = [
    "BRANCHES",
    "NAME",
    "PHI",
    "DeltaParams",
    "Params",
    "arm_angles",
    "branch_signs",
    "build",
    "closed_form_configuration",
    "closed_form_fk",
    "closed_form_ik",
    "closure_spec",
    "configuration",
    "forward_kinematics",
    "inverse_kinematics",
    "jacobian",
    "jacobian_factors",
    "joint_values",
    "reference_pose",
    "sphere_centres",
    "urdf_xml",
]
