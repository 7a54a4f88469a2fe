"""Identifiable geometry: the base calibration parameters, the combinations the measurements can see.

The measurement Jacobians ``dy/dx`` (:class:`~pkm.core.calibration.measurement.CalibrationModel`) stacked at a set
of poses (the rotation rows times the mechanism's characteristic length, so that a rank means the same on a robot of
5 cm and of 5 m), the columns scaled to unit norm: the rank and the combinations follow by the same two routes as the
dynamic base parameters (:mod:`pkm.core.identification.base`):

1. **double precision**: a QR decomposition with column pivoting (``scipy.linalg.qr``), the rank at the largest
   drop of the relative pivots (:func:`~pkm.core.identification.rank.decide_rank`), the dependent columns
   expressed on the independent ones (``K = R_11^{-1} R_12``) and named as ``base.py`` names them;
2. **the exact route**: the same Jacobian in :data:`~pkm.core.identification.precise.DIGITS`-digit arithmetic, the
   model's constants recognised (:func:`~pkm.core.identification.precise.recognise`), the configurations closed
   again by Newton's method in ``mpmath``, the implicit-function solve done in ``mpmath``, and the rank of the
   fixed-point pivoted QR (:func:`~pkm.core.identification.precise.pivoted_qr`) decided with the rounding floor of
   :func:`~pkm.core.identification.precise.precise_rank`.

What a model cannot see is stated: the parameters whose column is zero at every pose (:attr:`BaseGeometry.unseen`:
a free joint's origin, a frame that carries nothing measured) and, for every other dependent parameter, the
independent ones it is absorbed by (:attr:`BaseGeometry.absorbed`: an actuator offset by the joint origin along its
axis, a base joint's position by the tracker's frame).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.calibration.measurement import CalibrationModel, check_model
from pkm.core.identification.base import base_split
from pkm.core.identification.rank import RankDecision, decide_rank
from pkm.errors import InvalidInputError


@dataclass(frozen=True)
class BaseGeometry:
    """The identifiable combinations of the calibration parameters (module doc).

    Attributes:
        names: Each combination, readable: ``"leg1.offset + leg1.z"``.
        map: ``P`` (n_base x p): ``beta = P x``, linearised at the nominal parameters.
        independent: The indices (into the parameters) each combination is named after: the parameters an
            estimate frees, the others held at their nominal values.
        decision: The double-precision rank decision.
        precise: The exact route's rank decision (None when not run); :attr:`routes_agree` compares.
        unseen: The parameters no measurement sees (zero columns).
        absorbed: Every other dependent parameter -> the independent ones it is absorbed by.
        parameters: The names of all parameters (the columns).
        rows: The Jacobian rows stacked (poses times rows per pose).
    """

    names: tuple[str, ...]
    map: np.ndarray
    independent: tuple[int, ...]
    decision: RankDecision
    precise: RankDecision | None
    unseen: tuple[str, ...]
    absorbed: dict[str, tuple[str, ...]]
    parameters: tuple[str, ...]
    rows: int

    def __len__(self) -> int:
        return len(self.names)

    @property
    def routes_agree(self) -> bool | None:
        """Whether the exact route finds the same count (None when it was not run)."""
        return None if self.precise is None else self.precise.rank == len(self.names)


def _row_scale(model: CalibrationModel) -> np.ndarray:
    """Each residual row's weight in the rank: 1 for lengths, the characteristic length for angles."""
    L = max(model.mech.characteristic_length, 1e-12)
    return np.array([L if u == "rad" and model.kind != "passive" else 1.0 for u in model.rows.units])


def stacked_jacobian(model: CalibrationModel, readings: ArrayLike, x: ArrayLike | None = None) -> np.ndarray:
    """The residual Jacobian at ``readings`` (n poses) and parameters ``x`` (default nominal), stacked
    ((n rows) x p), rows weighted as the rank needs (module doc)."""
    y, J, _ = model.evaluate(x, readings)
    _, Jr = model.residual(y, y, J)
    assert Jr is not None
    Jr = Jr * _row_scale(model)[None, :, None]
    return Jr.reshape(-1, Jr.shape[2])


