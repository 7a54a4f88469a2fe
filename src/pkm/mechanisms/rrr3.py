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
sign convention behind its numbering, so this correspondence is ours.

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

import math
from dataclasses import dataclass

import numpy as np

from pkm.core.mechanism import (Mechanism, as_scalar, as_tolerance, as_vector, check_mechanism, finite_result,
                                wrap_angle)
from pkm.core.spec import Branch, Closure, ClosureSpec, TaskSpec
from pkm.core.urdf import UrdfBuilder
from pkm.errors import (
    AssemblyError,
    BranchError,
    InvalidInputError,
    InvalidParameterError,
    SingularityError,
    UnreachableError,
)
from pkm.mechanisms._common import (
    check_numbers,
    check_params,
    check_positive,
    make_mechanism,
    rod_inertia,
    spec_parameters,
)

NAME = "rrr3"
SQRT3 = math.sqrt(3.0)
MODES: dict[str, tuple[int, int, int]] = {
    f"mode{k + 1}": tuple(-1 if (k >> (2 - i)) & 1 else 1 for i in range(3)) for k in range(8)
}
"""Working mode name -> signs of ``(psi_1, psi_2, psi_3)`` (see the module doc)."""

_REACH_TOL = 1e-12  # relative to a + b: a distance this close to the reach limits counts as on them
_SINGULAR_TOL = 1e-6  # the reference pose must be at least this far (dimensionless) from singularities


@dataclass(frozen=True)
class Rrr3Params:
    """Planar 3-RRR design (paper sec. III workspace study by default).

    Attributes:
        a: Proximal (actuated) link length [m] (40 cm).
        b: Distal link length [m] (40 cm).
        h: Platform side ``AB = BC = CA`` [m] (10 cm).
        H: Base side, the actuator separation ``PQ = QR = RP`` [m] (100 cm).
        mode: Working mode 1..8 of the reference configuration (see the module doc).
        home: Reference placement ``(dx, dy, Phi)``: the platform centroid's offset from the
            base centroid [m] and the orientation [rad]; ``(0, 0, 0)``: centred, ``Phi = 0``.
        m_proximal: Mass of a proximal link [kg] (illustrative; not in the paper).
        m_distal: Mass of a distal link [kg] (illustrative).
        m_platform: Platform mass [kg] (illustrative).
    """

    a: float = 0.40
    b: float = 0.40
    h: float = 0.10
    H: float = 1.00
    mode: int = 1
    home: tuple[float, float, float] = (0.0, 0.0, 0.0)
    m_proximal: float = 0.20
    m_distal: float = 0.15
    m_platform: float = 0.10

    def __post_init__(self):
        check_positive(self, "a", "b", "h", "H", "m_proximal", "m_distal", "m_platform")
        if isinstance(self.mode, bool) or not isinstance(self.mode, int) or not 1 <= self.mode <= 8:
            raise InvalidParameterError("mode", f"must be an integer 1..8 (working mode), got {self.mode!r}",
                                        self.mode)
        check_numbers(self, "home", 3, "(dx, dy, Phi) in m, m, rad")
        try:
            margin_inv, margin_dir = singularity_measures(self, home_task(self), self.mode)
        except UnreachableError as exc:
            raise InvalidParameterError(
                "home", f"reference pose {tuple(self.home)} is unreachable with this design (leg {exc.leg} misses "
                        f"by {exc.excess:.4g} m); choose another home or other lengths", self.home) from None
        except SingularityError:
            raise InvalidParameterError(
                "home", f"reference pose {tuple(self.home)} puts a platform vertex on its base vertex (a = b); "
                        "choose another home", self.home) from None
        if margin_inv < _SINGULAR_TOL or margin_dir < _SINGULAR_TOL:
            kind = "inverse (a leg stretched or folded)" if margin_inv < _SINGULAR_TOL else "direct"
            raise InvalidParameterError(
                "home", f"reference pose {tuple(self.home)} is {kind}-singular in mode{self.mode}; choose another "
                        "home or mode", self.home)


# ---------------------------------------------------------------------- geometry
def mode_signs(mode: int | str) -> tuple[int, int, int]:
    """Signs of ``(psi_1, psi_2, psi_3)`` of a working mode given as ``k`` or ``"modek"`` (k = 1..8)."""
    key = f"mode{mode}" if isinstance(mode, (int, np.integer)) and not isinstance(mode, bool) else mode
    if not isinstance(key, str) or key not in MODES:
        raise InvalidInputError("mode", f"use 1..8 or 'mode1'..'mode8', got {mode!r}", mode)
    return MODES[key]


