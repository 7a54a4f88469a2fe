"""Delta workspace and condition-number maps, vectorised over grids of platform positions.

The same closed forms as :mod:`pkm.mechanisms.delta` (arm circle against forearm sphere for the
inverse kinematics, :func:`~pkm.mechanisms.delta.jacobian_factors` for the Jacobian), evaluated
on arrays of points at once instead of one pose at a time. Unreachable points are not errors
here: they are reported in an explicit ``reachable`` mask, and their condition numbers are
``inf`` (never NaN), so that no average can silently include them.

The workspace is the set of platform centres every arm can reach (no motor or ball-joint
limits: the paper gives none), restricted to the half-space below the base (``z < 0``), as the
paper admits only the negative root of its forward kinematics. That set is symmetric about the
base plane, so this is half of the full reach set.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pkm.core.differential.indices import KINDS, check_method
from pkm.core.differential.indices import condition_numbers as core_condition_numbers
from pkm.errors import InvalidInputError
from pkm.mechanisms._common import check_params, circle_sphere, circle_sphere_reach, real
from pkm.mechanisms.delta import PHI, DeltaParams, jacobian_factors
from pkm.mechanisms.delta.kinematics import branch_signs
from pkm.validation import as_array

MAX_NODES = 16_000_000  #: grid nodes of :func:`workspace` at most (the grids it returns: memory)
CHUNK_NODES = 1 << 20  #: grid nodes :func:`workspace` evaluates at once (whole z slices; its temporaries: memory)

__all__ = ["WorkspaceGrid", "condition_numbers", "inverse_kinematics_batch", "workspace"]


def _points(P) -> np.ndarray:
    P = as_array(P, "points", "platform centres (..., 3) [m]")
    if P.ndim < 1 or P.shape[-1] != 3:
        raise InvalidInputError("points", f"expected an array of shape (..., 3) [m], got {P.shape}", P)
    if not np.all(np.isfinite(P)):
        raise InvalidInputError("points", "holds non-finite coordinates", P)
    return P


def inverse_kinematics_batch(params: DeltaParams, points, branch="knee_out") -> tuple[np.ndarray, np.ndarray]:
    """Motor angles for many platform centres at once (the closed form of
    :func:`pkm.mechanisms.delta.inverse_kinematics`, same branches and wrapping).

    Args:
        params: The design.
        points: Platform centres [m], shape (..., 3).
        branch: ``"knee_out"``/``"knee_in"`` for all arms, or one per arm.

    Returns:
        ``theta`` [rad] of shape (..., 3) and ``reachable`` (bool, shape (...)): every arm reaches.
        Where an arm does not reach, its angle is that of the nearest elbow position (the
        clipped arc cosine; 0 where the point's terms overflow, near the float range), finite but meaningless: use
        the mask.
    """
    params = check_params(params, DeltaParams)
    return _inverse_kinematics(params, _points(points), branch, params.R)


def _inverse_kinematics(params: DeltaParams, P: np.ndarray, branch, R) -> tuple[np.ndarray, np.ndarray]:
    """:func:`inverse_kinematics_batch` with the base radius ``R`` [m] in place of ``params.R`` (a float, or an
    array of shape ``P.shape[:-1]``: one design a point)."""
    signs = branch_signs(branch)
    theta = np.empty(P.shape)
    reachable = np.ones(P.shape[:-1], dtype=bool)
    for i in range(3):
        ci, si = math.cos(PHI[i]), math.sin(PHI[i])
        with np.errstate(over="ignore", invalid="ignore"):  # (coordinates near the float range: unreachable)
            w = ci * P[..., 0] + si * P[..., 1]  # along the motor axis
            u = -si * P[..., 0] + ci * P[..., 1] - (R - params.r)
        theta[..., i], reach_i, _, _ = circle_sphere(u, P[..., 2], w, params.La, params.Lb, signs[i])
        reachable &= reach_i
    theta[~np.isfinite(theta)] = 0.0  # (a point whose terms overflow reaches nothing: its angles 0, finite)
    return theta, reachable


def condition_numbers(params: DeltaParams, points, branch="knee_out", kinds=KINDS,
                      method: str = "lapack") -> tuple[dict[str, np.ndarray], np.ndarray]:
    """Condition numbers of ``J = dX/dth`` at many platform centres.

    They are computed on ``J^-1 = diag(d)^-1 A`` (no inversion needed; every kind of
    :func:`pkm.core.differential.indices.condition_number` takes the same value on a matrix and its inverse).

    Args:
        params: The design.
        points: Platform centres [m], shape (..., 3).
        branch: Working mode (see :func:`inverse_kinematics_batch`).
        kinds: Which conventions (``"fro"``: raw ``||J||_F ||J^-1||_F`` >= 3; ``"fro_normalized"``:
            the same over 3, >= 1; ``"2"``: ``sigma_max / sigma_min`` >= 1).
        method: The singular values' route, ``"lapack"`` or ``"jacobi"`` (faster on many points; see
            :func:`pkm.core.differential.indices.condition_numbers`).

    Returns:
        ``{kind: K}`` each of shape (...), ``inf`` at unreachable points and where an arm is
        stretched or folded onto its forearm, and the ``reachable`` mask.
    """
    params = check_params(params, DeltaParams)
    return _condition_numbers(params, _points(points), branch, kinds, params.R, method)


def _condition_numbers(params: DeltaParams, P: np.ndarray, branch, kinds, R,
                       method: str = "lapack") -> tuple[dict[str, np.ndarray], np.ndarray]:
    """:func:`condition_numbers` with the base radius ``R`` [m] in place of ``params.R`` (a float, or an array of
    shape ``P.shape[:-1]``: one design a point)."""
    if isinstance(kinds, str) or not isinstance(kinds, (tuple, list)):
        raise InvalidInputError("kinds", f"expected a tuple of kinds among {KINDS}, got {kinds!r}", kinds)
    unknown = [k for k in kinds if not isinstance(k, str) or k not in KINDS]
    if unknown or not kinds:
        raise InvalidInputError("kinds", f"choose among {KINDS}, got {tuple(kinds)!r}", kinds)
    check_method(method)
    theta, reachable = _inverse_kinematics(params, P, branch, R)
    A, d = jacobian_factors(params, P[reachable], theta[reachable], R if np.ndim(R) == 0 else R[reachable])
    ok = np.all(d != 0.0, axis=-1)
    Jinv = A / np.where(ok[..., None], d, 1.0)[..., None]
    each = core_condition_numbers(Jinv[ok], tuple(kinds), method) if ok.any() else {}
    out = {}
    for kind in kinds:
        K = np.full(P.shape[:-1], np.inf)
        k = np.full(len(A), np.inf)
        if ok.any():
            k[ok] = each[kind]
        K[reachable] = k
        out[kind] = K
    return out, reachable


@dataclass(frozen=True)
class WorkspaceGrid:
    """The workspace below the base sampled on a regular grid (cell centres), with condition maps.

    Attributes:
        params: The design.
        branch: Working mode the condition numbers were computed on.
        spacing: Grid step [m] (cells are cubes of this side).
        axes: The grid's x, y and z node coordinates [m].
        reachable: Mask of shape ``(nx, ny, nz)``: every arm reaches the node.
        K: ``{kind: array (nx, ny, nz)}``, ``inf`` where unreachable or singular.
    """

    params: DeltaParams
    branch: object
    spacing: float
    axes: tuple[np.ndarray, np.ndarray, np.ndarray]
    reachable: np.ndarray
    K: dict[str, np.ndarray]

    @property
    def volume(self) -> float:
        """Reachable volume below the base [m^3] (node count times cell volume)."""
        return float(np.count_nonzero(self.reachable)) * self.spacing**3

    def conditioned_volume(self, k_max: float, kind: str = "2") -> float:
        """Volume [m^3] of the nodes where ``K <= k_max`` (condition number of convention ``kind``)."""
        if kind not in self.K:
            raise InvalidInputError("kind", f"not computed on this grid; computed: {sorted(self.K)}", kind)
        if not (math.isfinite(k_max) and k_max >= 1.0):
            raise InvalidInputError("k_max", f"must be a finite bound >= 1, got {k_max!r}", k_max)
        return float(np.count_nonzero(self.K[kind] <= k_max)) * self.spacing**3

    def weighted_volume(self, kind: str = "2") -> float:
        """``integral of 1/K over the workspace`` [m^3]: the volume times the mean of ``1/K``
        (Gosselin and Angeles' global condition index), a trade-off with no threshold."""
        if kind not in self.K:
            raise InvalidInputError("kind", f"not computed on this grid; computed: {sorted(self.K)}", kind)
        return float(np.sum(1.0 / self.K[kind])) * self.spacing**3


def workspace(params: DeltaParams, spacing: float = 0.008, branch="knee_out", kinds=KINDS) -> WorkspaceGrid:
    """Sample the workspace below the base on a grid of cubes of side ``spacing`` [m].

    The grid covers ``|x|, |y| <= La + Lb`` and ``-(La + Lb) <= z <= 0``, which contains every
    reachable point (each ball joint lies within ``La + Lb`` of its motor, and the motors
    surround the axis). Computed on the vertical lines of the grid that may hold a reachable node (a necessary test,
    with a margin), in chunks of whole z slices (at most :data:`CHUNK_NODES` nodes, or one slice) to bound memory; in
    each, which nodes every arm reaches first (no angle needed), then the angles and the condition
    numbers of those nodes only, by Jacobi rotations (the same numbers, bit for bit, as :func:`condition_numbers` of
    every node with ``method="jacobi"``; those of ``np.linalg.svd`` to a few ``eps * K`` relative).
    ``kinds`` empty: the reachable nodes only (no condition numbers).

    Raises:
        InvalidInputError: if ``spacing`` is not a finite length in (0, (La + Lb) / 4].
    """
    params = check_params(params, DeltaParams)
    L = params.La + params.Lb
    if real(spacing) is None or not 0.0 < spacing <= L / 4:
        raise InvalidInputError("spacing", f"must be a length in (0, {L / 4:.4g}] m, got {spacing!r}", spacing)
    n = math.ceil(L / spacing)
    if 4 * n**3 > MAX_NODES:
        raise InvalidInputError("spacing", f"{4 * n**3} grid nodes exceed {MAX_NODES}; take a spacing of at least "
                                           f"{L / (MAX_NODES / 4) ** (1 / 3):.4g} m", spacing)
    xy = (np.arange(-n, n) + 0.5) * spacing
    z = -(np.arange(n)[::-1] + 0.5) * spacing
    reachable = np.zeros((len(xy), len(xy), len(z)), dtype=bool)
    K = {kind: np.full(reachable.shape, np.inf) for kind in kinds}
    X, Y = np.meshgrid(xy, xy, indexing="ij")
    near = _columns(params, X, Y)
    xs, ys = X[near][:, None], Y[near][:, None]
    step = max(1, CHUNK_NODES // max(len(xs), 1))  # z slices per chunk
    for k0 in range(0, len(z), step):
        zk = z[k0:k0 + step]
        reach = _reaches(params, xs, ys, zk)  # (ncolumns, nz): the x, y terms once for every slice
        reachable[:, :, k0:k0 + step][near] = reach
        if kinds and reach.any():  # the angles and the Jacobians of the reachable nodes only
            c, k = np.nonzero(reach)
            Kk, _ = condition_numbers(params, np.stack([xs[c, 0], ys[c, 0], zk[k]], axis=-1), branch, kinds, "jacobi")
            for kind in kinds:
                column = np.full(reach.shape, np.inf)
                column[reach] = Kk[kind]
                K[kind][:, :, k0:k0 + step][near] = column
    return WorkspaceGrid(params, branch, float(spacing), (xy, xy.copy(), z), reachable, K)


def _columns(params: DeltaParams, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Which vertical lines ``(x, y)`` [m] may hold a reachable point: for every arm, the forearm sphere meets the arm's
    plane (``w^2 <= Lb^2``, ``s = sqrt(Lb^2 - w^2)``) and the elbow circle can come within ``s`` of the line
    (``|u| <= La + s``, as ``rho >= |u|``), each with a margin (1e-5 of ``La + Lb``, of its square) far above what
    the reach test's ``1e-12`` slack and round-off allow: a line left out holds no node that test calls reachable."""
    L = params.La + params.Lb
    near = np.ones(np.shape(x), dtype=bool)
    for i in range(3):
        ci, si = math.cos(PHI[i]), math.sin(PHI[i])
        w2 = (ci * x + si * y) ** 2
        u = -si * x + ci * y - (params.R - params.r)
        near &= (w2 <= params.Lb**2 + 1e-5 * L**2) & (
            np.abs(u) <= params.La + np.sqrt(np.maximum(params.Lb**2 - w2, 0.0)) + 1e-5 * L)
    return near


def _reaches(params: DeltaParams, x, y, z) -> np.ndarray:
    """The ``reachable`` mask of :func:`inverse_kinematics_batch` (the same test, bit for bit), without the angles,
    at the points of coordinates ``x, y, z`` [m] (arrays that broadcast together)."""
    reachable = np.ones(np.broadcast_shapes(np.shape(x), np.shape(y), np.shape(z)), dtype=bool)
    for i in range(3):
        ci, si = math.cos(PHI[i]), math.sin(PHI[i])
        w = ci * x + si * y
        u = -si * x + ci * y - (params.R - params.r)
        reachable &= circle_sphere_reach(u, z, w, params.La, params.Lb)
    return reachable
