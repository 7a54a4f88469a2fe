"""The actuator-space model (:mod:`pkm.core.dynamics.model`) as expressions of the twin: ``M_a``, ``h_a``, ``g_a``,
the friction ``f_a`` and the forward dynamics, for the kernels (:class:`~pkm.core.twin.kernels.Kernels`) and the
compiled simulation (:mod:`~pkm.core.twin.simulation`).

With the closure rows ``W J = [J_a J_p]`` (:attr:`Twin.closure_rows`), the joint rates ``v = G qd`` and
accelerations ``a = G qdd + a_b`` come from the sparse LU of ``J_p`` with its pivots fixed at the reference (under
redundant actuation the core's pseudo-inverse, :attr:`~pkm.core.twin.tree.Twin.passive_solve`: the same ``G``), and
``τ(q, qd, qdd) = Gᵀ rnea(q, v, a)`` is the twin's inverse dynamics (one transposed solve, no matrix ``G``). It is
linear in ``qdd``, so

* ``M_a = ∂τ/∂qdd`` (the lower triangle, mirrored: exactly symmetric); ``h_a = τ(q, qd, 0)``; ``g_a = τ(q, 0, 0)``;
* ``f_a = Gᵀ (-D v - F tanh(v / c))`` (Pinocchio's ``damping`` ``D`` and ``friction`` ``F``, the actuators' viscous
  and Coulomb friction; ``c`` the Coulomb velocity, an input);
* ``qdd = M_a⁻¹ (τ_a + s f_a - h_a)`` by a Cholesky factorisation written out (``s`` = 1 with friction, 0
  without).

**Idle motions** (a rod spinning between two balls, :mod:`pkm.core.dynamics.model`): ``k`` passive coordinates
that the idle motions move independently at the reference (a pivoted Gram-Schmidt on the rows of their basis) are
treated as extra, unforced, coordinates ``z``: with the others the closures fix every rate. ``τ_e``, ``M_e`` are the
efforts and mass matrix in ``(q_a, z)``, with blocks ``[[A, B], [Bᵀ, C]]``; the model's mass-orthogonal map ``Ĝ``
(zero idle momentum) is ``Ĝ = G_e S`` with ``S = [I; -C⁻¹ Bᵀ]``, hence ``M_a = A - B C⁻¹ Bᵀ``,
``h_a = Sᵀ h_e(S qd)``, ``g_a = Sᵀ g_e``, ``f_a = Sᵀ G_eᵀ f(v)``. An idle motion without inertia of its own
(``C`` singular: a massless rod, a point-mass rod) has no such map: the kernels' pivot says so and the caller falls
back to the core, whose pseudo-inverse settles it.

:attr:`ActuatorTwin.pivot` is the smallest relative pivot of the LU (and of ``C``'s Cholesky): where it is under
:data:`pkm.core.twin.kernels.PIVOT_FLOOR` the kernels hand the sample to :func:`pkm.actuator_model`.
"""

from __future__ import annotations

import functools

import casadi as cs
import numpy as np

from pkm.core.model.mechanism import Mechanism
from pkm.core.model.plausibility import require_physical
from pkm.core.model.scale import JacobianScales
from pkm.core.twin.linear import HomogenisedPinv, PivotedLU
from pkm.core.twin.spatial import Expr
from pkm.core.twin.tree import Twin
from pkm.errors import SpecError

#: ``M_a`` is refused (the forward dynamics' pivot is 0) where its Cholesky factor's smallest diagonal entry is at
#: most this times its largest, the entries homogenised by the characteristic length (a prismatic actuator's times
#: ``L``): :func:`pkm.core.dynamics.model._solve_inertia`'s test (``sqrt(RTOL)``).
INERTIA_FLOOR = float(np.sqrt(1e-9))


def cholesky(M: Expr) -> tuple[list[list[Expr]], list[Expr]]:
    """The lower Cholesky factor of the symmetric ``M`` (n x n SX) as rows of entries, and its diagonal."""
    n = M.shape[0]
    L: list[list[Expr]] = [[0] * n for _ in range(n)]
    for j in range(n):
        d = M[j, j] - sum((L[j][k] * L[j][k] for k in range(j)), cs.SX(0))
        L[j][j] = cs.sqrt(d)
        for i in range(j + 1, n):
            L[i][j] = (M[i, j] - sum((L[i][k] * L[j][k] for k in range(j)), cs.SX(0))) / L[j][j]
    return L, [L[j][j] for j in range(n)]


def cholesky_solve(L: list[list[Expr]], b: Expr) -> Expr:
    """``x`` with ``L Lᵀ x = b``."""
    n = len(L)
    y: list = [None] * n
    for i in range(n):
        y[i] = (b[i] - sum((L[i][k] * y[k] for k in range(i)), cs.SX(0))) / L[i][i]
    x: list = [None] * n
    for i in reversed(range(n)):
        x[i] = (y[i] - sum((L[k][i] * x[k] for k in range(i + 1, n)), cs.SX(0))) / L[i][i]
    return cs.vertcat(*x)