def base_vertices(params: Rrr3Params) -> np.ndarray:
    """Base vertices ``P, Q, R`` as rows [m], shape (3, 2)."""
    params = check_params(params, Rrr3Params)
    H = params.H
    return np.array([[0.0, 0.0], [H, 0.0], [H / 2.0, H * SQRT3 / 2.0]])


def base_centroid(params: Rrr3Params) -> np.ndarray:
    """Centroid of the base triangle [m], shape (2,)."""
    params = check_params(params, Rrr3Params)
    return np.array([params.H / 2.0, params.H / (2.0 * SQRT3)])


def platform_vertices(params: Rrr3Params, a_point, phi: float) -> np.ndarray:
    """Platform vertices ``A, B, C`` as rows [m] (eqs. 1-2), from ``A`` [m] and ``Phi`` [rad]."""
    params = check_params(params, Rrr3Params)
    A = as_vector(a_point, 2, "a_point")
    phi = _scalar(phi, "phi")
    h = params.h
    return np.array([A, A + h * np.array([math.cos(phi), math.sin(phi)]),
                     A + h * np.array([math.cos(phi + math.pi / 3.0), math.sin(phi + math.pi / 3.0)])])


def centroid_from_a(params: Rrr3Params, a_point, phi: float) -> np.ndarray:
    """Platform centroid ``G`` [m] from the paper's ``A`` [m] and ``Phi`` [rad]."""
    params = check_params(params, Rrr3Params)
    A = as_vector(a_point, 2, "a_point")
    phi = _scalar(phi, "phi")
    return A + params.h / SQRT3 * np.array([math.cos(phi + math.pi / 6.0), math.sin(phi + math.pi / 6.0)])


def a_from_centroid(params: Rrr3Params, g_point, phi: float) -> np.ndarray:
    """The paper's platform point ``A`` [m] from the centroid ``G`` [m] and ``Phi`` [rad]."""
    params = check_params(params, Rrr3Params)
    G = as_vector(g_point, 2, "g_point")
    phi = _scalar(phi, "phi")
    return G - params.h / SQRT3 * np.array([math.cos(phi + math.pi / 6.0), math.sin(phi + math.pi / 6.0)])


def home_task(params: Rrr3Params) -> np.ndarray:
    """The reference task vector ``(x_G, y_G, Phi)`` [m, m, rad] of ``params.home``."""
    params = check_params(params, Rrr3Params)
    return np.concatenate([base_centroid(params) + np.asarray(params.home[:2], dtype=float), [params.home[2]]])


# ---------------------------------------------------------------------- closed forms
def _solve(params: Rrr3Params, a_point: np.ndarray, phi: float, mode: int | str) -> tuple[np.ndarray, np.ndarray]:
    """``(theta, psi)`` [rad] of the three legs for the paper's ``(A, Phi)`` in ``mode`` (eqs. 6-9)."""
    params = check_params(params, Rrr3Params)
    signs = mode_signs(mode)
    a, b = params.a, params.b
    lo, hi = abs(a - b), a + b
    targets = platform_vertices(params, a_point, phi) - base_vertices(params)
    theta, psi = np.empty(3), np.empty(3)
    for i, (x, y) in enumerate(targets):
        d = math.hypot(x, y)
        if d > hi * (1.0 + _REACH_TOL) or d < lo - hi * _REACH_TOL:
            excess = d - hi if d > hi else lo - d
            raise UnreachableError(i + 1, excess, "m", f"leg {i + 1}: distance {d:.6g} m from its base vertex to "
                                                        f"its platform vertex is outside [|a-b|, a+b] = "
                                                        f"[{lo:.6g}, {hi:.6g}] m")
        if d <= hi * _REACH_TOL:
            raise SingularityError("inverse", 0.0, f"leg {i + 1}: platform vertex on the base vertex (a = b), "
                                                   "the motor angle is undetermined")
        e1, e2, e3 = -2.0 * y * a, -2.0 * x * a, d * d + a * a - b * b
        s = math.sqrt(max(0.0, e1 * e1 + e2 * e2 - e3 * e3))  # 2 a d sin(delta) = 2 a b |sin psi|
        sigma = signs[i]  # psi > 0 <-> the '-' root of eq. (9)
        theta[i] = math.atan2(-e1, -e2) - sigma * math.atan2(s, e3)
        psi[i] = sigma * math.atan2(s, d * d - a * a - b * b)
    return wrap_angle(theta), psi


