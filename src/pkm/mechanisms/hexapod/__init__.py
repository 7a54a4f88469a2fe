"""Reconfigurable hexapod of two 3-RUS sub-manipulators (Sanchez-Alonso et al., RIAI 2016).

Geometry (paper eqs. 1-3, SI units, base frame O with Y up): for leg ``i`` (``i = 1..6``)
``e_r = (cos th_i, 0, sin th_i)``, ``e_y = (0, 1, 0)`` and the actuated axis
``u_i = e_r x e_y = (-sin th_i, 0, cos th_i)``, tangent to the base circle. The *leg frame*
has axes ``(e_r, e_y, u_i)`` (``= Ry(-th_i)``); a positive turn about ``u_i`` takes ``e_r``
towards ``e_y``.

* Sub-manipulator M1 (legs 1-3): the reconfiguration link of length ``Rr`` (Table 1's
  ``R_r``, eq. 2's ``R_c``: the same 150 mm) turns by ``beta`` about ``u_i`` at
  ``F_i = Rf e_r``, so ``A_i = F_i + Rr (cos beta e_r + sin beta e_y)``, i.e. eq. (2) with
  ``R = Rf + Rr cos beta`` and ``D = Rr sin beta``.
* Sub-manipulator M2 (legs 4-6): ``A_i = R2 e_r - H0 e_y``.
* Both: ``B_i = A_i + LA (cos alpha_i e_r + sin alpha_i e_y)`` (eq. 3, ``alpha_i`` the paper's
  *absolute* angle from the horizontal radial direction) and ``|C_i - B_i| = LB`` (eq. 6).

Platform (a triangular prism): its frame sits at ``P``, the centroid of ``C4 C5 C6`` (eq. 8),
its ``x`` axis points at ``C4`` (eq. 10) and its ``y`` axis is the unit normal from triangle
``C4C5C6`` to triangle ``C1C2C3`` (up at the reference pose). In that frame
``C*_{j+3} = r (cos psi_j, 0, sin psi_j)`` and ``C*_j = C*_{j+3} + h y`` (``j = 1, 2, 3``):
M1 holds the upper triangle ``C1C2C3``, M2 the lower one (eq. 4 with ``g = -y``).

Platform layouts (parameter ``layout``):

* ``"sector"`` (default): ``psi = 0, 120, 240 deg`` for ``C4, C5, C6``; each ``C_i`` lies in the
  angular sector of its base joint (``th_i`` near ``psi``). Seen from above (+Y) the triangles
  run counter-clockwise, so two printed equations change sign. Exact departures: eq. (5)
  becomes ``g = (2/sqrt 3) (C1 - C3) x (C2 - C3) / e^2`` (the factors of the cross product
  swapped; as printed it gives the upward normal, which would put ``C4..C6`` *above*
  ``C1..C3``), and eq. (11) becomes ``z = (C5 - C6) / |C5 - C6|`` (as printed it gives ``-z``, and
  eq. (12) then turns ``y`` downwards: the frame of eqs. 10-12 would be rotated by pi about x).
  Equivalently, the printed eqs. (5), (10)-(12) hold verbatim with the labels 2<->3 and 5<->6
  exchanged on the platform.
* ``"literal"``: eqs. (5), (10)-(12) read literally with Y up: ``psi = 0, 240, 120 deg``. It is
  self-consistent but ``C5`` (at 240 deg) faces ``A6`` (``th6 = 265 deg``) and ``C6`` (120 deg)
  faces ``A5`` (145 deg): legs 5 and 6 cross (and so do legs 2 and 3).

Only the sector layout with the ``elbow_out`` branch reproduces the paper's pose-T optimum
(sec. 4: both manipulabilities of eq. 37 peak near ``beta = -11 deg``; this model gives -10 deg
for ``w_rot`` and -11 deg for ``w_tras``, see the tests). With the same branch on both
sub-manipulators, the other layout/branch pairs peak at -59 deg (sector, elbow_in), 40 deg
(literal, elbow_out), 3.5/90 deg (literal, elbow_in). Note that ``sqrt(det(J J^T))`` grows as
``J_x`` nears a direct singularity: along ``beta`` at pose T, ``|det J_x|`` is smallest at -17.4 deg
(no crossing), and the smallest singular value of the passive-joint constraint columns is only
6.5e-3 there, so pose T lies close to a direct singularity.

Tree (URDF, loops open; Pinocchio model with ``nq = 26``, ``nv = 25``):

* ``beta_1`` (actuated), ``beta_2``, ``beta_3``: revolute joints at ``F_i`` about ``u_i``
  (frame axes ``(e_r, e_y, u_i)``, axis local z) carrying the reconfiguration links along
  local x. ``beta_2`` and ``beta_3`` are URDF *mimic* joints of ``beta_1`` (multiplier 1,
  offset 0), as the crossed-helical gear train of the paper's Fig. 2b couples the three
  links: Pinocchio gives the three of them one coordinate.
* ``alpha_i``: revolute at ``A_i`` about ``u_i``, arm ``LA`` along local x. For legs 1-3 the
  joint is carried by the reconfiguration link, so its coordinate is *relative*:
  ``alpha_i(joint) = alpha_i(paper) - beta`` (the screw model of eq. 18 uses relative rates,
  ``beta_dot`` and ``alpha_i_dot`` on successive screws); for legs 4-6 it sits on the base and
  equals the paper's ``alpha_i``. :func:`paper_alphas` and :func:`actuated_from_paper` convert.
* Universal joint at ``B_i``: ``knee_i`` about ``u_i`` (local z), the angle from ``LA`` to the
  projection of the rod ``LB`` on the leg plane (normal ``u_i``): 0 when that projection extends
  ``LA`` and +-pi when it folds back over it (the two double roots of the leg's inverse problem);
  then ``knee_i_b`` about the perpendicular axis (local y after the first turn); rod ``LB``
  along local x, frame ``leg_i_tip`` at its end.
* The spherical joints are point closures ``c_i``: ``leg_i_tip`` = ``platform_c_i`` (frame at
  ``C*_i`` on the platform).
* The platform: link ``platform_body`` on the URDF ``floating`` joint ``platform`` (free-flyer
  ``x y z qx qy qz qw``); the end effector is that joint's frame ``platform``, at ``P``. (The link
  cannot share the joint's name: Pinocchio 4.1 refuses a frame name that matches two frames.)

Actuated joints, in this order: ``alpha_1 .. alpha_6, beta_1``. Task: the platform pose and
``beta_1`` (``x y z qx qy qz qw beta``; 7 outputs for 7 actuators): the robot is redundant for
a pose, and ``beta`` is chosen by the user (the paper picks it by maximising manipulability).

Working modes: each leg has two solutions (``alpha = phi +- delta``, see
:func:`inverse_kinematics`). ``elbow_out`` (default, the paper's, see above):
``alpha = phi + delta``, the arm turned positively about ``u_i`` from the direction ``A_i C_i``,
so that ``B_i`` lies on the outer/lower side of the line ``A_iC_i``; then ``knee_i < 0``.
``elbow_in``: ``alpha = phi - delta``, ``knee_i > 0``.

Reachability of pose T (sec. 4: "only for ``-60 <= beta <= 90 deg``"): leg 1 folds too much
(``|C1 - A1| < LB - LA``) for ``beta`` below -59.51 deg (down to -121.8 deg); within the studied
``[-90, 90] deg`` the pose is reachable exactly for ``beta >= -59.51 deg``. Reachability of a leg
does not depend on its branch, and ``C1`` is the same in both layouts, so both branches and both
layouts give this interval (legs 2 and 3 lose the pose below -65.81/-60.02 deg in the sector
layout, -70.36/-91.81 deg in the literal one).

Printed equations corrected (derived from the geometry, checked in the tests):

* Eq. (17): ``Q_i = 2 C_xi cos th_i + 2 C_zi sin th_i`` (the second cosine is a sine).
* Eq. (15): the radicand begins with ``4 (C_yi - D)^2``, not ``4 (D - 2 C_yi)^2``; the rest of
  eqs. (15)-(16) is right. Its two signs give the two branches (at pose T, ``+`` gives
  ``elbow_out``; which sign gives which branch depends on the sign of the denominator).

Forward kinematics: the paper's semi-closed system (eqs. 4-7, nine quadratic equations in
``C1, C2, C3``) solved by Newton's method from a seed (:func:`forward_kinematics`), then the
pose by eqs. (8)-(13) with the layout's convention. It does not use the generic core. Newton's
method keeps the seed's assembly mode only when the seed is close enough: in the literal layout
at ``beta = 85 deg``, from pose T, it lands on another assembly about 35 mm away.
:func:`assembly_modes` searches for other assembly modes (multistart from random platform poses)
and checks each with the generic core's closure residual; at pose T it finds a second mode about
3 mm from the first (pose T lies near a direct singularity).

Platform rotations given by the user are checked by :func:`pkm.core.kinematics.task.as_rotation`: a defect
``max|R^T R - I|`` up to :data:`ROTATION_TOL` (matrices printed with 4 digits) is projected away,
a larger one is refused with its size.

Companion modules: :mod:`pkm.mechanisms.hexapod.screws` (screw-theory velocity and acceleration,
eqs. 18-33), :mod:`pkm.mechanisms.hexapod.singularities` (types 1-3, sec. 3.3),
:mod:`pkm.mechanisms.hexapod.indices` (``w_rot``, ``w_tras``, eqs. 34-37) and
:mod:`pkm.mechanisms.hexapod.reconfiguration` (the choice of ``beta``, sec. 4).

Pinocchio 4.1 and the mimic joints: the tree, frame Jacobians, frame accelerations, ``rnea`` and
``crba`` handle them; ``getConstraintsJacobian`` and ``aba`` raise ``RuntimeError`` and
``constraintDynamics`` aborts the interpreter on this model.

Masses are not given by the paper; the defaults are illustrative and only matter for dynamics.
"""

