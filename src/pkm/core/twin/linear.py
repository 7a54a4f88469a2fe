"""Sparse LU of a symbolic matrix, with its pivots chosen once from the matrix's value at a reference point.

A closure Jacobian is sparse (a leg's joints appear only in that leg's rows) and its structure does not change
with the configuration. Eliminating in an order chosen for that structure (Markowitz: the pivot that creates the
least fill, among those at least :data:`THRESHOLD` of their column's largest entry at the reference) costs far
fewer operations than a dense factorisation or the normal equations; each elimination step is written once and
shared, by common-subexpression elimination, between every right-hand side solved with it.

The pivots are fixed: at a configuration where one of them vanishes while the matrix does not, the
factorisation fails although a re-pivoted one would not. The factorisation therefore exposes its pivots
(:attr:`PivotedLU.pivots`); the kernels return the smallest relative one, and their callers fall back to the
generic core where it is small (see :mod:`pkm.core.twin.kernels`).

A tall matrix (more rows than columns: a planar mechanism's out-of-plane closure rows) is factored on the rows
where pivots are found; the others are dependent at the reference and ignored (their solution entries are zero in
:meth:`PivotedLU.solve_transposed`).
"""

from __future__ import annotations

import casadi as cs
import numpy as np

from pkm.core.twin.spatial import Expr

#: A pivot is taken only where it is at least this fraction of its column's largest remaining entry (at the reference).
THRESHOLD = 0.1


class PivotedLU:
    """``A = P^-1 L U Q^-1`` for an SX matrix ``A`` (m x n, m >= n), pivots chosen from ``A_ref = A(reference)``.

    Args:
        A: The matrix (SX, m x n with m >= n).
        A_ref: Its value at the reference point (numpy, m x n).
        rank_tol: Relative size under which a remaining entry counts as zero at the reference.

    Raises:
        ValueError: ``A_ref`` has rank below n (no pivot left for a column).
    """

    def __init__(self, A: Expr, A_ref: np.ndarray, rank_tol: float = 1e-9):
        m, n = A.shape
        if m < n:
            raise ValueError(f"a {m} x {n} matrix: PivotedLU needs at least as many rows as columns")
        scale = max(float(np.abs(A_ref).max(initial=0.0)), 1e-300)  # (n = 0: no column, every joint actuated)
        rows: list[dict[int, cs.SX]] = [{j: A[i, j] for j in range(n) if not A[i, j].is_zero()} for i in range(m)]
        num = [{j: float(A_ref[i, j]) for j in r} for i, r in enumerate(rows)]
        free_rows, free_cols = set(range(m)), set(range(n))
        #: ``(row, column)`` of each elimination step, in order.
        self.order: list[tuple[int, int]] = []
        self._factors: list[list[tuple[int, cs.SX]]] = []  # per step: (row, factor) of the rows it eliminated
        self.pivots: list = []
        for _ in range(n):
            best = None
            col_max = {j: 0.0 for j in free_cols}
            count_col = {j: 0 for j in free_cols}
            for i in free_rows:
                for j, x in num[i].items():
                    if j in free_cols and abs(x) > rank_tol * scale:
                        col_max[j] = max(col_max[j], abs(x))
                        count_col[j] += 1
            for i in free_rows:
                r_count = sum(1 for j, x in num[i].items() if j in free_cols and abs(x) > rank_tol * scale)
                for j, x in num[i].items():
                    if j in free_cols and abs(x) > rank_tol * scale and abs(x) >= THRESHOLD * col_max[j]:
                        key = ((r_count - 1) * (count_col[j] - 1), -abs(x) / col_max[j], i, j)
                        if best is None or key < best[0]:
                            best = (key, i, j)
            if best is None:
                raise ValueError(f"rank {len(self.order)} < {n} at the reference: no pivot for columns "
                                 f"{sorted(free_cols)}")
            _, p, c = best
            free_rows.discard(p)
            free_cols.discard(c)
            self.order.append((p, c))
            self.pivots.append(rows[p][c])
            step = []
            for i in list(free_rows):
                if c not in rows[i]:
                    continue
                f = rows[i].pop(c) / rows[p][c]
                fn = num[i].pop(c) / num[p][c]
                step.append((i, f))
                for j in rows[p]:
                    if j in free_cols:
                        rows[i][j] = rows[i].get(j, 0) - f * rows[p][j]
                        num[i][j] = num[i].get(j, 0.0) - fn * num[p][j]
            self._factors.append(step)
        self._u = rows  # row p of step k: its pivot and the columns still free at step k
        self.shape = (m, n)
        #: The pivots' values at the reference (for :meth:`smallest_relative_pivot`).
        self.reference_pivots = np.array([num[p][c] for p, c in self.order])

    def smallest_relative_pivot(self) -> Expr:
        """``min_k |pivot_k| / |pivot_k(reference)|`` (SX): near 0, the fixed pivot order fails here; 1 without a
        pivot (no column: nothing to fail)."""
        if not self.pivots:
            return cs.SX(1.0)
        return cs.mmin(cs.vertcat(*[cs.fabs(u) / abs(r) for u, r in zip(self.pivots, self.reference_pivots)]))

    def solve(self, b: Expr) -> Expr:
        """``x`` (n) with ``A x = b`` (b: m rows of SX; rows without a pivot are ignored)."""
        w = [b[i] for i in range(self.shape[0])]
        for (p, _), step in zip(self.order, self._factors):  # the elimination's row operations
            for i, f in step:
                w[i] = w[i] - f * w[p]
        x: list = [None] * self.shape[1]
        for p, c in reversed(self.order):
            s = w[p]
            for j, u in self._u[p].items():
                if j != c:
                    s = s - u * x[j]
            x[c] = s / self._u[p][c]
        return cs.vertcat(*x) if x else cs.SX(0, 1)

    def solve_transposed(self, b: Expr) -> Expr:
        """``y`` (m) with ``A^T y = b`` (b: n rows of SX), zero on the rows without a pivot."""
        z: list = [0] * self.shape[0]
        for k, (p, c) in enumerate(self.order):  # U^T z = b, in pivot order
            s = b[c]
            for pk, _ in self.order[:k]:
                u = self._u[pk].get(c)
                if u is not None:
                    s = s - u * z[pk]
            z[p] = s / self._u[p][c]
        for (p, _), step in zip(reversed(self.order), reversed(self._factors)):  # y = E^T z
            for i, f in step:
                z[p] = z[p] - f * z[i]
        return cs.vertcat(*z)