def inverse_kinematics(params: Rrr3Params, a_point, phi: float, mode: int | str | None = None) -> np.ndarray:
    """Motor angles ``(theta_1, theta_2, theta_3)`` [rad] in (-pi, pi], in the paper's terms (eq. 9).

    Args:
        params: The design.
        a_point: Platform vertex ``A`` [m], shape (2,).
        phi: Platform orientation ``Phi`` [rad].
        mode: Working mode (1..8 or ``"mode1"``..``"mode8"``); default ``params.mode``.

    Raises:
        UnreachableError: with the first leg whose base-vertex-to-platform-vertex distance is
            outside ``[|a - b|, a + b]``, and by how much [m].
        SingularityError: a platform vertex on its base vertex (only when ``a = b``).
    """
    return _solve(params, a_point, phi, params.mode if mode is None else mode)[0]


def joint_values(params: Rrr3Params, y, mode: int | str | None = None) -> dict[str, list[float]]:
    """Every joint coordinate of the tree (closed form) for the task vector ``y = (x_G, y_G, Phi)``."""
    params = check_params(params, Rrr3Params)
    y = as_vector(y, 3, "y")
    theta, psi = _solve(params, a_from_centroid(params, y[:2], y[2]), y[2], params.mode if mode is None else mode)
    out: dict[str, list[float]] = {}
    for i in range(3):
        out[f"motor_{i + 1}"] = [float(theta[i])]
        out[f"elbow_{i + 1}"] = [float(psi[i])]
    out["wrist_1"] = [float(wrap_angle(y[2] - theta[0] - psi[0]))]
    return out


def configuration(mech: Mechanism, y, mode: int | str | None = None) -> np.ndarray:
    """Full configuration vector ``q`` of ``mech`` for the task vector ``y`` (closed form)."""
    mech = check_mechanism(mech)
    return mech.q_from_dict(joint_values(mech.params, y, mode))


