"""Planar 3-RRR parallel robot (singularities and global condition index): tree, closures, closed forms.

Geometry (paper sec. II.A, SI units). The base triangle ``P, Q, R`` is equilateral
with side ``H``; the world origin is at ``P``, ``x`` along ``PQ``, ``z`` out of the
plane: ``P = (0, 0)``, ``Q = (H, 0)``, ``R = (H/2, H sqrt(3)/2)``. The moving
platform ``A, B, C`` is equilateral with side ``h``; the paper places it by ``A``
and the orientation ``Phi`` (eqs. 1-2)::

    B = A + h (cos Phi, sin Phi),    C = A + h (cos(Phi + pi/3), sin(Phi + pi/3)).

Leg 1 is ``P -> D1 -> A``, leg 2 ``Q -> D2 -> B``, leg 3 ``R -> D3 -> C``: a proximal
link ``a`` driven at the base vertex (``theta_i`` measured from ``+x``), then a distal
link ``b``; ``psi_i`` is the relative angle of the distal link (eq. 4):
``A = P + a (cos th_1, sin th_1) + b (cos(th_1 + psi_1), sin(th_1 + psi_1))``.

Tree: every joint axis is ``z``. Leg ``i``: ``motor_i`` (actuated, coordinate
``theta_i``) at its base vertex, link ``a`` along local ``x``, ``elbow_i`` (coordinate
``psi_i``: 0 = leg fully extended, +-pi = folded, both singular), link ``b`` along
local ``x``. Leg 1 carries the platform through ``wrist_1`` at ``A`` (coordinate
``Phi - theta_1 - psi_1``); legs 2 and 3 end at frames ``leg2_tip``, ``leg3_tip``,
tied by point closures ``wrist_2``, ``wrist_3`` to the platform frames ``platform_B``,
``platform_C``. The platform body frame has its origin at ``A`` and ``x`` along ``AB``
(its yaw is ``Phi``); frames ``platform_A`` (at ``A``) and ``platform_center`` (the
end effector, at the centroid ``G``, same axes) are attached to it.

Task: ``["x", "y", "yaw"]`` of the centroid ``G``, i.e. ``y = (x_G, y_G, Phi)``. The
paper locates the platform by ``A`` and ``Phi``; ``G = A + (h / sqrt 3)(cos(Phi + pi/6),
sin(Phi + pi/6))`` and the helpers :func:`centroid_from_a` / :func:`a_from_centroid`
convert. :func:`inverse_kinematics` takes the paper's ``(A, Phi)``.

Inverse kinematics (eqs. 6-9). In leg ``i``'s base-vertex frame (translated, not
rotated: ``(x, y)`` = platform vertex minus base vertex) eq. (6) reads
``e1 sin th + e2 cos th + e3 = 0`` with ``e1 = -2 y a``, ``e2 = -2 x a``,
``e3 = x^2 + y^2 + a^2 - b^2`` (eqs. 7-8), whose half-angle solution is eq. (9)::

    th = 2 atan((-e1 +/- sqrt(e1^2 + e2^2 - e3^2)) / (e3 - e2)).

Working modes. The two roots of eq. (9) are the two elbow postures of a leg:
the ``+`` root has ``psi_i < 0``, the ``-`` root ``psi_i > 0``. (With ``d = |(x, y)|``,
``alpha = atan2(y, x)``, ``delta`` the angle at the base vertex of the triangle
vertex-elbow-platform vertex, the ``+/-`` root is ``th = alpha +/- delta``.) The eight
working modes are the sign combinations of ``(psi_1, psi_2, psi_3)``, named
``"mode1"`` .. ``"mode8"``: mode ``k`` <-> the bits of ``k - 1``, leg 1 the most
significant; bit 0 -> ``psi_i > 0`` (``-`` root), bit 1 -> ``psi_i < 0`` (``+`` root).
``mode1`` = ``(+, +, +)`` (all ``-`` roots), ``mode8`` = ``(-, -, -)`` (all ``+`` roots);
for example ``mode3`` = bits ``010`` = ``(+, -, +)``. Modes 1 and 8 are the two that
keep the three legs alike, which agrees with the paper's finding (sec. VIII, Fig. 8)
that only the first and last modes are suitable; the paper does not print the
sign convention behind its numbering, so this correspondence is ours. As everywhere in
pkm, a working mode is a ``branch``: the functions take ``branch=`` (``k`` or ``"modek"``;
default the design's ``Rrr3Params.branch``), the spec names ``[branch.mode1]`` ..
``[branch.mode8]`` (``mode=`` and :func:`mode_signs` are the deprecated former names).

Departures from the paper:

* Eq. (9) is rebuilt (the OCR lost part of it) and evaluated in the equivalent form
  ``th = atan2(-e1, -e2) +/- atan2(sqrt(e1^2 + e2^2 - e3^2), e3)``, equal to it modulo
  ``2 pi``. The half-angle form divides by ``e3 - e2``, which vanishes at regular poses
  (where the other root is ``th = pi``); the atan2 form is defined at every reachable
  pose except the degenerate ``d = 0`` (only possible when ``a = b``; then ``theta_i`` is
  undetermined and :class:`~pkm.errors.SingularityError` is raised).
* The task point is the centroid ``G``, not the paper's ``A`` (see above).
* Eqs. (6)-(8) are written by the paper for leg 1, whose base vertex is the origin;
  for legs 2 and 3 they hold in the translated base-vertex frames, with ``theta_i`` still
  measured from the world ``+x`` axis.
* Eqs. (19)-(20) are rebuilt in :func:`jacobians` with the moments taken about ``G``
  (the task point) and without the homogenisation of eq. (25).
* Eq. (25) as printed divides the *direction* column ``s_ri`` by the characteristic length
  ``L``, which mixes 1 and 1/m in one row. :func:`homogenized_jacobians` divides the
  *moment* column ``(a_i x s_ri)`` by ``L`` instead, i.e. it uses the task rates
  ``(v_P, L Phi_dot)``, all in m/s; both the moment reference point ``P`` (``"centroid"``
  by default, ``"A"``, ``"origin"`` = the paper's ``O = P``) and ``L`` (default the platform
  circumradius ``h / sqrt 3``, Lou's "mean radius of the moving platform") are arguments.

Forward kinematics (:func:`forward_kinematics`; the paper gives none). With the motor
angles known the elbows ``D_i`` are known and the 3-RRR is a 3-RPR with three legs of fixed
length ``b``: ``|V_i(A, Phi) - D_i| = b``. Subtracting leg 1's equation from legs 2 and 3
leaves two equations linear in ``A``; substituting ``A(Phi)`` into leg 1's equation gives a
trigonometric polynomial of degree 4 in ``Phi`` (a degree-8 polynomial in ``z = e^{i Phi}``
whose roots on the unit circle are the assembly modes; for the 3-RPR at most 6 are real).
Its coefficients are read exactly off 16 samples by an FFT, its roots found from the
companion matrix, and every candidate is polished by Newton on the three leg equations and
kept only if they hold to ``tol``; duplicates (double roots at direct singularities) merge.

The reference design (paper sec. III, workspace study): links ``a = b = 40 cm``,
platform side ``h = 10 cm``, actuator separation ``H = 100 cm``, ``mode1``, centroid at
the base centroid with ``Phi = 0``. There every leg has ``|psi_i| = 99 deg`` and the
platform is far from a direct singularity (see the tests). Masses are not given by
the paper; the defaults are illustrative and only matter for dynamics.
"""

