"""Optimal excitation trajectories: the motion along which the base parameters are best identified.

**Parametrisation** (Swevers et al., IEEE Trans. Robot. Autom. 13(5), 1997): each actuated coordinate is a finite
Fourier series of period ``T`` (``ω_f = 2π/T``, ``L`` harmonics)::

    q_j(t) = q_j0 + Σ_l  a_jl / (ω_f l) sin(ω_f l t) - b_jl / (ω_f l) cos(ω_f l t)

with rates and accelerations exact; periodic, so that measurements can be averaged over periods and the
derivatives filtered without end effects.

**Criterion**: the **condition number** of the base regressor ``W_β`` stacked at ``M`` samples of one period, its
columns first scaled to unit norm (so that the parameters' units do not decide which are "small"), is minimised
(``log κ``, SLSQP, finite-difference gradients, at most ``max_iter`` iterations: the best iterate within the
limits is kept, and a last iterate outside them is shrunk toward its offsets until inside) over the offsets and
coefficients; the log-determinant is the
other usual choice, not taken: it rewards large motions as much as well-spread ones, which the limits then have to
stop. Every objective evaluation closes the loops along the samples warm-started (the compiled twin's path when it
builds: :meth:`pkm.Kernels.close_loops_path`) and stacks the compiled regressor.

**Constraints**, at the ``M`` samples: each actuated coordinate within its joint limits and within ``amplitude``
of its reference, whichever is tighter (``amplitude`` [rad or m], default :data:`AMPLITUDE`: the bound where the
model states no limit, as on most shipped mechanisms, and the tighter one where its limits are wider;
:attr:`Excitation.bounds` holds the bounds used), each rate within its actuator's speed limit, each effort (the model's own parameters: ``Y θ``)
within its actuator's continuous limit. After the optimisation, on a resampling ``DENSE`` times finer, every
constraint is checked again, the passive joints' limits too, and the distance to every singularity
(:func:`pkm.diagnose`'s ``direct_distance`` and ``inverse_distance``) must stay above ``singularity`` (default
:data:`SINGULARITY`); where a check fails, the motion is shrunk toward its offsets (coefficients times
:data:`SHRINK`) until it holds. The assembly mode cannot change along the result: the loops are closed by
continuation from the reference along a path that stays that far from every direct singularity, where two modes
would have to meet.

An excitation that cannot meet its limits (the efforts at the offsets alone beyond a torque limit, a reference
outside the joint limits) raises :class:`~pkm.errors.InvalidInputError` naming the limit and by how much.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import scipy.optimize

from pkm.core.identification.base import AMPLITUDE, BaseParameters, base_parameters, per_unit
from pkm.core.identification.regressor import close_along, known_efforts, parameters, regressor_batch
from pkm.core.model.joints import stated_limits
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import InvalidInputError, PkmError
from pkm.validation import as_count, as_scalar

SINGULARITY = 1e-2  # smallest relative distance to a direct or inverse singularity along an excitation
DENSE = 4  # the checks run on this many times the optimisation's samples
SHRINK = 0.8  # a motion that fails a check is shrunk by this, toward its offsets, until it holds
MAX_SHRINK = 20  # ... at most this many times


def fourier(t: np.ndarray, offset: np.ndarray, a: np.ndarray, b: np.ndarray, omega: float) \
        -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions, rates and accelerations (each len(t) x na) of the series (module doc): ``offset`` (na), ``a``, ``b``
    (na x L), ``omega`` = ``ω_f`` [rad/s]."""
    t = np.asarray(t, dtype=float)[:, None, None]
    wl = omega * np.arange(1, a.shape[1] + 1)[None, None, :]
    s, c = np.sin(wl * t), np.cos(wl * t)
    q = offset[None, :] + np.sum(a[None] / wl * s - b[None] / wl * c, axis=2)
    qd = np.sum(a[None] * c + b[None] * s, axis=2)
    qdd = np.sum(-a[None] * wl * s + b[None] * wl * c, axis=2)
    return q, qd, qdd


