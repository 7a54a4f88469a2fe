"""Velocity and acceleration of the reconfigurable hexapod by screw theory (paper eqs. 18-33).

Screws (Plücker, pole O, conventions of :mod:`pkm.core.differential.screws`), per leg ``i`` in chain order:
``$r = [u; F x u]`` (reconfiguration joint, legs 1-3 only), ``$1 = [u; A x u]`` (actuated),
``$2 = [u; B x u]``, ``$3 = [v; B x v]`` (universal joint), ``$4, $5, $6 = [u|v|w; C x (u|v|w)]``
(spherical joint), ``$f = [0; w]`` (the paper's virtual prismatic joint along the rod, rate 0);
``u`` is the actuated axis, ``w = (C - B) / LB`` the rod direction and ``v = w x u / |w x u|``.
For legs 4-6, which have no reconfiguration joint, ``$r`` is the zero screw.

Rates: the actuated rates ``qd = (alpha_1..alpha_6, beta)`` are those of the mechanism's actuated
joint coordinates (:data:`pkm.mechanisms.hexapod.ACTUATED`): for legs 1-3, ``alpha_i`` is measured
from the reconfiguration link, as in eq. (18) where ``$r`` turns at ``beta_dot`` and ``$1`` at
``alpha_i_dot`` on top of it. (With the paper's absolute angles of eq. 3 the ``$1`` rate would be
``alpha_i_dot - beta_dot``.)

The rod screw ``$6`` is reciprocal to every joint screw of its leg but ``$r``, ``$1`` (and
``$f``), so the Klein form with ``$6`` gives, row by row (eqs. 20-25, 31-33):

* velocity: ``J_x^T DELTA V = J'_q qd_beta + J_q qd_alpha`` with ``J_x = [$6_1 .. $6_6]``,
  ``J_q = diag {$1_i; $6_i}``, ``J'_q = diag({$r_i; $6_i}, 1, 1, 1)`` and
  ``qd_beta = beta_dot (1, 1, 1, 0, 0, 0)``;
* acceleration: ``J_x^T DELTA A = J'_q qdd_beta + J_q qdd_alpha + C`` with ``A`` the reduced
  acceleration ``[w_dot; a_O - w x v_O]`` (eq. 26) and ``C_i = {L_i; $6_i}``, ``L_i`` the Lie
  screw of acceleration of leg i (eqs. 29-30, :func:`pkm.core.differential.screws.chain_lie_term`), which
  needs every joint rate of the leg (:func:`leg_rates`).

Departures from the printed text: eq. (22)-(25) say ``{$r_i; $6_i} = 1`` "because the screws are
collinear"; they are not collinear, and the entry is kept as the Klein form (it equals
``Rr u.(c x w) + LA u.(a x w)``, ``c`` and ``a`` the unit directions of the reconfiguration link
and the arm). The ``1`` entries of ``J'_q`` for legs 4-6 multiply zero rates; they are kept as
printed. Eq. (27) numbers the acceleration magnitudes from 1 where eq. (18) numbers the rates
from r; the Lie product sums run over the chain as in eq. (29).

Everything here is checked against the generic core (:func:`pkm.core.twist_jacobian`,
:func:`pkm.core.accelerations`) and against finite differences in the tests.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from pkm.core.differential import screws
from pkm.core.kinematics.task import as_rotation
from pkm.errors import InvalidInputError, SingularityError
from pkm.mechanisms._common import circle_sphere_cs
from pkm.mechanisms.hexapod import geometry as hx
from pkm.mechanisms.hexapod import params as hp
from pkm.validation import as_vector

#: Chain order of the screws of a leg (rows of :func:`leg_screws`).
CHAIN = ("r", "1", "2", "3", "4", "5", "6", "f")


@functools.lru_cache(maxsize=32)
def leg_axes(params: hp.HexapodParams) -> np.ndarray:
    """Leg frames ``(e_r, e_y, u_i)`` as columns, stacked ``(6, 3, 3)``."""
    return np.stack([hp.leg_frame(th) for th in params.theta])


@functools.lru_cache(maxsize=32)
def _trig(params: hp.HexapodParams) -> tuple[np.ndarray, np.ndarray]:
    th = np.asarray(params.theta)
    return np.cos(th), np.sin(th)


@dataclass(frozen=True)
class LegBatch:
    """Geometry of the six legs for a batch of configurations (leading shape ``S``).

    Stored in the leg frames ``(e_r, e_y, u_i)``; the world points and the angles are properties.

    Attributes:
        C: Spherical joint centres, ``(*S, 6, 3)`` [m].
        w: Rod unit directions ``(C - B) / LB`` (world), ``(*S, 6, 3)``.
        margin: Reachability margin ``rho - |K|`` of each leg, ``(*S, 6)`` [m]: >= 0 where the leg
            reaches (``rho`` the distance from ``C`` to ``A`` within the leg plane, ``K`` as in
            :func:`pkm.mechanisms._common.circle_sphere`).
        klein_1: ``{$1_i; $6_i} = u.((C - A) x w)`` [m], ``(*S, 6)`` (the diagonal of ``J_q``).
        klein_r: ``{$r_i; $6_i} = u.((C - F) x w)`` [m], ``(*S, 6)`` (0 for legs 4-6).
        a_r, a_y: ``A`` in the leg frame [m]; cos_a, sin_a: ``cos alpha``, ``sin alpha``; cos_t, sin_t:
            ``cos theta_i``, ``sin theta_i``.
    """

    C: np.ndarray
    w: np.ndarray
    margin: np.ndarray
    klein_1: np.ndarray
    klein_r: np.ndarray
    a_r: np.ndarray
    a_y: np.ndarray
    cos_a: np.ndarray
    sin_a: np.ndarray
    cos_t: np.ndarray
    sin_t: np.ndarray
    LA: float

    def _world(self, r: np.ndarray, y: np.ndarray) -> np.ndarray:
        return np.stack([r * self.cos_t, y, r * self.sin_t], axis=-1)

    @property
    def A(self) -> np.ndarray:
        """Actuated joint centres, ``(*S, 6, 3)`` [m]."""
        return self._world(self.a_r, self.a_y)

    @property
    def B(self) -> np.ndarray:
        """Universal joint centres, ``(*S, 6, 3)`` [m] (meaningless where ``margin < 0``)."""
        return self._world(self.a_r + self.LA * self.cos_a, self.a_y + self.LA * self.sin_a)

    @property
    def alphas(self) -> np.ndarray:
        """The paper's absolute arm angles, ``(*S, 6)`` [rad]."""
        return np.arctan2(self.sin_a, self.cos_a)


