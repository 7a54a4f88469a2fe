"""The regressor as a twin expression: ``Y_a = ∂τ_a/∂θ``, exact, compiled with the other kernels.

The twin's inverse dynamics (:attr:`~pkm.core.twin.tree.Twin.inverse_dynamics`: joint rates and accelerations from
the actuated ones, RNEA under gravity, the projection by one transposed solve) is built once more with every body's
ten standard parameters as symbols ``θ`` (Pinocchio's order, :data:`~pkm.core.model.bodies.BODY_FIELDS`:
``m``, the first moments ``h = m c``, the inertia about the joint frame's origin), and differentiated by CasADi:
the efforts are linear in ``θ``, so the Jacobian holds no ``θ`` and is the regressor itself, not an approximation.
The drives' columns follow (reflected inertia ``q̈_j``, viscous ``q̇_j``, Coulomb ``tanh(q̇_j / COULOMB_VELOCITY)``,
offset 1), as in :func:`pkm.core.identification.regressor.regressor`, whose column order this is.

A body's spatial force from its parameters and a spatial motion ``[v; ω]``: ``f = m v - h x ω``,
``n = I_o ω + h x v`` (Featherstone's, the inertia about the frame's origin), which is what Pinocchio's
``Inertia.toDynamicParameters`` stores.

Mimic joints (the hexapod's β coupling) are joints of the twin like any other, so the compiled route needs no
special case; mechanisms with idle motions have none (the twin's passive solve needs none; pkm's Python regressor
handles them).
"""

from __future__ import annotations

import weakref

import casadi as cs

from pkm.core.dynamics.model import COULOMB_VELOCITY
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.twin.spatial import Expr
from pkm.core.twin.tree import Twin, theta_times
from pkm.errors import InvalidInputError


class ParametricTwin(Twin):
    """A :class:`Twin` whose bodies' inertial parameters are the symbols :attr:`theta` (10 per body)."""

    def __init__(self, mech: Mechanism):
        super().__init__(mech)
        #: The standard parameters, ten per body in joint order (symbols).
        self.theta = cs.SX.sym("theta", 10 * (len(self.joints) - 1))

    def _inertia_times(self, j: int, m: Expr) -> Expr:
        return theta_times(self.theta[10 * (j - 1):10 * j], m)


def regressor_expression(twin: ParametricTwin) -> cs.SX:
    """``Y_a`` (na x p) of the twin's symbols :attr:`~Twin.q`, :attr:`~Twin.qd`, :attr:`~Twin.qdd` (module doc)."""
    mech = twin.mech
    theta = twin.theta
    bodies = cs.substitute(cs.jacobian(twin.inverse_dynamics, theta), theta, cs.DM.zeros(theta.shape[0]))
    drives = cs.SX.zeros(mech.na, 4 * mech.na)
    for i in range(mech.na):
        drives[i, 4 * i:4 * i + 4] = cs.horzcat(twin.qdd[i], twin.qd[i], cs.tanh(twin.qd[i] / COULOMB_VELOCITY), 1.0)
    return cs.horzcat(bodies, drives)


def regressor_function(mech: Mechanism, twin: ParametricTwin | None = None) -> cs.Function:
    """``pkm_regressor(q, qd, qdd) -> (Yt, pivot)``: the regressor transposed (p x na, dense, after CSE: its
    column-major nonzeros are ``Y_a`` row after row, so that a batch's output is the stacked regressor without a
    copy) and the passive solve's smallest relative pivot
    (:meth:`~pkm.core.twin.linear.PivotedLU.smallest_relative_pivot`).

    Built once per mechanism (the compiled kernels and the 50-digit rank route take the same one), on ``twin`` where
    given (a :class:`ParametricTwin` of ``mech`` whose kinematics, closure rows and passive solve another expression
    has built already: the 50-digit route's Newton step), else on a new one.

    Raises:
        SpecError: the mechanism has idle motions, or a joint kind the twin does not handle.
        InvalidInputError: ``twin`` is not a :class:`ParametricTwin` of ``mech``.
    """
    mech = check_mechanism(mech)
    if twin is not None and (not isinstance(twin, ParametricTwin) or twin.mech is not mech):
        raise InvalidInputError("twin", "expected a ParametricTwin of the mechanism given", type(twin).__name__)
    if mech not in _FUNCTIONS:
        twin = ParametricTwin(mech) if twin is None else twin
        Y = regressor_expression(twin)
        outs = cs.cse([cs.densify(Y.T), cs.densify(cs.SX(twin.passive_lu.smallest_relative_pivot()))])
        _FUNCTIONS[mech] = cs.Function("pkm_regressor", [twin.q, twin.qd, twin.qdd], outs, ["q", "qd", "qdd"],
                                       ["Yt", "pivot"])
    return _FUNCTIONS[mech]


_FUNCTIONS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # mechanism -> its regressor_function


__all__ = ["ParametricTwin", "regressor_expression", "regressor_function"]
