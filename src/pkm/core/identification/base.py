"""Base parameters: the combinations of the dynamic parameters that the efforts can identify.

Many parameters never reach the actuators (a body's inertia about an axis it cannot turn about) or only in fixed
combinations (the masses of bodies that move together); the **base parameters** ``β = P θ`` are the largest set of
independent combinations, ``Y_a θ = Y_β β`` for every motion. Numerical route (Gautier's): the regressor stacked at
random regular states, its columns scaled to unit norm, a QR decomposition with column pivoting (``scipy.linalg.qr``);
the rank is where ``|R_kk| / |R_00|`` drops by the largest factor (the **gap**, stated in the result with the values
either side) among the values under ``1e-6``, the last one kept above ``1e-10`` (below, the regressor's own rounding:
the 3-RRR has 7 pivots between 1e-15 and 1e-17, then exact zeros, and its rank is 22, not 29); a gap under :data:`CLEAR_GAP` is reported as ``ambiguous``: the
decision is then not to be trusted in double precision (Iriarte et al., arXiv 1706.09153). The independent columns
``θ_1`` give ``β = θ_1 + K θ_2`` with ``K = R_11⁻¹ R_12`` (on unit-norm columns, entries under 1e-6 dropped as
rounding; then scaled back to the parameters' units).
"""

from __future__ import annotations

import re
import weakref
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike

from pkm.core.identification.rank import CLEAR_GAP, RankDecision, decide_rank
from pkm.core.identification.regressor import Parameters, parameters, regressor
from pkm.core.kinematics.solve import close_loops
from pkm.core.model.mechanism import Mechanism, check_mechanism, require_independent_actuators
from pkm.errors import ConvergenceError, InvalidInputError, SingularityError
from pkm.validation import as_scalar

if TYPE_CHECKING:
    from pkm.core.identification.precise import PreciseRank

_STATES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # mechanism -> {(n, seed, spreads): states}
MAX_SAMPLES = 10_000  # states stacked at most (each costs about a millisecond)
COEFFICIENT_TOL = 1e-6  # coefficients of K on unit-norm columns under this are dropped (rounding of R_11^-1 R_12)


@dataclass(frozen=True)
class BaseParameters:
    """The base parameters of a mechanism (module doc).

    Attributes:
        names: Each combination, readable: ``"platform.m + 3 rod.m"``.
        map: ``P`` (n_base x p): ``β = P θ`` for the standard parameters ``θ`` of :func:`parameters`.
        values: ``P θ`` for the mechanism's own parameters.
        independent: The indices (into ``θ``) of the parameter each combination is named after.
        decision: The rank decision (its gap, and whether it is ambiguous).
        parameters: The standard parameters.
        samples: The number of random states stacked.
        tie: With tied legs, ``T`` (p x p_tied): the standard columns summed into each tied one (``Y T``), else None.
        tied_names: The tied parameters' names (``"arm_*.m"``), empty without ties.
        precise: The rank decided again in 50-digit arithmetic on the same samples (``precise=True``), else None;
            :attr:`routes_agree` compares the counts.
    """

    names: tuple[str, ...]
    map: np.ndarray
    values: np.ndarray
    independent: tuple[int, ...]
    decision: RankDecision
    parameters: Parameters
    samples: int
    tie: np.ndarray | None = None
    tied_names: tuple[str, ...] = ()
    precise: PreciseRank | None = None

    @property
    def routes_agree(self) -> bool | None:
        """Whether the second route (:mod:`~pkm.core.identification.precise`, 50 digits) finds the same count; None
        when it was not run."""
        return None if self.precise is None else self.precise.decision.rank == len(self.names)

    def __len__(self) -> int:
        return len(self.names)

    def regressor(self, Y: ArrayLike) -> np.ndarray:
        """The base regressor ``Y_β`` of a standard one ``Y`` (its independent columns: ``Y θ = Y_β β``)."""
        Y = np.asarray(Y, dtype=float)
        return (Y if self.tie is None else Y @ self.tie)[:, list(self.independent)]


def _coefficient(c: float) -> str:
    f = Fraction(c).limit_denominator(12)
    if abs(float(f) - c) <= 1e-9 * max(abs(c), 1.0):
        return str(f) if f.denominator != 1 else str(f.numerator)
    return f"{c:.6g}"


