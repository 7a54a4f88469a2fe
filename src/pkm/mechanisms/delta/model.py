"""The Delta as a Pinocchio tree plus loop closures: URDF, closure spec and the mechanism built from parameters.

Collision primitives (``<collision>`` elements of the URDF, sizes from :class:`DeltaParams`):

* ``base``: a disc of radius ``R`` (to the motor axes) and thickness ``base_thickness``, its lower face in the
  plane of the motor axes (the plate the motors hang from);
* ``arm_i``: a cylinder of radius ``arm_radius`` from the motor axis (joint ``motor_i``) to the elbow axis (joint
  ``knee_i``);
* ``forearm_i``: a cylinder of radius ``rod_radius`` on the parallelogram's centre line, from the elbow (joint
  ``knee_i_b``) to the ball line (frame ``forearm_i_tip``, closed on ``platform_ball_i``). Its two rods are not
  drawn apart: their offset, along the motor axis, turns in the centre line's frame as ``knee_i_b`` turns, and a
  primitive is fixed in its link;
* ``platform``: a disc of radius ``r`` and thickness ``platform_thickness`` whose mid-plane holds the ball points.

The massless links (``knee_cross_i``, the guide) carry none. Neighbours touch where they are jointed (arm and
forearm at the elbow, forearm and platform at the balls, arm and base at the motor).
"""

from __future__ import annotations

import numpy as np

from pkm.core.model.mechanism import Mechanism
from pkm.core.model.spec import Branch, Closure, ClosureSpec, TaskSpec
from pkm.core.model.urdf import UrdfBuilder
from pkm.mechanisms._common import (
    PM54_040,
    check_params,
    disc_collision,
    make_mechanism,
    rod_collision,
    rod_inertia,
    rot_z,
    spec_parameters,
)
from pkm.mechanisms.delta.kinematics import joint_values, reference_pose
from pkm.mechanisms.delta.params import BRANCHES, NAME, PHI, DeltaParams


# ---------------------------------------------------------------------- tree and spec
def urdf_xml(params: DeltaParams) -> str:
    """The URDF tree (see the module doc for the modelling of the parallelograms); the motors' limits a ROBOTIS
    PM54-040-S250-R servo's (:data:`pkm.mechanisms._common.PM54_040`: 3.9 N m continuous, 28.4 rev/min = 2.974
    rad/s no-load, from its public datasheet https://emanual.robotis.com/docs/en/dxl/p/pm54-040-s250-r/)."""
    params = check_params(params, DeltaParams)
    b = UrdfBuilder(NAME)
    b.link("base")
    disc_collision(b, "base", (0.0, 0.0, params.base_thickness / 2), (0.0, 0.0, 1.0), params.R, params.base_thickness)
    reach = 2.0 * (params.R + params.La + params.Lb)
    for i in range(3):
        n = i + 1
        Rz = rot_z(PHI[i])
        b.link(f"arm_{n}", params.m_arm, (0.0, params.La / 2, 0.0), rod_inertia(params.m_arm, params.La, 1))
        b.joint(f"motor_{n}", "revolute", "base", f"arm_{n}", Rz @ np.array([0.0, params.R, 0.0]), Rz,
                axis=(1.0, 0.0, 0.0), effort=PM54_040.effort, velocity=PM54_040.speed)
        rod_collision(b, f"arm_{n}", (0.0, 0.0, 0.0), (0.0, params.La, 0.0), params.arm_radius)
        b.link(f"knee_cross_{n}")
        b.joint(f"knee_{n}", "revolute", f"arm_{n}", f"knee_cross_{n}", (0.0, params.La, 0.0), axis=(1.0, 0.0, 0.0))
        b.link(f"forearm_{n}", params.m_forearm, (0.0, params.Lb / 2, 0.0),
               rod_inertia(params.m_forearm, params.Lb, 1))
        rod_collision(b, f"forearm_{n}", (0.0, 0.0, 0.0), (0.0, params.Lb, 0.0), params.rod_radius)
        b.joint(f"knee_{n}_b", "revolute", f"knee_cross_{n}", f"forearm_{n}", axis=(0.0, 0.0, 1.0))
        b.frame(f"forearm_{n}_tip", f"forearm_{n}", (0.0, params.Lb, 0.0))
    b.link("guide_x")
    b.link("guide_y")
    mp, r = params.m_platform, params.r
    b.link("platform", mp, inertia=np.diag([mp * r * r / 4, mp * r * r / 4, mp * r * r / 2]))
    disc_collision(b, "platform", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), r, params.platform_thickness)
    b.joint("platform_x", "prismatic", "base", "guide_x", axis=(1.0, 0.0, 0.0), limits=(-reach, reach))
    b.joint("platform_y", "prismatic", "guide_x", "guide_y", axis=(0.0, 1.0, 0.0), limits=(-reach, reach))
    b.joint("platform_z", "prismatic", "guide_y", "platform", axis=(0.0, 0.0, 1.0), limits=(-reach, reach))
    for i in range(3):
        b.frame(f"platform_ball_{i + 1}", "platform", rot_z(PHI[i]) @ np.array([0.0, params.r, 0.0]))
    return b.to_xml()


def closure_spec(params: DeltaParams) -> ClosureSpec:
    params = check_params(params, DeltaParams)
    reference = {k: tuple(v) for k, v in joint_values(params, reference_pose(params)).items()}
    return ClosureSpec(
        mechanism=NAME,
        description="Delta robot (Hernandez Reyna & Sandoval-Castro 2018); parallelograms as centre lines, "
                    "platform orientation kept by a massless translational guide",
        urdf=f"{NAME}.urdf",
        end_effector="platform",
        actuated=("motor_1", "motor_2", "motor_3"),
        closures=tuple(Closure(f"ball_{n}", "point", f"forearm_{n}_tip", f"platform_ball_{n}") for n in (1, 2, 3)),
        task=TaskSpec(("x", "y", "z")),
        reference=reference,
        branches={name: Branch(name, {f"knee_{n}": s for n in (1, 2, 3)},
                               f"all elbows {'outward' if name == 'knee_out' else 'inward'} (knee_i "
                               f"{'<' if s < 0 else '>'} 0)") for name, s in BRANCHES.items()},
        default_branch="knee_out",
        parameters=spec_parameters(params),
    )


def build(params: DeltaParams | None = None) -> Mechanism:
    """The Delta as a :class:`~pkm.core.Mechanism` (paper design when ``params`` is None)."""
    params = DeltaParams() if params is None else params
    return make_mechanism(urdf_xml(params), closure_spec(params), params)
