"""Closed-form kinematics of the planar 3-RRR: inverse and forward position, velocities, the task vector."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from pkm._moved import renamed, renamed_fields, renamed_keyword
from pkm.core.differential.indices import inverse_condition, singularity_class
from pkm.core.kinematics.newton import gauss_newton
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import (
    AssemblyError,
    BranchError,
    InvalidInputError,
    InvalidParameterError,
    SingularityError,
    UnreachableError,
)
from pkm.mechanisms._common import (
    best_reference,
    check_params,
)
from pkm.mechanisms.rrr3.params import MODES, REACH_TOL, SQRT3, Rrr3Params, base_centroid, base_vertices, branch_signs
from pkm.validation import as_scalar, as_tolerance, as_vector, finite_result, wrap_angle


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


# ---------------------------------------------------------------------- closed forms
def leg_reach(a: float, b: float, tx, ty) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(d2, dist, reachable)`` of an RR leg (:func:`leg_elbows`' test, alone: a map decides reachability on every
    node and places the elbows on the reachable ones only): the squared distance and the distance from the base
    vertex to the platform vertex ``(tx, ty)`` [m^2, m] and whether it lies in ``[|a - b|, a + b]`` (to
    ``REACH_TOL``) and is not 0."""
    lo, hi = abs(a - b), a + b
    with np.errstate(over="ignore", invalid="ignore"):  # beyond the float range: not reachable
        d2 = tx * tx + ty * ty
        dist = np.sqrt(d2)
        return d2, dist, (dist <= hi * (1.0 + REACH_TOL)) & (dist >= lo - hi * REACH_TOL) & (dist > 0.0)