def jacobians(params: Rrr3Params, y, mode: int | str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The paper's ``J_x``, ``J_q`` (eqs. 16-20, rebuilt) with ``J_x yd = J_q theta_dot``.

    Row ``i`` is the reciprocal product of leg ``i``'s wrench (a unit force ``u_i`` along its
    distal link, through its platform vertex) with the platform twist and with the motor's
    twist: ``J_x[i] = [u_i, (V_i - G) x u_i]``, ``J_q[i, i] = (D_i - O_i) x u_i = a sin psi_i``
    (``O_i`` base vertex, ``D_i`` elbow, ``V_i`` platform vertex; planar cross products).
    The moments are taken about the centroid ``G`` so that ``yd = (xd_G, yd_G, Phi_dot)``, the
    task rates; no homogenisation (eq. 25) is applied. ``J_x`` is singular at a direct
    singularity, ``J_q`` at an inverse one.

    Returns:
        ``(J_x, J_q)``: (3, 3) arrays; ``J_x`` columns in [1, 1, m], ``J_q`` in [m].
    """
    params = check_params(params, Rrr3Params)
    y = as_vector(y, 3, "y")
    A = a_from_centroid(params, y[:2], y[2])
    theta, psi = _solve(params, A, y[2], params.mode if mode is None else mode)
    V = platform_vertices(params, A, y[2])
    Jx, Jq = np.empty((3, 3)), np.zeros((3, 3))
    for i in range(3):
        u = np.array([math.cos(theta[i] + psi[i]), math.sin(theta[i] + psi[i])])
        r = V[i] - y[:2]
        Jx[i] = [u[0], u[1], r[0] * u[1] - r[1] * u[0]]
        Jq[i, i] = params.a * math.sin(psi[i])
    return Jx, Jq


REFERENCES = ("centroid", "A", "origin")
"""Moment reference points of :func:`homogenized_jacobians`: the platform centroid ``G``, vertex ``A``,
the world origin ``O = P`` (the paper's eq. 14)."""


def characteristic_length(params: Rrr3Params) -> float:
    """Default ``L`` of eq. (25) [m]: the platform circumradius ``h / sqrt 3`` (Lou's mean platform radius)."""
    params = check_params(params, Rrr3Params)
    return params.h / SQRT3


def reference_point(params: Rrr3Params, y, reference: str = "centroid") -> np.ndarray:
    """The point [m] about which moments are taken (one of :data:`REFERENCES`) for task vector ``y``."""
    params = check_params(params, Rrr3Params)
    y = as_vector(y, 3, "y")
    if reference == "centroid":
        return y[:2].copy()
    if reference == "A":
        return a_from_centroid(params, y[:2], y[2])
    if reference == "origin":
        return np.zeros(2)
    raise InvalidInputError("reference", f"use one of {REFERENCES}, got {reference!r}", reference)


def homogenized_jacobians(params: Rrr3Params, y, mode: int | str | None = None, *, length: float | None = None,
                          reference: str = "centroid") -> tuple[np.ndarray, np.ndarray]:
    """Eq. (25), read consistently: ``J_x`` with its moment column divided by ``L``, and ``J_q``.

    ``J_x[i] = [u_i, ((V_i - P) x u_i) / L]`` and ``J_x (v_P, L Phi_dot) = J_q theta_dot``, where
    ``v_P`` is the velocity of the platform point at the reference ``P`` (see the module doc for
    why the moment column, not the direction column, carries ``L``). All of ``J_x`` is then
    dimensionless and ``J_q = diag(a sin psi_i)`` is in m, so ``J_q^-1 J_x`` (motor rates per
    m/s) has a unit-free condition number.

    Args:
        params: The design.
        y: Task vector ``(x_G, y_G, Phi)`` [m, m, rad].
        mode: Working mode; default ``params.mode``.
        length: Characteristic length ``L`` [m], finite and > 0; default :func:`characteristic_length`.
        reference: Moment reference point, one of :data:`REFERENCES`.

    Returns:
        ``(J_x, J_q)``: (3, 3) arrays, ``J_x`` dimensionless, ``J_q`` in [m].
    """
    params = check_params(params, Rrr3Params)
    L = characteristic_length(params) if length is None else _length(length)
    Jx, Jq = jacobians(params, y, mode)
    d = as_vector(y, 3, "y")[:2] - reference_point(params, y, reference)  # G - P
    Jx[:, 2] += d[0] * Jx[:, 1] - d[1] * Jx[:, 0]  # (V - P) x u = (V - G) x u + (G - P) x u
    with np.errstate(over="ignore"):  # a tiny L overflows: reported below
        Jx[:, 2] /= L
    return finite_result(Jx, "homogenized J_x", f"length = {L!r} m is too small (the moment column overflows)"), Jq


def singularity_measures(params: Rrr3Params, y, mode: int | str | None = None) -> tuple[float, float]:
    """Dimensionless distances to the two kinds of singularity at task vector ``y``.

    Returns:
        ``(inverse, direct)``: ``min_i |sin psi_i|`` (0 when a leg is stretched or folded, eq. 20)
        and ``|det J_x|`` of :func:`homogenized_jacobians` with the default ``L`` and the centroid
        (0 when the three distal-link lines meet in a point or are parallel, eq. 19); both are
        unchanged by a uniform scaling of the design.
    """
    params = check_params(params, Rrr3Params)
    Jx, Jq = homogenized_jacobians(params, y, mode)
    return float(np.min(np.abs(np.diag(Jq)))) / params.a, abs(float(np.linalg.det(Jx)))


def classify_singularity(params: Rrr3Params, y, mode: int | str | None = None, *, tol: float = 1e-8) -> str:
    """``"regular"``, ``"inverse"`` (``J_q`` singular), ``"direct"`` (``J_x`` singular) or ``"combined"`` (both).

    Args:
        params: The design.
        y: Task vector ``(x_G, y_G, Phi)`` [m, m, rad].
        mode: Working mode; default ``params.mode``.
        tol: A measure of :func:`singularity_measures` at or below ``tol`` counts as singular.
    """
    params = check_params(params, Rrr3Params)
    tol = as_scalar(tol, "tol", low=0.0)
    inv, direct = singularity_measures(params, y, mode)
    return {(False, False): "regular", (True, False): "inverse", (False, True): "direct",
            (True, True): "combined"}[(inv <= tol, direct <= tol)]


# ---------------------------------------------------------------------- forward kinematics
@dataclass(frozen=True)
class FkSolution:
    """One assembly mode of the forward kinematics.

    Attributes:
        y: Task vector ``(x_G, y_G, Phi)`` [m, m, rad], ``Phi`` in (-pi, pi].
        a_point: The paper's platform vertex ``A`` [m].
        psi: Elbow angles ``(psi_1, psi_2, psi_3)`` [rad] (see the module doc).
        mode: Working mode name of the solution (signs of ``psi``), ``None`` if a leg is exactly stretched
            or folded.
        residual: Largest ``| |V_i - D_i| - b |`` over the legs [m].
    """

    y: np.ndarray
    a_point: np.ndarray
    psi: np.ndarray
    mode: str | None
    residual: float


_FK_SAMPLES = 16  # FFT samples of the degree-4 trigonometric polynomial (>= 9 makes the coefficients exact)
_FK_NEWTON = 30  # Newton iterations allowed per candidate


def _fk_offsets(h: float, phi):
    """Vertex offsets ``r_k(Phi)`` from ``A`` (eqs. 1-2), shape (3, 2, ...), and their derivatives."""
    phi = np.asarray(phi, dtype=float)
    zero = np.zeros_like(phi)
    r = np.array([[zero, zero], [h * np.cos(phi), h * np.sin(phi)],
                  [h * np.cos(phi + math.pi / 3.0), h * np.sin(phi + math.pi / 3.0)]])
    dr = np.array([[zero, zero], [-h * np.sin(phi), h * np.cos(phi)],
                   [-h * np.sin(phi + math.pi / 3.0), h * np.cos(phi + math.pi / 3.0)]])
    return r, dr


def _fk_eliminated(D: np.ndarray, b: float, h: float, phi):
    """Leg 1's equation times ``delta^2`` with ``A(Phi) = N / delta`` from legs 2, 3 minus leg 1; and ``N``, ``delta``."""
    r, _ = _fk_offsets(h, phi)
    M = np.empty((2, 2) + np.shape(phi))
    c = np.empty((2,) + np.shape(phi))
    for k in (1, 2):
        w = [r[k][j] - D[k][j] + D[0][j] for j in range(2)]
        M[k - 1, 0], M[k - 1, 1] = 2.0 * w[0], 2.0 * w[1]
        c[k - 1] = D[0] @ D[0] - ((r[k][0] - D[k][0]) ** 2 + (r[k][1] - D[k][1]) ** 2)
    delta = M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0]
    N = np.array([M[1, 1] * c[0] - M[0, 1] * c[1], M[0, 0] * c[1] - M[1, 0] * c[0]])
    F = N[0] ** 2 + N[1] ** 2 - 2.0 * delta * (N[0] * D[0][0] + N[1] * D[0][1]) + delta ** 2 * (D[0] @ D[0] - b * b)
    return F, N, delta


