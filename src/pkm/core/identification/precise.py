"""The second route to the base parameters' rank: the regressor in 50-digit arithmetic on the same samples.

Rank decisions in double precision are unreliable for low-mobility mechanisms (Iriarte et al., arXiv 1706.09153):
a combination that is only just identifiable and the rounding of a dependent one both leave pivots between 1e-10
and 1e-16, and no threshold tells them apart. This route removes the rounding instead of guessing past it:

1. **The model's constants, recognised.** The twin's expressions (:mod:`pkm.core.twin`) hold the geometry as
   doubles: ``cos(fl(π/2)) = 6.1e-17`` where the designer meant 0, ``0.8660254037844386`` for ``√3/2``, ``0.4``
   for 2/5. Each constant is replaced by the exact number it rounds (:func:`recognise`: 0 under ``1e-14``, else a
   fraction of denominator at most ``10⁶`` times 1, √2, √3 or √6, matched to 4 units in the last place); those it
   cannot recognise (``cos 5°``, a general Gough-Stewart's coordinates) stay their exact binary value and are
   counted (:attr:`PreciseRank.unrecognised`). Their rounding is part of the model as written, and it reaches the
   regressor: the hexapod, with 90 such constants, shows six pivots between ``6e-20`` and ``2e-22`` that its
   rotations' rounding puts there (an orthogonal matrix rounded entrywise is orthogonal to ``1e-16`` only). With
   constants not recognised, pivots under :data:`MODEL_FLOOR` (``1e-15``) are therefore counted as rounding too:
   below what the model's own numbers define.
2. **The samples, closed again.** The same random states as the numerical route, their loops closed anew to
   ``10⁻⁴⁵`` by the twin's own Newton iteration (:attr:`~pkm.core.twin.tree.Twin.closure_newton`) run in
   ``mpmath`` at :data:`DIGITS` digits, the actuated coordinates, rates and accelerations held.
3. **The regressor evaluated exactly as built.** The twin's regressor expression (``∂τ_a/∂θ``,
   :mod:`pkm.core.twin.regressor`) evaluated instruction by instruction (:class:`Program`: CasADi's own
   instruction list, each operation in ``mpmath``), vectorised over the samples.
4. **The rank.** The columns scaled to unit norm, a Householder QR with column pivoting in 224-bit fixed point
   (:func:`pivoted_qr`: Python integers, exact to ``4e-68`` on entries of at most 1), and the rank decided by the same largest-drop rule as the numerical route among pivots under ``1e-6``, with the
   rounding floor at ``10^(-DIGITS + 10)`` (every constant recognised) or :data:`MODEL_FLOOR` instead of ``1e-10``:
   a rounding pivot now sits near ``1e-50``. What the route catches that the first cannot: a combination that the
   efforts carry between ``1e-15`` and ``1e-10`` of the largest, which double precision drops as its own rounding
   (the test plants one: gravity tilted by ``1e-12`` rad makes the 3-RRR's proximal first moments identifiable at
   that level).

The two routes then find the same count or :class:`~pkm.core.identification.base.BaseParameters` says they do not
(:attr:`~pkm.core.identification.base.BaseParameters.routes_agree`; the independent columns each route names may
differ where columns tie, and need not: any independent set spans the same combinations).

Cost: each sample's regressor costs ``n_instructions`` operations at about a microsecond each, the QR about
``2 m n r`` integer operations (``m`` rows, ``n`` live columns, ``r`` the rank: the elimination stops where every
remaining column is rounding): 0.3 s for the 3-RRR, 0.4 s for the Delta, 1.3 s for the Gough-Stewart, 2 s for
the hexapod (``pkm bench identification``).
"""

from __future__ import annotations

import functools
import hashlib
import math
import weakref
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import casadi as cs
import mpmath
import numpy as np

from pkm.core.identification.rank import RankDecision, decide_rank
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import ConvergenceError, InvalidInputError, SpecError

DIGITS = 50  # the working precision [decimal digits]
CLOSURE_TOL = 1e-45  # the loops closed again to this (largest residual, lengths in the characteristic length, rad)
MAX_NEWTON = 8  # Newton iterations at most (from a double-precision closure, three suffice)
MAX_DENOMINATOR = 10**6  # a constant is recognised as a fraction of denominator up to this times 1, √2, √3, √6
ZERO = 1e-14  # constants under this (absolute) are rounding of a zero (cos(fl(π/2)) = 6.1e-17)
MODEL_FLOOR = 1e-15  # with constants not recognised, relative pivots under this are their rounding's reach