def leg_batch(params: hp.HexapodParams, C: np.ndarray, beta, signs: np.ndarray) -> LegBatch:
    """Closed-form inverse kinematics of the six legs, vectorised over a batch.

    In leg frame ``(e_r, e_y, u)`` with ``d = C - A``: ``(cos alpha, sin alpha)`` of
    :func:`pkm.mechanisms._common.circle_sphere_cs` (as :func:`pkm.mechanisms.hexapod.inverse_kinematics`);
    the Klein forms are computed there too (``u`` is the third axis): ``{$1; $6} = d_r w_y - d_y w_r``.

    Args:
        params: The design.
        C: Spherical joint centres, ``(*S, 6, 3)`` [m] (broadcast against ``beta``).
        beta: Reconfiguration angles, shape ``S`` (or broadcastable) [rad].
        signs: ``+1`` (elbow_out) or ``-1`` (elbow_in) per leg, shape (6,).

    Returns:
        The legs; where ``margin < 0`` the values are those of the clipped ``acos`` (no assembly).
    """
    ct, st = _trig(params)
    C = np.asarray(C, dtype=float)
    beta = np.asarray(beta, dtype=float)[..., None]
    shape = np.broadcast_shapes(C.shape[:-2], beta.shape[:-1])
    if C.shape[:-2] != shape:
        C = np.broadcast_to(C, shape + (6, 3))
    a_r = np.empty(shape + (6,))
    a_y = np.empty(shape + (6,))
    a_r[..., :3] = params.Rf + params.Rr * np.cos(beta)
    a_y[..., :3] = params.Rr * np.sin(beta)
    a_r[..., 3:] = params.R2
    a_y[..., 3:] = -params.H0
    Cx, Cy, Cz = C[..., 0], C[..., 1], C[..., 2]
    c_r = Cx * ct + Cz * st
    c_u = Cz * ct - Cx * st
    d_r, d_y = c_r - a_r, Cy - a_y
    ca, sa, rho, K = circle_sphere_cs(d_r, d_y, c_u, params.LA, params.LB, signs)
    w_r, w_y, w_u = (d_r - params.LA * ca) / params.LB, (d_y - params.LA * sa) / params.LB, c_u / params.LB
    kr = np.zeros(shape + (6,))
    kr[..., :3] = ((c_r - params.Rf) * w_y - Cy * w_r)[..., :3]
    w = np.stack([w_r * ct - w_u * st, w_y, w_r * st + w_u * ct], axis=-1)
    return LegBatch(C, w, rho - np.abs(K), d_r * w_y - d_y * w_r, kr, a_r, a_y, ca, sa, ct, st, params.LA)


