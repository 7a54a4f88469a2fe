"""The estimate: the base calibration parameters by weighted nonlinear least squares, their standard deviations,
and the accuracy before and after on held-out poses.

:func:`calibrate` frees the independent parameters of the base geometry (:func:`~pkm.core.calibration.identifiable.
base_geometry`), holds the others at their nominal values (a dependent parameter's error is absorbed by those it
combines with: :attr:`~pkm.core.calibration.identifiable.BaseGeometry.absorbed`), and minimises the residuals
divided by the instrument's standard deviations (``sigma``: position [m], angle [rad], passive reading [rad or m])
with ``scipy.optimize.least_squares``: Levenberg-Marquardt (``method="lm"``) without bounds and with the plain
loss, else the trust-region reflective method (``"trf"``) with the bounds and a robust ``loss`` (``"soft_l1"``,
``"huber"``, ``"cauchy"``; ``f_scale`` one standard deviation). The residual's Jacobian is the model's exact one
(:mod:`~pkm.core.calibration.measurement`), the loops closed anew at every iterate from the last closed poses.

**Standard deviations**: ``sqrt(diag(s^2 (J^T J)^{-1}))`` of the weighted Jacobian at the solution, ``s^2`` the
reduced chi-square (the sum of squared weighted residuals over rows minus free parameters: 1 when ``sigma`` is the
noise); :attr:`Calibration.std` per free parameter. With a robust loss, the residuals and the Jacobian's rows are
weighted again by the loss's weights at the solution (``sqrt(rho'(r²))``, :func:`robust_weights`: the fit's own
iteratively reweighted view), so that the chi-square and the deviations are those of the rows the fit kept, not
inflated by the outliers it set aside (the 3-PRS with one pose 100 sigma off, Cauchy's loss: 0.41, where the
unweighted residuals gave 490 and the deviations 22 times the clean fit's; they are now 0.78 of them). The loss
weighs rows within the noise below 1 too (Cauchy's: 1/2 at one sigma), so that a robust chi-square sits under 1
where the plain one would be 1.

**Accuracy** (:func:`accuracy`): per pose, the position error ``|p - p_m|`` [m] and the orientation error (the
angle of ``R_m^T R`` [rad]; the planar yaw's difference), their mean, RMS and maximum.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.calibration.identifiable import BaseGeometry, base_geometry
from pkm.core.calibration.measurement import CalibrationModel, check_model
from pkm.errors import ConvergenceError, InvalidInputError, PkmWarning, SingularityError, UnknownNameError
from pkm.validation import as_count, wrap_angle

#: The least squares stop when the cost or the step changes by less than this, relative.
TOL = 1e-10
#: The same for the trust-region method (bounds, robust losses), whose last steps are slower.
TRF_TOL = 1e-8
#: the relative smallest singular value of the Jacobian (unit columns) at the solution under which the estimated
#: parameters' standard deviations are refused (SingularityError) rather than taken from a pseudo-inverse
STD_RTOL = 1e-10
LOSSES = ("linear", "soft_l1", "huber", "cauchy", "arctan")
#: The least squares' default budget of residual evaluations, per estimated parameter (MINPACK's own ``100 n``):
#: 40 poses of the shipped Delta (33 base parameters) need 12 at the default spread, 589 at 0.1 rad; 12 poses
#: (the fewest), 132 and 1394.
NFEV_PER_PARAMETER = 100
#: Default instrument standard deviations: a laser tracker's 10 µm and 20 µrad, an encoder's 20 µrad.
SIGMA = {"m": 10e-6, "rad": 20e-6}


@dataclass(frozen=True)
class Accuracy:
    """Pose errors over a set of poses (module doc): ``position`` and ``orientation`` each ``(mean, rms, max)``
    [m] and [rad] (None where the model does not measure it); ``n`` poses."""

    position: tuple[float, float, float] | None
    orientation: tuple[float, float, float] | None
    n: int

    def as_dict(self) -> dict[str, float]:
        """Flat ``{"position_rms": ..., ...}`` (SI)."""
        out: dict[str, float] = {}
        for what, stats in (("position", self.position), ("orientation", self.orientation)):
            for label, v in zip(("mean", "rms", "max"), stats or ()):
                out[f"{what}_{label}"] = v
        return out


@dataclass(frozen=True)
class Calibration:
    """A calibration's result (module doc).

    Attributes:
        model: The calibration model.
        x: Every parameter's value (the dependent ones at their nominal values).
        free: The indices of the estimated parameters (the base geometry's independent ones).
        std: Their standard deviations (SI).
        base: The base geometry at the nominal parameters.
        chi2: The reduced chi-square (module doc): on the robust loss's weights where there is one, the outliers
            weighing what the loss gives them.
        before: The accuracy of the starting parameters (``x0``, nominal by default) at the calibration poses.
        after: The residual accuracy of the calibrated model there.
        nfev: Residual evaluations.
        method: ``"lm"`` or ``"trf"``; ``loss`` the loss.
        loss: See ``method``.
        sigma: The standard deviations the residuals were divided by (per unit).
    """

    model: CalibrationModel
    x: np.ndarray
    free: tuple[int, ...]
    std: np.ndarray
    base: BaseGeometry
    chi2: float
    before: Accuracy
    after: Accuracy
    nfev: int
    method: str
    loss: str
    sigma: Mapping[str, float] = field(default_factory=dict)

    def values(self) -> dict[str, float]:
        """Every parameter by name (SI)."""
        return dict(zip(self.model.names, map(float, self.x)))

    def changes(self) -> dict[str, tuple[float, float]]:
        """The estimated parameters: name -> (value - nominal, standard deviation) (SI)."""
        nominal = self.model.parameters.nominal
        return {self.model.names[k]: (float(self.x[k] - nominal[k]), float(s)) for k, s in zip(self.free, self.std)}


def _angle_errors(R: np.ndarray, Rm: np.ndarray) -> np.ndarray:
    return np.array([np.linalg.norm(pin.log3(a.T @ b)) for a, b in zip(Rm, R)])


def _stats(e: np.ndarray) -> tuple[float, float, float]:
    return float(np.mean(e)), float(np.sqrt(np.mean(e * e))), float(np.max(e))


def pose_errors(model: CalibrationModel, y: np.ndarray, measured: ArrayLike) -> Accuracy:
    """The :class:`Accuracy` of predictions ``y`` against ``measured`` (:meth:`CalibrationModel.evaluate`'s
    layout); for ``passive``, ``position`` holds the readings' errors (in their joints' units)."""
    Ym = np.asarray(measured, dtype=float)
    if model.kind == "pose":
        R, Rm = (a[:, 3:].reshape(-1, 3, 3).transpose(0, 2, 1) for a in (y, Ym))
        return Accuracy(_stats(np.linalg.norm(y[:, :3] - Ym[:, :3], axis=1)), _stats(_angle_errors(R, Rm)), len(y))
    if model.kind == "position":
        return Accuracy(_stats(np.linalg.norm(y - Ym, axis=1)), None, len(y))
    if model.kind == "planar":
        yaw = np.abs(wrap_angle(y[:, 2] - Ym[:, 2]))
        return Accuracy(_stats(np.linalg.norm(y[:, :2] - Ym[:, :2], axis=1)), _stats(yaw), len(y))
    return Accuracy(_stats(np.abs(y - Ym).ravel()), None, len(y))


def accuracy(model: CalibrationModel, x: ArrayLike | None, readings: ArrayLike, measured: ArrayLike) -> Accuracy:
    """The pose errors of the model with parameters ``x`` (None: nominal) at ``readings`` against ``measured``."""
    return pose_errors(model, model.measure(x, readings), measured)


def _weights(model: CalibrationModel, sigma: Mapping[str, float]) -> np.ndarray:
    out = []
    for u in model.rows.units:
        s = sigma.get(u, SIGMA.get(u))
        if s is None or not s > 0.0:
            raise InvalidInputError("sigma", f"expected a positive standard deviation for the {u} rows", sigma)
        out.append(1.0 / s)
    return np.array(out)


def robust_weights(loss: str, z: np.ndarray) -> np.ndarray:
    """``rho'(z)`` of a least-squares ``loss`` (scipy's, ``f_scale`` 1) at ``z = r²`` (the squared weighted residuals):
    each row's weight at the solution of the robust fit (iteratively reweighted least squares: the robust normal
    equations are ``Jᵀ diag(rho') r = 0``); 1 for ``"linear"``."""
    if loss == "soft_l1":
        return 1.0 / np.sqrt(1.0 + z)
    if loss == "huber":
        return np.where(z <= 1.0, 1.0, 1.0 / np.sqrt(np.maximum(z, 1.0)))
    if loss == "cauchy":
        return 1.0 / (1.0 + z)
    if loss == "arctan":
        return 1.0 / (1.0 + z * z)
    return np.ones_like(z)


def calibrate(model: CalibrationModel, readings: ArrayLike, measured: ArrayLike, *,
              sigma: Mapping[str, float] | None = None, loss: str = "linear",
              bounds: Mapping[str, tuple[float, float]] | None = None, base: BaseGeometry | None = None,
              x0: ArrayLike | None = None, max_nfev: int | None = None) -> Calibration:
    """Estimate ``model``'s base parameters from the measurements ``measured`` (n x ny, :meth:`CalibrationModel.
    evaluate`'s layout) at the actuators' ``readings`` (n x na) (module doc).

    Args:
        model: The calibration model.
        readings: The actuators' readings [rad or m].
        measured: What the instrument measured at each pose.
        sigma: The instrument's standard deviations by unit (``{"m": 1e-5, "rad": 2e-5}``: :data:`SIGMA`).
        loss: ``"linear"`` (least squares) or a robust loss (:data:`LOSSES`).
        bounds: ``{name: (low, high)}`` on estimated parameters (SI; then ``trf``).
        base: The base geometry (default: computed at the nominal parameters and these poses, double precision).
        x0: The starting parameters (default nominal).
        max_nfev: Residual evaluations at most (default :data:`NFEV_PER_PARAMETER` per estimated parameter;
            ``pkm calibrate --max-evaluations``).

    Raises:
        InvalidInputError: fewer residual rows than free parameters, shapes that do not match, an unknown loss;
            ``model`` no :class:`CalibrationModel`.
        UnknownNameError: a bound on a parameter that is not estimated.
        ConvergenceError: the least squares ran out of evaluations (``max_nfev``) before they converged: its
            ``residual`` the reduced chi-square reached, its ``iterations`` the evaluations.

    Examples:
        A simulated calibration: a perturbed 3-PRS measured with a laser tracker's noise.

        >>> import pkm
        >>> from pkm.core.calibration.estimate import perturbed, simulate
        >>> model = pkm.CalibrationModel(pkm.load("prs3"), "pose")
        >>> poses = pkm.calibration_poses(model, 12, spread=0.2, pool=14).readings
        >>> measured = simulate(model, perturbed(model, seed=1), poses, seed=2)
        >>> cal = pkm.calibrate(model, poses, measured)
        >>> len(cal.free), cal.before.position[1] > 1e-3, cal.after.position[1] < 2e-5
        (34, True, True)
    """
    import scipy.optimize

    model = check_model(model)
    M = model._readings(readings)
    Ym = np.asarray(measured, dtype=float)
    ny = model.measure(None, M[:1]).shape[1]
    if Ym.shape != (len(M), ny):
        raise InvalidInputError("measured", f"expected {len(M)} x {ny} measurements ({model.kind})", Ym.shape)
    if not isinstance(loss, str) or loss not in LOSSES:
        raise UnknownNameError("loss", loss, LOSSES)
    sig = dict(SIGMA, **(sigma or {}))
    w = _weights(model, sig)
    if base is None:
        base = base_geometry(model, M, precise=False)
    free = list(base.independent)
    rows = len(M) * len(w)
    if rows <= len(free):
        raise InvalidInputError("readings", f"{len(M)} poses give {rows} residuals for {len(free)} base parameters: "
                                            f"give more poses", len(M))
    x = model.vector(x0).copy()
    seeds = model.seeds(M)
    state: dict[str, np.ndarray] = {"Q": seeds}

    start = x[free].copy()

    def parts(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        xx = x.copy()
        xx[free] = start + z  # (the deviation from the start: MINPACK's first step is then bounded in J's scale)
        try:
            try:
                Q = model.close(xx, M, state["Q"])
            except ConvergenceError:
                Q = model.close(xx, M, seeds)
        except ConvergenceError:  # (a step too long for the loops to close: a large residual makes it shorter)
            return np.full(rows, 1e6), np.zeros((rows, len(free)))
        state["Q"] = Q
        y, J, _ = model.evaluate(xx, M, Q)
        r, Jr = model.residual(y, Ym, J)
        assert Jr is not None
        return (r * w).ravel(), (Jr[:, :, free] * w[None, :, None]).reshape(rows, len(free))

    cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    def cached(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        key = z.tobytes()
        if key not in cache:
            cache.clear()
            cache[key] = parts(z)
        return cache[key]

    lo, hi = np.full(len(free), -np.inf), np.full(len(free), np.inf)
    for name, (a, b) in (bounds or {}).items():
        k = model.parameters.index(name)
        if k not in free:
            raise UnknownNameError("estimated parameter", name, [model.names[i] for i in free])
        lo[free.index(k)], hi[free.index(k)] = a, b
    method = "lm" if loss == "linear" and not bounds else "trf"
    budget = NFEV_PER_PARAMETER * len(free) if max_nfev is None else as_count(max_nfev, "max_nfev")
    tol = TOL if method == "lm" else TRF_TOL
    lo, hi = lo - start, hi - start
    z0 = np.clip(np.zeros(len(free)), lo, hi)
    r0 = cached(z0)[0]
    before = accuracy(model, x, M, Ym)
    sol = scipy.optimize.least_squares(lambda z: cached(z)[0], z0, jac=lambda z: cached(z)[1], method=method,
                                       loss=loss, f_scale=1.0, bounds=(lo, hi) if method == "trf" else (-np.inf, np.inf),
                                       x_scale="jac", max_nfev=budget, **dict.fromkeys(("xtol", "ftol", "gtol"), tol))
    dof = rows - len(free)
    if sol.status < 0:  # (scipy's "improper input")
        raise ConvergenceError(f"calibration least squares ({sol.message})", float(sol.fun @ sol.fun / dof),
                               int(sol.nfev), tol, sol)
    if sol.status == 0:  # (the fit is judged by its chi-square in units of the noise, the steps by tol: both said)
        chi2 = float(sol.fun @ sol.fun / dof)
        raise ConvergenceError("calibration least squares", chi2, int(sol.nfev), tol, sol, message=(
            f"calibration least squares ran out of evaluations ({sol.nfev}) before converging: reduced chi-square "
            f"{chi2:.4g} (from {float(r0 @ r0) / dof:.4g}; 1 when the fit leaves the stated noise), the last step "
            f"still above the relative tolerance {tol:.0e}; give more: max_nfev (pkm calibrate "
            f"--max-evaluations), or poses that see the parameters better (a larger spread, more poses)"))
    x[free] = start + sol.x
    r, J = cached(sol.x)
    w_robust = np.sqrt(robust_weights(loss, r * r))  # (1 for the plain loss; an outlier's row weighs less)
    r, J = r * w_robust, J * w_robust[:, None]
    chi2 = float(r @ r / dof)
    scale = np.linalg.norm(J, axis=0)  # (unit columns: the conditioning of the parameters, not of their units)
    _, sv, Vt = np.linalg.svd(J / np.where(scale > 0.0, scale, 1.0), full_matrices=False)
    if not sv[-1] > STD_RTOL * sv[0]:  # (a pseudo-inverse would give finite, meaningless deviations: refused)
        worst = free[int(np.argmax(np.abs(Vt[-1])))]
        raise SingularityError("calibration", float(sv[-1]), f"the estimated parameters are not all determined by "
                               f"these poses at the solution (most in the undetermined direction: "
                               f"{model.names[worst]!r}): their deviations do not exist; give more or other poses",
                               distance=float(sv[-1] / sv[0]))
    cov = (Vt.T / sv**2) @ Vt / np.outer(scale, scale) * chi2
    std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    if loss == "linear" and chi2 > 9.0 and float(r0 @ r0) > 0.0:  # (a robust loss expects its outliers)
        warnings.warn(f"the calibrated model leaves residuals {np.sqrt(chi2):.3g} times the stated sigma (reduced "
                      f"chi-square {chi2:.3g}): a sigma too small, a wrong measurement model or outliers (loss)",
                      PkmWarning, stacklevel=2)
    return Calibration(model, x, tuple(free), std, base, chi2, before, accuracy(model, x, M, Ym), int(sol.nfev),
                       method, loss, sig)


def perturbed(model: CalibrationModel, seed: int = 0, *, length: float = 2e-3, angle: float = np.deg2rad(0.5),
              gain: float = 1e-3) -> np.ndarray:
    """A random "true" parameter vector: every length within ``length`` [m] and every angle within ``angle`` [rad]
    of its nominal value (uniform), gains within ``gain`` of 1 (simulated calibrations)."""
    rng = np.random.default_rng(seed)
    P = model.parameters
    spread = np.array([length if u == "m" else angle if u == "rad" else gain for u in P.units])
    return P.nominal + rng.uniform(-1.0, 1.0, len(P)) * spread


def simulate(model: CalibrationModel, x_true: ArrayLike, readings: ArrayLike, *,
             sigma: Mapping[str, float] | None = None, seed: int = 0) -> np.ndarray:
    """What the instrument would read at ``readings`` on the mechanism of parameters ``x_true``, with Gaussian
    noise of ``sigma`` by unit (default :data:`SIGMA`; ``{"m": 0, "rad": 0}`` for none): a pose's position noise
    per axis, its orientation turned by a random rotation vector of ``sigma["rad"]`` per axis.

    Raises:
        ConvergenceError: the mechanism of ``x_true`` does not reach a pose (its loops do not close there): choose
            poses it reaches (:func:`~pkm.core.calibration.poses.calibration_poses`' ``reachable``, with
            :meth:`CalibrationModel.reaches <pkm.core.calibration.measurement.CalibrationModel.reaches>`).
    """
    rng = np.random.default_rng(seed)
    sig = dict(SIGMA, **(sigma or {}))
    try:
        y = model.measure(x_true, readings)
    except ConvergenceError as exc:
        raise ConvergenceError(exc.what, exc.residual, exc.iterations, exc.tolerance, exc.result, message=(
            f"{exc}: the simulated robot does not reach this pose; choose poses it reaches (calibration_poses(..., "
            f"reachable=lambda m: model.reaches(x_true, m)[0]))")) from None
    if model.kind == "pose":
        y[:, :3] += rng.normal(0.0, sig["m"], (len(y), 3))
        for k in range(len(y)):
            R = y[k, 3:].reshape(3, 3).T @ pin.exp3(rng.normal(0.0, sig["rad"], 3))
            y[k, 3:] = R.T.ravel()
    else:
        units = model.rows.units
        y += rng.normal(0.0, 1.0, y.shape) * np.array([sig[u] for u in units])
    return y


__all__ = ["LOSSES", "NFEV_PER_PARAMETER", "SIGMA", "Accuracy", "Calibration", "accuracy", "calibrate", "perturbed",
           "pose_errors", "robust_weights", "simulate"]