def base_geometry(model: CalibrationModel, readings: ArrayLike, *, precise: bool = True,
                  precise_poses: int | None = None) -> BaseGeometry:
    """The base calibration parameters of ``model`` measured at ``readings`` (n x na actuator readings) by the
    double-precision route and, with ``precise``, the exact route on the first ``precise_poses`` poses (default:
    enough for as many rows as parameters, plus two poses) (module doc).

    Raises:
        InvalidInputError: fewer rows than the parameters the measurements see; ``model`` no
            :class:`CalibrationModel`.

    Examples:
        >>> import pkm
        >>> model = pkm.CalibrationModel(pkm.load("prs3"), "pose")
        >>> poses = pkm.calibration_poses(model, 12, spread=0.2, pool=14).readings
        >>> base = pkm.base_geometry(model, poses, precise=False)
        >>> len(base), base.unseen[:2]
        (34, ('knee_1.pitch', 'coupler_1_tip_fixed.x'))
        >>> sorted(base.absorbed["slider_1.offset"])  # (a slider's offset: seen only with its tilt and the tracker's)
        ['slider_1.pitch', 'slider_2.pitch', 'slider_3.pitch', 'tracker.pitch', 'tracker.z']
    """
    model = check_model(model)
    M = np.atleast_2d(np.asarray(readings, dtype=float))
    W = stacked_jacobian(model, M)
    names = model.names
    p = len(names)
    scale = np.linalg.norm(W, axis=0)
    live = np.flatnonzero(scale > 1e-12 * scale.max())
    if W.shape[0] < len(live):
        raise InvalidInputError("readings", f"{len(M)} poses give {W.shape[0]} rows for {len(live)} parameters the "
                                            f"measurements see: give at least "
                                            f"{-(-len(live) // len(model.rows.labels))} poses", len(M))
    split = base_split(W, names)
    decision, Pmap, combos, K = split.decision, split.P, split.names, split.K
    ind, dep, order = split.independent, split.dependent, split.order
    unseen = tuple(names[k] for k in range(p) if k not in set(live))
    absorbed = {names[j]: tuple(names[int(ind[i])] for i in np.flatnonzero(K[:, c] != 0.0))
                for c, j in enumerate(dep)}
    second = None
    if precise:
        n = precise_poses or min(len(M), -(-len(live) // len(model.rows.labels)) + 2)
        second = precise_rank(model, M[:n])
    return BaseGeometry(tuple(combos), Pmap, tuple(int(ind[row]) for row in order), decision, second, unseen,
                        absorbed, names, W.shape[0])


# ---------------------------------------------------------------------- the exact route
def _mp_solve(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """``A^{-1} B`` for a square ``A`` of ``mpmath`` numbers (Gaussian elimination with partial pivoting)."""
    A, B = A.copy(), B.copy()
    n = A.shape[0]
    for k in range(n):
        i = k + int(np.argmax([abs(a) for a in A[k:, k]]))
        if A[i, k] == 0:
            raise InvalidInputError("model", "the closure Jacobian is singular at a pose (exact route)", k)
        if i != k:
            A[[k, i]], B[[k, i]] = A[[i, k]], B[[i, k]]
        f = A[k + 1:, k] / A[k, k]
        A[k + 1:, k:] = A[k + 1:, k:] - np.outer(f, A[k, k:])
        B[k + 1:] = B[k + 1:] - np.outer(f, B[k])
    X = np.empty_like(B)
    for k in range(n - 1, -1, -1):
        X[k] = (B[k] - A[k, k + 1:] @ X[k + 1:]) / A[k, k]
    return X


def _lstsq(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """The least-squares solution of ``A X = B`` (``A`` of full column rank, ``mpmath``): the solve itself for a
    square ``A``, else the normal equations (a consistent tall system: its exact solution either way)."""
    return _mp_solve(A, B) if A.shape[0] == A.shape[1] else _mp_solve(A.T @ A, A.T @ B)


def _angle(c: float, recognise: Callable[[float], tuple[Any, bool]]) -> tuple[Any, bool]:
    """An angle's exact value: a recognised number, else a recognised multiple of pi (``pi/2``, ``2 pi/3``: what a
    designer means by ``1.5707963267948966``), else its binary value (not recognised)."""
    import mpmath

    exact, ok = recognise(c)
    if ok:
        return exact, True
    turns, ok = recognise(c / math.pi)
    if ok and abs(float(turns) * math.pi - c) <= 4.0 * math.ulp(c):
        return turns * mpmath.pi, True
    return exact, False


def precise_rank(model: CalibrationModel, readings: ArrayLike) -> RankDecision:
    """The rank of the stacked Jacobian at ``readings`` in :data:`~pkm.core.identification.precise.DIGITS` digits
    (module doc, route 2).

    Raises:
        ConvergenceError: a pose does not close to :data:`~pkm.core.identification.precise.CLOSURE_TOL`.
        InvalidInputError: a closure Jacobian is singular, or the mechanism has idle motions.
    """
    import casadi as cs
    import mpmath

    from pkm.core.identification.precise import (
        CLOSURE_TOL,
        DIGITS,
        MAX_NEWTON,
        MODEL_FLOOR,
        Program,
        pivoted_qr,
        recognise,
    )
    from pkm.errors import ConvergenceError

    if model.idle:
        raise InvalidInputError("precise", f"{model.mech.name} has {model.idle} idle motion(s): the exact route "
                                           f"solves the closure as a square system; use precise=False", model.idle)
    M = np.atleast_2d(np.asarray(readings, dtype=float))
    Q = model.close(None, M)
    tw = model.twin
    dq = cs.SX.sym("dq", model.mech.nv)
    with mpmath.workdps(DIGITS):
        full, close = Program(model._full), Program(model._close)
        retract = Program(cs.Function("retract", [tw.q, dq], [cs.densify(tw.retract(dq))]))

        values, known = [], 0
        for value, unit in zip(model.parameters.nominal, model.parameters.units):
            exact, ok = _angle(float(value), recognise) if unit == "rad" else recognise(float(value))
            values.append(exact)
            known += ok
        x = np.array([[v] * len(M) for v in values], dtype=object)
        m = np.array([[recognise(float(a))[0] for a in row] for row in M.T], dtype=object)
        q = np.array([[mpmath.mpf(float(a)) for a in row] for row in Q.T], dtype=object)
        nv, p, S = model.mech.nv, len(model.names), len(M)
        for _ in range(MAX_NEWTON):
            g, Gq = close(q, m, x)
            worst = max(abs(a) for a in g.ravel())
            if worst < CLOSURE_TOL:
                break
            step = np.empty((nv, S), dtype=object)
            for k in range(S):
                G = Gq[:, k].reshape(nv, -1).T  # (column-major nonzeros of a dense matrix)
                step[:, k] = -_lstsq(G, g[:, k:k + 1])[:, 0]
            q = retract(q, step)[0]
        else:
            raise ConvergenceError(f"loop closure in {DIGITS} digits", float(worst), MAX_NEWTON, CLOSURE_TOL)
        g, Gq, Gx, y, Yq, Yx = full(q, m, x)
        rows_g = g.shape[0]
        ny = y.shape[0]
        scale = _row_scale(model)
        blocks = []
        for k in range(S):
            G = Gq[:, k].reshape(nv, rows_g).T
            dqdx = -_lstsq(G, Gx[:, k].reshape(p, rows_g).T)
            J = Yx[:, k].reshape(p, ny).T + Yq[:, k].reshape(nv, ny).T @ dqdx
            if model.kind == "pose":  # (the rotation residual's derivative at a zero residual: vee of skew(R^T dR))
                R = y[3:, k].reshape(3, 3).T
                dRm = np.empty((3, 3, p), dtype=object)
                for i in range(3):
                    for j in range(3):
                        dRm[i, j] = J[3 + i + 3 * j]
                A = np.einsum("ji,jlp->ilp", R, dRm)
                rot = np.stack([A[2, 1] - A[1, 2], A[0, 2] - A[2, 0], A[1, 0] - A[0, 1]]) / 2
                J = np.vstack([J[:3], rot])
            blocks.append(J * np.array([mpmath.mpf(float(s)) for s in scale], dtype=object)[:, None])
        W = np.vstack(blocks)
        unrecognised = full.unrecognised + close.unrecognised + retract.unrecognised + len(values) - known
        floor = MODEL_FLOOR if unrecognised else 10.0 ** (-DIGITS + 10)
        norms = np.array([mpmath.sqrt((W[:, j] * W[:, j]).sum()) for j in range(W.shape[1])], dtype=object)
        top = max(norms)
        live = np.flatnonzero([c > top * floor for c in norms])
        if W.shape[0] < len(live):
            raise InvalidInputError("readings", f"{S} poses give {W.shape[0]} rows for {len(live)} seen parameters "
                                                f"(exact route): give more poses", S)
        rel, _ = pivoted_qr(W[:, live] / norms[live], stop=10.0 ** (-DIGITS + 10))
    return decide_rank(rel, floor=floor)


__all__ = ["BaseGeometry", "base_geometry", "precise_rank", "stacked_jacobian"]