def _fk_legs(D: np.ndarray, b: float, h: float, x: np.ndarray):
    """Leg equations ``|V_k - D_k|^2 - b^2`` [m^2] at ``x = (x_A, y_A, Phi)`` and their Jacobian."""
    r, dr = _fk_offsets(h, x[2])
    e = x[:2] + r - D  # (3, 2)
    f = np.sum(e * e, axis=1) - b * b
    J = np.column_stack([2.0 * e[:, 0], 2.0 * e[:, 1], 2.0 * np.sum(e * dr, axis=1)])
    return f, J, e


def forward_kinematics(params: Rrr3Params, theta, *, tol: float = 1e-10) -> tuple[FkSolution, ...]:
    """Every real assembly mode (up to 6) for the motor angles ``theta`` (see the module doc).

    Args:
        params: The design.
        theta: Motor angles ``(theta_1, theta_2, theta_3)`` [rad].
        tol: Largest leg-length error [m] accepted for a solution.

    Returns:
        The solutions sorted by ``Phi``, each verified to ``tol``.

    Raises:
        AssemblyError: no real assembly exists (``deficit``: the smallest leg-1 length error over ``Phi``, m).
        SingularityError: the equations are degenerate (a continuum of assemblies, e.g. a self-motion).
    """
    params = check_params(params, Rrr3Params)
    theta = as_vector(theta, 3, "theta")
    tol = as_tolerance(tol, "tol")
    a, b, h = params.a, params.b, params.h
    D = base_vertices(params) + a * np.column_stack([np.cos(theta), np.sin(theta)])
    phis = 2.0 * math.pi * np.arange(_FK_SAMPLES) / _FK_SAMPLES
    F, _, delta = _fk_eliminated(D, b, h, phis)
    coef = np.fft.fft(F) / _FK_SAMPLES  # coef[k] multiplies e^{i k Phi}; k = -4..4 used
    scale = float(np.max(np.abs(F)))
    if scale == 0.0 or np.max(np.abs(coef)) <= 1e-13 * max(scale, 1e-300):
        raise SingularityError("direct", 0.0, "the forward-kinematics equations vanish identically: the platform "
                                              "has a continuum of assemblies (self-motion)")
    poly = np.array([coef[k % _FK_SAMPLES] for k in range(4, -5, -1)])  # z^4 F(z): highest power first
    big = np.abs(poly) > 1e-12 * np.max(np.abs(poly))
    lead, trail = int(np.argmax(big)), len(poly) - int(np.argmax(big[::-1]))
    roots = np.roots(poly[lead:trail]) if trail - lead > 1 else np.array([])
    candidates = [float(np.angle(z)) for z in roots if abs(abs(z) - 1.0) < 1e-4]
    solutions: list[FkSolution] = []
    for phi in candidates:
        _, Np, dp = _fk_eliminated(D, b, h, phi)
        if abs(dp) > 1e-9 * float(np.max(np.abs(delta))):
            A = Np / dp
        else:  # delta and N vanish together at this root: A(Phi) is 0/0 there, take its limit
            _, Nn, dn = _fk_eliminated(D, b, h, np.array([phi - 1e-6, phi + 1e-6]))
            A = np.mean(Nn / dn, axis=1)
        sol = _fk_polish(params, D, np.array([A[0], A[1], phi]), theta, tol)
        if sol is not None and not any(np.max(np.abs(np.r_[s.y[:2] - sol.y[:2], wrap_angle(s.y[2] - sol.y[2])]))
                                       < 1e-8 for s in solutions):
            solutions.append(sol)
    if not solutions:
        dense = np.linspace(0.0, 2.0 * math.pi, 721)
        _, Nd, dd = _fk_eliminated(D, b, h, dense)
        ok = np.abs(dd) > 1e-12 * max(float(np.max(np.abs(dd))), 1e-300)
        gap = np.abs(np.hypot(Nd[0][ok] / dd[ok] - D[0][0], Nd[1][ok] / dd[ok] - D[0][1]) - b)
        raise AssemblyError(float(np.min(gap)) if gap.size else float("inf"), "m",
                            f"motor angles {tuple(round(float(t), 6) for t in theta)} rad admit no assembly of this design")
    return tuple(sorted(solutions, key=lambda s: s.y[2]))


