"""The Gough-Stewart platform as a Pinocchio tree plus loop closures: URDF, closure spec, the mechanism."""

from __future__ import annotations

import numpy as np

from pkm.core.model.mechanism import Mechanism
from pkm.core.model.spec import Branch, Closure, ClosureSpec, TaskSpec
from pkm.core.model.urdf import UrdfBuilder
from pkm.mechanisms._common import SA2_PD, check_params, make_mechanism, rod_inertia, spec_parameters
from pkm.mechanisms.gough_stewart.kinematics import joint_values, reference_pose
from pkm.mechanisms.gough_stewart.params import NAME, GoughStewartParams


def urdf_xml(params: GoughStewartParams) -> str:
    """The tree: the platform on a free-flyer; per leg a cylinder on a universal joint at ``a_i`` (written as a
    revolute, made Pinocchio's ``JointModelUniversal`` by the spec's ``[joint_types]``) and a rod on the prismatic
    leg joint along the cylinder's z axis, its coordinate the leg length; the ball joint at the rod's tip is a
    point closure on the platform. Collision geometry (:mod:`pkm.core.collision`): each cylinder a capsule of
    ``cylinder_radius`` from the universal joint's centre ``leg_min / 2`` along the leg, each rod one of
    ``rod_radius`` from the ball joint's centre ``leg_min / 2`` back (the frames ``cylinder_<n>_end`` and
    ``rod_<n>_end`` are their far ends), the platform a disc of the platform points' largest radius and
    ``platform_thickness``."""
    params = check_params(params, GoughStewartParams)
    b = UrdfBuilder(NAME)
    b.link("base")
    radius = float(np.max(np.linalg.norm(params.platform_points[:, :2], axis=1)))
    mp = params.m_platform
    b.link("platform_link", mp, inertia=np.diag([mp * radius ** 2 / 4, mp * radius ** 2 / 4, mp * radius ** 2 / 2]))
    b.joint("platform", "floating", "base", "platform_link")
    b.collision("platform_link", "cylinder", radius=radius, length=params.platform_thickness)
    half, mid = params.m_leg / 2.0, 0.5 * (params.leg_min + params.leg_max)
    for i in range(6):
        n = i + 1
        b.link(f"cylinder_{n}", half, (0.0, 0.0, mid / 4), rod_inertia(half, mid / 2, 2))
        b.joint(f"u{n}", "revolute", "base", f"cylinder_{n}", params.base[i], axis=(1.0, 0.0, 0.0))
        b.link(f"rod_{n}", half, (0.0, 0.0, -mid / 4), rod_inertia(half, mid / 2, 2))
        b.joint(f"leg{n}", "prismatic", f"cylinder_{n}", f"rod_{n}", axis=(0.0, 0.0, 1.0),
                limits=(params.leg_min, params.leg_max), effort=SA2_PD.effort, velocity=SA2_PD.speed)  # (a Linearmech SA 2 PD: 310 N, 0.5 m/s)
        b.frame(f"ball_{n}", f"rod_{n}")
        b.frame(f"cylinder_{n}_end", f"cylinder_{n}", (0.0, 0.0, params.leg_min / 2))  # (drawn: the cylinder, the rod)
        b.frame(f"rod_{n}_end", f"rod_{n}", (0.0, 0.0, -params.leg_min / 2))
        b.frame(f"socket_{n}", "platform_link", params.platform[i])
        b.collision(f"cylinder_{n}", "capsule", (0.0, 0.0, params.leg_min / 4), radius=params.cylinder_radius,
                    length=params.leg_min / 2)
        b.collision(f"rod_{n}", "capsule", (0.0, 0.0, -params.leg_min / 4), radius=params.rod_radius,
                    length=params.leg_min / 2)
    return b.to_xml()


def closure_spec(params: GoughStewartParams) -> ClosureSpec:
    params = check_params(params, GoughStewartParams)
    reference = {k: tuple(v) for k, v in joint_values(params, reference_pose(params)).items()}
    return ClosureSpec(
        mechanism=NAME,
        description="6-UPS Gough-Stewart platform: universal joints on the base, actuated legs, ball joints (point "
                    "closures) on a free platform; task = the platform's pose",
        urdf=f"{NAME}.urdf",
        end_effector="platform",
        actuated=tuple(f"leg{n}" for n in range(1, 7)),
        closures=tuple(Closure(f"ball_{n}", "point", f"ball_{n}", f"socket_{n}") for n in range(1, 7)),
        task=TaskSpec(("pose",)),
        reference=reference,
        joint_types={f"u{n}": "universal" for n in range(1, 7)},
        branches={"extended": Branch("extended", {f"leg{n}": 1 for n in range(1, 7)},
                                     "every leg length positive (the other working modes reverse legs through their "
                                     "universal joints)")},
        default_branch="extended",
        parameters=spec_parameters(params),
    )


def build(params: GoughStewartParams | None = None) -> Mechanism:
    """The Gough-Stewart platform as a :class:`~pkm.core.Mechanism` (the default design when ``params`` is None)."""
    params = GoughStewartParams() if params is None else params
    return make_mechanism(urdf_xml(params), closure_spec(params), params)
