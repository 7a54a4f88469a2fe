"""Sparse multivariate polynomials: the one representation the homotopy, the polishing and the certificates share.

A :class:`Poly` is a map from exponent tuples to complex coefficients over ``n`` variables. The reduced
kinematic equations (:mod:`pkm.core.modes.reduce`) are built from them by ordinary arithmetic, always expanded,
so that their degree is their true degree (Bertini counts paths from the degrees it is given, and a product left
unexpanded would inflate them). :class:`System` compiles a list of them to arrays for evaluation,
Jacobians and the constant second derivatives of a quadratic system (Smale's alpha test,
:mod:`pkm.core.modes.certify`).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

_TOL = 0.0  # coefficients are kept exactly as computed (cancellation to 0.0 drops a term)


class Poly:
    """A polynomial in ``n`` variables; ``terms`` maps exponent tuples to coefficients."""

    __slots__ = ("n", "terms")
    __array_ufunc__ = None  # numpy scalars and arrays defer to Poly's reflected operators

    def __init__(self, n: int, terms: dict[tuple[int, ...], complex] | None = None):
        self.n = n
        self.terms = {} if terms is None else {e: c for e, c in terms.items() if abs(c) > _TOL}

    @classmethod
    def const(cls, n: int, c: complex) -> Poly:
        return cls(n, {(0,) * n: c})

    @classmethod
    def var(cls, n: int, i: int) -> Poly:
        e = [0] * n
        e[i] = 1
        return cls(n, {tuple(e): 1.0})

    def _coerce(self, other: Poly | complex) -> Poly:
        return other if isinstance(other, Poly) else Poly.const(self.n, other)

    def __add__(self, other: Poly | complex) -> Poly:
        other = self._coerce(other)
        out = dict(self.terms)
        for e, c in other.terms.items():
            out[e] = out.get(e, 0.0) + c
        return Poly(self.n, out)

    __radd__ = __add__

    def __neg__(self) -> Poly:
        return Poly(self.n, {e: -c for e, c in self.terms.items()})

    def __sub__(self, other: Poly | complex) -> Poly:
        return self + (-self._coerce(other))

    def __rsub__(self, other: Poly | complex) -> Poly:
        return self._coerce(other) - self

    def __mul__(self, other: Poly | complex) -> Poly:
        if not isinstance(other, Poly):
            return Poly(self.n, {e: c * other for e, c in self.terms.items()})
        out: dict[tuple[int, ...], complex] = {}
        for e1, c1 in self.terms.items():
            for e2, c2 in other.terms.items():
                e = tuple(a + b for a, b in zip(e1, e2))
                out[e] = out.get(e, 0.0) + c1 * c2
        return Poly(self.n, out)

    __rmul__ = __mul__

    def cleaned(self, scale: float, rel: float = 1e-12) -> Poly:
        """Without the terms below ``rel * scale``: the rounding left where exact arithmetic cancels (a
        coordinate that drops out of an equation must not stay in it at 1e-17, raising its degree)."""
        return Poly(self.n, {e: c for e, c in self.terms.items() if abs(c) > rel * scale})

    @property
    def degree(self) -> int:
        return max((sum(e) for e in self.terms), default=0)

    def homogeneous(self) -> bool:
        """Every term of the same degree (a polynomial on a projective space)."""
        return len({sum(e) for e in self.terms}) <= 1

    def __call__(self, x: ArrayLike) -> complex:
        return System([self])(np.asarray(x))[0]

    def __repr__(self) -> str:
        return f"Poly(n={self.n}, degree={self.degree}, terms={len(self.terms)})"


def variables(n: int) -> list[Poly]:
    """The ``n`` coordinate polynomials ``x_0 .. x_{n-1}``."""
    return [Poly.var(n, i) for i in range(n)]


def dot(a: Iterable, b: Iterable) -> Any:  # a Poly or a number, as the entries
    out = 0.0
    for x, y in zip(a, b):
        out = x * y + out
    return out


def matvec(M: Sequence[Sequence], v: Sequence) -> list:
    return [dot(row, v) for row in M]


class System:
    """Polynomials compiled for evaluation: ``F(x)``, ``J(x)`` and, for a system of degree <= 2, the constant
    Hessians. Works on one point ``(n,)`` or stacks ``(..., n)``."""

    def __init__(self, polys: Sequence[Poly]):
        if not polys:
            raise ValueError("a system needs at least one polynomial")
        self.polys = list(polys)
        self.n = polys[0].n
        self.degrees = [p.degree for p in polys]
        self._E = [np.array(list(p.terms) or [(0,) * self.n], dtype=int).reshape(-1, self.n) for p in polys]
        self._c = [np.array(list(p.terms.values()) or [0.0], dtype=complex) for p in polys]

    def __len__(self) -> int:
        return len(self.polys)

    @staticmethod
    def _monomials(x: np.ndarray, E: np.ndarray) -> np.ndarray:
        return np.prod(x[..., None, :] ** E, axis=-1)  # (..., terms)

    def __call__(self, x: ArrayLike) -> np.ndarray:
        x = np.asarray(x, dtype=complex)
        return np.stack([self._monomials(x, E) @ c for E, c in zip(self._E, self._c)], axis=-1)

    def jacobian(self, x: ArrayLike) -> np.ndarray:
        x = np.asarray(x, dtype=complex)
        rows = []
        for E, c in zip(self._E, self._c):
            cols = []
            for i in range(self.n):
                k = E[:, i].copy()
                Ei = E.copy()
                Ei[:, i] = np.maximum(k - 1, 0)
                cols.append(self._monomials(x, Ei) @ (c * k))
            rows.append(np.stack(cols, axis=-1))
        return np.stack(rows, axis=-2)  # (..., m, n)

    def hessians(self) -> np.ndarray:
        """The second derivatives ``d2 F_k / dx_i dx_j`` (m, n, n) of a system of degree <= 2 (constant)."""
        if max(self.degrees) > 2:
            raise ValueError("constant Hessians exist for systems of degree <= 2 only")
        H = np.zeros((len(self), self.n, self.n), dtype=complex)
        for k, (E, c) in enumerate(zip(self._E, self._c)):
            for e, ck in zip(E, c):
                idx = np.flatnonzero(e)
                if e.sum() != 2:
                    continue
                if len(idx) == 1:
                    H[k, idx[0], idx[0]] += 2.0 * ck
                else:
                    H[k, idx[0], idx[1]] += ck
                    H[k, idx[1], idx[0]] += ck
        return H


def fix(p: Poly, i: int, value: complex) -> Poly:
    """``p`` with variable ``i`` set to ``value`` and removed (``n - 1`` variables): a projective polynomial on the
    affine chart ``x_i = value``."""
    out: dict[tuple[int, ...], complex] = {}
    for e, c in p.terms.items():
        k = e[:i] + e[i + 1:]
        out[k] = out.get(k, 0.0) + c * value ** e[i]
    return Poly(p.n - 1, out)
