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
6.5e-3 at the reference configuration, so pose T lies close to a direct singularity.

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

Platform rotations given by the user are checked by :func:`pkm.core.task.as_rotation`: a defect
``max|R^T R - I|`` up to :data:`ROTATION_TOL` (matrices printed with 4 digits) is projected away,
a larger one is refused with its size.

Companion modules: :mod:`pkm.mechanisms.hexapod_screws` (screw-theory velocity and acceleration,
eqs. 18-33), :mod:`pkm.mechanisms.hexapod_singularities` (types 1-3, sec. 3.3),
:mod:`pkm.mechanisms.hexapod_indices` (``w_rot``, ``w_tras``, eqs. 34-37) and
:mod:`pkm.mechanisms.hexapod_reconfigure` (the choice of ``beta``, sec. 4).

Pinocchio 4.1 and the mimic joints: the tree, frame Jacobians, frame accelerations, ``rnea`` and
``crba`` handle them; ``getConstraintsJacobian`` and ``aba`` raise ``RuntimeError`` and
``constraintDynamics`` aborts the interpreter on this model.

Masses are not given by the paper; the defaults are illustrative and only matter for dynamics.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pkm.core import constraints
from pkm.core.mechanism import (
    Mechanism,
    as_array,
    as_count,
    as_scalar,
    as_tolerance,
    as_vector,
    check_mechanism,
    wrap_angle,
)
from pkm.core.spec import Branch, Closure, ClosureSpec, TaskSpec
from pkm.core.task import ROTATION_TOL, as_rotation  # noqa: F401 (ROTATION_TOL: part of this module's API)
from pkm.core.urdf import UrdfBuilder
from pkm.errors import AssemblyError, ConvergenceError, InvalidInputError, InvalidParameterError, UnreachableError
from pkm.mechanisms._common import (
    arm_angle,
    check_finite,
    check_numbers,
    check_params,
    check_positive,
    make_mechanism,
    rod_inertia,
    rot_y,
    rot_z,
    spec_parameters,
)

NAME = "hexapod"
LAYOUTS = {"sector": (0.0, 120.0, 240.0), "literal": (0.0, 240.0, 120.0)}  # psi of C4, C5, C6 [deg]
BRANCHES = {"elbow_out": -1, "elbow_in": 1}  # sign of knee_i
DEFAULT_BRANCH = "elbow_out"
ACTUATED = ("alpha_1", "alpha_2", "alpha_3", "alpha_4", "alpha_5", "alpha_6", "beta_1")
#: The paper's pose T (sec. 4) as printed: rotation rows (4 digits) and position [m].
POSE_T_ROTATION = (0.9623, -0.1306, -0.2388, 0.0842, 0.9771, -0.1952, 0.2588, 0.1677, 0.9513)
POSE_T_POSITION = (0.0, -0.350, 0.0)

#: Largest ``max|R^T R - I|`` accepted for a platform rotation given by the user (then projected on SO(3)).
HOME_ROTATION_TOL = 1e-2  # parameter files may carry coarser matrices

_E_Y = np.array([0.0, 1.0, 0.0])


