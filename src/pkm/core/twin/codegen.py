"""The twin's functions as generated C, compiled and loaded; with drivers that run them over batches, paths and grids.

:func:`compile_library` writes CasADi functions as C (CasADi's code generator, one file), appends drivers, compiles
the whole with the system's C compiler (``cc -O2 -shared``; ``-O0`` above :data:`LARGE` instructions) and loads it
with :mod:`ctypes`:

* ``NAME_batch(n, in, out)``: the function on ``n`` samples, each input and output a sample-major array;
  ``NAME_batch_steps(n, in, out, steps)`` with each input's stride (0: one value for every sample, a design);
* ``NAME_follow(n, q0, targets, q_out, residual, pivot, iterations, max_iter, tol, design)``, for a Newton
  iteration (inputs ``q, target`` and, for a twin with design inputs, ``design``; outputs ``q_next, residual,
  pivot``): per target, iterate from the previous solution (the first from ``q0``) until the residual is at most
  ``tol`` or ``max_iter`` iterations were made;
* ``NAME_grid(...)`` (:func:`map_source`): the maps' breadth-first solve over a grid (:mod:`pkm.core.analysis.maps`).

:func:`numpy_function` runs a function vectorised over samples with numpy instead (one statement per instruction),
for machines without a compiler. Libraries are cached by the hash of their source (the folder :func:`cache_dir`), so
a mechanism is compiled once per machine. Without a C compiler (or when it fails) :func:`compile_library` returns
None and says why.
"""

from __future__ import annotations

import ctypes
import hashlib
import math
import os
import shutil
import subprocess
import tempfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import casadi as cs

if TYPE_CHECKING:
    import numpy as np

_FLAGS = ("-shared", "-fPIC")
#: ctypes types of the generated code's ``casadi_real*`` and ``casadi_int`` (``long long``).
C_REAL_P = ctypes.POINTER(ctypes.c_double)
C_INT = ctypes.c_longlong
#: A branch quantity (the sine of an elbow) this close to 0 lies on the boundary between working modes: a map counts
#: the node in both. (Newton locates a double root, where the elbow is straight, to about the square root of the
#: machine precision: the sign of a sine under 1e-6 there is noise.)
BRANCH_TOL = 1e-6
#: Functions with more instructions than this are compiled with ``-O0``: gcc 12's ``-O2`` takes 40 s on the hexapod's
#: 52,000-instruction derivatives (one basic block), ``-O0`` 2.5 s.
LARGE = 20_000

_BATCH = r"""
/* pkm drivers */
static const casadi_int NAME_isz[] = {ISZ}, NAME_osz[] = {OSZ};

static int NAME_pkm_alloc(const casadi_real*** arg, casadi_real*** res, casadi_int** iw, casadi_real** w) {
  casadi_int sz_arg, sz_res, sz_iw, sz_w;
  NAME_work(&sz_arg, &sz_res, &sz_iw, &sz_w);
  *arg = calloc(sz_arg + 1, sizeof(casadi_real*)); *res = calloc(sz_res + 1, sizeof(casadi_real*));
  *iw = malloc(sizeof(casadi_int) * (sz_iw + 1)); *w = malloc(sizeof(casadi_real) * (sz_w + 1));
  return !(*arg && *res && *iw && *w);
}

static void NAME_pkm_free(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w) {
  free((void*) arg); free(res); free(iw); free(w);
}

int NAME_batch_steps(casadi_int n, const casadi_real** in, casadi_real** out, const casadi_int* steps) {
  /* steps[i]: input i's stride (NULL: every input its size; 0: one value for every sample) */
  const casadi_real** arg; casadi_real** res; casadi_int* iw; casadi_real* w; int flag = 0;
  if (NAME_pkm_alloc(&arg, &res, &iw, &w)) return 2;
  for (casadi_int k = 0; k < n && !flag; ++k) {
    for (int i = 0; i < NIN; ++i) arg[i] = in[i] + k * (steps ? steps[i] : NAME_isz[i]);
    for (int i = 0; i < NOUT; ++i) res[i] = out[i] + k * NAME_osz[i];
    flag = NAME(arg, res, iw, w, 0);
  }
  NAME_pkm_free(arg, res, iw, w);
  return flag;
}

int NAME_batch(casadi_int n, const casadi_real** in, casadi_real** out) { return NAME_batch_steps(n, in, out, 0); }
"""