@dataclass(frozen=True)
class BaseSplit:
    """The double-precision base decomposition of a regressor's columns (:func:`base_split`).

    Attributes:
        decision: The rank decision on the pivoted QR's diagonal.
        live: The columns that are not zero (norm above 1e-12 times the largest).
        independent: The independent columns, in pivot order; ``dependent``: the other live columns.
        K: ``dependent = independent @ K`` (r x len(dependent)), coefficients under ``COEFFICIENT_TOL`` zeroed.
        order: ``independent``'s rows in column order (the base parameters' order).
        P: Each base combination's row over every column (r x n), in ``order``.
        names: Each combination's readable name.
    """

    decision: RankDecision
    live: np.ndarray
    independent: np.ndarray
    dependent: np.ndarray
    K: np.ndarray
    order: np.ndarray
    P: np.ndarray
    names: tuple[str, ...]


def base_split(W: np.ndarray, names: tuple[str, ...]) -> BaseSplit:
    """The base combinations of ``W``'s columns (named ``names``): a QR with column pivoting of the unit-norm live
    columns, its rank decided by :func:`decide_rank`, the dependent columns as combinations of the independent ones
    (back to unscaled columns). Shared by the dynamic base parameters and the geometric ones
    (:mod:`pkm.core.calibration.identifiable`)."""
    scale = np.linalg.norm(W, axis=0)
    live = np.flatnonzero(scale > 1e-12 * scale.max())
    Ws = W[:, live] / scale[live]
    _, R, perm = scipy.linalg.qr(Ws, mode="economic", pivoting=True)
    decision = decide_rank(np.abs(np.diag(R)))
    r = decision.rank
    K = scipy.linalg.solve_triangular(R[:r, :r], R[:r, r:]) if r < len(live) else np.zeros((r, 0))
    ind, dep = live[perm[:r]], live[perm[r:]]
    K[np.abs(K) < COEFFICIENT_TOL] = 0.0
    K = K * scale[dep][None, :] / scale[ind][:, None]  # (back to unscaled columns)
    order = np.argsort(ind)
    Pmap = np.zeros((r, len(names)))
    combos: list[str] = []
    for row in order:
        Pmap[len(combos), ind[row]] = 1.0
        Pmap[len(combos), dep] = K[row]
        combos.append(_name(names, int(ind[row]), [(int(j), float(c)) for j, c in zip(dep, K[row]) if c != 0.0]))
    return BaseSplit(decision, live, ind, dep, K, order, Pmap, tuple(combos))


def _name(names: tuple[str, ...], lead: int, terms: list[tuple[int, float]]) -> str:
    out = names[lead]
    for j, c in terms:
        text = _coefficient(abs(c))
        out += (" - " if c < 0 else " + ") + ("" if text == "1" else text + " ") + names[j]
    return out


#: Default bound of ``|q_j - q_j,reference|`` per unit [rad or m]: an excitation's amplitude
#: (:mod:`~pkm.core.identification.excitation`; a calibration pose's spread is its own,
#: :func:`pkm.core.calibration.poses.default_spread`, in characteristic lengths for a length).
AMPLITUDE = {"rad": 0.3, "m": 0.03}
#: The random states' spread per unit (:func:`random_states`: the base parameters need generic states, not large ones).
STATE_SPREAD = {"rad": 0.1, "m": 0.1}


def per_unit(mech: Mechanism, value: float | Mapping[str, float], name: str, joints: Sequence[str] | None = None) \
        -> np.ndarray:
    """An amount per actuated coordinate (na; per joint of ``joints``, one-coordinate joints, where given) [rad or m]:
    ``value`` a mapping by unit (``{"rad": 0.3, "m": 0.03}``: each joint takes its unit's), or one positive number,
    the same in every joint's unit: refused where revolute and prismatic joints mix (there it would mean rad and m
    alike).

    Raises:
        InvalidInputError: a number on a mixed mechanism, a missing unit, a value that is not positive.
    """
    units = ["rad" if mech.joints[j].revolute else "m" for j in (mech.actuated_names if joints is None else joints)]
    if not isinstance(value, Mapping):
        number = as_scalar(value, name, low=0.0, strict_low=True)
        if len(set(units)) > 1:
            raise InvalidInputError(name, f"one number ({number:g}) for revolute and prismatic joints alike: give "
                                          f"one per unit, {{'rad': ..., 'm': ...}}", value)
        return np.full(len(units), number)
    missing = sorted(set(units) - set(value))
    if missing:
        raise InvalidInputError(name, f"no value for the {', '.join(missing)} joints (expected a mapping by unit, "
                                      f"'rad' and 'm')", dict(value))
    return np.array([as_scalar(value[u], f"{name}[{u!r}]", low=0.0, strict_low=True) for u in units])


