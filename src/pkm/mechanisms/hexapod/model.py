"""The reconfigurable hexapod as a Pinocchio tree plus loop closures: URDF, closure spec and the mechanism built from parameters.

Collision primitives (``<collision>`` elements of the URDF, sizes from :class:`HexapodParams`), cylinders of
radius ``link_radius`` on each link's axis:

* ``recon_i`` (legs 1-3): from the pivot ``F_i`` (joint ``beta_i``) to ``A_i`` (joint ``alpha_i``);
* ``arm_i``: from ``A_i`` (joint ``alpha_i``) to ``B_i`` (joint ``knee_i``);
* ``rod_i``: from ``B_i`` (joint ``knee_i_b``) to the spherical joint ``C_i`` (frame ``leg_i_tip``, closed on
  ``platform_c_i``);
* ``platform_body``: the prism as a cylinder of radius ``r`` along the platform's ``y`` axis between the planes
  of its two triangles (``y = 0`` and ``y = h``), the ``C_i`` on its rims.

The base carries none (the paper states its joint centres, not its shape), nor do the massless ``knee_cross_i``.
Neighbours touch where they are jointed.
"""

from __future__ import annotations

import numpy as np

from pkm.core.model.mechanism import (
    Mechanism,
)
from pkm.core.model.spec import Branch, Closure, ClosureSpec, TaskSpec
from pkm.core.model.urdf import UrdfBuilder
from pkm.mechanisms._common import (
    PH54_200,
    check_params,
    disc_collision,
    make_mechanism,
    rod_collision,
    rod_inertia,
    spec_parameters,
)
from pkm.mechanisms.hexapod.geometry import base_points, platform_local_points
from pkm.mechanisms.hexapod.kinematics import joint_values, reference_pose
from pkm.mechanisms.hexapod.params import (
    ACTUATED,
    BRANCHES,
    DEFAULT_BRANCH,
    NAME,
    HexapodParams,
    leg_frame,
)


# ---------------------------------------------------------------------- tree and spec
def urdf_xml(params: HexapodParams) -> str:
    """The URDF tree (see the module doc)."""
    params = check_params(params, HexapodParams)
    b = UrdfBuilder(NAME)
    b.link("base")
    for i, th in enumerate(params.theta):
        n = i + 1
        L = leg_frame(th)
        if i < 3:
            b.link(f"recon_{n}", params.m_recon, (params.Rr / 2, 0.0, 0.0), rod_inertia(params.m_recon, params.Rr, 0))
            b.joint(f"beta_{n}", "revolute", "base", f"recon_{n}", params.Rf * L[:, 0], L,
                    mimic=None if n == 1 else ("beta_1", 1.0, 0.0), effort=PH54_200.effort, velocity=PH54_200.speed)
            rod_collision(b, f"recon_{n}", (0.0, 0.0, 0.0), (params.Rr, 0.0, 0.0), params.link_radius)
            b.link(f"arm_{n}", params.m_arm, (params.LA / 2, 0.0, 0.0), rod_inertia(params.m_arm, params.LA, 0))
            b.joint(f"alpha_{n}", "revolute", f"recon_{n}", f"arm_{n}", (params.Rr, 0.0, 0.0), effort=PH54_200.effort, velocity=PH54_200.speed)
        else:
            b.link(f"arm_{n}", params.m_arm, (params.LA / 2, 0.0, 0.0), rod_inertia(params.m_arm, params.LA, 0))
            b.joint(f"alpha_{n}", "revolute", "base", f"arm_{n}", base_points(params, 0.0)[i], L, effort=PH54_200.effort, velocity=PH54_200.speed)
        rod_collision(b, f"arm_{n}", (0.0, 0.0, 0.0), (params.LA, 0.0, 0.0), params.link_radius)
        b.link(f"knee_cross_{n}")
        b.joint(f"knee_{n}", "revolute", f"arm_{n}", f"knee_cross_{n}", (params.LA, 0.0, 0.0))
        b.link(f"rod_{n}", params.m_rod, (params.LB / 2, 0.0, 0.0), rod_inertia(params.m_rod, params.LB, 0))
        rod_collision(b, f"rod_{n}", (0.0, 0.0, 0.0), (params.LB, 0.0, 0.0), params.link_radius)
        b.joint(f"knee_{n}_b", "revolute", f"knee_cross_{n}", f"rod_{n}", axis=(0.0, 1.0, 0.0))
        b.frame(f"leg_{n}_tip", f"rod_{n}", (params.LB, 0.0, 0.0))
    mp, r = params.m_platform, params.r
    b.link("platform_body", mp, (0.0, params.h / 2, 0.0), np.diag([mp * r * r / 4, mp * r * r / 2, mp * r * r / 4]))
    disc_collision(b, "platform_body", (0.0, params.h / 2, 0.0), (0.0, 1.0, 0.0), r, params.h)
    b.joint("platform", "floating", "base", "platform_body")
    for i, c in enumerate(platform_local_points(params)):
        b.frame(f"platform_c_{i + 1}", "platform_body", c)
    return b.to_xml()


def closure_spec(params: HexapodParams) -> ClosureSpec:
    """The closure spec: six point closures (the spherical joints), reference at the home pose."""
    params = check_params(params, HexapodParams)
    values = joint_values(params, *reference_pose(params))
    return ClosureSpec(
        mechanism=NAME,
        description="Reconfigurable hexapod of two 3-RUS sub-manipulators (Sanchez-Alonso et al. 2016); "
                    "beta_2, beta_3 mimic beta_1 (gear train); alpha_1..alpha_3 relative to the "
                    "reconfiguration links",
        urdf=f"{NAME}.urdf",
        end_effector="platform",
        actuated=ACTUATED,
        closures=tuple(Closure(f"c_{n}", "point", f"leg_{n}_tip", f"platform_c_{n}") for n in range(1, 7)),
        task=TaskSpec(("pose",), ("beta_1",)),
        reference={k: tuple(v) for k, v in values.items()},
        branches={name: Branch(name, {f"knee_{n}": s for n in range(1, 7)},
                               f"arm turned {'+' if s < 0 else '-'}delta about u_i from A_iC_i, B_i on the "
                               f"{'outer' if s < 0 else 'inner'} side (knee_i {'<' if s < 0 else '>'} 0)")
                  for name, s in BRANCHES.items()},
        default_branch=DEFAULT_BRANCH,
        parameters=spec_parameters(params),
    )


def build(params: HexapodParams | None = None) -> Mechanism:
    """The hexapod as a :class:`~pkm.core.Mechanism` (paper design when ``params`` is None)."""
    params = HexapodParams() if params is None else params
    return make_mechanism(urdf_xml(params), closure_spec(params), params)