def _mp(value: float | int | Fraction, root: int = 1) -> mpmath.mpf:
    if isinstance(value, Fraction):
        out = mpmath.mpf(value.numerator) / value.denominator
    else:
        out = mpmath.mpf(value)
    return out * mpmath.sqrt(root) if root != 1 else out


def recognise(c: float) -> tuple[mpmath.mpf, bool]:
    """The exact number the double ``c`` rounds, and whether it was recognised (module doc, step 1): 0 for
    ``|c| < 1e-14``; else ``p/q · √k`` for ``k`` in 1, 2, 3, 6 and ``q ≤ 10⁶`` when it lies within 4 units in the
    last place of ``c``; else ``c`` itself (its exact binary value), not recognised."""
    if abs(c) < ZERO:
        return mpmath.mpf(0), True
    ulp = math.ulp(c)
    for k in (1, 2, 3, 6):
        x = c / math.sqrt(k)
        f = Fraction(x).limit_denominator(MAX_DENOMINATOR)
        if abs(float(f) * math.sqrt(k) - c) <= 4.0 * ulp and abs(float(f) - x) <= 4.0 * math.ulp(x):
            return _mp(f, k), True
    return mpmath.mpf(c), False


_UNARY: dict[int, Callable[[Any], Any]] = {
    cs.OP_ASSIGN: lambda x: x, cs.OP_NEG: lambda x: -x, cs.OP_SQ: lambda x: x * x, cs.OP_TWICE: lambda x: x + x,
    cs.OP_INV: lambda x: 1 / x, cs.OP_FABS: abs, cs.OP_EXP: mpmath.exp, cs.OP_LOG: mpmath.log,
    cs.OP_SQRT: mpmath.sqrt, cs.OP_SIN: mpmath.sin, cs.OP_COS: mpmath.cos, cs.OP_TAN: mpmath.tan,
    cs.OP_ASIN: mpmath.asin, cs.OP_ACOS: mpmath.acos, cs.OP_ATAN: mpmath.atan, cs.OP_SINH: mpmath.sinh,
    cs.OP_COSH: mpmath.cosh, cs.OP_TANH: mpmath.tanh, cs.OP_ASINH: mpmath.asinh, cs.OP_ACOSH: mpmath.acosh,
    cs.OP_ATANH: mpmath.atanh, cs.OP_SIGN: mpmath.sign, cs.OP_FLOOR: mpmath.floor, cs.OP_CEIL: mpmath.ceil,
    cs.OP_ERF: mpmath.erf, cs.OP_LOG1P: mpmath.log1p, cs.OP_EXPM1: mpmath.expm1,
    cs.OP_NOT: lambda x: mpmath.mpf(x == 0),
}
_BINARY: dict[int, Callable[[Any, Any], Any]] = {
    cs.OP_ADD: lambda x, y: x + y, cs.OP_SUB: lambda x, y: x - y, cs.OP_MUL: lambda x, y: x * y,
    cs.OP_DIV: lambda x, y: x / y, cs.OP_POW: lambda x, y: x ** y, cs.OP_CONSTPOW: lambda x, y: x ** y,
    cs.OP_ATAN2: mpmath.atan2, cs.OP_HYPOT: mpmath.hypot, cs.OP_FMIN: min, cs.OP_FMAX: max,
    cs.OP_COPYSIGN: lambda x, y: abs(x) if y >= 0 else -abs(x),
    cs.OP_IF_ELSE_ZERO: lambda c, x: x if c != 0 else mpmath.mpf(0),
    cs.OP_LT: lambda x, y: mpmath.mpf(x < y), cs.OP_LE: lambda x, y: mpmath.mpf(x <= y),
    cs.OP_EQ: lambda x, y: mpmath.mpf(x == y), cs.OP_NE: lambda x, y: mpmath.mpf(x != y),
    cs.OP_AND: lambda x, y: mpmath.mpf(x != 0 and y != 0), cs.OP_OR: lambda x, y: mpmath.mpf(x != 0 or y != 0),
}
#: The operations numpy's object arrays run themselves (their operators call mpmath's): no per-element wrapper.
_ARRAY_OPS = {cs.OP_ASSIGN, cs.OP_NEG, cs.OP_SQ, cs.OP_TWICE, cs.OP_INV, cs.OP_ADD, cs.OP_SUB, cs.OP_MUL, cs.OP_DIV}