@dataclass(frozen=True)
class HexapodParams:
    """Reconfigurable hexapod design (paper Table 1 by default).

    Attributes:
        Rf: Radius of the reconfiguration pivots ``F_i`` (M1) [m] (50 mm).
        Rr: Reconfiguration link length (``R_r`` of Table 1, ``R_c`` of eq. 2) [m] (150 mm).
        R2: Radius of the actuated joints ``A_4..A_6`` (M2) [m] (450 mm).
        H0: Depth of the plane of ``A_4..A_6`` below O [m] (200 mm).
        LA: Arm length [m] (200 mm).
        LB: Rod length (``B_i`` to ``C_i``) [m] (400 mm).
        h: Height of the platform prism [m] (34 mm).
        r: Circumradius of the platform triangles [m] (50 mm).
        theta: Angular position ``th_i`` of leg i about Y, from +X [rad] (35, 155, 275, 25, 145, 265 deg).
        layout: ``"sector"`` or ``"literal"`` platform layout (see the module doc).
        home_rotation: Reference platform orientation, rows of a 3x3 matrix [-] (the paper's pose T as
            printed; projected on SO(3) by SVD).
        home_position: Reference position of ``P`` [m] (pose T: (0, -350, 0) mm).
        home_beta: Reference reconfiguration angle [rad] (0).
        m_recon: Mass of a reconfiguration link [kg] (illustrative; not in the paper).
        m_arm: Mass of an arm ``LA`` [kg] (illustrative).
        m_rod: Mass of a rod ``LB`` [kg] (illustrative).
        m_platform: Platform mass [kg] (illustrative).
    """

    Rf: float = 0.050
    Rr: float = 0.150
    R2: float = 0.450
    H0: float = 0.200
    LA: float = 0.200
    LB: float = 0.400
    h: float = 0.034
    r: float = 0.050
    theta: tuple[float, ...] = tuple(math.radians(a) for a in (35.0, 155.0, 275.0, 25.0, 145.0, 265.0))
    layout: str = "sector"
    home_rotation: tuple[float, ...] = POSE_T_ROTATION
    home_position: tuple[float, float, float] = POSE_T_POSITION
    home_beta: float = 0.0
    m_recon: float = 0.15
    m_arm: float = 0.25
    m_rod: float = 0.15
    m_platform: float = 0.80

    def __post_init__(self):
        check_positive(self, "Rf", "Rr", "R2", "LA", "LB", "h", "r", "m_recon", "m_arm", "m_rod", "m_platform")
        check_finite(self, "H0", "home_beta")
        if not isinstance(self.layout, str) or self.layout not in LAYOUTS:
            raise InvalidParameterError("layout", f"must be one of {sorted(LAYOUTS)}, got {self.layout!r}",
                                        self.layout)
        for name, n, what in (("theta", 6, "(angles in rad)"), ("home_rotation", 9, "(rows of a rotation)"),
                              ("home_position", 3, "(a point in m)")):
            check_numbers(self, name, n, what)
        try:
            as_rotation(self.home_rotation, "home_rotation", HOME_ROTATION_TOL)
        except InvalidInputError as exc:
            raise InvalidParameterError("home_rotation", f"must be the rows of a rotation matrix ({exc})",
                                        self.home_rotation) from None
        try:
            inverse_kinematics(self, home_rotation(self), self.home_position, self.home_beta)
        except UnreachableError as exc:
            raise InvalidParameterError(
                "home_position", f"the reference pose is unreachable with this design (leg {exc.leg} misses by "
                                 f"{exc.excess:.4g} m); choose another home pose, home_beta or other lengths",
                self.home_position) from None


Params = HexapodParams


# ---------------------------------------------------------------------- geometry
def leg_frame(theta_i: float) -> np.ndarray:
    """Axes ``(e_r, e_y, u_i)`` of leg frame i as columns (``= Ry(-th_i)``)."""
    return rot_y(-theta_i)


def home_rotation(params: HexapodParams) -> np.ndarray:
    """The reference orientation: ``params.home_rotation`` projected on SO(3) (SVD)."""
    params = check_params(params, HexapodParams)
    return as_rotation(params.home_rotation, "home_rotation", HOME_ROTATION_TOL)


def base_points(params: HexapodParams, beta: float) -> np.ndarray:
    """Actuated joint centres ``A_1..A_6`` for reconfiguration angle ``beta`` [rad] (eqs. 1-2), rows [m]."""
    params = check_params(params, HexapodParams)
    out = np.empty((6, 3))
    for i, th in enumerate(params.theta):
        e_r = leg_frame(th)[:, 0]
        if i < 3:
            out[i] = params.Rf * e_r + params.Rr * (math.cos(beta) * e_r + math.sin(beta) * _E_Y)
        else:
            out[i] = params.R2 * e_r - params.H0 * _E_Y
    return out


def platform_local_points(params: HexapodParams) -> np.ndarray:
    """Spherical joint centres ``C*_1..C*_6`` in the platform frame, rows [m]."""
    params = check_params(params, HexapodParams)
    low = np.array([[params.r * math.cos(math.radians(p)), 0.0, params.r * math.sin(math.radians(p))]
                    for p in LAYOUTS[params.layout]])
    return np.vstack([low + params.h * _E_Y, low])


