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

from pkm.core.mechanism import Mechanism, as_vector, wrap_angle
from pkm.core.spec import Branch, Closure, ClosureSpec, TaskSpec
from pkm.core.urdf import UrdfBuilder
from pkm.errors import InvalidInputError, InvalidParameterError, SingularityError, UnreachableError
from pkm.mechanisms._common import check_positive, make_mechanism, rod_inertia, spec_parameters

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
        if not isinstance(self.home, (tuple, list)) or len(self.home) != 3:
            raise InvalidParameterError("home", "must be (dx, dy, Phi) in m, m, rad", self.home)
        for k, v in enumerate(self.home):
            if not isinstance(v, (int, float)) or not math.isfinite(v):
                raise InvalidParameterError("home", f"component {k} is not a finite number", self.home)
        try:
            Jx, Jq = jacobians(self, home_task(self), self.mode)
        except UnreachableError as exc:
            raise InvalidParameterError(
                "home", f"reference pose {tuple(self.home)} is unreachable with this design (leg {exc.leg} misses "
                        f"by {exc.excess:.4g} m); choose another home or other lengths", self.home) from None
        except SingularityError:
            raise InvalidParameterError(
                "home", f"reference pose {tuple(self.home)} puts a platform vertex on its base vertex (a = b); "
                        "choose another home", self.home) from None
        margin_inv = float(np.min(np.abs(np.diag(Jq)))) / self.a  # min |sin psi_i|
        Jn = Jx * np.array([1.0, 1.0, SQRT3 / self.h])  # moments per platform circumradius: scale-free
        margin_dir = abs(float(np.linalg.det(Jn)))
        if margin_inv < _SINGULAR_TOL or margin_dir < _SINGULAR_TOL:
            kind = "inverse (a leg stretched or folded)" if margin_inv < _SINGULAR_TOL else "direct"
            raise InvalidParameterError(
                "home", f"reference pose {tuple(self.home)} is {kind}-singular in mode{self.mode}; choose another "
                        "home or mode", self.home)


# ---------------------------------------------------------------------- geometry
def mode_signs(mode: int | str) -> tuple[int, int, int]:
    """Signs of ``(psi_1, psi_2, psi_3)`` of a working mode given as ``k`` or ``"modek"`` (k = 1..8)."""
    key = f"mode{mode}" if isinstance(mode, (int, np.integer)) and not isinstance(mode, bool) else mode
    if key not in MODES:
        raise InvalidInputError("mode", f"use 1..8 or 'mode1'..'mode8', got {mode!r}", mode)
    return MODES[key]


def base_vertices(params: Rrr3Params) -> np.ndarray:
    """Base vertices ``P, Q, R`` as rows [m], shape (3, 2)."""
    H = params.H
    return np.array([[0.0, 0.0], [H, 0.0], [H / 2.0, H * SQRT3 / 2.0]])


def base_centroid(params: Rrr3Params) -> np.ndarray:
    """Centroid of the base triangle [m], shape (2,)."""
    return np.array([params.H / 2.0, params.H / (2.0 * SQRT3)])


def platform_vertices(params: Rrr3Params, a_point, phi: float) -> np.ndarray:
    """Platform vertices ``A, B, C`` as rows [m] (eqs. 1-2), from ``A`` [m] and ``Phi`` [rad]."""
    A = as_vector(a_point, 2, "a_point")
    phi = _scalar(phi, "phi")
    h = params.h
    return np.array([A, A + h * np.array([math.cos(phi), math.sin(phi)]),
                     A + h * np.array([math.cos(phi + math.pi / 3.0), math.sin(phi + math.pi / 3.0)])])


def centroid_from_a(params: Rrr3Params, a_point, phi: float) -> np.ndarray:
    """Platform centroid ``G`` [m] from the paper's ``A`` [m] and ``Phi`` [rad]."""
    A = as_vector(a_point, 2, "a_point")
    phi = _scalar(phi, "phi")
    return A + params.h / SQRT3 * np.array([math.cos(phi + math.pi / 6.0), math.sin(phi + math.pi / 6.0)])


def a_from_centroid(params: Rrr3Params, g_point, phi: float) -> np.ndarray:
    """The paper's platform point ``A`` [m] from the centroid ``G`` [m] and ``Phi`` [rad]."""
    G = as_vector(g_point, 2, "g_point")
    phi = _scalar(phi, "phi")
    return G - params.h / SQRT3 * np.array([math.cos(phi + math.pi / 6.0), math.sin(phi + math.pi / 6.0)])


def home_task(params: Rrr3Params) -> np.ndarray:
    """The reference task vector ``(x_G, y_G, Phi)`` [m, m, rad] of ``params.home``."""
    return np.concatenate([base_centroid(params) + np.asarray(params.home[:2], dtype=float), [params.home[2]]])


# ---------------------------------------------------------------------- closed forms
def _solve(params: Rrr3Params, a_point: np.ndarray, phi: float, mode: int | str) -> tuple[np.ndarray, np.ndarray]:
    """``(theta, psi)`` [rad] of the three legs for the paper's ``(A, Phi)`` in ``mode`` (eqs. 6-9)."""
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


# ---------------------------------------------------------------------- uniform interface
# Every mechanism module offers these, over the task vector ``y`` laid out as
# :class:`pkm.core.TaskMap` does (here: centroid x, y and yaw Phi). No closed-form forward
# kinematics: the paper gives none (up to 6 assembly modes; the generic core solves it).
def closed_form_ik(params: Rrr3Params, y, branch: str | None = None) -> np.ndarray:
    """Actuated coordinates for task vector ``y`` (closed form); ``branch`` = working mode name."""
    y = as_vector(y, 3, "y")
    return inverse_kinematics(params, a_from_centroid(params, y[:2], y[2]), y[2], branch)


def closed_form_configuration(mech: Mechanism, y, branch: str | None = None) -> np.ndarray:
    """Every joint coordinate for task vector ``y`` (closed form); ``branch`` = working mode name."""
    return configuration(mech, y, branch)


# ---------------------------------------------------------------------- tree and spec
def urdf_xml(params: Rrr3Params) -> str:
    """The URDF tree (see the module doc)."""
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
def _scalar(x, name: str) -> float:
    return float(as_vector([x] if np.ndim(x) == 0 else x, 1, name)[0])