_FOLLOW = r"""
int NAME_follow(casadi_int n, const casadi_real* q0, const casadi_real* targets, casadi_real* q_out,
                casadi_real* residual, casadi_real* pivot, casadi_int* iterations, casadi_int max_iter,
                casadi_real tol, const casadi_real* design) {
  const casadi_real** arg; casadi_real** res; casadi_int* iw; casadi_real* w;
  const casadi_int nq = NAME_isz[0], nt = NAME_isz[1];
  casadi_real* cur = malloc(sizeof(casadi_real) * nq); casadi_real* next = malloc(sizeof(casadi_real) * nq);
  if (!cur || !next || NAME_pkm_alloc(&arg, &res, &iw, &w)) return 2;
  memcpy(cur, q0, sizeof(casadi_real) * nq);
  for (casadi_int k = 0; k < n; ++k) {
    casadi_real r = 0.0, p = 0.0; casadi_int it = 0;
    arg[1] = targets + k * nt; res[0] = next; res[1] = &r; res[2] = &p; DESIGN_FOLLOW
    do {
      arg[0] = cur;
      if (NAME(arg, res, iw, w, 0)) { NAME_pkm_free(arg, res, iw, w); free(cur); free(next); return 1; }
      memcpy(cur, next, sizeof(casadi_real) * nq);
      ++it;
    } while (!(r <= tol) && it < max_iter && r == r);
    memcpy(q_out + k * nq, cur, sizeof(casadi_real) * nq);
    residual[k] = r; pivot[k] = p; iterations[k] = it;
  }
  NAME_pkm_free(arg, res, iw, w); free(cur); free(next);
  return 0;
}
"""


_JACOBI_SV = r"""
static void SV_NAME(casadi_int m, casadi_int n, casadi_real* A, casadi_real* s) {
  /* singular values (descending) of the column-major m x n matrix A (m >= n), one-sided Jacobi; A is destroyed */
  for (int sweep = 0; sweep < 60; ++sweep) {
    casadi_real off = 0.0;
    for (casadi_int p = 0; p < n; ++p) for (casadi_int r = p + 1; r < n; ++r) {
      casadi_real a = 0.0, b = 0.0, g = 0.0;
      for (casadi_int i = 0; i < m; ++i) { a += A[p*m+i]*A[p*m+i]; b += A[r*m+i]*A[r*m+i]; g += A[p*m+i]*A[r*m+i]; }
      if (a == 0.0 || b == 0.0 || fabs(g) <= SKIP_TOL * sqrt(a * b)) continue;
      if (fabs(g) / sqrt(a * b) > off) off = fabs(g) / sqrt(a * b);
      casadi_real z = (b - a) / (2.0 * g), t = (z >= 0 ? 1.0 : -1.0) / (fabs(z) + sqrt(1.0 + z * z));
      casadi_real c = 1.0 / sqrt(1.0 + t * t), sn = c * t;
      for (casadi_int i = 0; i < m; ++i) {
        casadi_real x = A[p*m+i], y = A[r*m+i]; A[p*m+i] = c * x - sn * y; A[r*m+i] = sn * x + c * y;
      }
    }
    if (off <= STOP_TOL) break;
  }
  for (casadi_int j = 0; j < n; ++j) { casadi_real a = 0.0; for (casadi_int i = 0; i < m; ++i) a += A[j*m+i]*A[j*m+i]; s[j] = sqrt(a); }
  for (casadi_int j = 1; j < n; ++j) for (casadi_int k = j; k > 0 && s[k] > s[k-1]; --k) { casadi_real t = s[k]; s[k] = s[k-1]; s[k-1] = t; }
}
"""


def jacobi_sv(name: str, skip: float, stop: float) -> str:
    """The C source of ``static void <name>(m, n, A, s)``: the singular values (descending) of the column-major
    ``m x n`` matrix ``A`` (``m >= n``) by one-sided Jacobi, ``A`` destroyed; a pair of columns whose cosine is under
    ``skip`` is left as it is, the sweeps stop when every cosine is under ``stop``."""
    return _JACOBI_SV.replace("SV_NAME", name).replace("SKIP_TOL", repr(skip)).replace("STOP_TOL", repr(stop))