class Program:
    """A CasADi SX function as a list of operations run in ``mpmath`` on object arrays (one entry per sample).

    Its constants are :func:`recognise`\\ d; :attr:`unrecognised` counts those kept as their binary value.

    Raises:
        SpecError: the function holds an operation this evaluator does not run (named).
    """

    def __init__(self, fun: cs.Function):
        if not fun.is_a("SXFunction"):
            raise InvalidInputError("fun", "expected a CasADi SX function", fun)
        self.fun = fun
        self.n_work = int(fun.sz_w())
        self.unrecognised = 0
        self.constants = 0
        ops: list[tuple] = []
        for k in range(fun.n_instructions()):
            op, args, out = fun.instruction_id(k), fun.instruction_input(k), fun.instruction_output(k)
            if op == cs.OP_CONST:
                value, known = recognise(float(fun.instruction_constant(k)))
                self.constants += 1
                self.unrecognised += not known
                ops.append(("const", out[0], value))
            elif op == cs.OP_INPUT:
                ops.append(("in", out[0], args[0], args[1]))
            elif op == cs.OP_OUTPUT:
                ops.append(("out", args[0], out[0], out[1]))
            elif op in _UNARY:
                f = _UNARY[op] if op in _ARRAY_OPS else np.frompyfunc(_UNARY[op], 1, 1)
                ops.append(("call", out[0], f, (args[0],)))
            elif op in _BINARY:
                f = _BINARY[op] if op in _ARRAY_OPS else np.frompyfunc(_BINARY[op], 2, 1)
                ops.append(("call", out[0], f, tuple(args[:2])))
            else:
                raise SpecError(fun.name(), f"the high-precision evaluator does not run CasADi operation {op}")
        self.ops = ops

    def __call__(self, *inputs: np.ndarray) -> list[np.ndarray]:
        """The outputs' nonzeros (n_nz, S) for inputs (n_in, S), object arrays of ``mpmath.mpf``."""
        fun = self.fun
        if len(inputs) != fun.n_in():
            raise InvalidInputError("inputs", f"expected {fun.n_in()} inputs, got {len(inputs)}", len(inputs))
        S = inputs[0].shape[1] if inputs and inputs[0].ndim == 2 else 1
        w: list[Any] = [None] * self.n_work
        outs = [np.full((fun.nnz_out(i), S), mpmath.mpf(0), dtype=object) for i in range(fun.n_out())]
        for op in self.ops:
            kind = op[0]
            if kind == "call":
                _, o, f, args = op
                w[o] = f(*(w[a] for a in args))
            elif kind == "const":
                w[op[1]] = np.full(S, op[2], dtype=object)
            elif kind == "in":
                w[op[1]] = inputs[op[2]][op[3]]
            else:
                outs[op[2]][op[3]] = w[op[1]]
        return outs


def to_mp(x: np.ndarray) -> np.ndarray:
    """A float array as an object array of ``mpmath.mpf`` (each the double's exact value)."""
    x = np.asarray(x, dtype=float)
    return np.frompyfunc(mpmath.mpf, 1, 1)(x).astype(object)


@functools.lru_cache(maxsize=8)
def _programs(mech: Mechanism) -> tuple[Program, Program]:
    from pkm.core.twin.regressor import ParametricTwin, regressor_function

    twin = ParametricTwin(mech)  # (one twin for both: the regressor reuses the closure rows and passive solve built
    newton = twin.closure_newton  # for the Newton step; the kinematics are a plain Twin's, the same instructions)
    step = Program(cs.Function("newton", [twin.q, twin.target], [newton["q_next"], newton["residual"]]))
    return step, Program(regressor_function(mech, twin))


def close_precisely(mech: Mechanism, Q: np.ndarray, step: Program) -> np.ndarray:
    """The closed configurations ``Q`` (S, nq, double) closed again in :data:`DIGITS` digits: (nq, S) objects.

    Raises:
        ConvergenceError: a sample's residual is not under :data:`CLOSURE_TOL` after :data:`MAX_NEWTON` steps.
    """
    q = to_mp(Q.T)
    target = q[np.asarray(mech.act_q, dtype=int)]
    worst = mpmath.inf
    for _ in range(MAX_NEWTON):
        q_next, residual = step(q, target)
        q = q_next
        worst = max(residual[0])
        if worst < CLOSURE_TOL:
            return q
    raise ConvergenceError(f"loop closure in {DIGITS} digits", float(worst), MAX_NEWTON, CLOSURE_TOL)