def leg_elbows(a: float, b: float, tx, ty, sign) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The elbow of an RR leg, vectorised over the leading axes of ``tx, ty`` (and ``sign``): the one
    closed form of the 3-RRR leg (eqs. 6-9), for single poses and for maps.

    Args:
        a, b: Proximal and distal lengths [m].
        tx, ty: The platform vertex relative to the leg's base vertex [m].
        sign: ``+1`` for ``psi > 0`` (the elbow on the right of base vertex -> platform vertex), ``-1``.

    Returns:
        ``(Dx, Dy, dist, reachable)``: the elbow relative to the base vertex [m], the distance from the
        base vertex to the platform vertex [m] and whether it lies in ``[|a - b|, a + b]`` (to
        ``REACH_TOL``) and is not 0 (there the elbow is the clipped one: finite, but no assembly).
    """
    d2, dist, reachable = leg_reach(a, b, tx, ty)
    return (*elbow_at(a, b, tx, ty, sign, d2, dist), dist, reachable)


def elbow_at(a: float, b: float, tx, ty, sign, d2, dist) -> tuple[np.ndarray, np.ndarray]:
    """:func:`leg_elbows`' elbow ``(Dx, Dy)`` [m] from :func:`leg_reach`'s ``d2, dist`` at the same ``tx, ty``."""
    with np.errstate(over="ignore", invalid="ignore"):  # beyond the float range: not reachable
        safe = np.where(dist > 0.0, dist, 1.0)
        ex, ey = tx / safe, ty / safe
        along = (a * a - b * b + d2) / (2.0 * safe)  # the elbow's projection on base vertex -> platform vertex
        off = np.sqrt(np.clip(a * a - along * along, 0.0, None))
        return along * ex + sign * off * ey, along * ey - sign * off * ex


def _solve(params: Rrr3Params, a_point: np.ndarray, phi: float, branch: int | str | None) -> tuple[np.ndarray, np.ndarray]:
    """``(theta, psi)`` [rad] of the three legs for the paper's ``(A, Phi)`` in working mode ``branch`` (None:
    ``params.branch``) (eqs. 6-9)."""
    params = check_params(params, Rrr3Params)
    a, b = params.a, params.b
    T = platform_vertices(params, a_point, phi) - base_vertices(params)
    Dx, Dy, dist, reachable = leg_elbows(a, b, T[:, 0], T[:, 1], np.array(branch_signs(params.branch if branch is None else branch), dtype=float))
    for i in np.flatnonzero(~reachable):
        d, lo, hi = float(dist[i]), abs(a - b), a + b
        if not math.isfinite(d):
            raise UnreachableError(int(i) + 1, math.inf, "m", f"leg {i + 1}: the platform vertex is beyond the float "
                                                              "range (check the units)")
        if d > hi * (1.0 + REACH_TOL) or d < lo - hi * REACH_TOL:
            raise UnreachableError(int(i) + 1, d - hi if d > hi else lo - d, "m",
                                   f"leg {i + 1}: distance {d:.6g} m from its base vertex to its platform vertex is "
                                   f"outside [|a-b|, a+b] = [{lo:.6g}, {hi:.6g}] m")
        raise SingularityError("inverse", 0.0, f"leg {i + 1}: platform vertex on the base vertex (a = b), "
                                               "the motor angle is undetermined")
    ux, uy = T[:, 0] - Dx, T[:, 1] - Dy  # the distal link
    return wrap_angle(np.arctan2(Dy, Dx)), np.arctan2(Dx * uy - Dy * ux, Dx * ux + Dy * uy)


@renamed_keyword(mode="branch")
def inverse_kinematics(params: Rrr3Params, a_point, phi: float, branch: int | str | None = None) -> np.ndarray:
    """Motor angles ``(theta_1, theta_2, theta_3)`` [rad] in (-pi, pi], in the paper's terms (eq. 9).

    Args:
        params: The design.
        a_point: Platform vertex ``A`` [m], shape (2,).
        phi: Platform orientation ``Phi`` [rad].
        branch: Working mode (1..8 or ``"mode1"``..``"mode8"``); default ``params.branch``. (``mode=``: its
            deprecated former name.)

    Raises:
        UnreachableError: with the first leg whose base-vertex-to-platform-vertex distance is
            outside ``[|a - b|, a + b]``, and by how much [m].
        SingularityError: a platform vertex on its base vertex (only when ``a = b``).
    """
    return _solve(params, a_point, phi, branch)[0]


@renamed_keyword(mode="branch")
def joint_values(params: Rrr3Params, y, branch: int | str | None = None) -> dict[str, list[float]]:
    """Every joint coordinate of the tree (closed form) for the task vector ``y = (x_G, y_G, Phi)`` in working mode
    ``branch`` (default ``params.branch``)."""
    params = check_params(params, Rrr3Params)
    y = as_vector(y, 3, "y")
    theta, psi = _solve(params, a_from_centroid(params, y[:2], y[2]), y[2], branch)
    out: dict[str, list[float]] = {}
    for i in range(3):
        out[f"motor_{i + 1}"] = [float(theta[i])]
        out[f"elbow_{i + 1}"] = [float(psi[i])]
    out["wrist_1"] = [float(wrap_angle(y[2] - theta[0] - psi[0]))]
    return out


@renamed_keyword(mode="branch")
def configuration(mech: Mechanism, y, branch: int | str | None = None) -> np.ndarray:
    """Full configuration vector ``q`` of ``mech`` for the task vector ``y`` (closed form) in working mode ``branch``
    (default ``mech.params.branch``)."""
    mech = check_mechanism(mech)
    return mech.q_from_dict(joint_values(mech.params, y, branch))


@renamed_keyword(mode="branch")
def jacobians(params: Rrr3Params, y, branch: int | str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The paper's ``J_x``, ``J_q`` (eqs. 16-20, rebuilt) with ``J_x yd = J_q theta_dot`` in working mode ``branch``
    (default ``params.branch``).

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
    theta, psi = _solve(params, A, y[2], branch)
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


@renamed_keyword(mode="branch")
def homogenized_jacobians(params: Rrr3Params, y, branch: int | str | None = None, *, length: float | None = None,
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
        branch: Working mode; default ``params.branch``.
        length: Characteristic length ``L`` [m], finite and > 0; default :func:`characteristic_length`.
        reference: Moment reference point, one of :data:`REFERENCES`.

    Returns:
        ``(J_x, J_q)``: (3, 3) arrays, ``J_x`` dimensionless, ``J_q`` in [m].
    """
    params = check_params(params, Rrr3Params)
    L = characteristic_length(params) if length is None else _length(length)
    Jx, Jq = jacobians(params, y, branch)
    d = as_vector(y, 3, "y")[:2] - reference_point(params, y, reference)  # G - P
    Jx[:, 2] += d[0] * Jx[:, 1] - d[1] * Jx[:, 0]  # (V - P) x u = (V - G) x u + (G - P) x u
    with np.errstate(over="ignore"):  # a tiny L overflows: reported below
        Jx[:, 2] /= L
    return finite_result(Jx, "homogenized J_x", f"length = {L!r} m is too small (the moment column overflows)"), Jq