_GRID = r"""
/* pkm map driver: STEP (q, y -> q_next, step, pivot), its fallback QRSTEP (q, y -> q_next, step: taken where
   STEP's smallest relative pivot is under PIVOT_FLOOR) and INDEX (q, y, scale -> K, residual, branch) over a grid of
   task targets (dims[0] fastest), breadth first from root nodes: a node is solved from the neighbour that reached
   it (one seed), each root from q0; its neighbours are queued with its solution. */
JACOBI_SV

int STEP_grid(const casadi_int* dims, casadi_int ndim, const casadi_real* targets, const casadi_real* q0,
              const casadi_real* scale, const casadi_real* signs, const casadi_int* roots, casadi_int nroots,
              casadi_int max_iter, casadi_real step_tol, casadi_real tol,
              signed char* state, casadi_real* sv, casadi_int* iterations, casadi_real* q_out,
              const casadi_real* design) {
  /* state: 0 not reached, 1 solved, -3 failed (not converged, or in another mode), -2 queued; a node is queued
     by each solved neighbour (2 ndim tries at most) until one solves it; q_out (NULL: not kept) the solutions */
  const casadi_int nq = NQ, nt = NT, m = KROWS, n = KCOLS, nb = NB, nsv = (m < n ? m : n);
  casadi_int total = 1, stride[3] = {1, 1, 1};
  for (casadi_int d = 0; d < ndim; ++d) { stride[d] = total; total *= dims[d]; }
  const casadi_real **sa, **ia; casadi_real **sr, **ir; casadi_int *siw, *iiw; casadi_real *sw, *iw_;
  casadi_int cap = 1024, head = 0, size = 0;
  casadi_int* qnode = malloc(sizeof(casadi_int) * cap);
  casadi_real* qseed = malloc(sizeof(casadi_real) * cap * nq);
  casadi_real *cur = malloc(sizeof(casadi_real) * nq), *next = malloc(sizeof(casadi_real) * nq);
  casadi_real *K = malloc(sizeof(casadi_real) * (m * n + 1)), *Kt = malloc(sizeof(casadi_real) * (m * n + 1));
  casadi_real *branch = malloc(sizeof(casadi_real) * (nb + 1));
  casadi_real stepv = 0.0, resid = 0.0, pivot = 0.0;
  const casadi_real **qa; casadi_real **qr; casadi_int *qiw; casadi_real *qw;
  if (!qnode || !qseed || !cur || !next || !K || !Kt || !branch || STEP_pkm_alloc(&sa, &sr, &siw, &sw)
      || INDEX_pkm_alloc(&ia, &ir, &iiw, &iw_) || QRSTEP_pkm_alloc(&qa, &qr, &qiw, &qw)) return 2;
  unsigned char* tries = calloc((size_t) total, 1);
  if (!tries) return 2;
  DESIGN_GRID
  for (casadi_int k = 0; k < total; ++k) { state[k] = 0; iterations[k] = 0; for (casadi_int j = 0; j < nsv; ++j) sv[k * nsv + j] = NAN; }
  for (casadi_int r = 0; r < nroots; ++r) {  /* each root not reached from an earlier one starts a search */
    if (state[roots[r]] != 0) continue;
    qnode[head] = roots[r]; memcpy(qseed + head * nq, q0, sizeof(casadi_real) * nq); size = 1; state[roots[r]] = -2;
    ++tries[roots[r]];
    while (size > 0) {
      casadi_int k = qnode[head];
      memcpy(cur, qseed + head * nq, sizeof(casadi_real) * nq);
      head = (head + 1) % cap; --size;
      if (state[k] == 1) continue;  /* solved from an earlier entry */
      const casadi_real* target = targets + k * nt;
      casadi_real previous = INFINITY;
      for (casadi_int it = 0; it < max_iter; ++it) {
        sa[0] = cur; sa[1] = target; sr[0] = next; sr[1] = &stepv; sr[2] = &pivot;
        if (STEP(sa, sr, siw, sw, 0)) return 1;
        if (!(pivot >= PIVOT_FLOOR)) {
          qa[0] = cur; qa[1] = target; qr[0] = next; qr[1] = &stepv;
          if (QRSTEP(qa, qr, qiw, qw, 0)) return 1;
        }
        iterations[k] += 1;
        if (!(stepv <= INFINITY)) break;  /* a singular matrix at the root: keep the last finite iterate */
        memcpy(cur, next, sizeof(casadi_real) * nq);
        if (stepv <= step_tol) break;
        if (it >= 2 && stepv > 0.9 * previous) break;  /* not converging (a singular root still halves its step) */
        previous = stepv;
      }
      state[k] = -3;  /* failed from this seed: another neighbour may do better */
      /* converged, stalled or stopped: the residual decides (a double root stalls at a residual of 1e-16) */
      ia[0] = cur; ia[1] = target; ia[2] = scale; ir[0] = K; ir[1] = &resid; ir[2] = branch;
      if (INDEX(ia, ir, iiw, iw_, 0)) return 1;
      if (!(resid <= tol)) continue;
      int same = 1;  /* (a branch quantity within BRANCH_TOL of 0: on the boundary between modes, in both) */
      for (casadi_int b = 0; b < nb; ++b) if (signs[b] != 0.0 && !(signs[b] * branch[b] > -BRANCH_TOL)) same = 0;
      if (!same) continue;  /* solved in another mode */
      state[k] = 1;
      if (q_out) memcpy(q_out + k * nq, cur, sizeof(casadi_real) * nq);
      if (m >= n) { memcpy(Kt, K, sizeof(casadi_real) * m * n); STEP_pkm_sv(m, n, Kt, sv + k * nsv); }
      else {  /* K^T, column-major n x m */
        for (casadi_int i = 0; i < m; ++i) for (casadi_int j = 0; j < n; ++j) Kt[i * n + j] = K[j * m + i];
        STEP_pkm_sv(n, m, Kt, sv + k * nsv);
      }
      for (casadi_int d = 0; d < ndim; ++d) {  /* queue the neighbours not reached yet, with this solution */
        casadi_int c = (k / stride[d]) % dims[d];
        for (int dir = -1; dir <= 1; dir += 2) {
          if ((dir < 0 && c == 0) || (dir > 0 && c == dims[d] - 1)) continue;
          casadi_int nb_k = k + dir * stride[d];
          if (state[nb_k] == 1 || tries[nb_k] >= 2 * ndim) continue;  /* (queued again: tried from each side) */
          if (size == cap) {  /* grow the ring buffer, unrolled from head */
            casadi_int* n2 = malloc(sizeof(casadi_int) * 2 * cap);
            casadi_real* s2 = malloc(sizeof(casadi_real) * 2 * cap * nq);
            if (!n2 || !s2) return 2;
            for (casadi_int i = 0; i < size; ++i) {
              n2[i] = qnode[(head + i) % cap];
              memcpy(s2 + i * nq, qseed + ((head + i) % cap) * nq, sizeof(casadi_real) * nq);
            }
            free(qnode); free(qseed); qnode = n2; qseed = s2; head = 0; cap *= 2;
          }
          casadi_int tail = (head + size) % cap;
          qnode[tail] = nb_k; memcpy(qseed + tail * nq, cur, sizeof(casadi_real) * nq); ++size;
          state[nb_k] = -2; ++tries[nb_k];  /* queued */
        }
      }
    }
  }
  STEP_pkm_free(sa, sr, siw, sw); INDEX_pkm_free(ia, ir, iiw, iw_); QRSTEP_pkm_free(qa, qr, qiw, qw);
  free(tries); free(qnode); free(qseed); free(cur); free(next); free(K); free(Kt); free(branch);
  return 0;
}
"""