@dataclass(frozen=True)
class PreciseRank:
    """The rank decided on the regressor in :data:`DIGITS`-digit arithmetic (module doc).

    Attributes:
        decision: The rank, the relative pivots (as floats: the smallest near ``1e-45``) and the gap.
        independent: The pivoted columns kept, as indices into the columns given.
        rows: The rows stacked (samples times actuators).
        constants: The model's constants in the expressions; ``unrecognised`` of them kept as binary values.
        unrecognised: See ``constants``.
        floor: The rounding floor of the decision: ``10^(-DIGITS + 10)``, or :data:`MODEL_FLOOR` with constants not
            recognised (module doc).
    """

    decision: RankDecision
    independent: tuple[int, ...]
    rows: int
    constants: int
    unrecognised: int
    floor: float


BITS = 224  # the QR's fixed-point scale (2^-224 = 4e-68 absolute on entries of at most 1: 67 digits)


def _fixed(x: Any) -> int:
    """``int(mpmath.nint(x * 2**BITS))`` (the QR's fixed point, at the working precision): for an ``mpf``, on its raw
    value, without the four ``mpf`` the expression makes (a third of the hexapod's QR); the same integer (tested)."""
    if isinstance(x, mpmath.mpf):
        prec, rounding = mpmath.mp._prec_rounding
        raw = mpmath.libmp.mpf_mul_int(x._mpf_, 1 << BITS, prec, rounding)
        return int(mpmath.libmp.to_int(mpmath.libmp.mpf_nint(raw, prec, rounding)))
    return int(mpmath.nint(x * (1 << BITS)))