@renamed_keyword(mode="branch")
def singularity_measures(params: Rrr3Params, y, branch: int | str | None = None) -> tuple[float, float]:
    """Dimensionless distances to the two kinds of singularity at task vector ``y`` in working mode ``branch``
    (default ``params.branch``).

    Returns:
        ``(inverse, direct)``: ``min_i |sin psi_i|`` (0 when a leg is stretched or folded, eq. 20)
        and ``|det J_x|`` of :func:`homogenized_jacobians` with the default ``L`` and the centroid
        (0 when the three distal-link lines meet in a point or are parallel, eq. 19); both are
        unchanged by a uniform scaling of the design.
    """
    params = check_params(params, Rrr3Params)
    Jx, Jq = homogenized_jacobians(params, y, branch)
    return float(np.min(np.abs(np.diag(Jq)))) / params.a, abs(float(np.linalg.det(Jx)))


@renamed_keyword(mode="branch")
def classify_singularity(params: Rrr3Params, y, branch: int | str | None = None, *, tol: float = 1e-8) -> str:
    """``"regular"``, ``"inverse"`` (``J_q`` singular), ``"direct"`` (``J_x`` singular) or ``"combined"`` (both).

    Args:
        params: The design.
        y: Task vector ``(x_G, y_G, Phi)`` [m, m, rad].
        branch: Working mode; default ``params.branch``.
        tol: A measure of :func:`singularity_measures` at or below ``tol`` counts as singular.
    """
    params = check_params(params, Rrr3Params)
    tol = as_scalar(tol, "tol", low=0.0)
    inv, direct = singularity_measures(params, y, branch)
    return singularity_class(inv <= tol, direct <= tol)


