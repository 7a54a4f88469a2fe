"""Singularities of the reconfigurable hexapod (paper sec. 3.3): classification and distance measures.

From the velocity equation ``J_x^T DELTA V = J'_q qd_beta + J_q qd_alpha`` (eq. 22,
:mod:`pkm.mechanisms.hexapod.screws`):

* type 1 (inverse kinematics): ``det J_q = 0``: in some leg the arm ``LA`` and the rod ``LB``
  are fully extended or folded, ``{$1_i; $6_i} = 0``; or ``det J'_q = 0``: in some leg of M1 the
  reconfiguration link ``Rr`` and the rod are collinear, ``{$r_i; $6_i} = 0`` (the paper shows
  this implies ``det J_q = 0``);
* type 2 (direct kinematics): ``det J_x = 0``: the rod lines ``$6_i`` are linearly dependent, e.g.
  the three rods of a sub-manipulator coplanar and concurrent (or parallel), or all the triangles
  ``F``, ``A_4A_5A_6``, ``C_1C_2C_3``, ``C_4C_5C_6`` concentric with the same orientation (every
  ``$6_i`` then has a zero second dual component: the platform can spin about Y);
* type 3 (combined): both.

Distance measures (dimensionless, 0 at the singularity):

* ``transmission[i] = |{$1_i; $6_i}| / LA = |u_i . (a_i x w_i)|``: the sine of the angle between
  the arm and the rod seen along the actuated axis (1 when perpendicular);
* ``transmission_r[i] = |{$r_i; $6_i}| / (Rr + LA)`` for legs 1-3;
* ``sigma_direct``: smallest singular value of ``J_x`` with the pole at ``P`` and the dual parts
  divided by a characteristic length (default the platform circumradius ``r``), so that it does
  not depend on where the platform is nor on the unit of length; ``sigma_m1``, ``sigma_m2`` the
  same for the 6x3 blocks of each sub-manipulator (one of them loses rank in the paper's
  examples).

The determinants are reported too (``det J_q`` [m^6], ``det J'_q`` [m^3], ``det J_x`` [m^3],
pole-independent).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pkm.core.differential import screws
from pkm.core.differential.indices import singularity_class
from pkm.mechanisms import hexapod as hx
from pkm.mechanisms._common import check_params
from pkm.mechanisms.hexapod import screws as hs
from pkm.validation import as_scalar, finite_result

KINDS = {t: singularity_class(bool(t & 1), bool(t & 2)) for t in range(4)}  # the paper's types 0-3


@dataclass(frozen=True)
class SingularityReport:
    """Singularity class and distances of one configuration (see the module doc).

    Attributes:
        type: 0 (regular), 1 (inverse), 2 (direct) or 3 (combined), the paper's numbering.
        kind: ``KINDS[type]``.
        inverse_legs: Legs (1-based) with ``transmission <= tol`` (``J_q`` singular there).
        reconfiguration_legs: Legs of M1 with ``transmission_r <= tol`` (``J'_q`` singular there).
        transmission: Per leg, shape (6,).
        transmission_r: Legs 1-3, shape (3,).
        sigma_direct: Smallest singular value of the homogenised ``J_x``.
        sigma_m1, sigma_m2: The same for the screws of legs 1-3 and of legs 4-6 (6x3 blocks).
        det_Jq, det_Jq_prime, det_Jx: The determinants [m^6, m^3, m^3].
        tol: The threshold used on the distances.
    """

    type: int
    kind: str
    inverse_legs: tuple[int, ...]
    reconfiguration_legs: tuple[int, ...]
    transmission: np.ndarray
    transmission_r: np.ndarray
    sigma_direct: float
    sigma_m1: float
    sigma_m2: float
    det_Jq: float
    det_Jq_prime: float
    det_Jx: float
    tol: float


def classify(params: hx.HexapodParams, R, P, beta: float, branch=hx.DEFAULT_BRANCH, *, tol: float = 1e-6,
             length: float | None = None) -> SingularityReport:
    """Classify a configuration (platform pose, ``beta`` [rad], working mode) as the paper does.

    Args:
        params: The design.
        R: Platform orientation; P: its position [m]; beta: reconfiguration angle [rad].
        branch: Working mode, for all legs or one per leg.
        tol: A distance at or below ``tol`` counts as singular.
        length: Characteristic length of ``sigma_direct`` [m] (default ``params.r``).

    Raises:
        UnreachableError: a leg cannot reach the pose; InvalidInputError: bad input.
    """
    check_params(params, hx.HexapodParams)
    tol = as_scalar(tol, "tol", low=0.0, strict_low=True)
    L = params.r if length is None else as_scalar(length, "length", low=0.0, strict_low=True, unit="m")
    J = hs.jacobians(params, R, P, beta, branch)
    jq, jqp = np.diag(J.Jq), np.diag(J.Jq_prime)
    trans = np.abs(jq) / params.LA
    trans_r = np.abs(jqp[:3]) / (params.Rr + params.LA)
    S = screws.shift(J.Jx.T, np.asarray(P, dtype=float))  # rows: $6_i with the pole at P
    with np.errstate(over="ignore"):  # a tiny L overflows: reported by smin below
        S[:, 3:] /= L

    def smin(A: np.ndarray) -> float:
        finite_result(A, "screw matrix", f"length = {L!r} m is too small to scale the moments (overflow)")
        return float(np.linalg.svd(A, compute_uv=False)[-1])

    sd, s1, s2 = smin(S), smin(S[:3].T), smin(S[3:].T)
    inverse_legs = tuple(int(i) + 1 for i in np.flatnonzero(trans <= tol))
    recon_legs = tuple(int(i) + 1 for i in np.flatnonzero(trans_r <= tol))
    t = (1 if inverse_legs or recon_legs else 0) + (2 if sd <= tol else 0)
    return SingularityReport(t, KINDS[t], inverse_legs, recon_legs, trans, trans_r, sd, s1, s2,
                             float(np.prod(jq)), float(np.prod(jqp)), float(np.linalg.det(J.Jx)), tol)


__all__ = ["KINDS", "SingularityReport", "classify"]
