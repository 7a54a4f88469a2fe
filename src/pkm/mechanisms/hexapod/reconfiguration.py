"""Choosing the reconfiguration angle beta of the hexapod for a pose or along a path (paper sec. 4).

The robot has seven actuators for a six-dimensional task: ``beta`` is free within its limits
(the paper studies ``[-90, 90] deg``) and within the interval where the pose is reachable. The
paper picks, pose by pose, the ``beta`` that maximises ``w_rot`` or ``w_tras`` (eqs. 35-36).
Here:

* :func:`reachable_intervals`: where, within the limits, a pose is reachable, in closed form.
  Legs 4-6 do not depend on ``beta`` (if one misses, every ``beta`` fails). Leg i of 1-3 reaches
  when the distance ``rho`` from ``C_i`` to ``A_i`` within the leg plane lies in
  ``[|LA - s|, LA + s]``, ``s = sqrt(LB^2 - c_u^2)`` (``c_u`` the offset of ``C_i`` from the leg
  plane, which ``beta`` does not change); and ``rho^2 = a - b cos(beta - phi)`` as ``A_i`` turns
  on its circle about ``F_i``, so each bound is an arc of ``beta``.
* :func:`optimal_beta`: ``beta*`` of one pose, by :func:`pkm.core.analysis.redundant_parameter.maximise`
  (a grid start then a trust-region SQP on proxqp QPs) on the reachable interval that holds the
  best grid node.
* :func:`beta_profile`: the whole profile along a path, by
  :func:`pkm.core.analysis.redundant_parameter.optimise_profile`: maximise ``sum_k f_k(beta_k) / s - (mu/2)
  sum_k (beta_{k+1} - beta_k)^2`` with ``|beta_{k+1} - beta_k| <= delta`` and each ``beta_k`` in
  its reachable interval. The *base model* is the robot without reconfiguration: ``beta = 0`` at
  every pose (Fig. 1 of the paper; the gain is ``f(beta_k) / f(0) - 1``).

Both use the closed-form inverse kinematics and the screw Jacobians, vectorised
(:class:`pkm.mechanisms.hexapod.indices.PoseIndex`), not the generic core (the tests check the
two agree). A pose that no ``beta`` within the limits reaches raises
:class:`~pkm.errors.UnreachableError` saying so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pkm.core.analysis import redundant_parameter
from pkm.errors import InvalidInputError, UnreachableError
from pkm.mechanisms import hexapod as hx
from pkm.mechanisms.hexapod import indices as hi
from pkm.mechanisms.hexapod import screws as hs

#: The paper's range of beta (sec. 4) [rad].
LIMITS = (-math.pi / 2, math.pi / 2)
#: Beta intervals are shrunk by this much at a reachability edge, where a leg is singular [rad].
EDGE = 1e-9


@dataclass(frozen=True)
class BetaChoice:
    """``beta*`` of one pose.

    Attributes:
        beta: The maximiser [rad].
        value: The index there.
        index: Its name.
        interval: The reachable interval searched ``(lo, hi)`` [rad].
        intervals: Every reachable interval within the limits [rad].
        optimum: The solver's record (:class:`pkm.core.analysis.redundant_parameter.PointOptimum`).
    """

    beta: float
    value: float
    index: str
    interval: tuple[float, float]
    intervals: tuple[tuple[float, float], ...]
    optimum: redundant_parameter.PointOptimum

    @property
    def beta_deg(self) -> float:
        return math.degrees(self.beta)


@dataclass(frozen=True)
class BetaProfile:
    """A beta profile along a path of poses.

    Attributes:
        beta: The profile [rad], shape (n,).
        value: The index along it.
        index: The index name.
        pointwise: ``beta*`` pose by pose (no rate limit) [rad].
        pointwise_value: The index there.
        start: The pointwise optima clipped to the rate limit [rad] (where the SQP starts).
        base_value: The index of the base model (``beta = 0``), ``nan`` where it cannot reach.
        relative_gain: ``value / base_value - 1`` (``nan`` where the base model cannot reach).
        lower, upper: The reachable interval used at each pose [rad].
        rate_limit: ``delta`` [rad per pose]; smoothness: ``mu`` [1/rad^2].
        result: The solver's record (:class:`pkm.core.analysis.redundant_parameter.ProfileOptimum`): objective,
            iterations, QP statuses, ...
    """

    beta: np.ndarray
    value: np.ndarray
    index: str
    pointwise: np.ndarray
    pointwise_value: np.ndarray
    start: np.ndarray
    base_value: np.ndarray
    relative_gain: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    rate_limit: float
    smoothness: float
    result: redundant_parameter.ProfileOptimum

    def mean_gain(self, start: int = 0) -> float:
        """Mean of ``relative_gain`` over the poses ``k >= start`` the base model reaches."""
        return self.result.mean_gain(start)


def reachable_intervals(params: hx.HexapodParams, R, P, limits=LIMITS) -> tuple[tuple[float, float], ...]:
    """The intervals of ``beta`` within ``limits`` [rad] where the pose is reachable.

    Raises:
        UnreachableError: no ``beta`` in the limits reaches the pose (the leg and its excess [m]
            at the ``beta`` that comes closest).
    """
    return _intervals(hi.PoseIndex(params, [(R, P)]), 0, _limits(limits))


def _limits(limits) -> tuple[float, float]:
    try:
        lo, up = (float(v) for v in limits)
    except (TypeError, ValueError, OverflowError):
        raise InvalidInputError("limits", f"expected (lower, upper) in rad, got {limits!r}", limits) from None
    if not (math.isfinite(lo) and math.isfinite(up) and lo < up):
        raise InvalidInputError("limits", f"need finite lower < upper [rad], got {limits!r}", limits)
    if up - lo > 2.0 * math.pi + 1e-9 or max(abs(lo), abs(up)) > 1e3:
        raise InvalidInputError("limits", f"(lower, upper) = {limits!r} rad spans more than one turn or lies beyond "
                                          "1000 rad; beta is an angle: give at most one turn (2 pi rad)", limits)
    return lo, up


def _intervals(f: hi.PoseIndex, k: int, limits: tuple[float, float],
               where: str = "") -> tuple[tuple[float, float], ...]:
    """The reachable intervals of pose ``k``, exactly (see :func:`reachable_intervals`)."""
    p = f.params
    legs = f.legs(np.array([k]), np.zeros(1))
    if np.any(legs.margin[0, 3:] < 0.0):
        _raise_unreachable(f, k, 0.0, limits, where + "legs 4-6 do not depend on beta; ")
    out = [limits]
    c_loc = np.einsum("lji,lj->li", hs.leg_axes(p)[:3], f.C[k, :3])  # C_1..C_3 in their leg frames
    for c_r, c_y, c_u in c_loc:
        s = p.LB**2 - c_u**2
        if s < 0.0:
            out = []
            break
        r_lo, r_hi = abs(p.LA - math.sqrt(s)), p.LA + math.sqrt(s)
        # rho^2(beta) = a - b cos(beta - phi): distance from C to A in the leg plane, squared
        a = (c_r - p.Rf) ** 2 + c_y**2 + p.Rr**2
        b = 2.0 * p.Rr * math.hypot(c_r - p.Rf, c_y)
        phi = math.atan2(c_y, c_r - p.Rf)
        if b < 1e-15:
            out = out if r_lo**2 <= a <= r_hi**2 else []
            continue
        lo_c, hi_c = (a - r_hi**2) / b, (a - r_lo**2) / b  # lo_c <= cos(beta - phi) <= hi_c
        if lo_c > 1.0 or hi_c < -1.0:
            out = []
            break
        t1, t2 = math.acos(min(hi_c, 1.0)), math.acos(max(lo_c, -1.0))
        arcs = [(phi + t1, phi + t2), (phi - t2, phi - t1)]
        out = _intersect(out, _wrap_arcs(arcs, limits))
    if not out:
        b_grid = np.linspace(*limits, 361)
        worst = f.legs(np.full(b_grid.size, k), b_grid).margin.min(axis=1)
        _raise_unreachable(f, k, float(b_grid[int(np.argmax(worst))]), limits, where)
    return tuple(out)


def _wrap_arcs(arcs, limits) -> list[tuple[float, float]]:
    """The arcs (angles, any turn) that fall within ``limits``, clipped, sorted and merged."""
    lo, up = limits
    pieces = []
    for a, c in arcs:
        n0 = math.floor((lo - c) / (2 * math.pi))
        for n in range(n0, n0 + 2 + int((up - lo) / (2 * math.pi))):
            a_, c_ = max(a + 2 * math.pi * n, lo), min(c + 2 * math.pi * n, up)
            if a_ <= c_:
                pieces.append((a_, c_))
    pieces.sort()
    merged: list[tuple[float, float]] = []
    for a, c in pieces:
        if merged and a <= merged[-1][1] + 1e-12:
            merged[-1] = (merged[-1][0], max(merged[-1][1], c))
        else:
            merged.append((a, c))
    return merged


def _intersect(A, B) -> list[tuple[float, float]]:
    return [(max(a0, b0), min(a1, b1)) for a0, a1 in A for b0, b1 in B if max(a0, b0) <= min(a1, b1)]


def _raise_unreachable(f: hi.PoseIndex, k: int, beta: float, limits, why: str) -> None:
    try:
        hx.inverse_kinematics(f.params, f.R[k], f.P[k], beta, "elbow_out")
    except UnreachableError as exc:
        raise UnreachableError(exc.leg, exc.excess, "m",
                               f"{why}the pose is unreachable for every beta in [{math.degrees(limits[0]):.6g}, "
                               f"{math.degrees(limits[1]):.6g}] deg (closest at beta = {math.degrees(beta):.2f} deg)"
                               ) from None
    raise UnreachableError(0, 0.0, "m", f"{why}legs 1-3 reach this pose only at separate values of beta "
                                        f"within [{math.degrees(limits[0]):.6g}, {math.degrees(limits[1]):.6g}] deg")


def optimal_beta(params: hx.HexapodParams, R, P, index: str = "w_rot", *, branch=hx.DEFAULT_BRANCH,
                 point: str = "O", limits=LIMITS, tol: float = 1e-8) -> BetaChoice:
    """``beta*`` maximising ``index`` at one pose within the limits and the reachable interval.

    Args:
        params: The design.
        R: Platform orientation (rotation matrix; see :func:`pkm.mechanisms.hexapod.as_rotation`).
        P: Platform position [m].
        index: ``"w_rot"`` or ``"w_tras"``.
        branch: Working mode (all legs or one per leg).
        point: Reference point of ``w_tras`` (``"O"``, the paper's, or ``"P"``).
        limits: ``(lower, upper)`` of beta [rad].
        tol: Accuracy on ``beta`` [rad].

    Raises:
        UnreachableError: no beta in the limits reaches the pose.
        InvalidInputError: bad rotation (with its defect), index, point or limits.
    """
    f = hi.PoseIndex(params, [(R, P)], index, branch, point)
    lims = _limits(limits)
    spans = _intervals(f, 0, lims)
    choice, best = _best_interval(f, 0, spans, lims, tol)
    return BetaChoice(float(best.x[0]), float(best.value[0]), index, choice, spans, best)


def _inner(span: tuple[float, float], limits: tuple[float, float]) -> tuple[float, float]:
    """The interval shrunk by :data:`EDGE` at its reachability edges (not at the limits)."""
    a, c = span
    a, c = a + EDGE * (a > limits[0]), c - EDGE * (c < limits[1])
    return a, max(a, c)


def _best_interval(f: hi.PoseIndex, k: int, spans, limits, tol: float):
    """The reachable interval of pose ``k`` holding the largest maximum, and that maximum."""
    best, choice = None, None
    for span in spans:
        lo, up = _inner(span, limits)
        opt = redundant_parameter.maximise(lambda kk, x: f(np.full_like(kk, k), x), [lo], [up], tol=tol)
        if best is None or opt.value[0] > best.value[0]:
            best, choice = opt, span
    return choice, best


def beta_profile(params: hx.HexapodParams, poses, index: str = "w_rot", *, rate_limit: float = math.radians(2.0),
                 smoothness: float = 1.0, branch=hx.DEFAULT_BRANCH, point: str = "O", limits=LIMITS,
                 tol: float = 1e-8) -> BetaProfile:
    """The beta profile along a path of poses (see the module doc).

    At each pose the reachable interval holding that pose's ``beta*`` is used.

    Args:
        params: The design.
        poses: Sequence of ``(R, P)``.
        index: ``"w_rot"`` or ``"w_tras"``.
        rate_limit: ``delta``, the largest change of beta between consecutive poses [rad].
        smoothness: ``mu`` [1/rad^2], weight of the squared changes against the index summed
            over the path and divided by its largest pointwise optimum.
        branch, point, limits, tol: As for :func:`optimal_beta`.

    Raises:
        UnreachableError: a pose is unreachable for every beta in the limits (its index in the message).
        InvalidInputError: bad input, or no profile meets the rate limit within the reachable intervals.
    """
    f = hi.PoseIndex(params, poses, index, branch, point)
    lims = _limits(limits)
    n = len(f)
    chosen = []
    for k in range(n):
        spans = _intervals(f, k, lims, f"pose {k}: ")
        chosen.append(spans[0] if len(spans) == 1 else _best_interval(f, k, spans, lims, tol)[0])
    lower, upper = np.array([_inner(s, lims) for s in chosen]).T
    pw = redundant_parameter.maximise(f, lower, upper, tol=tol)
    res = redundant_parameter.optimise_profile(f, lower, upper, rate_limit=rate_limit, smoothness=smoothness,
                                       baseline=0.0, tol=tol, pointwise=pw)
    return BetaProfile(res.x, res.value, index, pw.x, pw.value, res.start, res.baseline_value, res.relative_gain,
                       lower, upper, float(rate_limit), float(smoothness), res)


__all__ = ["EDGE", "LIMITS", "BetaChoice", "BetaProfile", "beta_profile", "optimal_beta",
           "reachable_intervals"]
