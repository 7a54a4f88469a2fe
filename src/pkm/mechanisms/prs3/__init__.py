"""3-PRS robot (Diaz-Rodriguez, Carretero, Bautista-Quintero & Chacon, 2016): tree, closures, closed forms.

Geometry (paper eqs. 6-7, SI units): base frame O at the centre of the base, Z up. Leg ``i``
(``i = 1, 2, 3``) lies in the vertical plane spanned by ``e_r,i = (cos phi_i, sin phi_i, 0)`` and
``e_z``, ``phi_i = 0, 120, 240 deg``. Its rail (prismatic joint ``slider_i``) passes through
``a_i = g e_r,i`` with direction ``u_1,i = cos(gamma) e_r,i + sin(gamma) e_z``; the slider sits at
``S_i = a_i + d_i u_1,i``. A revolute ``knee_i`` of axis ``e_t,i = e_z x e_r,i`` (normal to the leg
plane) carries the coupler of length ``l`` to the spherical joint at the platform point
``B_i = p + R b_i``, ``b_i = h e_r,i`` in the platform frame. The platform (link ``platform_link``)
is a free body: URDF ``floating`` joint ``platform``, whose frame ``platform`` at ``p`` is the end
effector. Each spherical joint is a point closure ``coupler_i_tip`` == ``platform_ball_i``.

Rail inclination: ``gamma`` is the angle between the rail and the base plane, measured in the
leg plane from ``e_r,i`` (outward) towards ``e_z``: for ``gamma < pi/2`` the rail rises away from
the centre, for ``gamma > pi/2`` towards it. DH table 1 (``alpha_i1 = gamma_i``) does not fix
this direction without the paper's missing Fig. 2; the choice only matters for inclined rails
(Table 2 has ``gamma = pi/2``: vertical rails).

Joint conventions: ``slider_i`` is ``d_i``, the distance from ``a_i`` along ``u_1,i``. ``knee_i`` is
``theta_i``, with ``u_2,i = cos(theta_i) w_i + sin(theta_i) u_1,i`` the coupler direction and
``w_i = -sin(gamma) e_r,i + cos(gamma) e_z`` the inward normal to the rail in the leg plane:
``theta_i = 0`` when the coupler is perpendicular to the rail pointing inward, which is the double
root of eq. (10). Working modes (``Branch`` on the signs of ``knee_i``): ``slider_below`` (default,
the prototype of Fig. 1) has ``theta_i > 0``, the coupler pointing up the rail, the slider below the
spherical joint; ``slider_above`` has ``theta_i < 0``. (The other double root, coupler pointing
outward, is at ``theta_i = +-pi``, outside the useful workspace.)

Task: the paper's independent coordinates ``(z_p, beta, phi)`` with ``R = Rz(alpha) Ry(beta) Rx(phi)``
(eq. 1), i.e. pkm's task components ``["z", "pitch", "roll"]``. The parasitic motion
``x_p, y_p, alpha`` follows from the three spherical-joint centres staying in their leg planes
(eqs. 12-14, ``e_t,i . B_i = 0``): :func:`parasitic_motion`.

Actuation: ``"P"`` (sliders, Table 2 and sec. 5) or ``"R"`` (knees). With vertical rails and
``"R"`` the three passive sliders are parallel: the platform can rise with every knee locked, a
direct (type 2) singularity everywhere; :func:`pkm.core.diagnose` reports it. Knee actuation needs
inclined rails.

Departures from the paper (each covered by a test):

* Eq. (10) lacks a square: ``d_i = c_i.u_1,i -+ sqrt((c_i.u_1,i)^2 - c_i.c_i + l^2)`` with
  ``c_i = p + R b_i - a_i`` (as printed the radicand mixes m and m^2). ``slider_below`` takes the
  minus sign.
* Eq. (15) as printed does not hold for the layout of eqs. (6)-(7): its ``x_p`` and ``y_p`` are those
  of the layout rotated by 90 deg about Z (leg 1 on the +Y axis). For eqs. (6)-(7) the leg-plane
  conditions give ``R_01 = R_10`` (hence eq. 15's ``alpha``, which is right) and
  ``x_p = h (R_00 - R_11) / 2 = h/2 (c_a c_b - s_a s_b s_f - c_a c_f)``, ``y_p = -h R_10 = -h s_a c_b``:
  eq. (15)'s ``(x_p, y_p)`` is our ``(y_p, -x_p)``. Both vanish at ``beta = phi = 0`` and differ at
  second order in the angles. The printed form is kept as :func:`paper_parasitic_motion`.
* Eq. (7) labels ``a_i`` in frame p; it is in frame O.
* The paper has no forward-kinematics method: ``closed_form_fk`` is not offered (use
  :func:`pkm.core.close_loops`).

Masses and inertias: Table 2, read from ``dynamics/prs3_table2.toml`` (:func:`table2`). The slider
is a point mass at the revolute centre (it only translates, so its rotational inertia does no
work); the coupler's centre of mass is at ``l/2`` (Table 2's ``m_x2 = l m2 / 2``) with inertia
``m2 l^2 / 12`` about both transverse axes through it (Table 2's ``I_zz2`` about the revolute axis
direction) and 0 about its own axis.
"""

from __future__ import annotations

from pkm.mechanisms.prs3.kinematics import (
    ROOT_TOL,
    branch_names,
    closed_form_configuration,
    closed_form_ik,
    configuration,
    inverse_kinematics,
    joint_values,
    leg_geometry,
    leg_vectors,
    paper_constraint_jacobians,
    paper_parasitic_motion,
    parasitic_motion,
    platform_pose,
    reference_pose,
)
from pkm.mechanisms.prs3.model import (
    build,
    closure_spec,
    urdf_xml,
)
from pkm.mechanisms.prs3.params import (
    ACTUATIONS,
    BRANCHES,
    DEFAULT_BRANCH,
    NAME,
    PHI,
    TABLE2_FILE,
    TABLE2_FORMAT,
    TABLE2_KEYS,
    Params,
    Prs3Params,
    as_task,
    table2,
)

#: The paper has no forward-kinematics method (the generic core's ``close_loops`` solves it).
closed_form_fk = None

__all__ = [
    "ACTUATIONS",
    "BRANCHES",
    "DEFAULT_BRANCH",
    "NAME",
    "PHI",
    "ROOT_TOL",
    "TABLE2_FILE",
    "TABLE2_FORMAT",
    "TABLE2_KEYS",
    "Params",
    "Prs3Params",
    "as_task",
    "branch_names",
    "build",
    "closed_form_configuration",
    "closed_form_fk",
    "closed_form_ik",
    "closure_spec",
    "configuration",
    "inverse_kinematics",
    "joint_values",
    "leg_geometry",
    "leg_vectors",
    "paper_constraint_jacobians",
    "paper_parasitic_motion",
    "parasitic_motion",
    "platform_pose",
    "reference_pose",
    "table2",
    "urdf_xml",
]