def cache_dir() -> Path:
    """Where compiled twins are kept: the folder ``twin`` of pkm's cache (:func:`pkm.cache.cache_dir`:
    ``$PKM_CACHE_DIR``, else ``$XDG_CACHE_HOME/pkm``, ``~/.cache/pkm``)."""
    from pkm.cache import cache_dir as root

    return root() / "twin"


def source(funs: cs.Function | Iterable[cs.Function], *, follow: bool = False) -> str:
    """The C source of one CasADi function or a list (CasADi's code generator, one preamble), each with its batch
    driver, and the path driver if ``follow``."""
    funs = [funs] if isinstance(funs, cs.Function) else list(funs)
    gen = cs.CodeGenerator(f"{funs[0].name()}.c", {"with_header": False})
    for fun in funs:
        gen.add(fun)
    sizes = lambda n, f: ", ".join(str(f(i)) for i in range(n))
    text = gen.dump() + "#include <math.h>\n#include <stdlib.h>\n#include <string.h>\n"
    for fun in funs:
        drivers = (_BATCH + (_FOLLOW if follow else "")).replace("NIN", str(fun.n_in())).replace("NOUT", str(fun.n_out()))
        drivers = drivers.replace("DESIGN_FOLLOW", "arg[2] = design;" if fun.n_in() > 2 else "(void) design;")
        drivers = drivers.replace("ISZ", sizes(fun.n_in(), fun.nnz_in)).replace("OSZ", sizes(fun.n_out(), fun.nnz_out))
        text += drivers.replace("NAME", fun.name())
    return text


