"""Choosing the Delta's base radius R: reach and conditioning of a pose vs R, workspace vs R.

The paper (sec. 5) varies R at one pose, (0, 0, -375) mm, and looks at the condition number of
``J = dX/dth``; it also says the workspace shrinks as R grows. This module makes each step a
function of the design: the exact range of R over which a pose is reachable (closed form), the
condition numbers along R, the R that minimises a condition number at a pose, and two ways to
choose R for a task: the largest well-conditioned workspace (``K <= k_max``), or the lowest mean
``K`` over a given task region.

Every ``params`` below is a :class:`~pkm.mechanisms.delta.DeltaParams` whose ``R`` is replaced
by each value studied; its ``La``, ``Lb``, ``r`` are kept.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from pkm.core.differential.indices import KINDS
from pkm.errors import InvalidInputError, UnreachableError
from pkm.mechanisms._common import check_params, circle_sphere_reach, real
from pkm.mechanisms.delta import PHI, DeltaParams, arm_angles
from pkm.mechanisms.delta.kinematics import _arm_frame_points
from pkm.mechanisms.delta.workspace import _condition_numbers, condition_numbers, workspace
from pkm.validation import as_array, as_count, as_vector

__all__ = ["RadiusStudy", "condition_vs_radius", "radius_minimising_condition", "reachable_radii",
           "region_mean_condition", "workspace_vs_radius"]


def _intersect(a: list[tuple[float, float]], b: list[tuple[float, float]]) -> list[tuple[float, float]]:
    out = [(max(lo1, lo2), min(hi1, hi2)) for lo1, hi1 in a for lo2, hi2 in b]
    return sorted((lo, hi) for lo, hi in out if lo <= hi)


def reachable_radii(params: DeltaParams, p) -> tuple[tuple[float, float], ...]:
    """The base radii R [m] for which the platform centre ``p`` [m] is reachable, in closed form.

    Arm ``i`` reaches ``p`` when the forearm sphere meets the elbow circle: with ``w`` the
    coordinate of ``p`` along the motor axis, ``s = sqrt(Lb^2 - w^2)`` and ``rho`` the distance
    from the motor axis in the arm plane, ``|s - La| <= rho <= s + La``. As ``rho^2 = u^2 + z^2``
    with ``u = y_i - (R - r)``, each arm allows R in at most two intervals; the result is their
    intersection over the three arms and with R > 0. At the ends an arm is stretched
    (``rho = La + s``) or folded (``rho = |s - La|``) onto its forearm.

    Returns:
        Disjoint closed intervals ``(R_lo, R_hi)`` [m], in increasing order; empty when no R works.
    """
    params = check_params(params, DeltaParams)
    p = as_vector(p, 3, "p")
    allowed = [(0.0, math.inf)]
    for i in range(3):
        ci, si = math.cos(PHI[i]), math.sin(PHI[i])
        w, y, z = ci * p[0] + si * p[1], -si * p[0] + ci * p[1], p[2]
        if abs(w) > params.Lb:
            return ()
        s = math.sqrt(params.Lb**2 - w * w)
        hi2 = (s + params.La) ** 2 - z * z
        if hi2 < 0.0:
            return ()
        lo, hi = math.sqrt(max((s - params.La) ** 2 - z * z, 0.0)), math.sqrt(hi2)
        # u = y - (R - r) in [-hi, -lo] U [lo, hi]
        arm = [(y + params.r + lo, y + params.r + hi), (y + params.r - hi, y + params.r - lo)]
        allowed = _intersect(allowed, arm)
    merged: list[tuple[float, float]] = []
    for lo, hi in allowed:
        lo = max(lo, 0.0)
        if hi <= 0.0:
            continue
        if merged and lo <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(hi, merged[-1][1]))
        else:
            merged.append((lo, hi))
    return tuple(merged)


def condition_vs_radius(params: DeltaParams, p, R_values, branch="knee_out", kinds=KINDS) -> dict[str, np.ndarray]:
    """Condition numbers of ``J`` at the pose ``p`` [m] for each base radius in ``R_values`` [m] (every radius in
    one batch: the numbers, bit for bit, of :func:`~pkm.mechanisms.delta.workspace.condition_numbers` of each design).

    Raises:
        UnreachableError: if ``p`` is out of reach for one of the radii (arm and distance named).
    """
    params = check_params(params, DeltaParams)
    p = as_vector(p, 3, "p")
    R_values = np.atleast_1d(as_array(R_values, "R_values", "base radii [m]"))
    if R_values.ndim != 1 or not np.all(np.isfinite(R_values)) or np.any(R_values <= 0.0):
        raise InvalidInputError("R_values", "must be finite radii > 0 [m]", R_values)
    x, y, z = _arm_frame_points(p)  # the reach test of arm_angles, every radius at once
    misses = np.flatnonzero(~circle_sphere_reach(y - (R_values - params.r)[:, None], z, x, params.La, params.Lb)
                            .all(axis=-1))
    for R in R_values[misses[:1]]:
        arm_angles(params.La, params.Lb, R - params.r, p, (1, 1, 1), f" at R = {R:.6g} m")  # which arm, how far
    if len(R_values):  # (DeltaParams' own bound on R, 1e6 m, as when each radius made its design: the largest checked)
        dataclasses.replace(params, R=float(np.max(R_values)))
    K, _ = _condition_numbers(params, np.broadcast_to(p, (len(R_values), 3)), branch, kinds, R_values)
    return K


def radius_minimising_condition(params: DeltaParams, p, branch="knee_out", kind: str = "2",
                                n_scan: int = 400) -> tuple[float, float]:
    """The base radius [m] that minimises the condition number of ``J`` at pose ``p``, and that minimum.

    Scans the reachable radii (:func:`reachable_radii`, each interval on ``n_scan`` points,
    ends excluded), then refines the best cell by bounded Brent minimisation to 1e-10 m.

    Raises:
        UnreachableError: if no radius reaches ``p``.
    """
    p = as_vector(p, 3, "p")
    n_scan = as_count(n_scan, "n_scan", low=1, high=100_000)
    intervals = reachable_radii(params, p)
    if not intervals:
        raise UnreachableError(1, math.inf, "m", f"no base radius reaches {p.tolist()}")
    best: tuple[float, float, tuple[float, float]] = (math.inf, math.nan, (math.nan, math.nan))
    for lo, hi in intervals:
        grid = np.linspace(lo, hi, n_scan + 2)[1:-1]
        K = condition_vs_radius(params, p, grid, branch, (kind,))[kind]
        j = int(np.argmin(K))
        if K[j] < best[0]:
            best = (float(K[j]), float(grid[j]), (float(grid[max(j - 1, 0)]), float(grid[min(j + 1, len(grid) - 1)])))
    if not math.isfinite(best[0]):
        raise UnreachableError(1, 0.0, "m", "singular at every reachable radius")
    a, b = best[2]
    res = minimize_scalar(lambda R: condition_vs_radius(params, p, [R], branch, (kind,))[kind][0],
                          bounds=(a, b), method="bounded", options={"xatol": 1e-10, "maxiter": 200})
    return (float(res.x), float(res.fun)) if res.fun <= best[0] else (float(best[1]), float(best[0]))


@dataclass(frozen=True)
class RadiusStudy:
    """Workspaces of one family of designs, R varying (see :func:`workspace_vs_radius`).

    Attributes:
        R: Base radii [m].
        volume: Reachable volume below the base for each R [m^3].
        K_sorted: For each R, the condition numbers (convention ``kind``) of the reachable grid
            nodes, sorted (``inf`` at singular nodes).
        kind: Condition-number convention (``"2"``, ``"fro"``, ``"fro_normalized"``).
        spacing: Grid step [m].
        branch: Working mode.
    """

    R: np.ndarray
    volume: np.ndarray
    K_sorted: tuple[np.ndarray, ...]
    kind: str
    spacing: float
    branch: object

    def conditioned_volume(self, k_max: float) -> np.ndarray:
        """Volume [m^3] of the part of each workspace where ``K <= k_max``."""
        if real(k_max) is None or not k_max >= 1.0:
            raise InvalidInputError("k_max", f"must be a finite bound >= 1, got {k_max!r}", k_max)
        return np.array([np.searchsorted(K, k_max, side="right") for K in self.K_sorted]) * self.spacing**3

    def weighted_volume(self) -> np.ndarray:
        """``integral of 1/K`` over each workspace [m^3] (volume times mean ``1/K``; no threshold)."""
        return np.array([np.sum(1.0 / K) for K in self.K_sorted]) * self.spacing**3

    def best_conditioned(self, k_max: float) -> float:
        """The R [m] with the largest volume where ``K <= k_max`` (the smallest such R on ties)."""
        return float(self.R[int(np.argmax(self.conditioned_volume(k_max)))])

    def best_weighted(self) -> float:
        """The R [m] with the largest ``integral of 1/K``."""
        return float(self.R[int(np.argmax(self.weighted_volume()))])


def workspace_vs_radius(params: DeltaParams, R_values, *, kind: str = "2", spacing: float = 0.008,
                        branch="knee_out") -> RadiusStudy:
    """Sample the workspace (:func:`pkm.mechanisms.delta.workspace.workspace`) for each base radius.

    Args:
        params: The design (its ``R`` replaced by each value).
        R_values: Base radii [m].
        kind: Condition-number convention kept per node.
        spacing: Grid step [m].
        branch: Working mode.
    """
    params = check_params(params, DeltaParams)
    R_values = np.atleast_1d(as_array(R_values, "R_values", "base radii [m]"))
    volume, K_sorted = [], []
    for R in R_values:
        grid = workspace(dataclasses.replace(params, R=float(R)), spacing, branch, (kind,))
        volume.append(grid.volume)
        K_sorted.append(np.sort(grid.K[kind][grid.reachable]))
    return RadiusStudy(R_values, np.array(volume), tuple(K_sorted), kind, float(spacing), branch)


def region_mean_condition(params: DeltaParams, R_values, region, *, kind: str = "2",
                          branch="knee_out") -> np.ndarray:
    """Mean condition number over the task ``region`` (points [m], shape (N, 3)) for each base radius.

    A radius for which some point of the region is out of reach (or singular) scores ``inf``:
    it cannot serve that task. The best R for the region is ``R_values[argmin]``.
    """
    params = check_params(params, DeltaParams)
    region = as_array(region, "region", "points (N, 3) [m]")
    if region.ndim != 2 or region.shape[1] != 3 or len(region) == 0:
        raise InvalidInputError("region", f"expected N >= 1 points of shape (N, 3) [m], got {region.shape}", region)
    out = []
    for R in np.atleast_1d(as_array(R_values, "R_values", "base radii [m]")):
        K, reachable = condition_numbers(dataclasses.replace(params, R=float(R)), region, branch, (kind,))
        out.append(float(np.mean(K[kind])) if reachable.all() and np.all(np.isfinite(K[kind])) else math.inf)
    return np.array(out)