def _symmetric(M: Expr) -> Expr:
    """``M``'s lower triangle mirrored."""
    n = M.shape[0]
    out = cs.SX.zeros(n, n)
    for i in range(n):
        for j in range(i + 1):
            out[i, j] = M[i, j]
            out[j, i] = M[i, j]
    return out


def idle_columns(mech: Mechanism, rtol: float = 1e-9) -> list[int]:
    """The velocity coordinates (passive) taken as the idle motions' own at the reference: one per idle motion,
    chosen by Gram-Schmidt with pivoting on the rows of their basis (the coordinates the motions move most
    independently); empty without idle motions."""
    from pkm.core.differential.velocity import idle_motions

    N = idle_motions(mech, mech.q_reference, rtol=rtol)
    if not N.shape[1]:
        return []
    rows = N.copy()
    chosen: list[int] = []
    for _ in range(N.shape[1]):
        norms = np.linalg.norm(rows, axis=1)
        norms[chosen] = -1.0
        i = int(np.argmax(norms))
        chosen.append(i)
        u = rows[i] / norms[i]
        rows = rows - np.outer(rows @ u, u)
    return sorted(chosen)


class ActuatorTwin:
    """The actuator-space model of ``twin``'s mechanism as expressions (see the module doc) of the twin's symbols
    ``q``, ``qd`` (na), ``qdd`` (na) and of :attr:`tau` (na) and :attr:`friction` (2: the friction's factor ``s``, 1
    or 0, and the Coulomb velocity ``c`` [rad/s or m/s])."""

    def __init__(self, twin: Twin):
        self.tw = twin
        mech = twin.mech
        require_physical(mech, "the compiled dynamics (the twin's actuator-space model)")
        self.tau = cs.SX.sym("tau", mech.na)
        self.friction = cs.SX.sym("friction", 2)
        self.idle = idle_columns(mech)
        self.extended = [int(c) for c in mech.act_v] + self.idle
        self.passive = [int(c) for c in mech.passive_v if int(c) not in self.idle]
        rows = twin.closure_rows
        Jp = rows["jacobian"][:, self.passive]
        try:
            self.lu = PivotedLU(Jp, twin.at_reference(Jp)) if self.passive else None
            #: The solves of the rates and the efforts: the LU's, or under redundant actuation the core's
            #: pseudo-inverse (:attr:`pkm.core.twin.tree.Twin.passive_solve`); the LU's pivots still judge the sample.
            self.solve: PivotedLU | HomogenisedPinv | None = self.lu
            if self.lu is not None and mech.dependent_actuators:
                sc = JacobianScales.of(mech)
                self.solve = HomogenisedPinv(Jp, twin.at_reference(Jp), sc.constraint_rows, sc.columns[self.passive])
        except ValueError as e:
            raise SpecError(mech.source, f"the closures do not fix the passive joints at the reference ({e})") from None
        self._Ja = rows["jacobian"][:, self.extended]

    # ---------------------------------------------------------------- the extended coordinates
    def _spread(self, ext: Expr, passive: Expr) -> cs.SX:
        out = cs.SX.zeros(self.tw.mech.nv)
        for k, c in enumerate(self.extended):
            out[c] = ext[k]
        for k, c in enumerate(self.passive):
            out[c] = passive[k]
        return out

    def _rates(self, ext: Expr, rhs: Expr | int = 0) -> cs.SX:
        """Joint rates (or accelerations, with the drift as ``rhs``) from the extended coordinates' ``ext``."""
        if self.solve is None:
            return self._spread(ext, cs.SX(0, 1))
        return self._spread(ext, -self.solve.solve(self._Ja @ ext + rhs))

    def project(self, x: Expr) -> Expr:
        """``G_eᵀ x`` for joint efforts ``x`` (nv): ``x_e - J_eᵀ λ`` with ``J_pᵀ λ = x_p``."""
        ext = cs.vertcat(*[x[c] for c in self.extended])
        if self.solve is None:
            return ext
        lam = self.solve.solve_transposed(cs.vertcat(*[x[c] for c in self.passive]))
        return ext - self._Ja.T @ lam

    @functools.cached_property
    def _extended(self) -> dict:
        """``τ_e(q, qd_e, qdd_e)``, its mass matrix and bias, the joint rates, over symbols of the extended size."""
        tw = self.tw
        n = len(self.extended)
        qd_e, qdd_e = cs.SX.sym("qd_e", n), cs.SX.sym("qdd_e", n)
        v = self._rates(qd_e)
        a = cs.substitute(self._rates(qdd_e, tw.closure_rows["drift"]), tw.v, v)
        tau = self.project(cs.substitute(tw.rnea, cs.vertcat(tw.v, tw.a), cs.vertcat(v, a)))
        M = _symmetric(cs.jacobian(tau, qdd_e))
        return {"qd": qd_e, "v": v, "M": M, "h": cs.substitute(tau, qdd_e, cs.DM.zeros(n))}

    @functools.cached_property
    def _reduction(self) -> dict:
        """``S`` (as the map of the actuated rates to the extended ones), ``M_a``, and ``C``'s pivots."""
        e = self._extended
        na = self.tw.mech.na
        M = e["M"]
        if not self.idle:
            return {"qd_e": self.tw.qd, "M": M, "pivots": [], "S": None}
        A, B, C = M[:na, :na], M[:na, na:], M[na:, na:]
        L, diag = cholesky(C)
        CinvBt = cs.horzcat(*[cholesky_solve(L, B[i, :].T) for i in range(na)])  # k x na
        S = cs.vertcat(cs.DM.eye(na), -CinvBt)
        Ma = _symmetric(A - B @ CinvBt)
        ref = self.tw.at_reference(cs.vertcat(*diag)).ravel()
        pivots = [d * d / (r * r) if r > 0 else cs.SX(0) for d, r in zip(diag, ref)]
        return {"qd_e": S @ self.tw.qd, "M": Ma, "pivots": pivots, "S": S}

    def _reduce(self, x: Expr) -> Expr:
        """``Sᵀ x`` for extended efforts ``x``."""
        S = self._reduction["S"]
        return x if S is None else S.T @ x

    # ---------------------------------------------------------------- the model
    @functools.cached_property
    def pivot(self) -> Expr:
        """The smallest relative pivot: the LU's (:meth:`PivotedLU.smallest_relative_pivot`) and, with idle motions,
        ``C``'s squared Cholesky pivots relative to the reference."""
        parts = list(self._reduction["pivots"])
        if self.lu is not None:
            parts.append(self.lu.smallest_relative_pivot())
        return cs.mmin(cs.vertcat(*parts)) if parts else cs.SX(1.0)

    @functools.cached_property
    def v(self) -> Expr:
        """The joint rates ``Ĝ qd`` (nv)."""
        e = self._extended
        return cs.substitute(e["v"], e["qd"], self._reduction["qd_e"])

    @functools.cached_property
    def mass_matrix(self) -> Expr:
        """``M_a(q)`` (na x na), symmetric."""
        return self._reduction["M"]

    @functools.cached_property
    def bias(self) -> Expr:
        """``h_a(q, qd)`` (na): Coriolis, centrifugal, gravity and closure-drift efforts."""
        e = self._extended
        return self._reduce(cs.substitute(e["h"], e["qd"], self._reduction["qd_e"]))

    @functools.cached_property
    def gravity(self) -> Expr:
        """``g_a(q)`` (na)."""
        e = self._extended
        return self._reduce(cs.substitute(e["h"], e["qd"], cs.DM.zeros(e["qd"].shape[0])))

    @functools.cached_property
    def friction_efforts(self) -> Expr:
        """``f_a(q, qd)`` (na) at the Coulomb velocity ``friction[1]`` (without the factor ``friction[0]``)."""
        model = self.tw.mech.model
        D, F = np.asarray(model.damping, dtype=float), np.asarray(model.friction, dtype=float)
        v = self.v
        f = cs.SX.zeros(self.tw.mech.nv)
        for i in (int(k) for k in np.flatnonzero((D != 0.0) | (F != 0.0))):
            f[i] = -float(D[i]) * v[i] - float(F[i]) * cs.tanh(v[i] / self.friction[1])
        return self._reduce(self.project(f))

    @functools.cached_property
    def forward_dynamics(self) -> dict:
        """``qdd`` (na) for the efforts :attr:`tau` and ``pivot``: :attr:`pivot`, 0 where ``M_a``'s Cholesky factor
        fails :data:`INERTIA_FLOOR`."""
        L, diag = cholesky(self.mass_matrix)
        rhs = self.tau + self.friction[0] * self.friction_efforts - self.bias
        d = cs.vertcat(*diag) * cs.DM(JacobianScales.of(self.tw.mech).actuated)  # (homogenised, as _solve_inertia)
        ok = cs.if_else(cs.mmin(d) > INERTIA_FLOOR * cs.mmax(d), 1.0, 0.0)
        return {"qdd": cholesky_solve(L, rhs), "pivot": cs.fmin(self.pivot, ok)}


__all__ = ["INERTIA_FLOOR", "ActuatorTwin", "cholesky", "cholesky_solve", "idle_columns"]