def map_source(step: cs.Function, qr_step: cs.Function, index: cs.Function, pivot_floor: float) -> str:
    """The C source of a map: ``step``, its fallback ``qr_step`` and ``index`` (see :data:`_GRID`) with their batch
    drivers and the grid driver ``<step>_grid``."""
    nq, nt = step.nnz_in(0), step.nnz_in(1)
    m, n = index.size_out(0)
    design = ("sa[2] = design; qa[2] = design; ia[3] = design;  /* the design: one for every node */"
              if step.n_in() > 2 else "(void) design;")
    grid = (_GRID.replace("JACOBI_SV\n", jacobi_sv("STEP_pkm_sv", 1e-17, 1e-16)).replace("DESIGN_GRID", design)
            .replace("QRSTEP", qr_step.name()).replace("STEP", step.name()).replace("INDEX", index.name())
            .replace("PIVOT_FLOOR", repr(float(pivot_floor))).replace("BRANCH_TOL", repr(BRANCH_TOL)).replace("NQ", str(nq)).replace("NT", str(nt))
            .replace("KROWS", str(m)).replace("KCOLS", str(n)).replace("NB", str(index.nnz_out(2))))
    return source([step, qr_step, index]) + grid


def compile_library(fun: cs.Function | Iterable[cs.Function], *, follow: bool = False,
                    directory: str | os.PathLike[str] | None = None, text: str | None = None,
                    flags: tuple[str, ...] | None = None) -> tuple[ctypes.CDLL | None, str]:
    """``fun`` (one CasADi function or a list) and its drivers compiled and loaded. Returns ``(library, how)``;
    ``library`` is None, and ``how`` says why, when there is no C compiler on the PATH (``cc``, ``gcc`` or
    ``clang``) or it failed.

    Args:
        fun: CasADi functions with dense inputs and outputs.
        follow: Add the path driver (``fun`` is a Newton iteration: see the module doc).
        directory: Where the source and library go (default :func:`cache_dir`).
        text: The C source, when not :func:`source` of ``fun`` (:func:`map_source`).
        flags: The compiler's optimisation flags, in place of ``-O2`` (``-O0`` above :data:`LARGE` instructions);
            ``-shared -fPIC`` are added (:mod:`pkm.core.twin.simd`).
    """
    funs = [fun] if isinstance(fun, cs.Function) else list(fun)
    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None:
        return None, "no C compiler on the PATH: cc, gcc or clang"
    text = source(funs, follow=follow) if text is None else text
    folder = Path(directory) if directory is not None else cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    flags = (*(flags if flags is not None else ("-O2" if sum(f.n_instructions() for f in funs) <= LARGE else "-O0",)),
             *_FLAGS)
    digest = hashlib.sha256((text + " ".join(flags)).encode()).hexdigest()[:20]
    name = funs[0].name()
    library = folder / f"{name}-{digest}.so"
    if not library.exists():
        with tempfile.TemporaryDirectory(dir=folder) as tmp:  # compiled aside, then moved: safe for parallel builds
            c_file = Path(tmp) / f"{name}.c"
            c_file.write_text(text)
            built = Path(tmp) / library.name
            run = subprocess.run([cc, *flags, "-o", str(built), str(c_file), "-lm"], capture_output=True, text=True,
                                 check=False, timeout=900)
            if run.returncode != 0:
                return None, f"the C compiler failed: {run.stderr.strip()[-300:]}"
            os.replace(built, library)
    return ctypes.CDLL(str(library)), f"C ({Path(cc).name} {flags[0]}, {library})"


def pointers(arrays: Iterable[np.ndarray]) -> ctypes.Array:
    """The ``double*`` array of ``arrays``' data (C-contiguous float64 arrays): how the drivers take their inputs
    and outputs."""
    arrays = list(arrays)
    return (C_REAL_P * len(arrays))(*[a.ctypes.data_as(C_REAL_P) for a in arrays])