#: A draw's path gives up when its continuation step falls below this fraction of the first (1e-3 for a closure
#: that must succeed): after one halving of a step that failed. A draw outside the workspace is passed over at a
#: twelfth of the cost (the hexapod's 107 states: 8.6 s at 1e-3, 5.4 s at 0.05, 2.0 s), and the states drawn on the
#: shipped mechanisms are the same to the last bit at 1e-3, 0.05 and 0.5 (a draw is random: one that needs a path
#: finer than this is passed over for the next).
DRAW_MIN_STEP = 0.5


def closed_draws(mech: Mechanism, rng: np.random.Generator, spread: np.ndarray, tries: int) \
        -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Random actuator readings ``qa`` about the reference, each within ``spread`` (na) [rad or m] of it (uniform),
    with their closed configurations ``q`` (closed from the reference, within the joint limits): ``(qa, q)`` for
    each of ``tries`` draws that closes (one that does not close or is singular is passed over). The one draw of
    :func:`random_states` and the calibration's candidate poses (:func:`pkm.core.calibration.poses.candidates`).

    Raises:
        StructureError: redundant actuation (:attr:`~pkm.core.Mechanism.dependent_actuators`), at the first draw:
            readings drawn one by one never agree with the actuators the others fix, so no draw would close; the
            dependent actuators named, with the independent ones to load the mechanism with instead.
    """
    require_independent_actuators(mech, "random readings drawn one by one never agree with them, so no random state "
                                        "closes its loops", "to draw states (identification, excitation, calibration "
                                        "poses)")
    qa0 = mech.actuated_q(mech.q_reference)
    for _ in range(tries):
        qa = qa0 + rng.uniform(-spread, spread, mech.na)
        try:
            q = close_loops(mech, qa, mech.q_reference, min_step=DRAW_MIN_STEP).q
        except (ConvergenceError, SingularityError):
            continue
        if not mech.outside_limits(q):
            yield qa, q


def random_states(mech: Mechanism, n: int, seed: int = 0, spread: float | Mapping[str, float] | None = None) \
        -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """``n`` random regular states ``(q, qd, qdd)``: each actuated coordinate moved by up to ``spread`` [rad or m;
    :func:`per_unit`, default :data:`STATE_SPREAD`] from the reference and closed from it (:func:`closed_draws`:
    states that do not close or are singular are drawn again), rates and accelerations standard normal. The last
    few draws are kept per mechanism (the tied and untied base parameters share theirs: the hexapod's 107 states
    cost 8 s)."""
    mech = check_mechanism(mech)
    bound = per_unit(mech, STATE_SPREAD if spread is None else spread, "spread")
    key = (n, seed, bound.tobytes())
    kept = _STATES.setdefault(mech, {})
    if key in kept:
        return [(q.copy(), qd.copy(), qdd.copy()) for q, qd, qdd in kept[key]]
    rng = np.random.default_rng(seed)
    out: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    for _, q in closed_draws(mech, rng, bound, 20 * n):
        out.append((q, rng.standard_normal(mech.na), rng.standard_normal(mech.na)))
        if len(out) == n:
            break
    if len(out) < n:
        raise InvalidInputError("spread", f"only {len(out)} of {n} random states closed within the limits", spread)
    if len(kept) >= 4:
        kept.pop(next(iter(kept)))
    kept[key] = tuple((q.copy(), qd.copy(), qdd.copy()) for q, qd, qdd in out)
    return out


def leg_ties(names: tuple[str, ...]) -> tuple[np.ndarray, tuple[str, ...]]:
    """``T`` (p x p_tied) and the tied names: parameters whose body or joint names differ only by a trailing leg
    number (``arm_1.m``, ``arm_2.m``, ``arm_3.m`` -> ``arm_*.m``; ``motor_1.viscous`` ... -> ``motor_*.viscous``)
    share one column, the others keep theirs. The rule assumes the legs are built alike, each in its own frames
    (as every mechanism pkm generates is, and as the tests check on the shipped ones)."""
    keys = []
    for name in names:
        owner, field = name.rsplit(".", 1)
        stem = re.sub(r"_\d+$", "_*", owner)
        keys.append(f"{stem}.{field}")
    counts: dict[str, int] = {}
    for k in keys:
        counts[k] = counts.get(k, 0) + 1
    labels = [k if counts[k] > 1 and "*" in k else n for k, n in zip(keys, names)]
    tied = tuple(dict.fromkeys(labels))
    T = np.zeros((len(names), len(tied)))
    for i, label in enumerate(labels):
        T[i, tied.index(label)] = 1.0
    return T, tied


def require_precise(mech: Mechanism, what: str = "pkm.base_parameters(precise=True)") -> None:
    """Refuse, before any work, a mechanism on which the precise route of :func:`base_parameters` cannot run: its
    rank decided a second time in 50-digit arithmetic takes the twin's regressor, which needs a mechanism without idle
    motions (:meth:`pkm.core.twin.tree.Twin`). ``what`` names the asker in the message.

    Raises:
        SpecError: ``mech`` has idle motions at its reference (naming how many, and the double-precision route).
    """
    from pkm.core.differential.velocity import idle_motions
    from pkm.errors import SpecError

    idle = idle_motions(mech, mech.q_reference).shape[1]
    if idle:
        raise SpecError(mech.source, f"{what} decides the base parameters' rank a second time in 50-digit arithmetic "
                                     f"on the twin's regressor, which needs a mechanism without idle motions, and "
                                     f"{mech.name} has {idle}: pass precise=False to pkm.base_parameters (the "
                                     "double-precision route alone) and identify it in Python")


def base_parameters(mech: Mechanism, n_samples: int | None = None, *, seed: int = 0,
                    tie_legs: bool = False, precise: bool = True) -> BaseParameters:
    """The base parameters of ``mech`` by the numerical route (module doc), from ``n_samples`` random states
    (default: enough for three times as many rows as parameters); ``tie_legs``: one parameter set per kind of leg
    (:func:`leg_ties`), which lowers the count; ``precise``: decide the rank a second time in 50-digit arithmetic
    on the same samples (:mod:`~pkm.core.identification.precise`: 0.4 s for the Delta, 2 s for the hexapod's 248
    parameters), the result saying whether the two routes agree (:attr:`BaseParameters.routes_agree`).
    The numerical route's base parameters are returned either way: where the routes disagree, the caller decides
    (the precise rank says which combinations double precision could not see).

    Raises:
        InvalidInputError: fewer states than needed for as many rows as parameters, or more than ``MAX_SAMPLES``.
        SpecError: ``precise`` on a mechanism whose twin cannot build the regressor (idle motions): pass
            ``precise=False`` (refused before any work, :func:`require_precise`).

    Examples:
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> base = pkm.base_parameters(delta, 50, precise=False)
        >>> len(base.names), len(pkm.parameters(delta).names)
        (48, 132)
        >>> base.names[0]
        'arm_1.mz'
    """
    mech = check_mechanism(mech)
    if precise:
        require_precise(mech)
    P = parameters(mech)
    p = len(P)
    n = n_samples if n_samples is not None else max(10, -(-3 * p // mech.na))
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InvalidInputError("n_samples", "expected a positive integer", n_samples)
    least = -(-p // mech.na)
    if not least <= n <= MAX_SAMPLES:
        raise InvalidInputError("n_samples", f"{n} states stack {n * mech.na} rows for {p} parameters: give from "
                                             f"{least} (as many rows as parameters) to {MAX_SAMPLES}", n_samples)
    states = random_states(mech, n, seed)
    W = np.vstack([regressor(mech, *state) for state in states])
    names, theta, T = P.names, P.values, None
    if tie_legs:
        T, names = leg_ties(P.names)
        W, theta = W @ T, np.linalg.pinv(T) @ P.values  # (a tied value: its legs' mean)
    split = base_split(W, names)
    decision, Pmap, combos = split.decision, split.P, split.names
    ind, order = split.independent, split.order
    full = Pmap if T is None else Pmap @ np.linalg.pinv(T)
    second = None
    if precise:
        from pkm.core.identification.precise import precise_rank

        second = precise_rank(mech, states[:-(-(p + 2 * mech.na) // mech.na)], T)  # (as many rows as it needs)
    return BaseParameters(tuple(combos), full, Pmap @ theta, tuple(int(ind[row]) for row in order), decision, P, n,
                          T, names if T is not None else (), second)


__all__ = ["AMPLITUDE", "CLEAR_GAP", "STATE_SPREAD", "BaseParameters", "BaseSplit", "RankDecision", "base_parameters",
           "base_split", "closed_draws", "decide_rank", "leg_ties", "per_unit", "random_states", "require_precise"]