from __future__ import annotations

from pkm.core.kinematics.task import ROTATION_TOL
from pkm.mechanisms.hexapod.geometry import (
    actuated_from_paper,
    base_points,
    branch_names,
    elbow_points,
    inverse_kinematics,
    paper_alphas,
    platform_local_points,
    platform_points,
)
from pkm.mechanisms.hexapod.kinematics import (
    AssemblyMode,
    assembly_modes,
    closed_form_configuration,
    closed_form_fk,
    closed_form_ik,
    configuration,
    forward_kinematics,
    joint_values,
    pose_from_points,
    reference_pose,
    task_vector,
)
from pkm.mechanisms.hexapod.model import (
    build,
    closure_spec,
    urdf_xml,
)
from pkm.mechanisms.hexapod.params import (
    ACTUATED,
    BRANCHES,
    DEFAULT_BRANCH,
    HOME_ROTATION_TOL,
    LAYOUTS,
    NAME,
    HexapodParams,
    Params,
    leg_frame,
)

__all__ = [
    "ACTUATED",
    "BRANCHES",
    "DEFAULT_BRANCH",
    "HOME_ROTATION_TOL",
    "LAYOUTS",
    "NAME",
    "ROTATION_TOL",
    "AssemblyMode",
    "HexapodParams",
    "Params",
    "actuated_from_paper",
    "assembly_modes",
    "base_points",
    "branch_names",
    "build",
    "closed_form_configuration",
    "closed_form_fk",
    "closed_form_ik",
    "closure_spec",
    "configuration",
    "elbow_points",
    "forward_kinematics",
    "inverse_kinematics",
    "joint_values",
    "leg_frame",
    "paper_alphas",
    "platform_local_points",
    "platform_points",
    "pose_from_points",
    "reference_pose",
    "task_vector",
    "urdf_xml",
]