@dataclass(frozen=True)
class Excitation:
    """An optimised excitation (module doc).

    Attributes:
        joints: The actuated joints, in order.
        period: ``T`` [s]; ``omega`` = ``2π/T`` [rad/s].
        offset: ``q_j0`` (na) [rad or m].
        a: Sine coefficients (na x L) [rad/s or m/s].
        b: Cosine coefficients (na x L).
        condition: The scaled base regressor's condition number reached, at the optimisation's samples.
        condition_start: ... at the starting coefficients.
        t: The dense check's times (one period) [s].
        Q: Closed configurations there (n x nq); ``QD``, ``QDD``: actuated rates, accelerations (n x na).
        TAU: The efforts there with the model's own parameters (n x na) [N m or N].
        margins: Each limit's smallest margin along the dense samples, as a fraction of the limit (1 = unused;
            ``"singularity"``: the smallest distance over the bound).
        shrunk: How many times the motion was shrunk after the optimisation (module doc).
        iterations: SLSQP's iterations.
        bounds: Each actuated coordinate's position bounds used (na x 2) [rad or m]: the tighter of its joint limits
            and ``amplitude`` about its reference.
    """

    joints: tuple[str, ...]
    period: float
    offset: np.ndarray
    a: np.ndarray
    b: np.ndarray
    condition: float
    condition_start: float
    t: np.ndarray
    Q: np.ndarray
    QD: np.ndarray
    QDD: np.ndarray
    TAU: np.ndarray
    margins: dict[str, float] = field(default_factory=dict)
    shrunk: int = 0
    iterations: int = 0
    bounds: np.ndarray | None = None

    @property
    def omega(self) -> float:
        return 2.0 * np.pi / self.period

    def __call__(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Actuated positions, rates and accelerations at times ``t`` [s] (each len(t) x na)."""
        return fourier(np.atleast_1d(t), self.offset, self.a, self.b, self.omega)


def _limits(mech: Mechanism, amplitude: float | Mapping[str, float] | None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    lo, hi = stated_limits(mech.model, mech.act_q)
    ref = mech.actuated_q(mech.q_reference)
    amp = per_unit(mech, AMPLITUDE if amplitude is None else amplitude, "amplitude")
    lo, hi = np.maximum(lo, ref - amp), np.minimum(hi, ref + amp)
    bad = np.flatnonzero(~(lo < ref) | ~(ref < hi))
    if bad.size:
        j = int(bad[0])
        raise InvalidInputError("joint limits", f"{mech.actuated_names[j]}'s reference {ref[j]:.6g} is not inside "
                                                f"its limits [{lo[j]:.6g}, {hi[j]:.6g}]", ref[j])
    speed = np.array([a.velocity_limit for a in mech.actuators], dtype=float)
    effort = np.array([a.effort_limit for a in mech.actuators], dtype=float)
    return lo, hi, speed, effort


def excite(mech: Mechanism, *, period: float = 10.0, harmonics: int = 5, samples: int = 60,
           base: BaseParameters | None = None, tie_legs: bool = False,
           amplitude: float | Mapping[str, float] | None = None,
           singularity: float = SINGULARITY, seed: int = 0, max_iter: int = 60) -> Excitation:
    """An optimal excitation of ``mech`` (module doc): ``period`` ``T`` [s], ``harmonics`` ``L``, ``samples``
    ``M`` per period for the optimisation; ``base``: the base parameters whose regressor is conditioned (default
    :func:`base_parameters` with ``tie_legs``, double precision only); ``amplitude`` [rad or m] bounds each
    actuated coordinate's excursion from its reference (per unit, ``{"rad": 0.3, "m": 0.03}`` by default:
    :data:`AMPLITUDE`; one number where the actuators are all revolute or all prismatic:
    :func:`~pkm.core.identification.base.per_unit`); ``singularity``: the smallest
    relative distance to a direct or inverse singularity; ``seed``: the random starting coefficients.

    Raises:
        InvalidInputError: bad arguments, or an excitation that cannot meet its limits (the limit named, and by
            how much).

    Examples:
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> base = pkm.base_parameters(delta, 50, precise=False)
        >>> ex = pkm.excite(delta, harmonics=2, samples=20, base=base, max_iter=3)
        >>> ex.Q.shape, ex.TAU.shape
        ((80, 12), (80, 3))
        >>> bool(ex.condition < ex.condition_start)
        True
    """
    mech = check_mechanism(mech)
    period = as_scalar(period, "period")
    if not 0.0 < period <= 1e4:
        raise InvalidInputError("period", f"expected a period in (0, 1e4] s, got {period}", period)
    L, M = as_count(harmonics, "harmonics"), as_count(samples, "samples")
    if L < 1 or M < 2 * L + 2:
        raise InvalidInputError("samples", f"expected at least {2 * L + 2} samples for {L} harmonics, got {M}", M)
    singularity = as_scalar(singularity, "singularity")
    base = base if base is not None else base_parameters(mech, tie_legs=tie_legs, precise=False)
    if M * mech.na < len(base):
        raise InvalidInputError("samples", f"{M} samples give {M * mech.na} rows for {len(base)} base parameters: "
                                           f"give at least {-(-len(base) // mech.na)}", M)
    na, omega = mech.na, 2.0 * np.pi / period
    lo, hi, speed, effort = _limits(mech, amplitude)
    theta = parameters(mech).values
    t = np.arange(M) * period / M
    half = 0.5 * (hi - lo)
    ref = mech.actuated_q(mech.q_reference)

    def unpack(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return ref + half * x[:na], x[na:na + na * L].reshape(na, L), x[na + na * L:].reshape(na, L)

    def state(x: np.ndarray, times: np.ndarray) -> tuple[np.ndarray, ...]:
        qa, qd, qdd = fourier(times, *unpack(x), omega)
        Q = close_along(mech, qa)
        W = regressor_batch(mech, Q, qd, qdd)
        return qa, qd, qdd, Q, W, known_efforts(mech, Q, qd)  # (the springs' and passive friction's efforts)

    cache: dict[bytes, tuple[np.ndarray, ...] | None] = {}

    def evaluated(x: np.ndarray) -> tuple[np.ndarray, ...] | None:
        key = x.tobytes()
        if key not in cache:
            try:
                cache[key] = state(x, t)
            except (PkmError, np.linalg.LinAlgError):
                cache[key] = None
            if len(cache) > 256:
                cache.pop(next(iter(cache)))
        return cache[key]

    def log_condition(x: np.ndarray) -> float:
        s = evaluated(x)
        if s is None:
            return 50.0
        Wb = base.regressor(s[4])
        Wb = Wb / np.maximum(np.linalg.norm(Wb, axis=0), 1e-300)
        sv = np.linalg.svd(Wb, compute_uv=False)
        return float(np.log(sv[0] / max(sv[-1], 1e-300)))

    def margins(x: np.ndarray) -> np.ndarray:
        s = evaluated(x)
        if s is None:
            return -np.ones(2 * M * na)
        qa, qd, _, _, W, K = s
        out = [((qa - lo) / half).ravel(), ((hi - qa) / half).ravel()]
        if np.isfinite(speed).any():
            out.append((1.0 - np.abs(qd[:, np.isfinite(speed)]) / speed[np.isfinite(speed)]).ravel())
        if np.isfinite(effort).any():
            tau = (W @ theta).reshape(M, na) + K
            out.append((1.0 - np.abs(tau[:, np.isfinite(effort)]) / effort[np.isfinite(effort)]).ravel())
        return np.concatenate(out)

    # the efforts at the offsets alone (rest at the reference): no motion can do with less
    rest = evaluated(np.zeros(na + 2 * na * L))
    if rest is not None and np.isfinite(effort).any():
        tau0 = (rest[4] @ theta).reshape(M, na)[0] + rest[5][0]
        over = np.abs(tau0) - effort
        if np.any(over > 0):
            j = int(np.argmax(over))
            raise InvalidInputError("effort limit", f"{mech.actuated_names[j]} needs {abs(tau0[j]):.6g} at rest at "
                                                    f"the reference, over its limit {effort[j]:.6g} by "
                                                    f"{over[j]:.3g}", effort[j])
    rng = np.random.default_rng(seed)
    wl = omega * np.arange(1, L + 1)
    # start: each joint's series using about a third of its range, spread over the harmonics
    coef = rng.uniform(-1.0, 1.0, (2, na, L)) * (half[:, None] / 3.0) * wl[None, :] / np.sqrt(L)
    x0 = np.concatenate([np.zeros(na), coef[0].ravel(), coef[1].ravel()])
    for _ in range(MAX_SHRINK):
        if evaluated(x0) is not None and margins(x0).min() >= 0.0:
            break
        x0[na:] *= SHRINK
    start = float(np.exp(log_condition(x0)))
    best_f, best_x = [log_condition(x0)], [x0.copy()]

    def keep(xk: np.ndarray) -> None:  # (the best feasible iterate: SLSQP stopped early may end infeasible)
        f = log_condition(xk)
        if f < best_f[0] and evaluated(xk) is not None and margins(xk).min() >= -1e-9:
            best_f[0], best_x[0] = f, xk.copy()

    res = scipy.optimize.minimize(log_condition, x0, method="SLSQP", callback=keep,
                                  constraints=[{"type": "ineq", "fun": margins}],
                                  bounds=[(-0.9, 0.9)] * na + [(None, None)] * (2 * na * L),
                                  options={"maxiter": max_iter, "ftol": 1e-6})
    candidate = res.x.copy()
    for _ in range(MAX_SHRINK):  # (SLSQP stopped early may end outside the limits: shrink its result until inside)
        if evaluated(candidate) is not None and margins(candidate).min() >= -1e-9:
            keep(candidate)
            break
        candidate *= SHRINK
    x = best_x[0]
    dense = np.arange(DENSE * M) * period / (DENSE * M)
    shrunk = 0
    while shrunk <= MAX_SHRINK:
        try:
            checked = _check(mech, state(x, dense), lo, hi, half, speed, effort, theta, singularity)
        except (PkmError, np.linalg.LinAlgError):
            checked = None
        if checked is not None:
            break
        x = x.copy()
        x[na:] *= SHRINK
        shrunk += 1
    else:
        raise InvalidInputError("singularity", f"no motion within {MAX_SHRINK} shrinks keeps every limit and a "
                                               f"distance {singularity:g} from every singularity", singularity)
    _, qd, qdd, Q, W, K = state(x, dense)
    offset, a, b = unpack(x)
    return Excitation(tuple(mech.actuated_names), period, offset, a, b, float(np.exp(log_condition(x))), start,
                      dense, Q, qd, qdd, (W @ theta).reshape(len(dense), na) + K, checked, shrunk, int(res.nit),
                      np.column_stack([lo, hi]))


def _check(mech: Mechanism, s: tuple[np.ndarray, ...], lo: np.ndarray, hi: np.ndarray, half: np.ndarray,
           speed: np.ndarray, effort: np.ndarray, theta: np.ndarray, singularity: float) -> dict[str, float] | None:
    """Each limit's smallest margin on the dense samples (module doc), or None where one is not met."""
    from pkm.core.differential.velocity import singularity_distances

    qa, qd, _, Q, W, K = s
    na = mech.na
    tau = (W @ theta).reshape(len(qa), na) + K
    out = {"joint": float(min(((qa - lo) / half).min(), ((hi - qa) / half).min()))}
    out["speed"] = float((1.0 - np.abs(qd) / speed).min())  # (an infinite limit: a margin of 1, unused)
    out["effort"] = float((1.0 - np.abs(tau) / effort).min())
    if min(out.values()) < 0.0 or any(mech.outside_limits(q) for q in Q):
        return None
    worst = np.inf
    for q in Q[::max(1, len(Q) // (4 * 60))]:  # (every sample up to 240 of them)
        worst = min(worst, *singularity_distances(mech, q))
    if worst < singularity:
        return None
    out["singularity"] = float(worst / singularity)
    return out


def write_csv(mech: Mechanism, excitation: Excitation, path: str, *, periods: int = 1, dt: float | None = None) \
        -> str:
    """The excitation as a samples table (the columns of :mod:`pkm.core.dynamics.samples`: ``time``,
    ``q.<joint>``, ``qd.<joint>``, ``qdd.<joint>``, ``tau.<joint>``; the efforts the model's own), ``periods``
    periods at ``dt`` [s] (default: the dense samples' step), written by
    :func:`pkm.core.dynamics.samples.write_csv`."""
    from pkm.core.dynamics import samples

    mech = check_mechanism(mech)
    step = excitation.t[1] - excitation.t[0] if dt is None else as_scalar(dt, "dt")
    n = round(as_count(periods, "periods") * excitation.period / step)
    t = np.arange(n + 1) * step
    qa, qd, qdd = excitation(t)
    Q = close_along(mech, qa)
    tau = (regressor_batch(mech, Q, qd, qdd) @ parameters(mech).values).reshape(len(t), mech.na)
    tau += known_efforts(mech, Q, qd)  # (the springs' and the passive joints' friction)
    cols = {"time": t}
    for prefix, values in (("q", qa), ("qd", qd), ("qdd", qdd), ("tau", tau)):
        cols.update({f"{prefix}.{j}": values[:, k] for k, j in enumerate(mech.actuated_names)})
    return str(samples.write_csv(cols, path))


def write_motion(mech: Mechanism, excitation: Excitation, path: str, *, periods: int = 1, dt: float | None = None,
                 case: str = "excitation") -> str:
    """The excitation as a motion file (:mod:`pkm.motion`, ``space = "actuated"``, one ``fourier`` law per actuated
    joint, the coefficients exact: ``repr`` of each float), ``periods`` periods sampled every ``dt`` [s]."""
    from pkm.motion import motion_file, toml_floats

    mech = check_mechanism(mech)
    step = excitation.t[1] - excitation.t[0] if dt is None else as_scalar(dt, "dt")
    laws = {n: f'law = "fourier", offset = {float(excitation.offset[k])!r}, omega = {excitation.omega!r}, '
               f"a = {toml_floats(excitation.a[k])}, b = {toml_floats(excitation.b[k])}"
            for k, n in enumerate(excitation.joints)}
    out = motion_file(path, case, laws, space="actuated", mechanism=mech.name,
                      description=f"optimal excitation: condition number {excitation.condition:.4g} (from "
                                  f"{excitation.condition_start:.4g})", source="pkm.excite",
                      duration=as_count(periods, "periods") * excitation.period, dt=float(step))
    return str(out)


__all__ = ["AMPLITUDE", "SINGULARITY", "Excitation", "excite", "fourier", "write_csv", "write_motion"]