def platform_points(params: HexapodParams, R: np.ndarray, P) -> np.ndarray:
    """``C_1..C_6`` in the base frame for platform orientation ``R`` and position ``P`` (eq. 14), rows [m]."""
    params = check_params(params, HexapodParams)
    return np.asarray(P, dtype=float) + platform_local_points(params) @ np.asarray(R, dtype=float).T


def elbow_points(params: HexapodParams, alphas, beta: float) -> np.ndarray:
    """Universal-joint centres ``B_1..B_6`` from the paper's absolute ``alpha_i`` and ``beta`` [rad] (eq. 3), rows [m]."""
    params = check_params(params, HexapodParams)
    alphas = as_vector(alphas, 6, "alphas")
    A = base_points(params, beta)
    return np.array([A[i] + params.LA * (leg_frame(params.theta[i]) @ [math.cos(alphas[i]), math.sin(alphas[i]), 0.0])
                     for i in range(6)])


def paper_alphas(q_actuated) -> np.ndarray:
    """The paper's absolute ``alpha_1..alpha_6`` [rad] from the actuated vector (spec order).

    Legs 1-3: ``alpha(paper) = alpha(joint) + beta``; legs 4-6 unchanged.
    """
    qa = as_vector(q_actuated, 7, "q_actuated")
    return np.concatenate([qa[:3] + qa[6], qa[3:6]])


def actuated_from_paper(alphas, beta: float) -> np.ndarray:
    """The actuated vector (``alpha_1..alpha_6`` joint coordinates, ``beta_1``) from the paper's angles."""
    a = as_vector(alphas, 6, "alphas")
    b = _scalar(beta, "beta")
    return np.concatenate([wrap_angle(a[:3] - b), wrap_angle(a[3:]), [b]])


# ---------------------------------------------------------------------- closed forms
def inverse_kinematics(params: HexapodParams, R, P, beta: float,
                       branch: str | tuple[str, ...] = DEFAULT_BRANCH) -> np.ndarray:
    """The paper's absolute ``alpha_1..alpha_6`` [rad] for a platform pose and ``beta`` [rad].

    Per leg, with ``d = C_i - A_i`` in the leg frame, ``|C_i - B_i| = LB`` reads
    ``cos(alpha) d_r + sin(alpha) d_y = K``, ``K = (d.d + LA^2 - LB^2) / (2 LA)``, so
    ``alpha = phi +- delta`` with ``phi = atan2(d_y, d_r)``, ``delta = acos(K / hypot(d_r, d_y))``
    (``+`` for ``elbow_out``, ``-`` for ``elbow_in``).

    Args:
        params: The design.
        R: Platform orientation (3x3 rotation).
        P: Platform position [m], shape (3,).
        beta: Reconfiguration angle [rad].
        branch: ``"elbow_out"``/``"elbow_in"`` for all legs, or one per leg.

    Raises:
        InvalidInputError: ``R`` is not a rotation (see :func:`as_rotation`).
        UnreachableError: with the first leg that cannot reach and by how much [m].
    """
    params = check_params(params, HexapodParams)
    branches = _branches(branch)
    C = platform_points(params, as_rotation(R), as_vector(P, 3, "P"))
    A = base_points(params, _scalar(beta, "beta"))
    out = np.empty(6)
    for i in range(6):
        out[i] = _leg_angle(params, i, C[i] - A[i], branches[i])
    return out


def _leg_angle(params: HexapodParams, i: int, d: np.ndarray, branch: str) -> float:
    dr, dy, du = leg_frame(params.theta[i]).T @ d
    return arm_angle(dr, dy, du, params.LA, params.LB, -BRANCHES[branch], i + 1,
                     f"leg {i + 1}: the rod LB cannot span the distance from C_{i + 1} to the circle of B")


def joint_values(params: HexapodParams, R, P, beta: float,
                 branch: str | tuple[str, ...] = DEFAULT_BRANCH) -> dict[str, list[float]]:
    """Every joint coordinate of the tree (closed form) for a platform pose and ``beta``.

    Args:
        params: The design.
        R: Platform orientation (3x3 rotation).
        P: Platform position [m].
        beta: Reconfiguration angle [rad].
        branch: As for :func:`inverse_kinematics`.

    Returns:
        ``{joint name: coordinates}``; the platform's quaternion is that of ``R``.
    """
    params = check_params(params, HexapodParams)
    R = as_rotation(R)
    alphas = inverse_kinematics(params, R, P, beta, branch)
    return _joint_values(params, R, P, pin.Quaternion(R).coeffs(), beta, alphas)


