"""Pose selection: the calibration poses that make the base parameters best observed.

Candidates are random actuator readings around the reference, within ``spread`` of it (per unit, rad or m: by default
:data:`SPREAD` rad for a revolute actuator and :data:`SPREAD` characteristic lengths for a prismatic one,
:func:`default_spread`: the same poses for a robot of 5 cm and of 5 m), kept where the
nominal mechanism closes, within its joint limits (:meth:`~pkm.core.Mechanism.outside_limits`: the workspace) and
away from singularities: the closure system's smallest singular value over its largest (:func:`conditioning`) at
least ``margin``. Among them, ``n`` poses are chosen greedily to maximise the observability index **O1** (Borm and
Menq: the product of the singular values of the base parameters' scaled Jacobian, that is ``sqrt(det(J^T J))``, the
D-optimal criterion), each step adding the candidate that raises ``log det(J^T J + eps I)`` most (the matrix
determinant lemma: ``log det(I + J_k A^{-1} J_k^T)``). O1 is the one optimised; O4 (the noise amplification
``sigma_min^2 / sigma_max``) is reported for the choice (:attr:`PosePlan.o4`), not optimised.

**Poses the robot does not reach.** The candidates close on the nominal mechanism; the robot's own geometry differs,
and near the edge of the workspace or a singularity, where O1 likes its poses, some do not close on it: the robot
refuses them or faults there. With ``reachable`` (a trial move on the robot, or the simulated robot's
:meth:`~pkm.core.calibration.measurement.CalibrationModel.reaches`), a pose the greedy choice picks is first tried:
one the robot does not reach is left out (:attr:`PosePlan.refused`, a :class:`~pkm.errors.PkmWarning` names them)
and the next best candidate taken. The shipped hexapod perturbed by 2 mm and 0.5 degrees (``pkm calibrate plan
--simulate 1``) does not reach 13 of the 30 poses O1 picks without ``reachable``, 19 of the 49 it picks with it.
A choice with no refused pose is the one made without ``reachable``.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np

from pkm.core.calibration.identifiable import BaseGeometry, base_geometry, stacked_jacobian
from pkm.core.calibration.measurement import CalibrationModel, check_model
from pkm.core.identification.base import closed_draws, per_unit
from pkm.core.model.mechanism import Mechanism
from pkm.core.model.scale import JacobianScales
from pkm.errors import InvalidInputError, PkmError, PkmWarning
from pkm.validation import as_count, as_scalar

#: The closure system's default singularity margin (smallest over largest singular value, the matrix homogenised:
#: :func:`conditioning`).
MARGIN = 1e-3
#: The default spread of the readings about the reference: rad for a revolute actuator, characteristic lengths for a
#: prismatic one (:func:`default_spread`). At 0.1, poses of the shipped Delta and 3-PRS see their base parameters so
#: poorly that the least squares crawl (40 poses: 589 and 397 evaluations; at 0.2, 12 and 11); the 3-PRS's 16 poses:
#: log O1 -104 with 0.2 L, -146 with 0.1 m; an excitation's 0.03 m gives -214.
SPREAD = 0.2


def default_spread(mech: Mechanism) -> dict[str, float]:
    """The candidates' default spread per unit: :data:`SPREAD` rad for an angle, :data:`SPREAD` characteristic
    lengths for a length (a robot of 5 cm and one of 5 m are spread alike)."""
    return {"rad": SPREAD, "m": SPREAD * mech.characteristic_length}


@dataclass(frozen=True)
class PosePlan:
    """Chosen calibration poses.

    Attributes:
        readings: The actuator readings (n x na) [rad or m].
        o1: ``log`` of the O1 index (the product of the scaled base Jacobian's singular values).
        o4: The O4 index (``sigma_min^2 / sigma_max``) of the same Jacobian.
        candidates: The candidates drawn that closed within the limits and the margin.
        base: The base geometry the index is computed for.
        refused: The readings of the candidates the choice picked and ``reachable`` refused (k x na, in the order
            they were picked; none without ``reachable``).
    """

    readings: np.ndarray
    o1: float
    o4: float
    candidates: int
    base: BaseGeometry
    refused: np.ndarray = field(default_factory=lambda: np.empty((0, 0)))


def conditioning(model: CalibrationModel, readings: np.ndarray, x: np.ndarray | None = None) -> np.ndarray:
    """The closure system's ``sigma_min / sigma_max`` at each pose (the twin's closure and actuated rows, along the
    tangent space; the idle motions' zeros left out: :attr:`CalibrationModel.idle`): 0 at a singularity. The matrix
    is homogenised by the characteristic length ``L`` as pkm's singularity measures are
    (:class:`~pkm.core.model.scale.JacobianScales`: a rotation row and a revolute actuator's row times ``L``, a
    length column times ``L``), so that a robot of 5 cm and one of 5 m have the same margin."""
    M = np.atleast_2d(readings)
    Q = model.close(x, M)
    _, Gq = model._map("close", len(M))(Q.T, M.T, model.vector(x))
    G = np.array(Gq).reshape(-1, len(M), model.mech.nv).transpose(1, 0, 2)
    scales = JacobianScales.of(model.mech)
    rows = np.concatenate([scales.constraint_rows, scales.length / scales.actuated])
    s = np.linalg.svd(rows[:, None] * G * scales.columns, compute_uv=False)
    return s[:, -1 - model.idle] / s[:, 0]


def candidates(model: CalibrationModel, n: int, *, spread: float | Mapping[str, float] | None = None,
               margin: float = MARGIN, seed: int = 0) -> np.ndarray:
    """``n`` candidate readings (module doc), drawn by :func:`~pkm.core.identification.base.closed_draws` (as the
    identification's random states are). ``spread`` [rad or m]: the largest change of a reading from the reference,
    per unit (``{"rad": 0.2, "m": 0.1}``; default :func:`default_spread`: 0.2 rad, 0.2 characteristic lengths), or
    one number where the actuators are all revolute or all prismatic (:func:`~pkm.core.identification.base.per_unit`).

    Raises:
        InvalidInputError: fewer than ``n`` of ``20 n`` draws qualify (a smaller spread or margin may help); one
            ``spread`` for revolute and prismatic actuators alike.
    """
    n = as_count(n, "n")
    bound = per_unit(model.mech, default_spread(model.mech) if spread is None else spread, "spread")
    margin = as_scalar(margin, "margin", low=0.0)
    rng = np.random.default_rng(seed)
    out: list[np.ndarray] = []
    for qa, _ in closed_draws(model.mech, rng, bound, 20 * n):
        try:
            if conditioning(model, qa[None])[0] < margin:
                continue
        except PkmError:  # (a singular pose: drawn again)
            continue
        out.append(qa)
        if len(out) == n:
            break
    if len(out) < n:
        raise InvalidInputError("spread", f"only {len(out)} of {n} candidate poses closed within the limits and the "
                                          f"singularity margin {margin:g}", np.asarray(bound).tolist())
    return np.array(out)


def calibration_poses(model: CalibrationModel, n: int, *, pool: int | None = None,
                      spread: float | Mapping[str, float] | None = None, margin: float = MARGIN, seed: int = 0,
                      reachable: Callable[[np.ndarray], bool] | None = None) -> PosePlan:
    """``n`` poses maximising O1 among ``pool`` candidates (default ``4 n``; ``spread`` as :func:`candidates`')
    (module doc).

    Args:
        reachable: Whether the robot reaches one candidate's readings (na,), asked of each candidate the choice
            picks, in order: one refused is left out and the next best taken (module doc; :attr:`PosePlan.refused`).
            Fewer than ``n`` poses are returned, with a warning, where the pool runs out of candidates it accepts.

    Raises:
        InvalidInputError: too few poses for the parameters the measurements see or for the base parameters (asked
            for, or left once ``reachable`` refused some), or too few candidates.

    Warns:
        PkmWarning: ``reachable`` refused candidates the choice picked (how many, which), or fewer than ``n`` poses.

    Examples:
        >>> import pkm
        >>> model = pkm.CalibrationModel(pkm.load("prs3"), "pose")
        >>> plan = pkm.calibration_poses(model, 12, spread=0.2, pool=14)
        >>> plan.readings.shape, plan.candidates, len(plan.base)
        ((12, 3), 14, 34)
    """
    model, n = check_model(model), as_count(n, "n")
    C = candidates(model, pool or 4 * n, spread=spread, margin=margin, seed=seed)
    base = base_geometry(model, C, precise=False)
    rows = len(model.rows.labels)
    need = fewest_poses(model, base)
    if n < need:
        raise InvalidInputError("n", f"{n} poses give {n * rows} residuals for {len(model.names) - len(base.unseen)} "
                                     f"parameters the measurements see ({len(base)} base parameters): give at least "
                                     f"{need}", n)
    W = stacked_jacobian(model, C)[:, list(base.independent)]
    W = W / np.linalg.norm(W, axis=0)
    blocks = W.reshape(len(C), rows, -1)
    p = blocks.shape[2]
    A = 1e-9 * np.eye(p)
    chosen: list[int] = []
    refused: list[int] = []
    for _ in range(n):
        Ainv = np.linalg.inv(A)
        gain = np.array([-np.inf if k in chosen or k in refused else
                         np.linalg.slogdet(np.eye(rows) + B @ Ainv @ B.T)[1] for k, B in enumerate(blocks)])
        k = int(np.argmax(gain))
        while reachable is not None and gain[k] > -np.inf and not reachable(C[k]):
            refused.append(k)
            gain[k] = -np.inf
            k = int(np.argmax(gain))
        if gain[k] == -np.inf:  # (every candidate chosen or refused)
            break
        chosen.append(k)
        A = A + blocks[k].T @ blocks[k]
    if len(chosen) < n:
        what = (f"the robot reaches only {len(chosen)} of the {len(C)} candidates ({len(refused)} refused)" if refused
                else f"the pool holds only {len(C)} candidates")
        if len(chosen) < need:
            raise InvalidInputError("reachable" if refused else "pool",
                                    f"{what}, fewer than the {need} poses the parameters need: a larger pool, a "
                                    f"smaller spread or more margin from singularities (pkm calibrate plan --poses, "
                                    f"--spread)", len(chosen))
        warnings.warn(f"{what}: {len(chosen)} poses, not {n}", PkmWarning, stacklevel=2)
    if refused:
        warnings.warn(f"the robot does not reach {len(refused)} of the {len(chosen) + len(refused)} poses the O1 "
                      f"choice picked (of the {len(C)} candidates: {', '.join(str(k + 1) for k in refused)}; "
                      f"PosePlan.refused holds their readings): left out, the next best candidates taken",
                      PkmWarning, stacklevel=2)
    J = blocks[chosen].reshape(-1, p)
    s = np.linalg.svd(J, compute_uv=False)
    return PosePlan(C[chosen], float(np.sum(np.log(s))), float(s[-1] ** 2 / s[0]), len(C), base,
                    C[refused].reshape(len(refused), C.shape[1]))


def fewest_poses(model: CalibrationModel, base: BaseGeometry) -> int:
    """The fewest poses a calibration of ``model`` accepts: as many residual rows as parameters the measurements
    see (:func:`~pkm.core.calibration.identifiable.base_geometry`'s rule, which ``calibrate`` applies to the
    poses it is given) and more than the base parameters (:func:`~pkm.core.calibration.estimate.calibrate`'s)."""
    rows = len(model.rows.labels)
    live = len(model.names) - len(base.unseen)
    return max(-(-live // rows), len(base) // rows + 1)


__all__ = ["MARGIN", "SPREAD", "PosePlan", "calibration_poses", "candidates", "conditioning", "default_spread",
           "fewest_poses"]
