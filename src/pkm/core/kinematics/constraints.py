"""Loop-closure equations: residual, Jacobian and acceleration drift.

Conventions (one row block per closure, in spec order):

* point closure (``CONTACT_3D``, ``LOCAL_WORLD_ALIGNED``): residual
  ``r = p_A - p_B`` (world axes, m). The Jacobian is
  exactly ``dr/dq`` (on the tangent space).
* frame closure (``CONTACT_6D``, ``LOCAL``): residual ``r = -log6(A^-1 B)``
  (``[linear; angular]`` in frame A). Pinocchio's Jacobian is the velocity of
  A relative to B seen in A, which equals ``dr/dq`` at closure; away from it,
  Newton's method with this Jacobian still converges quadratically.

The drift is ``gamma = dJ/dt v``, so that the closure holds at second order
when ``J a + gamma = 0``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from pkm.core.model.scale import JacobianScales

if TYPE_CHECKING:
    from pkm.core.model.mechanism import Mechanism



def residual(mech: Mechanism, q: np.ndarray) -> np.ndarray:
    """Closure residual at ``q`` (see module doc)."""
    pin.framesForwardKinematics(mech.model, mech.data, q)
    return residual_from(mech, mech.data)


def residual_from(mech: Mechanism, d: pin.Data) -> np.ndarray:
    """The closure residual from the frame placements already in ``d`` (see :class:`pkm.core.Configuration`)."""
    out = np.empty(mech.n_constraints)
    k = 0
    for c, (fa, fb) in zip(mech.spec.closures, mech.closure_frames):
        if c.type == "point":
            out[k:k + 3] = d.oMf[fa].translation - d.oMf[fb].translation
            k += 3
        else:
            out[k:k + 6] = -pin.log6(d.oMf[fa].actInv(d.oMf[fb])).vector
            k += 6
    return out


def jacobian(mech: Mechanism, q: np.ndarray) -> np.ndarray:
    """Constraint Jacobian (n_constraints x nv), in the conventions of ``mech.constraint_models``.

    Built from frame Jacobians: ``J_A - J_B`` (world-aligned, linear rows) for a point closure,
    ``J_A - Ad(A^-1 B) J_B`` (local) for a frame closure. This equals
    ``pin.getConstraintsJacobian`` (a test pins it to 1e-15), which Pinocchio 4.1 refuses for
    models with mimic joints.
    """
    pin.computeJointJacobians(mech.model, mech.data, q)
    pin.updateFramePlacements(mech.model, mech.data)
    return jacobian_from(mech, mech.data)


def jacobian_from(mech: Mechanism, d: pin.Data) -> np.ndarray:
    """The constraint Jacobian from the joint Jacobians and frame placements already in ``d``."""
    m = mech.model
    rows = []
    for c, (fa, fb) in zip(mech.spec.closures, mech.closure_frames):
        if c.type == "point":
            rows.append(pin.getFrameJacobian(m, d, fa, pin.LOCAL_WORLD_ALIGNED)[:3]
                        - pin.getFrameJacobian(m, d, fb, pin.LOCAL_WORLD_ALIGNED)[:3])
        else:
            aMb = d.oMf[fa].actInv(d.oMf[fb])
            rows.append(pin.getFrameJacobian(m, d, fa, pin.LOCAL)
                        - aMb.toActionMatrix() @ pin.getFrameJacobian(m, d, fb, pin.LOCAL))
    return np.vstack(rows)


def pinocchio_jacobian(mech: Mechanism, q: np.ndarray) -> np.ndarray:
    """The same matrix from ``pin.getConstraintsJacobian`` (models without mimic joints only)."""
    m, d = mech.model, mech.data
    pin.computeJointJacobians(m, d, q)
    for cm, cd in zip(mech.constraint_models, mech.constraint_datas):
        cm.calc(m, d, cd)  # Pinocchio 4 returns a stale Jacobian without it
    return pin.getConstraintsJacobian(m, d, mech.constraint_models, mech.constraint_datas)


def largest(mech: Mechanism, Q: np.ndarray) -> np.ndarray:
    """The largest closure residual [m or rad] at each configuration of ``Q`` (n x nq): what a result reports as its
    ``residual`` where a solver's own residual counts lengths in the characteristic length."""
    return np.array([np.max(np.abs(residual(mech, q)), initial=0.0) for q in np.atleast_2d(Q)])


