"""The 3-PRS as a Pinocchio tree plus loop closures: URDF, closure spec and the mechanism built from parameters.

Collision primitives (``<collision>`` elements of the URDF, sizes from :class:`Prs3Params`):

* ``base``: a disc of radius ``g`` and thickness ``base_thickness`` under the base plane (``z = 0``), the rails
  standing on its rim at ``a_i``;
* ``slider_link_i``: a cube of edge ``slider_size`` centred on the knee axis on the rail (the origin of joint
  ``knee_i``), edges along the rail, the knee axis and ``w_i``;
* ``coupler_i``: a cylinder of radius ``link_radius`` from the knee (joint ``knee_i``) to the spherical joint
  (frame ``coupler_i_tip``, closed on ``platform_ball_i``);
* ``platform_link``: a disc of radius ``h`` and thickness ``platform_thickness`` whose mid-plane holds the
  spherical joints' centres.

The rails are not drawn (their length is not a design parameter). Neighbours touch where they are jointed.
"""

from __future__ import annotations

from pkm.core.model.mechanism import Mechanism
from pkm.core.model.spec import Branch, Closure, ClosureSpec, TaskSpec
from pkm.core.model.urdf import UrdfBuilder
from pkm.mechanisms._common import (
    PH54_200,
    SA2_PD,
    check_params,
    disc_collision,
    make_mechanism,
    rod_collision,
    rod_inertia,
    rot_y,
    rot_z,
    spec_parameters,
)
from pkm.mechanisms.prs3.kinematics import joint_values, leg_geometry, reference_pose
from pkm.mechanisms.prs3.params import ACTUATIONS, BRANCHES, DEFAULT_BRANCH, NAME, PHI, Prs3Params


# ---------------------------------------------------------------------- tree and spec
def urdf_xml(params: Prs3Params) -> str:
    """The URDF tree: free platform, and per leg base -> slider -> coupler (see the module doc)."""
    params = check_params(params, Prs3Params)
    b = UrdfBuilder(NAME)
    b.link("base")
    disc_collision(b, "base", (0.0, 0.0, -params.base_thickness / 2), (0.0, 0.0, 1.0), params.g,
                   params.base_thickness)
    reach = 2.0 * (params.g + params.h + 2.0 * params.l)  # slider travel (informative: pkm reads no limits)
    a, _, _, _, bp = leg_geometry(params)
    for i in range(3):
        n = i + 1
        # slider frame: x along the rail u_1, y along e_t (knee axis), z along w (coupler at theta = 0)
        b.link(f"slider_link_{n}", params.m_slider)
        b.joint(f"slider_{n}", "prismatic", "base", f"slider_link_{n}", a[i], rot_z(PHI[i]) @ rot_y(-params.gamma),
                axis=(1.0, 0.0, 0.0), limits=(-reach, reach), effort=SA2_PD.effort, velocity=SA2_PD.speed)  # (Linearmech SA 2 PD: 310 N, 0.5 m/s)
        e = params.slider_size
        b.collision(f"slider_link_{n}", "box", x=e, y=e, z=e)
        b.link(f"coupler_{n}", params.m_coupler, (0.0, 0.0, params.l / 2), rod_inertia(params.m_coupler, params.l, 2))
        knee = params.actuation == "R"  # (the knees actuated: a ROBOTIS PH54-200-S500-R drives each)
        b.joint(f"knee_{n}", "revolute", f"slider_link_{n}", f"coupler_{n}", axis=(0.0, 1.0, 0.0),
                effort=PH54_200.effort if knee else 1e3, velocity=PH54_200.speed if knee else 1e2)
        rod_collision(b, f"coupler_{n}", (0.0, 0.0, 0.0), (0.0, 0.0, params.l), params.link_radius)
        b.frame(f"coupler_{n}_tip", f"coupler_{n}", (0.0, 0.0, params.l))
    # link "platform_link": Pinocchio 4.1 refuses a name shared by a body frame and a joint frame
    b.link("platform_link", params.m_platform, inertia=params.platform_inertia)
    disc_collision(b, "platform_link", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), params.h, params.platform_thickness)
    b.joint("platform", "floating", "base", "platform_link")
    for i in range(3):
        b.frame(f"platform_ball_{i + 1}", "platform_link", bp[i])
    return b.to_xml()


def closure_spec(params: Prs3Params) -> ClosureSpec:
    """Closures, actuation (``params.actuation``), task, branches and the reference configuration."""
    params = check_params(params, Prs3Params)
    reference = {k: tuple(v) for k, v in joint_values(params, reference_pose(params)).items()}
    joint = ACTUATIONS[params.actuation]
    return ClosureSpec(
        mechanism=NAME,
        description=f"3-PRS (Diaz-Rodriguez et al. 2016), actuated in the {params.actuation} joints; spherical "
                    "joints as point closures, free platform",
        urdf=f"{NAME}.urdf",
        end_effector="platform",
        actuated=tuple(f"{joint}_{n}" for n in (1, 2, 3)),
        closures=tuple(Closure(f"ball_{n}", "point", f"coupler_{n}_tip", f"platform_ball_{n}") for n in (1, 2, 3)),
        task=TaskSpec(("z", "pitch", "roll")),
        reference=reference,
        branches={name: Branch(name, {f"knee_{n}": s for n in (1, 2, 3)},
                               f"every slider {name.split('_')[1]} its spherical joint "
                               f"(knee_i {'>' if s > 0 else '<'} 0)") for name, s in BRANCHES.items()},
        default_branch=DEFAULT_BRANCH,
        parameters=spec_parameters(params),
    )


def build(params: Prs3Params | None = None) -> Mechanism:
    """The 3-PRS as a :class:`~pkm.core.Mechanism` (Table 2 design when ``params`` is None)."""
    params = Prs3Params() if params is None else params
    return make_mechanism(urdf_xml(params), closure_spec(params), params)