def count_operations(fun: cs.Function) -> dict[str, int]:
    """The instructions of ``fun`` by CasADi operation (``mul``, ``add``, ``sin``...; inputs, outputs and constants
    included), counted on its virtual machine's instruction list (after whatever CSE built it)."""
    op = {getattr(cs, n): n[3:].lower() for n in dir(cs) if n.startswith("OP_")}
    counts: dict[str, int] = {}
    for k in range(fun.n_instructions()):
        name = op[fun.instruction_id(k)]
        counts[name] = counts.get(name, 0) + 1
    return counts


def paper_counts(fun: cs.Function) -> tuple[int, int, dict[str, int]]:
    """``(mul, add, functions)`` of ``fun`` counted as the papers and SYMORO count (:func:`count_operations`):
    ``*``, ``/``, squares and doublings as multiplications, ``+ -`` as additions, negations, inputs, outputs and
    constants free, every other operation apart by name."""
    counts = count_operations(fun)
    mul = sum(counts.pop(k, 0) for k in ("mul", "div", "sq", "twice"))
    add = sum(counts.pop(k, 0) for k in ("add", "sub"))
    for k in ("neg", "input", "output", "const"):
        counts.pop(k, None)
    return mul, add, counts


#: numpy expressions of CasADi's scalar operations (``a``, ``b``: the operands); ``fmin``/``fmax`` ignore a NaN
#: operand as C's do, comparisons and logic give 1.0 or 0.0. The JAX translation takes them with ``jnp`` for ``np``
#: (:mod:`pkm.core.twin.jaxgen`).
NUMPY_FORMS = {
    "ADD": "{a} + {b}", "SUB": "{a} - {b}", "MUL": "{a} * {b}", "DIV": "{a} / {b}", "NEG": "-{a}", "SQ": "{a} * {a}",
    "TWICE": "2.0 * {a}", "INV": "1.0 / {a}", "ASSIGN": "{a}", "POW": "{a} ** {b}", "CONSTPOW": "{a} ** {b}",
    "SIN": "np.sin({a})", "COS": "np.cos({a})", "TAN": "np.tan({a})", "ASIN": "np.arcsin({a})",
    "ACOS": "np.arccos({a})", "ATAN": "np.arctan({a})", "ATAN2": "np.arctan2({a}, {b})", "SQRT": "np.sqrt({a})",
    "EXP": "np.exp({a})", "LOG": "np.log({a})", "FABS": "np.abs({a})", "FMIN": "np.fmin({a}, {b})",
    "FMAX": "np.fmax({a}, {b})", "FLOOR": "np.floor({a})", "CEIL": "np.ceil({a})", "FMOD": "np.fmod({a}, {b})",
    "SIGN": "np.sign({a})", "COPYSIGN": "np.copysign({a}, {b})", "HYPOT": "np.hypot({a}, {b})",
    "SINH": "np.sinh({a})", "COSH": "np.cosh({a})", "TANH": "np.tanh({a})", "ASINH": "np.arcsinh({a})",
    "ACOSH": "np.arccosh({a})", "ATANH": "np.arctanh({a})", "EXPM1": "np.expm1({a})", "LOG1P": "np.log1p({a})",
    "IF_ELSE_ZERO": "np.where({a} != 0, {b}, 0.0)", "LT": "1.0 * ({a} < {b})", "LE": "1.0 * ({a} <= {b})",
    "EQ": "1.0 * ({a} == {b})", "NE": "1.0 * ({a} != {b})", "NOT": "1.0 * ({a} == 0)",
    "AND": "1.0 * (({a} != 0) & ({b} != 0))", "OR": "1.0 * (({a} != 0) | ({b} != 0))",
}