def worst_closure(mech: Mechanism, r: np.ndarray) -> tuple[float, int, str | None]:
    """The closure left most open by the residual ``r`` (its first ``n_constraints`` entries, in spec order):
    ``(norm of its block [m or rad], its 1-based index, its name)``; ``(0.0, 0, None)`` without closures."""
    worst: tuple[float, int, str | None] = (0.0, 0, None)
    k = 0
    for i, (cm, c) in enumerate(zip(mech.constraint_models, mech.spec.closures)):
        n = cm.residualSize()
        gap = float(np.linalg.norm(r[k:k + n]))
        if worst[2] is None or gap > worst[0]:
            worst = (gap, i + 1, c.name)
        k += n
    return worst


def block_gap(mech: Mechanism, r: np.ndarray, index: int) -> float:
    """The norm [m or rad] of closure ``index``'s block (1-based, as :func:`worst_closure` gives it) of the raw
    residual ``r``: the number to print for the closure a scaled residual found worst."""
    start = sum(cm.residualSize() for cm in mech.constraint_models[:index - 1])
    return float(np.linalg.norm(r[start:start + mech.constraint_models[index - 1].residualSize()]))


#: A configuration counts as assembled where no closure is open by more than this, relative to the mechanism's
#: characteristic length (:attr:`~pkm.core.model.mechanism.Mechanism.characteristic_length`; a rotation's gap in rad).
CLOSED_RTOL = 1e-6


def check_closed(mech: Mechanism, q: np.ndarray, what: str = "q") -> None:
    """Refuse a configuration whose loops are not closed (by :data:`CLOSED_RTOL`, relative to the mechanism's size):
    an answer computed there (a Jacobian, a capability) would be of no assembly of the mechanism.

    Raises:
        InvalidInputError: naming the closure most open, by how much [m or rad] and relative to the size.
    """
    from pkm.errors import InvalidInputError

    L = mech.characteristic_length
    raw = residual(mech, q)
    gap, index, name = worst_closure(mech, raw[:mech.n_constraints] * JacobianScales.of(mech).closure_residual)
    if gap > CLOSED_RTOL:
        open_by = block_gap(mech, raw, index)
        raise InvalidInputError(what, f"the loops are not closed: closure {name!r} is open by {open_by:.3g} (m or rad), "
                                      f"{gap:.3g} of the mechanism's size {L:.3g} m (at most {CLOSED_RTOL:g}); close "
                                      "them first (pkm.close_loops, pkm.solve_ik)", name)


def residual_and_jacobian(mech: Mechanism, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Both at once, with one kinematics pass (the loop closure's Newton step)."""
    pin.computeJointJacobians(mech.model, mech.data, q)
    pin.updateFramePlacements(mech.model, mech.data)
    return residual_from(mech, mech.data), jacobian_from(mech, mech.data)


def drift(mech: Mechanism, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``gamma = dJ/dt(q, v) v``: the closure acceleration produced by ``v`` alone (a = 0)."""
    m, d = mech.model, mech.data
    pin.forwardKinematics(m, d, q, v, np.zeros(m.nv))
    pin.updateFramePlacements(m, d)
    out = np.empty(mech.n_constraints)
    k = 0
    for c, (fa, fb) in zip(mech.spec.closures, mech.closure_frames):
        if c.type == "point":
            aa = pin.getFrameClassicalAcceleration(m, d, fa, pin.LOCAL_WORLD_ALIGNED).linear
            ab = pin.getFrameClassicalAcceleration(m, d, fb, pin.LOCAL_WORLD_ALIGNED).linear
            out[k:k + 3] = aa - ab
            k += 3
        else:
            # relative acceleration of A w.r.t. B in A: a_A - X a_B - v_A x (X v_B), X = Ad(A^-1 B)
            aMb = d.oMf[fa].actInv(d.oMf[fb])
            va = pin.getFrameVelocity(m, d, fa, pin.LOCAL)
            vb = aMb.act(pin.getFrameVelocity(m, d, fb, pin.LOCAL))
            aa = pin.getFrameAcceleration(m, d, fa, pin.LOCAL)
            ab = aMb.act(pin.getFrameAcceleration(m, d, fb, pin.LOCAL))
            out[k:k + 6] = (aa - ab - va.cross(vb)).vector
            k += 6
    return out
