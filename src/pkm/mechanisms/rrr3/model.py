"""The planar 3-RRR as a Pinocchio tree plus loop closures: URDF, closure spec and the mechanism built from parameters.

Collision primitives (``<collision>`` elements of the URDF, sizes from :class:`Rrr3Params`), all centred on the
mechanism's plane:

* ``proximal_i``: a cylinder of radius ``link_radius`` from the base vertex (joint ``motor_i``) to the elbow
  ``D_i`` (joint ``elbow_i``);
* ``distal_i``: a cylinder of radius ``link_radius`` from ``D_i`` to the platform vertex (``A``: joint
  ``wrist_1`` for leg 1; ``B``, ``C``: frames ``leg2_tip``, ``leg3_tip``, closed on ``platform_B``, ``platform_C``);
* ``platform``: the triangle's circumscribed disc (centre ``G``, radius ``h / sqrt 3``, through ``A``, ``B``,
  ``C``), ``platform_thickness`` thick.

The base carries none: it is the ground plate under the plane that every link would touch. The links of one
plane model a mechanism whose legs cannot cross (a built one stacks them at different heights).
Neighbours touch where they are jointed.
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
    spec_parameters,
)
from pkm.mechanisms.rrr3.kinematics import joint_values, reference_pose
from pkm.mechanisms.rrr3.params import MODES, NAME, SQRT3, Rrr3Params, base_vertices


# ---------------------------------------------------------------------- tree and spec
def urdf_xml(params: Rrr3Params) -> str:
    """The URDF tree (see the module doc)."""
    params = check_params(params, Rrr3Params)
    b = UrdfBuilder(NAME)
    b.link("base")
    for i, vertex in enumerate(base_vertices(params)):
        n = i + 1
        b.link(f"proximal_{n}", params.m_proximal, (params.a / 2.0, 0.0, 0.0),
               rod_inertia(params.m_proximal, params.a, 0))
        b.joint(f"motor_{n}", "revolute", "base", f"proximal_{n}", (vertex[0], vertex[1], 0.0),
                effort=PM54_040.effort, velocity=PM54_040.speed)  # (a ROBOTIS PM54-040-S250-R: 3.9 N m, 28.4 rev/min, its datasheet)
        rod_collision(b, f"proximal_{n}", (0.0, 0.0, 0.0), (params.a, 0.0, 0.0), params.link_radius)
        b.link(f"distal_{n}", params.m_distal, (params.b / 2.0, 0.0, 0.0), rod_inertia(params.m_distal, params.b, 0))
        rod_collision(b, f"distal_{n}", (0.0, 0.0, 0.0), (params.b, 0.0, 0.0), params.link_radius)
        b.joint(f"elbow_{n}", "revolute", f"proximal_{n}", f"distal_{n}", (params.a, 0.0, 0.0))
        if n > 1:
            b.frame(f"leg{n}_tip", f"distal_{n}", (params.b, 0.0, 0.0))
    h, m = params.h, params.m_platform
    g_local = (h / 2.0, h / (2.0 * SQRT3), 0.0)
    # thin equilateral plate of side h: polar moment m h^2 / 12 about its centroid
    b.link("platform", m, g_local, np.diag([m * h * h / 24.0, m * h * h / 24.0, m * h * h / 12.0]))
    disc_collision(b, "platform", g_local, (0.0, 0.0, 1.0), h / SQRT3, params.platform_thickness)
    b.joint("wrist_1", "revolute", "distal_1", "platform", (params.b, 0.0, 0.0))
    b.frame("platform_A", "platform")
    b.frame("platform_B", "platform", (h, 0.0, 0.0))
    b.frame("platform_C", "platform", (h / 2.0, h * SQRT3 / 2.0, 0.0))
    b.frame("platform_center", "platform", g_local)
    return b.to_xml()


def closure_spec(params: Rrr3Params) -> ClosureSpec:
    params = check_params(params, Rrr3Params)
    reference = {k: tuple(v) for k, v in joint_values(params, reference_pose(params)).items()}
    branches = {}
    for name, signs in MODES.items():
        psi = ", ".join("+" if s > 0 else "-" for s in signs)
        roots = ", ".join("-" if s > 0 else "+" for s in signs)
        branches[name] = Branch(name, {f"elbow_{n}": s for n, s in zip((1, 2, 3), signs)},
                                f"signs of (psi_1, psi_2, psi_3) = ({psi}); eq. (9) roots ({roots})")
    return ClosureSpec(
        mechanism=NAME,
        description="planar 3-RRR (singularities and GCI); revolutes at B and C as point closures, "
                    "task = platform centroid x, y and orientation Phi",
        urdf=f"{NAME}.urdf",
        end_effector="platform_center",
        actuated=("motor_1", "motor_2", "motor_3"),
        closures=tuple(Closure(f"wrist_{n}", "point", f"leg{n}_tip", f"platform_{v}") for n, v in ((2, "B"), (3, "C"))),
        task=TaskSpec(("x", "y", "yaw")),
        reference=reference,
        branches=branches,
        default_branch=f"mode{params.branch}",
        parameters=spec_parameters(params),
    )


def build(params: Rrr3Params | None = None) -> Mechanism:
    """The planar 3-RRR as a :class:`~pkm.core.Mechanism` (reference design when ``params`` is None)."""
    params = Rrr3Params() if params is None else params
    return make_mechanism(urdf_xml(params), closure_spec(params), params)
