"""Least-squares estimates of the base parameters from measured states and efforts.

``τ = W_β β + ε`` stacked over the samples (:mod:`pkm.core.identification.base`): ordinary least squares, or
Gautier's weighted least squares (each actuator's rows divided by the standard deviation of its own residual from a
first ordinary fit, so that an actuator measured with more noise counts less). The standard deviation of each
estimate is ``s_i = sqrt(s² [(W_βᵀ W_β)⁻¹]_ii)`` with ``s² = |r|² / (rows - n_base)`` on the (weighted) rows, its
relative standard deviation ``100 s_i / |β_i|`` [%], the usual measure of how well a parameter is identified (above
about 10 %: poorly).

**Warnings** (:class:`~pkm.errors.PoorIdentificationWarning`, the same sentences in :attr:`Estimate.warnings`):
fewer than :data:`EQUATIONS_PER_PARAMETER` equations (samples times actuators) per base parameter (the
standard deviations themselves are then poorly known), and every base parameter that is poorly identified: its
relative standard deviation above :data:`POOR_RELATIVE_STD` (its estimate cannot be told from zero) **and** its
uncertainty a share of the efforts above :data:`POOR_EFFORT_SHARE` (``s_i |W_β,i| / |τ|`` on the weighted rows,
:attr:`Estimate.effort_share`: the efforts a change of one standard deviation in it makes, over the efforts). The
second condition is the parameter's own scale, which does not vanish with its value: a parameter zero by symmetry
(a symmetric link's first moment, a drive without friction) is estimated near zero with a deviation that spans a
tiny share of the efforts, so it is *determined* (to be zero), and its relative deviation, always above 100 %,
says nothing; one the motion does not excite, or that is told apart from others only by the noise, spans more.
Remedies: a longer or better-excited run (:func:`pkm.excite`),
a higher filter cutoff (fewer samples decimated away, :func:`pkm.core.identification.measurements.measurements`),
fewer parameters (legs tied: ``tie_legs=True``, ``pkm identify --tie-legs``).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.identification.base import BaseParameters, base_parameters
from pkm.core.identification.regressor import known_efforts, regressor, spring_joints, spring_regressor
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import InvalidInputError, PoorIdentificationWarning, SingularityError
from pkm.validation import as_array

EQUATIONS_PER_PARAMETER = 3  # fewer equations than this per base parameter: a warning
POOR_RELATIVE_STD = 100.0  # [%] a base parameter's relative standard deviation above this: poor, where ...
#: ... its standard deviation's efforts (``s_i |W_β,i|``) also exceed this share of the efforts ``|τ|`` (weighted
#: rows): measured on 900 noisy equations (1 % of each actuator's range) of the Delta, its parameters zero by symmetry
#: span 1e-4 to 1e-3 and those the noise confounds 0.08 to 0.1; on the identification tour's exact table, 3e-6 to 4e-3
POOR_EFFORT_SHARE = 0.01
SHOWN = 6  # a warning's message names this many poorly identified parameters (its ``poor`` attribute holds all)


@dataclass(frozen=True)
class Estimate:
    """Estimated base parameters.

    Attributes:
        base: The base parameters estimated (their names, their map from the standard ones).
        values: ``β̂`` (n_base,).
        std: Their standard deviations (n_base,).
        relative_std: ``100 std / |values|`` [%] (inf where a value is zero).
        effort_share: ``std |W_β,i| / |τ|`` on the weighted rows: the share of the efforts one standard deviation
            of each parameter makes (module doc).
        poor: (property) Which are poorly identified (module doc: ``relative_std`` above
            :data:`POOR_RELATIVE_STD` and ``effort_share`` above :data:`POOR_EFFORT_SHARE`).
        residual_rms: Each actuator's residual RMS [N m, N] (unweighted).
        weights: Each actuator's weight (1 for ordinary least squares).
        method: ``"ols"`` or ``"wls"``.
        rows: The number of equations.
        warnings: What the data cannot carry (module doc), one sentence each; empty when nothing.
        springs: The springs identified with them (``estimate(..., springs=[joint, ...])``), one each.
    """

    base: BaseParameters
    values: np.ndarray
    std: np.ndarray
    relative_std: np.ndarray
    effort_share: np.ndarray
    residual_rms: np.ndarray
    weights: np.ndarray
    method: str
    rows: int
    warnings: tuple[str, ...] = ()
    springs: tuple[SpringEstimate, ...] = ()

    @property
    def poor(self) -> np.ndarray:
        """Which base parameters are poorly identified (module doc), a boolean per parameter."""
        return _poor(self.relative_std, self.effort_share)

    def predict(self, Y: ArrayLike) -> np.ndarray:
        """The efforts ``Y_β β̂`` of a standard regressor ``Y`` (rows as stacked by :func:`regressor`)."""
        return self.base.regressor(Y) @ self.values


@dataclass(frozen=True)
class SpringEstimate:
    """A joint spring identified with the base parameters (:func:`estimate`'s ``springs``): the actuators' efforts are
    linear in ``k`` and ``k rest`` (:func:`~pkm.core.identification.regressor.spring_regressor`).

    Attributes:
        joint: The sprung joint.
        stiffness: ``k`` [N m/rad, N/m].
        rest: Its rest position ``(k rest) / k`` [rad, m].
        stiffness_std: The standard deviation of ``k``.
        rest_std: That of ``rest`` (first order in the two estimates' covariance).
    """

    joint: str
    stiffness: float
    rest: float
    stiffness_std: float
    rest_std: float


def _solve(W: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(x, diag, Rinv)``: the least-squares solution, the diagonal of ``(WᵀW)⁻¹`` and ``R⁻¹`` (``(WᵀW)⁻¹ = R⁻¹
    R⁻ᵀ``: the covariances)."""
    Q, R = np.linalg.qr(W)
    d = np.abs(np.diag(R))
    if d.min() <= 1e-12 * d.max():
        raise SingularityError("regressor", float(d.min() / d.max()), "the samples do not excite every base parameter: "
                                                                      "give more, or more varied, motion")
    beta = np.linalg.solve(R, Q.T @ y)
    Rinv = np.linalg.inv(R)
    return beta, np.einsum("ij,ij->i", Rinv, Rinv), Rinv  # (diag of (W^T W)^-1)


def estimate(mech: Mechanism, Q: ArrayLike, QD: ArrayLike, QDD: ArrayLike, TAU: ArrayLike, *,
             base: BaseParameters | None = None, weighted: bool = True, springs: tuple[str, ...] | list[str] = ()) \
        -> Estimate:
    """Estimate the base parameters from N samples: closed configurations ``Q`` (N, nq), actuated rates and
    accelerations ``QD``, ``QDD`` (N, na) and the measured efforts ``TAU`` (N, na) [N m, N] (module doc).

    ``springs``: joints whose spring's stiffness and rest position are estimated too (:attr:`Estimate.springs`), as
    two more columns each, ``k`` and ``k rest`` (:func:`~pkm.core.identification.regressor.spring_regressor`): a
    spring the model lacks, or one whose ``[springs]`` values are to be checked (their share is then not subtracted
    as known). They must be excited apart from the base parameters: the rest of a spring on an actuated joint is
    its drive's offset (a :class:`~pkm.errors.SingularityError`).

    Raises:
        InvalidInputError: arrays of the wrong shape, non-finite values (the row named), fewer rows than parameters;
            a spring's joint of more than one coordinate.
        SingularityError: the motion does not excite every base parameter (and spring).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> rng = np.random.default_rng(0)
        >>> Q = np.array([pkm.solve_ik(delta, [x, y, -0.36]).q for x, y in 0.05 * rng.standard_normal((50, 2))])
        >>> QD, QDD = rng.standard_normal((50, 3)), 10 * rng.standard_normal((50, 3))
        >>> TAU = np.array([pkm.actuator_model(delta, q, qd).efforts(qdd)
        ...                 for q, qd, qdd in zip(Q, QD, QDD)])
        >>> base = pkm.base_parameters(delta, 50, precise=False)
        >>> est = pkm.estimate(delta, Q, QD, QDD, TAU, base=base)
        >>> len(est.values), bool(est.residual_rms.max() < 1e-9)
        (48, True)
        >>> np.allclose(est.predict(pkm.regressor(delta, Q[0], QD[0], QDD[0])), TAU[0])
        True
    """
    mech = check_mechanism(mech)
    sprung = spring_joints(mech, list(springs) if isinstance(springs, tuple) else springs)
    base = base if base is not None else base_parameters(mech)
    nb, ns = len(base), 2 * len(sprung)
    arrays = []
    for name, x, cols in (("Q", Q, mech.nq), ("QD", QD, mech.na), ("QDD", QDD, mech.na), ("TAU", TAU, mech.na)):
        arr = as_array(x, name, f"N x {cols}")
        if arr.ndim != 2 or arr.shape[1] != cols:
            raise InvalidInputError(name, f"expected N x {cols}, got shape {arr.shape}", arr.shape)
        bad = np.flatnonzero(~np.all(np.isfinite(arr), axis=1))
        if bad.size:
            raise InvalidInputError(name, f"row {int(bad[0])} is not finite", arr[bad[0]])
        arrays.append(arr)
    Q_, QD_, QDD_, TAU_ = arrays
    n = len(Q_)
    if not all(len(a) == n for a in arrays):
        raise InvalidInputError("TAU", f"expected as many samples of each: {[len(a) for a in arrays]}", n)
    if n * mech.na < nb + ns:
        raise InvalidInputError("Q", f"{n * mech.na} equations for {nb + ns} parameters: give more samples", n)
    W = base.regressor(np.vstack([regressor(mech, q, qd, qdd) for q, qd, qdd in zip(Q_, QD_, QDD_)]))
    if sprung:
        W = np.hstack([W, spring_regressor(mech, Q_, QD_, sprung)])
    TAU_ = TAU_ - known_efforts(mech, Q_, QD_, sprung)  # (the known springs' and the passive joints' friction)
    peak = float(np.abs(TAU_).max())
    s = _scale(peak)  # (the efforts' sums of squares overflow beyond 1e154: the fit runs on TAU / s, exactly)
    y = TAU_.reshape(-1) / s
    try:
        beta, diag, Rinv = _solve(W, y)  # (a regressor that the samples do not excite: SingularityError)
    except SingularityError as exc:
        if sprung:  # (the base alone excited: the springs are not told apart from it)
            try:
                _solve(W[:, :nb], y)
            except SingularityError:
                raise exc from None
            driven = [j for j in sprung if j in mech.actuated_names]
            raise SingularityError("regressor", exc.sigma_min, f"the samples do not excite the springs of {list(sprung)} "
                                                           "apart from the base parameters"
                                   + (f" (the rest of a spring on an actuated joint, {driven}, is its drive's "
                                      "offset: the two cannot be told apart)" if driven else "")) from None
        raise
    if peak == 0.0:
        raise InvalidInputError("TAU", "every effort is zero: the data carry no parameter (each relative deviation "
                                       "would be 0/0)", peak)
    weights = np.ones(mech.na)
    if weighted:
        r = (y - W @ beta).reshape(n, mech.na)
        sd = np.sqrt(np.sum(r * r, axis=0) / max(n - (nb + ns) / mech.na, 1.0))
        weights = 1.0 / np.maximum(sd, 1e-300)
        w = np.tile(weights, n)
        beta, diag, Rinv = _solve(W * w[:, None], y * w)
    w = np.tile(weights, n)
    r = (y - W @ beta) * w
    sigma2 = float(r @ r) / max(len(y) - (nb + ns), 1)
    std = np.sqrt(sigma2 * diag)
    cov = sigma2 * Rinv[nb:] @ Rinv[nb:].T  # (the springs' columns' covariances)
    with np.errstate(divide="ignore"):
        rel = np.where(beta != 0.0, 100.0 * std / np.abs(beta), np.inf)
    share = std * np.linalg.norm(W * w[:, None], axis=0) / np.linalg.norm(y * w)
    rms = np.sqrt(np.mean(((y - W @ beta).reshape(n, mech.na)) ** 2, axis=0))
    with np.errstate(over="ignore"):
        beta, std, rms, weights = beta * s, std * s, rms * s, weights / s if weighted else weights
        cov = cov * s * s
    if not all(np.all(np.isfinite(a)) for a in (beta, std, rms, weights)):
        raise InvalidInputError("TAU", f"efforts up to {peak:.3g} [N m, N] overflow the estimate (its values, "
                                       "standard deviations or residuals beyond 1.8e308)", peak)
    found = _warnings(base, n, len(y), rel[:nb], share[:nb])
    for warning in found:
        warnings.warn(warning, stacklevel=2)
    return Estimate(base, beta[:nb], std[:nb], rel[:nb], share[:nb], rms, weights, "wls" if weighted else "ols",
                    len(y), tuple(str(w) for w in found), _springs(sprung, beta[nb:], cov))


def _springs(joints: tuple[str, ...], x: np.ndarray, cov: np.ndarray) -> tuple[SpringEstimate, ...]:
    """The springs' estimates from ``x = (k_1, (k rest)_1, ...)`` and its covariance: ``rest = (k rest) / k``, its
    deviation to first order (``d rest = (d(k rest) - rest dk) / k``)."""
    out = []
    for i, joint in enumerate(joints):
        k, kr = float(x[2 * i]), float(x[2 * i + 1])
        rest = kr / k if k != 0.0 else math.nan
        g = np.array([-rest, 1.0]) / k if k != 0.0 else np.full(2, math.nan)
        C = cov[2 * i:2 * i + 2, 2 * i:2 * i + 2]
        out.append(SpringEstimate(joint, k, rest, math.sqrt(max(float(C[0, 0]), 0.0)),
                                  math.sqrt(max(float(g @ C @ g), 0.0)) if k != 0.0 else math.nan))
    return tuple(out)


def _scale(peak: float) -> float:
    """1, or for efforts whose squares overflow or underflow (``peak`` beyond ``2^±500``) the power of two
    at or below ``peak``, by which the fit divides them: exact, and every result is scaled back (the
    standard deviations and residuals with the values, a weighted fit's weights inversely)."""
    return 1.0 if 2.0**-500 <= peak <= 2.0**500 or peak == 0.0 else math.ldexp(1.0, math.frexp(peak)[1] - 1)


def _poor(relative_std: np.ndarray, effort_share: np.ndarray) -> np.ndarray:
    """The poorly identified parameters (module doc)."""
    return ~(relative_std <= POOR_RELATIVE_STD) & ~(effort_share <= POOR_EFFORT_SHARE)


def _warnings(base: BaseParameters, samples: int, equations: int, relative_std: np.ndarray,
              effort_share: np.ndarray) -> list[PoorIdentificationWarning]:
    """The module doc's warnings of an estimate from ``samples`` samples (``equations`` rows)."""
    nb = len(base)
    poor = [(name, float(r)) for name, r, bad in zip(base.names, relative_std, _poor(relative_std, effort_share))
            if bad]
    remedy = "a longer or better-excited run (pkm excite), a higher filter cutoff, or legs tied (--tie-legs)"
    out = []
    if equations < EQUATIONS_PER_PARAMETER * nb:
        out.append(PoorIdentificationWarning(
            f"{samples} samples ({equations} equations) for {nb} base parameters: fewer than "
            f"{EQUATIONS_PER_PARAMETER} equations per parameter, the estimate and its deviations are poorly "
            f"determined; give more samples: {remedy}", equations, nb, poor))
    if poor:
        shown = "; ".join(f"{name} ({r:.3g} %)" for name, r in poor[:SHOWN])
        more = f"; and {len(poor) - SHOWN} more" if len(poor) > SHOWN else ""
        out.append(PoorIdentificationWarning(
            f"{len(poor)} of {nb} base parameters are poorly identified: a relative standard deviation above "
            f"{POOR_RELATIVE_STD:g} % (cannot be told from zero) and one standard deviation worth more than "
            f"{100 * POOR_EFFORT_SHARE:g} % of the efforts (not excited, or confounded by the noise): {shown}{more}; "
            f"for a better estimate: {remedy}", equations, nb, poor))
    return out


__all__ = ["EQUATIONS_PER_PARAMETER", "POOR_EFFORT_SHARE", "POOR_RELATIVE_STD", "Estimate", "SpringEstimate", "estimate"]