def _fk_polish(params: Rrr3Params, D: np.ndarray, x: np.ndarray, theta: np.ndarray, tol: float) -> FkSolution | None:
    """Newton on the three leg equations from ``x = (x_A, y_A, Phi)``; the solution if it holds to ``tol``."""
    b = params.b
    for _ in range(_FK_NEWTON):
        f, J, e = _fk_legs(D, b, params.h, x)
        if np.max(np.abs(np.sqrt(np.sum(e * e, axis=1)) - b)) <= 0.01 * tol:
            break
        if not (np.all(np.isfinite(J)) and np.all(np.isfinite(f))):
            return None
        step = np.linalg.lstsq(J, -f, rcond=None)[0]
        x = x + step
        if not np.all(np.isfinite(x)):
            return None
    _, _, e = _fk_legs(D, b, params.h, x)
    residual = float(np.max(np.abs(np.sqrt(np.sum(e * e, axis=1)) - b)))
    if residual > tol:
        return None
    phi = float(wrap_angle(x[2]))
    A = x[:2].copy()
    link_a = np.column_stack([np.cos(theta), np.sin(theta)])
    u = e / b  # distal directions D -> V
    psi = np.arctan2(link_a[:, 0] * u[:, 1] - link_a[:, 1] * u[:, 0], np.sum(link_a * u, axis=1))
    signs = tuple(int(np.sign(p)) for p in psi)
    mode = next((name for name, s in MODES.items() if s == signs), None)
    y = np.concatenate([centroid_from_a(params, A, phi), [phi]])
    return FkSolution(y, A, psi, mode, residual)