class HomogenisedPinv:
    """The solves of :func:`pkm.core.differential.velocity.homogenised_pinv`'s pseudo-inverse ``A⁺ = columns Â⁺
    rows`` (``Â = rows A columns``) for an SX matrix ``A`` (m x n) of rank n whose rows are not all needed
    (redundant actuation: where :class:`PivotedLU`'s zeros on the rows without a pivot give one valid solution among
    many, and another map than the generic core's): ``x = A⁺ b`` (least squares) and ``y = (A⁺)ᵀ b`` (the solution
    of ``Aᵀ y = b`` of least ``|y / rows|``), by the normal equations ``ÂᵀÂ`` (n x n, factored by
    :class:`PivotedLU`, pivots chosen at the reference).

    Raises:
        ValueError: ``A_ref`` has rank below n.
    """

    def __init__(self, A: Expr, A_ref: np.ndarray, rows: np.ndarray, columns: np.ndarray):
        self.rows, self.columns = cs.DM(rows), cs.DM(columns)
        weight = np.outer(rows, columns)
        self.A_hat = A * cs.DM(weight)  # (elementwise)
        ref = np.asarray(A_ref, dtype=float) * weight
        self.lu = PivotedLU(self.A_hat.T @ self.A_hat, ref.T @ ref)

    def solve(self, b: Expr) -> Expr:
        """``x = A⁺ b`` (n; b: m rows of SX): ``A x = b`` where ``b`` is in ``A``'s range, else least squares."""
        return self.columns * self.lu.solve(self.A_hat.T @ (self.rows * cs.vertcat(b)))

    def solve_transposed(self, b: Expr) -> Expr:
        """``y = (A⁺)ᵀ b`` (m; b: n rows of SX): ``Aᵀ y = b`` with the least ``|y / rows|``."""
        return self.rows * (self.A_hat @ self.lu.solve(self.columns * cs.vertcat(b)))