from __future__ import annotations

from pkm.mechanisms.rrr3.kinematics import (
    REFERENCES,
    FkSolution,
    a_from_centroid,
    centroid_from_a,
    characteristic_length,
    classify_singularity,
    closed_form_configuration,
    closed_form_fk,
    closed_form_ik,
    configuration,
    forward_kinematics,
    homogenized_jacobians,
    inverse_kinematics,
    jacobians,
    joint_values,
    leg_elbows,
    platform_vertices,
    reference_point,
    reference_pose,
    singularity_measures,
)
from pkm.mechanisms.rrr3.model import (
    build,
    closure_spec,
    urdf_xml,
)
from pkm.mechanisms.rrr3.params import (
    MODES,
    NAME,
    REACH_TOL,
    SQRT3,
    Params,
    Rrr3Params,
    base_centroid,
    base_vertices,
    branch_signs,
    mode_signs,
)

__all__ = [
    "MODES",
    "NAME",
    "REACH_TOL",
    "REFERENCES",
    "SQRT3",
    "FkSolution",
    "Params",
    "Rrr3Params",
    "a_from_centroid",
    "base_centroid",
    "base_vertices",
    "branch_signs",
    "build",
    "centroid_from_a",
    "characteristic_length",
    "classify_singularity",
    "closed_form_configuration",
    "closed_form_fk",
    "closed_form_ik",
    "closure_spec",
    "configuration",
    "forward_kinematics",
    "homogenized_jacobians",
    "inverse_kinematics",
    "jacobians",
    "joint_values",
    "leg_elbows",
    "mode_signs",
    "platform_vertices",
    "reference_point",
    "reference_pose",
    "singularity_measures",
    "urdf_xml",
]