def klein_rows(legs: LegBatch) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(J_x^T DELTA, diag J_q, diag J'_q)`` of a batch: ``(*S, 6, 6)``, ``(*S, 6)``, ``(*S, 6)``.

    Row i of ``J_x^T DELTA`` is ``[(C_i x w_i)^T, w_i^T]``, so that it times ``[w; v_O]`` is
    ``{V; $6_i}``; ``J'_q`` has ``{$r_i; $6_i}`` for legs 1-3 and 1 (as printed) for legs 4-6.
    """
    M = np.concatenate([screws.cross(legs.C, legs.w), legs.w], axis=-1)
    jqp = legs.klein_r.copy()
    jqp[..., 3:] = 1.0
    return M, legs.klein_1, jqp


# ---------------------------------------------------------------------- one configuration
@dataclass(frozen=True)
class ScrewJacobians:
    """The matrices of eqs. (22)-(25) at one configuration (pole O).

    Attributes:
        Jx: Forward-kinematics Jacobian ``[$6_1 .. $6_6]`` (screws as columns), (6, 6).
        Jq: ``diag {$1_i; $6_i}`` [m], (6, 6).
        Jq_prime: ``diag({$r_i; $6_i}, 1, 1, 1)`` [m for the first three], (6, 6).
        P: Platform position [m] (to refer twists to ``P``).
    """

    Jx: np.ndarray
    Jq: np.ndarray
    Jq_prime: np.ndarray
    P: np.ndarray

    @property
    def JxT_delta(self) -> np.ndarray:
        """``J_x^T DELTA`` (rows ``[(C x w)^T, w^T]``)."""
        return self.Jx.T @ screws.DELTA

    def twist_jacobian(self, point: str = "O") -> np.ndarray:
        """Platform twist ``[w; v]`` per actuated rate ``(alpha_1..alpha_6, beta)``, (6, 7).

        Args:
            point: ``"O"`` (the paper's: ``v`` is the velocity of the platform point at O) or
                ``"P"`` (the velocity of the platform centre P).

        Raises:
            SingularityError: ``kind="direct"`` where ``J_x`` is singular.
        """
        rhs = np.column_stack([self.Jq, self.Jq_prime @ np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])])
        J = _solve_direct(self.JxT_delta, rhs)
        return _refer(J, point, self.P)


def jacobians(params: hp.HexapodParams, R, P, beta: float, branch=hp.DEFAULT_BRANCH) -> ScrewJacobians:
    """``J_x``, ``J_q``, ``J'_q`` of eqs. (23)-(25) for a platform pose and ``beta`` [rad].

    Raises:
        InvalidInputError: bad pose or branch; UnreachableError: a leg cannot reach.
    """
    legs, beta = _legs(params, R, P, beta, branch)
    M, jq, jqp = klein_rows(legs)
    return ScrewJacobians(screws.DELTA @ M.T, np.diag(jq), np.diag(jqp), np.asarray(P, dtype=float))


def leg_screws(params: hp.HexapodParams, R, P, beta: float, branch=hp.DEFAULT_BRANCH) -> np.ndarray:
    """The joint screws of every leg in chain order :data:`CHAIN`, shape (6, 8, 6) (pole O)."""
    legs, _ = _legs(params, R, P, beta, branch)
    return _chain_screws(params, legs)


def _chain_screws(params: hp.HexapodParams, legs: LegBatch) -> np.ndarray:
    u = leg_axes(params)[:, :, 2]
    v = screws.cross(legs.w, u)
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    F = np.zeros((6, 3))
    F[:3] = params.Rf * leg_axes(params)[:3, :, 0]
    S = np.stack([screws.line(u, F), screws.line(u, legs.A), screws.line(u, legs.B), screws.line(v, legs.B),
                  screws.line(u, legs.C), screws.line(v, legs.C), screws.line(legs.w, legs.C),
                  screws.prismatic(legs.w)], axis=1)
    S[3:, 0] = 0.0  # legs 4-6 have no reconfiguration joint
    return S


def twist(params: hp.HexapodParams, R, P, beta: float, qd, branch=hp.DEFAULT_BRANCH,
          point: str = "O") -> np.ndarray:
    """Platform twist ``[w; v]`` [rad/s, m/s] for actuated rates ``qd`` (eq. 22); ``point`` as in
    :meth:`ScrewJacobians.twist_jacobian`."""
    qd = as_vector(qd, 7, "qd")
    return jacobians(params, R, P, beta, branch).twist_jacobian(point) @ qd


def leg_rates(params: hp.HexapodParams, R, P, beta: float, qd, branch=hp.DEFAULT_BRANCH) -> np.ndarray:
    """Every joint rate of every leg, in chain order :data:`CHAIN`, shape (6, 8) [rad/s, m/s].

    The passive rates solve eq. (18)/(19), ``V - beta_dot $r - alpha_dot $1 = [$2..$6 $f] w``,
    a square system thanks to the virtual screw ``$f`` (whose rate comes out 0).

    Raises:
        SingularityError: ``kind="inverse"`` where a leg's passive screws are dependent.
    """
    qd = as_vector(qd, 7, "qd")
    legs, beta = _legs(params, R, P, beta, branch)
    S = _chain_screws(params, legs)
    return _rates(params, legs, beta, S, qd)


def _rates(params, legs: LegBatch, beta: float, S: np.ndarray, qd: np.ndarray) -> np.ndarray:
    M, jq, jqp = klein_rows(legs)
    V = _solve_direct(M, jq * qd[:6] + jqp * np.r_[np.full(3, qd[6]), np.zeros(3)])
    known = np.zeros((6, 8))
    known[:3, 0] = qd[6]
    known[:, 1] = qd[:6]
    rhs = V - np.einsum("lj,ljk->lk", known, S)
    passive = S[:, 2:]  # (6, 6 screws, 6)
    smin = np.linalg.svd(passive, compute_uv=False)[:, -1]
    if smin.min() < 1e-12:
        raise SingularityError("inverse", float(smin.min()), f"leg {int(np.argmin(smin)) + 1}: its passive "
                                                              "joint screws are dependent")
    known[:, 2:] = np.linalg.solve(np.swapaxes(passive, 1, 2), rhs[..., None])[..., 0]
    return known


def complementary_acceleration(params: hp.HexapodParams, R, P, beta: float, qd,
                               branch=hp.DEFAULT_BRANCH) -> np.ndarray:
    """The complementary acceleration ``C = [{L_i; $6_i}]`` of eq. (33), shape (6,) [m/s^2]."""
    qd = as_vector(qd, 7, "qd")
    legs, beta = _legs(params, R, P, beta, branch)
    S = _chain_screws(params, legs)
    L = screws.chain_lie_term(S, _rates(params, legs, beta, S, qd))
    return np.asarray(screws.klein(L, S[:, 6]))


def acceleration(params: hp.HexapodParams, R, P, beta: float, qd, qdd, branch=hp.DEFAULT_BRANCH) -> np.ndarray:
    """Reduced acceleration ``A = [w_dot; a_O - w x v_O]`` of the platform (eqs. 26, 33).

    Args:
        params: The design.
        R: Platform orientation; P: its position [m]; beta: reconfiguration angle [rad].
        qd: Actuated rates ``(alpha_1..alpha_6, beta)`` [rad/s].
        qdd: Actuated accelerations [rad/s^2].
        branch: Working mode (all legs or one per leg).

    Returns:
        ``A`` [rad/s^2, m/s^2]; the acceleration of the platform point at O is ``A[3:] + w x v_O``.
    """
    qdd = as_vector(qdd, 7, "qdd")
    J = jacobians(params, R, P, beta, branch)
    C = complementary_acceleration(params, R, P, beta, qd, branch)
    rhs = J.Jq @ qdd[:6] + J.Jq_prime @ np.r_[np.full(3, qdd[6]), np.zeros(3)] + C
    return _solve_direct(J.JxT_delta, rhs)


# ---------------------------------------------------------------------- helpers
def _legs(params, R, P, beta, branch) -> tuple[LegBatch, float]:
    beta = float(as_vector([beta], 1, "beta")[0])
    R = as_rotation(R)
    P = as_vector(P, 3, "P")
    hx.inverse_kinematics(params, R, P, beta, branch)  # validates, raises UnreachableError with the leg
    signs = np.array([-hp.BRANCHES[b] for b in hx.branch_names(branch)], dtype=float)
    return leg_batch(params, hx.platform_points(params, R, P), beta, signs), beta


def _solve_direct(M: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    s = np.linalg.svd(M, compute_uv=False)
    if s[-1] <= 1e-12 * max(s[0], 1.0):
        raise SingularityError("direct", float(s[-1]), "the rod screws $6_i are linearly dependent (det J_x = 0)")
    return np.linalg.solve(M, rhs)


def _refer(J: np.ndarray, point: str, P: np.ndarray) -> np.ndarray:
    if point == "O":
        return J
    if point == "P":
        return screws.shift(J.T, P).T
    raise InvalidInputError("point", f"use 'O' (the paper's) or 'P', got {point!r}", point)


__all__ = ["CHAIN", "LegBatch", "ScrewJacobians", "acceleration", "complementary_acceleration", "jacobians",
           "klein_rows", "leg_axes", "leg_batch", "leg_rates", "leg_screws", "twist"]