def pivoted_qr(A: np.ndarray, stop: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """The relative ``|R_kk| / |R_00|`` (floats) and the column order of a Householder QR with column pivoting of
    ``A`` (m x n, ``mpmath`` numbers, columns of at most unit norm) in :data:`BITS`-bit fixed point (Python
    integers: eight times faster than ``mpmath`` numbers, exact to ``4e-68`` absolute: orthogonal steps keep every
    entry at most 1). The largest remaining column norm first, as LAPACK's ``geqp3``.

    Once every remaining column's norm is under ``stop`` times the first pivot, the elimination ends and those
    norms (descending) stand for the remaining pivots: each bounds its ``|R_kk|`` from above, which is all a rank
    decision below them needs."""
    one = 1 << BITS
    X = np.frompyfunc(_fixed, 1, 1)(A).astype(object)
    m, n = X.shape
    perm = np.arange(n)
    pivots: list[int] = []
    norms = (X * X).sum(axis=0)  # (scaled by 2^(2 BITS): a column of 1e-40 keeps 1e-80)
    for k in range(min(m, n)):
        j = k + int(np.argmax([int(x) for x in norms[k:]]))
        if pivots and math.isqrt(int(norms[j])) <= stop * pivots[0]:
            rest = sorted(range(k, n), key=lambda i: -int(norms[i]))
            perm[k:] = perm[rest]
            pivots += [math.isqrt(int(norms[i])) for i in rest]
            break
        if j != k:
            X[:, [k, j]] = X[:, [j, k]]
            perm[[k, j]] = perm[[j, k]]
            norms[[k, j]] = norms[[j, k]]
        x = X[k:, k]
        alpha = math.isqrt(int((x * x).sum()))
        pivots.append(alpha)
        if alpha == 0:
            break
        v = x.copy()
        v[0] = v[0] + (alpha if x[0] >= 0 else -alpha)
        vv = int((v * v).sum())  # (scaled by 2^(2 BITS))
        if k + 1 < n:
            block = X[k:, k + 1:]
            coef = ((v @ block) << 1) * one // vv  # 2 vᵀB / vᵀv, scaled by 2^BITS
            X[k:, k + 1:] = block - (np.outer(v, coef) >> BITS)
            rest_block = X[k + 1:, k + 1:]
            norms[k + 1:] = (rest_block * rest_block).sum(axis=0)
    top = pivots[0] if pivots and pivots[0] else 1
    return np.array([p / top for p in pivots], dtype=float), perm


def _key(states: Sequence[tuple[np.ndarray, np.ndarray, np.ndarray]]) -> str:
    return hashlib.sha256(b"".join(np.ascontiguousarray(x).tobytes() for s in states for x in s)).hexdigest()


#: mechanism -> {the states' digest: (W, constants, unrecognised)} (weakly: a mechanism made anew is computed anew,
#: as :func:`~pkm.core.identification.base.random_states` keeps its draws; a model is not changed in place:
#: :class:`~pkm.core.model.mechanism.Mechanism`)
_REGRESSORS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def precise_regressor(mech: Mechanism, states: Sequence[tuple[np.ndarray, np.ndarray, np.ndarray]]) \
        -> tuple[np.ndarray, int, int]:
    """The regressor stacked at ``states`` in :data:`DIGITS` digits ((S na) x p objects; steps 1-3 of the module
    doc), the constants in its expressions and how many of them were not recognised. Kept for the last few
    calls (the tied and untied decisions share it).

    Raises:
        SpecError: the twin cannot build the mechanism's regressor (idle motions, a joint kind it lacks).
        ConvergenceError: a sample does not close in high precision.
    """
    mech = check_mechanism(mech)
    key = _key(states)
    kept = _REGRESSORS.setdefault(mech, {})
    if key not in kept:
        with mpmath.workdps(DIGITS):
            step, program = _programs(mech)
            q = close_precisely(mech, np.array([s[0] for s in states]), step)
            qd, qdd = (to_mp(np.array([s[i] for s in states]).T) for i in (1, 2))
            flat = program(q, qd, qdd)[0]
        na, S = mech.na, len(states)
        p = flat.shape[0] // na
        W = np.empty((S * na, p), dtype=object)
        for k in range(S):  # (the function gives Y transposed, column-major: Y row after row)
            W[k * na:(k + 1) * na] = flat[:, k].reshape(na, p)
        if len(kept) >= 4:
            kept.pop(next(iter(kept)))
        kept[key] = (W, step.constants + program.constants, step.unrecognised + program.unrecognised)
    return kept[key]


def precise_rank(mech: Mechanism, states: Sequence[tuple[np.ndarray, np.ndarray, np.ndarray]],
                 columns: np.ndarray | None = None) -> PreciseRank:
    """The rank of the regressor stacked at ``states`` (the numerical route's own), in :data:`DIGITS` digits
    (module doc); ``columns`` (p x c): combine the standard columns first (tied legs: ``Y T``). Of the rows, the
    first ``live columns + 2 na`` enter the QR (a rank needs no more rows than columns, and each row costs).

    Raises:
        SpecError: the twin cannot build the mechanism's regressor (idle motions, a joint kind it lacks).
        ConvergenceError: a sample does not close in high precision.
        InvalidInputError: fewer rows than live columns.
    """
    W, constants, unrecognised = precise_regressor(mech, states)
    with mpmath.workdps(DIGITS):
        if columns is not None:
            C = np.asarray(columns, dtype=float)
            if np.all((C == 0.0) | (C == 1.0)):  # (tied legs: sums of columns, not a product of mpmath matrices)
                W = np.stack([W[:, C[:, c] == 1.0].sum(axis=1) for c in range(C.shape[1])], axis=1)
            else:
                W = W @ to_mp(C)
        floor = MODEL_FLOOR if unrecognised else 10.0 ** (-DIGITS + 10)
        scale = np.array([mpmath.sqrt((W[:, j] * W[:, j]).sum()) for j in range(W.shape[1])], dtype=object)
        top = max(scale)
        live = np.flatnonzero([x > top * floor for x in scale])  # (a column under the floor is rounding: scaled
        # to unit norm it would look like any other)
        rows = min(len(W), len(live) + 2 * mech.na)
        if rows < len(live):
            raise InvalidInputError("states", f"{len(W)} rows for {len(live)} live columns: give more states",
                                    len(states))
        rel, perm = pivoted_qr(W[:rows, live] / scale[live], stop=10.0 ** (-DIGITS + 10))
    decision = decide_rank(rel, floor=floor)
    ind = tuple(sorted(int(live[perm[k]]) for k in range(decision.rank)))
    return PreciseRank(decision, ind, rows, constants, unrecognised, floor)


__all__ = ["DIGITS", "MODEL_FLOOR", "PreciseRank", "Program", "close_precisely", "pivoted_qr", "precise_rank",
           "precise_regressor", "recognise", "to_mp"]