def _joint_values(params: HexapodParams, R: np.ndarray, P, quat: np.ndarray, beta: float,
                  alphas: np.ndarray) -> dict[str, list[float]]:
    C = platform_points(params, R, P)
    B = elbow_points(params, alphas, beta)
    qa = actuated_from_paper(alphas, beta)
    out: dict[str, list[float]] = {"beta_1": [float(beta)]}
    for i in range(6):
        n = i + 1
        # rod direction in the arm frame = Rz(knee) Ry(knee_b) x
        w = rot_z(-alphas[i]) @ (leg_frame(params.theta[i]).T @ (C[i] - B[i])) / params.LB
        out[f"alpha_{n}"] = [float(qa[i])]
        out[f"knee_{n}"] = [math.atan2(w[1], w[0])]
        out[f"knee_{n}_b"] = [math.asin(max(-1.0, min(1.0, -w[2])))]
    out["platform"] = [float(x) for x in np.concatenate([np.asarray(P, dtype=float), quat])]
    return out


def configuration(mech: Mechanism, y, branch: str | tuple[str, ...] = DEFAULT_BRANCH) -> np.ndarray:
    """Full configuration ``q`` of ``mech`` for task vector ``y = (x, y, z, qx, qy, qz, qw, beta)`` (closed form)."""
    mech = check_mechanism(mech)
    R, P, quat, beta = _task(y)
    alphas = inverse_kinematics(mech.params, R, P, beta, branch)
    return mech.q_from_dict(_joint_values(mech.params, R, P, quat, beta, alphas))