def instructions(fun: cs.Function, table: dict[str, str], language: str
                 ) -> Iterator[tuple[str, object, list[int], list[int]]]:
    """The instructions of the SX function ``fun`` as ``(kind, value, inputs, outputs)``: ``kind`` is ``"input"``
    (``inputs``: which input and entry), ``"output"`` (``outputs``: which output and entry), ``"const"`` (``value``
    the constant) or ``"op"`` (``value`` the expression, ``table``'s template for the operation filled with the work
    variables ``w<k>``); ``outputs[0]`` (``inputs[0]`` of an output) is the work variable written (read).

    Raises:
        ValueError: an operation ``table`` (whose keys are CasADi's ``OP_`` names) has no form for, in ``language``.
    """
    names = {getattr(cs, f"OP_{k}"): k for k in table}
    for k in range(fun.n_instructions()):
        op = fun.instruction_id(k)
        i: list[int] = list(fun.instruction_input(k))
        o: list[int] = list(fun.instruction_output(k))
        if op == cs.OP_INPUT:
            yield "input", None, i, o
        elif op == cs.OP_OUTPUT:
            yield "output", None, i, o
        elif op == cs.OP_CONST:
            yield "const", float(fun.instruction_constant(k)), i, o
        elif op in names:
            yield "op", table[names[op]].format(a=f"w{i[0]}", b=f"w{i[1]}" if len(i) > 1 else ""), i, o
        else:
            op_name = next((n[3:] for n in dir(cs) if n.startswith("OP_") and getattr(cs, n) == op), op)
            raise ValueError(f"{fun.name()}: the operation {op_name} has no {language} form here")


def python_constant(x: float, module: str = "np") -> str:
    """``x`` as a Python expression that reads back to the same double (``np.inf``, ``np.nan``: ``module``'s)."""
    if math.isnan(x):
        return f"{module}.nan"
    if math.isinf(x):
        return f"{module}.inf" if x > 0 else f"(-{module}.inf)"
    return repr(float(x))


def numpy_source(fun: cs.Function) -> str:
    """Python source of ``fun`` vectorised over samples: ``def f(np, n, in0, in1, ...)`` with each input an
    ``(n, nnz)`` array, returning the outputs as ``(n, nnz)`` arrays, one numpy statement per instruction of the
    SX function (its work vector reused as the variables ``w0, w1, ...``).

    Raises:
        ValueError: ``fun`` is not an SX function, or uses an operation :data:`NUMPY_FORMS` lacks.
    """
    if not fun.is_a("SXFunction"):
        raise ValueError(f"{fun.name()}: numpy_source needs an SX function")
    ins = ", ".join(f"in{i}" for i in range(fun.n_in()))
    lines = [f"def f(np, n, {ins}):"]
    lines += [f"    out{i} = np.zeros((n, {fun.nnz_out(i)}))" for i in range(fun.n_out())]
    for kind, value, i, o in instructions(fun, NUMPY_FORMS, "numpy"):
        if kind == "input":
            lines.append(f"    w{o[0]} = in{i[0]}[:, {i[1]}]")
        elif kind == "output":
            lines.append(f"    out{o[0]}[:, {o[1]}] = w{i[0]}")
        elif kind == "const":
            lines.append(f"    w{o[0]} = {python_constant(float(value))}")  # type: ignore[arg-type]
        else:
            lines.append(f"    w{o[0]} = {value}")
    lines.append(f"    return [{', '.join(f'out{i}' for i in range(fun.n_out()))}]")
    return "\n".join(lines) + "\n"


def numpy_function(fun: cs.Function) -> Callable[..., list[np.ndarray]]:
    """``fun`` vectorised over samples with numpy (see :func:`numpy_source`): ``g(*inputs) -> outputs``, each an
    ``(n, nnz)`` array."""
    import numpy as np

    namespace: dict = {}
    exec(compile(numpy_source(fun), f"<pkm numpy {fun.name()}>", "exec"), namespace)  # source built above, no input
    f = namespace["f"]
    return lambda *arrays: f(np, arrays[0].shape[0], *arrays)


def compile_function(fun: cs.Function, directory: str | os.PathLike[str] | None = None) -> tuple[cs.Function, str]:
    """``fun`` as compiled C loaded back as a ``casadi.Function`` (``casadi.external``) when a C compiler is present;
    else ``fun`` itself, run by CasADi's virtual machine. Returns ``(function, how)``."""
    lib, how = compile_library(fun, directory=directory)
    if lib is None:
        return fun, f"CasADi's virtual machine ({how})"
    return cs.external(fun.name(), lib._name), how


__all__ = ["C_INT", "C_REAL_P", "NUMPY_FORMS", "cache_dir", "compile_function", "compile_library", "count_operations",
           "instructions", "map_source", "numpy_function", "numpy_source", "paper_counts", "pointers", "python_constant",
           "source"]