# ---------------------------------------------------------------------- uniform interface
# Every mechanism module offers these, over the task vector ``y`` laid out as
# :class:`pkm.core.TaskMap` does (here: centroid x, y and yaw Phi).
def closed_form_fk(params: Rrr3Params, q_actuated, seed=None) -> np.ndarray:
    """One assembly mode of :func:`forward_kinematics`: on ``params.mode``, nearest to ``seed``.

    Args:
        params: The design.
        q_actuated: Motor angles [rad].
        seed: Task vector the solution should be nearest to (default :func:`home_task`).

    Raises:
        AssemblyError: no assembly at all; BranchError: none on ``params.mode``.
    """
    params = check_params(params, Rrr3Params)
    target = home_task(params) if seed is None else as_vector(seed, 3, "seed")
    sols = [s for s in forward_kinematics(params, q_actuated) if s.mode == f"mode{params.mode}"]
    if not sols:
        expected = dict(zip(("elbow_1", "elbow_2", "elbow_3"), MODES[f"mode{params.mode}"]))
        raise BranchError(f"mode{params.mode}", expected, {})
    return min(sols, key=lambda s: float(np.max(np.abs(np.r_[s.y[:2] - target[:2],
                                                              wrap_angle(s.y[2] - target[2])])))).y.copy()


def closed_form_ik(params: Rrr3Params, y, branch: str | None = None) -> np.ndarray:
    """Actuated coordinates for task vector ``y`` (closed form); ``branch`` = working mode name."""
    params = check_params(params, Rrr3Params)
    y = as_vector(y, 3, "y")
    return inverse_kinematics(params, a_from_centroid(params, y[:2], y[2]), y[2], branch)


def closed_form_configuration(mech: Mechanism, y, branch: str | None = None) -> np.ndarray:
    """Every joint coordinate for task vector ``y`` (closed form); ``branch`` = working mode name."""
    return configuration(mech, y, branch)


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
        b.joint(f"motor_{n}", "revolute", "base", f"proximal_{n}", (vertex[0], vertex[1], 0.0))
        b.link(f"distal_{n}", params.m_distal, (params.b / 2.0, 0.0, 0.0), rod_inertia(params.m_distal, params.b, 0))
        b.joint(f"elbow_{n}", "revolute", f"proximal_{n}", f"distal_{n}", (params.a, 0.0, 0.0))
        if n > 1:
            b.frame(f"leg{n}_tip", f"distal_{n}", (params.b, 0.0, 0.0))
    h, m = params.h, params.m_platform
    g_local = (h / 2.0, h / (2.0 * SQRT3), 0.0)
    # thin equilateral plate of side h: polar moment m h^2 / 12 about its centroid
    b.link("platform", m, g_local, np.diag([m * h * h / 24.0, m * h * h / 24.0, m * h * h / 12.0]))
    b.joint("wrist_1", "revolute", "distal_1", "platform", (params.b, 0.0, 0.0))
    b.frame("platform_A", "platform")
    b.frame("platform_B", "platform", (h, 0.0, 0.0))
    b.frame("platform_C", "platform", (h / 2.0, h * SQRT3 / 2.0, 0.0))
    b.frame("platform_center", "platform", g_local)
    return b.to_xml()


def closure_spec(params: Rrr3Params) -> ClosureSpec:
    params = check_params(params, Rrr3Params)
    reference = {k: tuple(v) for k, v in joint_values(params, home_task(params)).items()}
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
        default_branch=f"mode{params.mode}",
        parameters=spec_parameters(params),
    )


Params = Rrr3Params


def build(params: Rrr3Params | None = None) -> Mechanism:
    """The planar 3-RRR as a :class:`~pkm.core.Mechanism` (reference design when ``params`` is None)."""
    params = Rrr3Params() if params is None else params
    return make_mechanism(urdf_xml(params), closure_spec(params), params)


# ---------------------------------------------------------------------- helpers
def _length(length) -> float:
    L = _scalar(length, "length")
    if L <= 0.0:
        raise InvalidInputError("length", f"the characteristic length must be > 0 m, got {L!r}", length)
    return L


def _scalar(x, name: str) -> float:
    return float(as_vector([x] if np.ndim(x) == 0 else x, 1, name)[0])