# ---------------------------------------------------------------------- forward kinematics
@renamed_fields(mode="branch")
@dataclass(frozen=True)
class FkSolution:
    """One assembly mode of the forward kinematics.

    Attributes:
        y: Task vector ``(x_G, y_G, Phi)`` [m, m, rad], ``Phi`` in (-pi, pi].
        a_point: The paper's platform vertex ``A`` [m].
        psi: Elbow angles ``(psi_1, psi_2, psi_3)`` [rad] (see the module doc).
        branch: Working mode name of the solution (``"mode1"``..``"mode8"``: signs of ``psi``), ``None`` if a
            leg is exactly stretched or folded. (``mode``: its deprecated former name.)
        residual: Largest ``| |V_i - D_i| - b |`` over the legs [m].
    """

    y: np.ndarray
    a_point: np.ndarray
    psi: np.ndarray
    branch: str | None
    residual: float

    @property
    def mode(self) -> str | None:
        """Deprecated former name of :attr:`branch` (a :class:`DeprecationWarning`)."""
        renamed("FkSolution", "mode", "branch")
        return self.branch


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

    def fun(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # (|e|^2 - b^2) / 2b: the distance error, to first order
        f, J, _ = _fk_legs(D, b, params.h, z)
        return f / (2.0 * b), J / (2.0 * b)

    x, _, _ = gauss_newton(fun, x, tol=0.01 * tol, max_iter=_FK_NEWTON)
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
    branch = next((name for name, s in MODES.items() if s == signs), None)
    y = np.concatenate([centroid_from_a(params, A, phi), [phi]])
    return FkSolution(y, A, psi, branch, residual)


# ---------------------------------------------------------------------- uniform interface
# Every mechanism module offers these, over the task vector ``y`` laid out as
# :class:`pkm.core.TaskMap` does (here: centroid x, y and yaw Phi).
def closed_form_fk(params: Rrr3Params, q_actuated, seed=None) -> np.ndarray:
    """One assembly mode of :func:`forward_kinematics`: on working mode ``params.branch``, nearest to ``seed``.

    Args:
        params: The design.
        q_actuated: Motor angles [rad].
        seed: Task vector the solution should be nearest to (default :func:`reference_pose`).

    Raises:
        AssemblyError: no assembly at all; BranchError: none on ``params.branch``.
    """
    params = check_params(params, Rrr3Params)
    target = reference_pose(params) if seed is None else as_vector(seed, 3, "seed")
    sols = [s for s in forward_kinematics(params, q_actuated) if s.branch == f"mode{params.branch}"]
    if not sols:
        expected = dict(zip(("elbow_1", "elbow_2", "elbow_3"), MODES[f"mode{params.branch}"]))
        raise BranchError(f"mode{params.branch}", expected, {})
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


# ---------------------------------------------------------------------- reference pose
REFERENCE_ORIENTATIONS = 49  # candidate reference orientations Phi in [-pi/3, pi/3] (the platform's symmetry)
SINGULAR_TOL = 1e-6  # a given reference pose must be at least this far (dimensionless) from singularity


def reference_pose(params: Rrr3Params) -> np.ndarray:
    """The design's reference task vector ``(x_G, y_G, Phi)`` [m, m, rad] in working mode ``params.branch``.

    ``params.home`` (offset from the base centroid, orientation) when given; otherwise the centred
    platform at the orientation of largest condition index (the inverse condition number of
    ``J_q^-1 J_x`` of :func:`homogenized_jacobians`, the paper's CI) among 49 values of ``Phi`` in
    ``[-pi/3, pi/3]`` (the one nearest ``Phi = 0`` of equal ones).

    Raises:
        InvalidParameterError: (``home``) the given pose is unreachable (which leg, by how much) or
            within 1e-6 of a singularity, or no candidate assembles at least 1e-3 from singularity.
    """
    params = check_params(params, Rrr3Params)
    return np.array(_reference(params))


@functools.lru_cache(maxsize=256)
def _reference(params: Rrr3Params) -> tuple[float, float, float]:
    G = base_centroid(params)
    if params.home is None:
        phis = sorted(np.linspace(-math.pi / 3.0, math.pi / 3.0, REFERENCE_ORIENTATIONS), key=abs)
        return best_reference("home", ((float(G[0]), float(G[1]), float(phi)) for phi in phis),
                              lambda y: condition_index(params, y), minimum=1e-3)
    y = (float(G[0] + params.home[0]), float(G[1] + params.home[1]), params.home[2])
    home = tuple(params.home)
    try:
        margin_inv, margin_dir = singularity_measures(params, y, params.branch)
    except UnreachableError as exc:
        raise InvalidParameterError(
            "home", f"reference pose {home} is unreachable with this design (leg {exc.leg} misses by "
                    f"{exc.excess:.4g} m); choose another home or other lengths", params.home) from None
    except SingularityError:
        raise InvalidParameterError(
            "home", f"reference pose {home} puts a platform vertex on its base vertex (a = b); choose another "
                    "home", params.home) from None
    if margin_inv < SINGULAR_TOL or margin_dir < SINGULAR_TOL:
        kind = "inverse (a leg stretched or folded)" if margin_inv < SINGULAR_TOL else "direct"
        raise InvalidParameterError(
            "home", f"reference pose {home} is {kind}-singular in mode{params.branch}; choose another home or branch",
            params.home)
    return y


def condition_index(params: Rrr3Params, y) -> float:
    """The inverse condition number of ``J_q^-1 J_x`` (:func:`homogenized_jacobians`, centroid, default
    length) at ``y`` in working mode ``params.branch``: in [0, 1], 0 at a singularity.

    Raises:
        UnreachableError, SingularityError: as :func:`homogenized_jacobians`.
    """
    Jx, Jq = homogenized_jacobians(params, y, params.branch)
    q = np.diag(Jq)
    if np.min(np.abs(q)) == 0.0:
        raise SingularityError("inverse", 0.0, "a leg stretched or folded")
    return float(inverse_condition(Jx / q[:, None]))


# ---------------------------------------------------------------------- helpers
def _length(length) -> float:
    L = _scalar(length, "length")
    if L <= 0.0:
        raise InvalidInputError("length", f"the characteristic length must be > 0 m, got {L!r}", length)
    return L


def _scalar(x, name: str) -> float:
    return float(as_vector([x] if np.ndim(x) == 0 else x, 1, name)[0])