def forward_kinematics(params: HexapodParams, alphas, beta: float, seed=None, *, tol: float = 1e-12,
                       max_iter: int = 50) -> np.ndarray:
    """``C_1..C_6`` [m] from the paper's absolute ``alpha_1..alpha_6`` and ``beta`` (eqs. 4-7).

    Unknowns ``C1, C2, C3`` (9); equations (6) for the six legs, with ``C_{i+3} = C_i + h g``
    (eq. 4, ``g`` from eq. 5 with the layout's sign, see the module doc), and (7) for the three
    sides of ``C1C2C3``. Each equation is divided by twice its length (LB or e) so that the
    residual is in metres. Newton's method with the exact Jacobian and a backtracking line search.

    Args:
        params: The design.
        alphas: The paper's absolute arm angles [rad], shape (6,).
        beta: Reconfiguration angle [rad].
        seed: ``C1, C2, C3`` to start from [m], shape (3, 3); default: those of the reference pose.
        tol: Tolerance on the infinity norm of the residual [m].
        max_iter: Newton iterations allowed.

    Returns:
        ``C_1..C_6`` as rows [m].

    Raises:
        ConvergenceError: with the residual, when Newton's method does not reach ``tol``.
    """
    params = check_params(params, HexapodParams)
    B = elbow_points(params, alphas, _scalar(beta, "beta"))
    if seed is None:
        seed = platform_points(params, home_rotation(params), params.home_position)[:3]
    X = as_vector(np.ravel(as_array(seed, "seed", "C1, C2, C3 (3, 3) [m]")), 9, "seed").copy()
    tol = as_tolerance(tol, "tol")
    max_iter = as_count(max_iter, "max_iter", low=1, high=10_000)
    e = params.r * math.sqrt(3.0)
    k = (-1.0 if params.layout == "sector" else 1.0) * 2.0 / (math.sqrt(3.0) * e * e)
    LB, h = params.LB, params.h
    pa, pb = np.array([0, 1, 0]), np.array([1, 2, 2])  # the sides C1C2, C2C3, C1C3
    legs, cols = np.arange(6), np.array([0, 1, 2, 0, 1, 2])

    def normal(C: np.ndarray) -> np.ndarray:  # eq. (5), unit when C1C2C3 is the platform's triangle
        a, b = C[1] - C[2], C[0] - C[2]
        return k * np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])

    def fun(x: np.ndarray, jacobian: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        C = x.reshape(3, 3)  # vectorised over the legs and the sides
        dv = np.vstack([C, C + h * normal(C)]) - B  # legs 1-3 at C_i, legs 4-6 at C_i + h g
        D = C[pa] - C[pb]
        f = np.empty(9)
        f[:6] = (np.einsum("ij,ij->i", dv, dv) - LB**2) / (2.0 * LB)
        f[6:] = (np.einsum("ij,ij->i", D, D) - e * e) / (2.0 * e)
        if not jacobian:
            return f, None
        dg = k * np.hstack([pin.skew(C[1] - C[2]), -pin.skew(C[0] - C[2]), pin.skew(C[0] - C[1])])  # dg/dX
        J = np.zeros((9, 9))
        J6 = np.zeros((6, 3, 3))
        J6[legs, cols] = dv / LB
        J[:6] = J6.reshape(6, 9)
        J[3:6] += h * (dv[3:] @ dg) / LB
        J3 = np.zeros((3, 3, 3))
        J3[np.arange(3), pa] = D / e
        J3[np.arange(3), pb] = -D / e
        J[6:] = J3.reshape(3, 9)
        return f, J

    f, J = fun(X)
    res, it = float(np.max(np.abs(f))), 0
    while res > tol and it < max_iter:
        it += 1
        if not (np.all(np.isfinite(J)) and np.all(np.isfinite(f))):  # a seed beyond the float range
            res = np.inf
            break
        try:
            step = -np.linalg.lstsq(J, f, rcond=None)[0]
        except np.linalg.LinAlgError:  # entries overflowing: no step
            break
        t = 1.0
        for _ in range(20):
            f_try, _ = fun(X + t * step, False)
            res_try = float(np.max(np.abs(f_try)))
            if res_try < res:
                break
            t *= 0.5
        if not np.isfinite(res_try):  # overflow far from any solution: stop at the last finite iterate
            break
        X, res = X + t * step, res_try
        f, J = fun(X)
    if not res <= tol:
        raise ConvergenceError("semi-closed forward kinematics (eqs. 4-7)", res if np.isfinite(res) else np.inf, it,
                               tol, detail="the actuated angles may admit no assembly near the seed; try another "
                                           "seed or assembly_modes()")
    C = X.reshape(3, 3)
    return np.vstack([C, C + params.h * normal(C)])


@dataclass(frozen=True)
class AssemblyMode:
    """One solution of the forward kinematics.

    Attributes:
        C: ``C_1..C_6`` as rows [m].
        R: Platform orientation (eqs. 9-12).
        P: Platform position [m] (eq. 8).
        q: The full configuration of the tree (closed-form joint values of this assembly).
        core_residual: Largest closure residual of the generic core at ``q`` [m]
            (:func:`pkm.core.constraints.residual`): the independent check of the solution.
    """

    C: np.ndarray
    R: np.ndarray
    P: np.ndarray
    q: np.ndarray
    core_residual: float


def assembly_modes(mech: Mechanism, q_actuated, *, n_starts: int = 32, seed: int = 0, tol: float = 1e-12,
                   max_iter: int = 25, distinct: float = 1e-6, verify_tol: float = 1e-9) -> list[AssemblyMode]:
    """Assembly modes for given actuated coordinates: the semi-closed FK (eqs. 4-13) from many seeds.

    Multistart: Newton's method (:func:`forward_kinematics`) from the reference pose and from
    ``n_starts - 1`` random platform poses (uniform rotations, positions in a box below the base
    spanning the legs' reach); solutions closer than ``distinct`` (max over ``C_i`` [m]) are merged.
    Each solution is then checked by the generic core: the full configuration built from it must
    close every loop to ``verify_tol`` (it always does when Newton converged; a failure would mean
    eqs. 4-13 and the tree disagree). There is no guarantee that every mode is found.

    Args:
        mech: The hexapod (:func:`build`).
        q_actuated: ``alpha_1..alpha_6`` (joint coordinates, relative for legs 1-3), ``beta_1`` [rad].
        n_starts: Seeds tried (>= 1).
        seed: Seed of the random generator (reproducible results).
        tol: Newton tolerance [m].
        max_iter: Newton iterations per seed.
        distinct: Distance under which two solutions are the same [m].
        verify_tol: Largest closure residual of the generic core accepted [m].

    Returns:
        The modes found, sorted by distance of ``P`` from the reference pose.

    Raises:
        AssemblyError: no seed converged (the actuated coordinates probably admit no assembly).
    """
    mech = check_mechanism(mech)
    params = check_params(mech.params, HexapodParams, "mech.params")
    qa = as_vector(q_actuated, 7, "q_actuated")
    n_starts = as_count(n_starts, "n_starts", low=1, high=100_000)
    seed = as_count(seed, "seed", low=0, high=2**63 - 1)
    tol, verify_tol = as_tolerance(tol, "tol"), as_tolerance(verify_tol, "verify_tol")
    max_iter = as_count(max_iter, "max_iter", low=1, high=10_000)
    distinct = as_scalar(distinct, "distinct", low=0.0, strict_low=True, unit="m")
    alphas, beta = paper_alphas(qa), float(qa[6])
    rng = np.random.default_rng(seed)
    reach = params.LA + params.LB
    seeds = [None]
    for _ in range(n_starts - 1):
        Rs = pin.Quaternion(*rng.normal(size=4)).normalized().toRotationMatrix()
        Ps = rng.uniform([-reach / 2, -reach - params.H0, -reach / 2], [reach / 2, params.Rr, reach / 2])
        seeds.append(platform_points(params, Rs, Ps)[:3])
    found: list[AssemblyMode] = []
    best_res = math.inf
    for s0 in seeds:
        try:
            C = forward_kinematics(params, alphas, beta, s0, tol=tol, max_iter=max_iter)
        except ConvergenceError as exc:
            best_res = min(best_res, exc.residual)
            continue
        if any(np.abs(C - m.C).max() < distinct for m in found):
            continue
        R, P = pose_from_points(params, C)
        q = mech.q_from_dict(_joint_values(params, R, P, pin.Quaternion(R).coeffs(), beta, alphas))
        res = float(np.abs(constraints.residual(mech, q)).max())
        if res > verify_tol or np.abs(mech.actuated_q(q) - actuated_from_paper(alphas, beta)).max() > 1e-12:
            raise ConvergenceError("assembly-mode check by the generic core", res, 0, verify_tol,
                                   detail="the semi-closed FK and the tree disagree")
        found.append(AssemblyMode(C, R, P, q, res))
    if not found:
        raise AssemblyError(best_res, "m", f"Newton's method failed from all {n_starts} seeds")
    P0 = np.asarray(params.home_position)
    return sorted(found, key=lambda m: float(np.linalg.norm(m.P - P0)))


def pose_from_points(params: HexapodParams, C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Platform orientation and position ``(R, P)`` from ``C_1..C_6`` (eqs. 8-13, layout's sign of eq. 11)."""
    params = check_params(params, HexapodParams)
    C = np.asarray(C, dtype=float)
    P = C[3:].mean(axis=0)
    x = (C[3] - P) / np.linalg.norm(C[3] - P)
    z = C[4] - C[5] if params.layout == "sector" else C[5] - C[4]
    z = z / np.linalg.norm(z)
    return np.column_stack([x, np.cross(z, x), z]), P


def task_vector(R, P, beta: float) -> np.ndarray:
    """The task vector ``(x, y, z, qx, qy, qz, qw, beta)`` of a pose and ``beta``."""
    return np.concatenate([np.asarray(P, dtype=float), pin.Quaternion(np.asarray(R, dtype=float)).coeffs(),
                           [float(beta)]])


# ---------------------------------------------------------------------- uniform interface
# Task vector y (as pkm.core.TaskMap lays it out): x y z qx qy qz qw of the frame ``platform``, then beta_1.
def closed_form_ik(params: HexapodParams, y, branch: str | tuple[str, ...] | None = None) -> np.ndarray:
    """Actuated coordinates (``alpha_1..alpha_6`` joint coordinates, ``beta_1``) for task vector ``y``."""
    params = check_params(params, HexapodParams)
    R, P, _, beta = _task(y)
    return actuated_from_paper(inverse_kinematics(params, R, P, beta, branch or DEFAULT_BRANCH), beta)


def closed_form_configuration(mech: Mechanism, y, branch: str | tuple[str, ...] | None = None) -> np.ndarray:
    """Every joint coordinate for task vector ``y`` (closed form)."""
    return configuration(mech, y, branch or DEFAULT_BRANCH)


def closed_form_fk(params: HexapodParams, q_actuated, seed=None) -> np.ndarray:
    """Task vector from the actuated coordinates by the paper's semi-closed method (eqs. 4-13).

    Args:
        params: The design.
        q_actuated: ``alpha_1..alpha_6`` (joint coordinates: relative for legs 1-3), ``beta_1`` [rad].
        seed: A task vector whose pose seeds Newton's method (its ``beta`` is ignored); default:
            the reference pose.

    Raises:
        ConvergenceError: when Newton's method fails (residual attached).
    """
    params = check_params(params, HexapodParams)
    qa = as_vector(q_actuated, 7, "q_actuated")
    C0 = None
    if seed is not None:
        R0, P0, _, _ = _task(seed, "seed")
        C0 = platform_points(params, R0, P0)[:3]
    C = forward_kinematics(params, paper_alphas(qa), qa[6], C0)
    R, P = pose_from_points(params, C)
    return task_vector(R, P, qa[6])


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
                    mimic=None if n == 1 else ("beta_1", 1.0, 0.0))
            b.link(f"arm_{n}", params.m_arm, (params.LA / 2, 0.0, 0.0), rod_inertia(params.m_arm, params.LA, 0))
            b.joint(f"alpha_{n}", "revolute", f"recon_{n}", f"arm_{n}", (params.Rr, 0.0, 0.0))
        else:
            b.link(f"arm_{n}", params.m_arm, (params.LA / 2, 0.0, 0.0), rod_inertia(params.m_arm, params.LA, 0))
            b.joint(f"alpha_{n}", "revolute", "base", f"arm_{n}", base_points(params, 0.0)[i], L)
        b.link(f"knee_cross_{n}")
        b.joint(f"knee_{n}", "revolute", f"arm_{n}", f"knee_cross_{n}", (params.LA, 0.0, 0.0))
        b.link(f"rod_{n}", params.m_rod, (params.LB / 2, 0.0, 0.0), rod_inertia(params.m_rod, params.LB, 0))
        b.joint(f"knee_{n}_b", "revolute", f"knee_cross_{n}", f"rod_{n}", axis=(0.0, 1.0, 0.0))
        b.frame(f"leg_{n}_tip", f"rod_{n}", (params.LB, 0.0, 0.0))
    mp, r = params.m_platform, params.r
    b.link("platform_body", mp, (0.0, params.h / 2, 0.0), np.diag([mp * r * r / 4, mp * r * r / 2, mp * r * r / 4]))
    b.joint("platform", "floating", "base", "platform_body")
    for i, c in enumerate(platform_local_points(params)):
        b.frame(f"platform_c_{i + 1}", "platform_body", c)
    return b.to_xml()


def closure_spec(params: HexapodParams) -> ClosureSpec:
    """The closure spec: six point closures (the spherical joints), reference at the home pose."""
    params = check_params(params, HexapodParams)
    values = joint_values(params, home_rotation(params), params.home_position, params.home_beta)
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


# ---------------------------------------------------------------------- helpers
def _branches(branch: str | tuple[str, ...]) -> tuple[str, ...]:
    branches = (branch,) * 6 if isinstance(branch, str) else tuple(branch) if isinstance(branch, (tuple, list)) else ()
    if len(branches) != 6 or any(not isinstance(b, str) or b not in BRANCHES for b in branches):
        raise InvalidInputError("branch", f"use {sorted(BRANCHES)} or a tuple of six, got {branch!r}", branch)
    return branches


def _scalar(x, name: str) -> float:
    return float(as_vector([x], 1, name)[0])


def _task(y, name: str = "y") -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """``(R, P, quaternion xyzw, beta)`` from a task vector; the quaternion must have norm 1 (to 1e-6)."""
    y = as_vector(y, 8, name)
    quat = y[3:7]
    nrm = np.linalg.norm(quat)
    if abs(nrm - 1.0) > 1e-6:
        raise InvalidInputError(name, f"quaternion (qx, qy, qz, qw) has norm {nrm:.6g}, expected 1", y)
    quat = quat / nrm
    R = pin.Quaternion(quat[3], quat[0], quat[1], quat[2]).toRotationMatrix()
    return R, y[:3].copy(), quat, float(y[7])
