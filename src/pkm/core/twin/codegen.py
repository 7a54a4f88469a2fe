"""The twin's functions as generated C, compiled and loaded; with drivers that run them over batches and paths.

:func:`compile_library` writes a CasADi function as C (CasADi's code generator), appends two drivers, compiles the
whole with the system's C compiler (``cc -O2 -shared``, ``-O0`` above :data:`LARGE` instructions) and loads it with :mod:`ctypes`:

* ``NAME_batch(n, in, out)``: the function on ``n`` samples, each input and output a sample-major array;
* ``NAME_follow(n, q0, targets, q_out, residual, pivot, iterations, max_iter, tol)``, for a Newton iteration
  (inputs ``q, target``; outputs ``q_next, residual, pivot``): per target, iterate from the previous solution
  (the first from ``q0``) until the residual is at most ``tol`` or ``max_iter`` iterations were made.

Libraries are cached by the hash of their source (the folder :func:`cache_dir`), so a mechanism is compiled once per
machine. Without a C compiler (or when it fails) :func:`compile_library` returns None and says why; the callers run
CasADi's virtual machine instead.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import casadi as cs

_FLAGS = ("-shared", "-fPIC")
#: Functions with more instructions than this are compiled with ``-O0``: gcc 12's ``-O2`` takes 40 s on the hexapod's
#: 52,000-instruction derivatives (one basic block), ``-O0`` 2.5 s.
LARGE = 20_000

_BATCH = r"""
/* pkm drivers */
#include <stdlib.h>
#include <string.h>
static const casadi_int NAME_isz[] = {ISZ}, NAME_osz[] = {OSZ};

static int NAME_pkm_alloc(const casadi_real*** arg, casadi_real*** res, casadi_int** iw, casadi_real** w) {
  casadi_int sz_arg, sz_res, sz_iw, sz_w;
  NAME_work(&sz_arg, &sz_res, &sz_iw, &sz_w);
  *arg = malloc(sizeof(casadi_real*) * (sz_arg + 1)); *res = malloc(sizeof(casadi_real*) * (sz_res + 1));
  *iw = malloc(sizeof(casadi_int) * (sz_iw + 1)); *w = malloc(sizeof(casadi_real) * (sz_w + 1));
  return !(*arg && *res && *iw && *w);
}

static void NAME_pkm_free(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w) {
  free((void*) arg); free(res); free(iw); free(w);
}

int NAME_batch(casadi_int n, const casadi_real** in, casadi_real** out) {
  const casadi_real** arg; casadi_real** res; casadi_int* iw; casadi_real* w; int flag = 0;
  if (NAME_pkm_alloc(&arg, &res, &iw, &w)) return 2;
  for (casadi_int k = 0; k < n && !flag; ++k) {
    for (int i = 0; i < NIN; ++i) arg[i] = in[i] + k * NAME_isz[i];
    for (int i = 0; i < NOUT; ++i) res[i] = out[i] + k * NAME_osz[i];
    flag = NAME(arg, res, iw, w, 0);
  }
  NAME_pkm_free(arg, res, iw, w);
  return flag;
}
"""

_FOLLOW = r"""
int NAME_follow(casadi_int n, const casadi_real* q0, const casadi_real* targets, casadi_real* q_out,
                casadi_real* residual, casadi_real* pivot, casadi_int* iterations, casadi_int max_iter,
                casadi_real tol) {
  const casadi_real** arg; casadi_real** res; casadi_int* iw; casadi_real* w;
  const casadi_int nq = NAME_isz[0], nt = NAME_isz[1];
  casadi_real* cur = malloc(sizeof(casadi_real) * nq); casadi_real* next = malloc(sizeof(casadi_real) * nq);
  if (!cur || !next || NAME_pkm_alloc(&arg, &res, &iw, &w)) return 2;
  memcpy(cur, q0, sizeof(casadi_real) * nq);
  for (casadi_int k = 0; k < n; ++k) {
    casadi_real r = 0.0, p = 0.0; casadi_int it = 0;
    arg[1] = targets + k * nt; res[0] = next; res[1] = &r; res[2] = &p;
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


def cache_dir() -> Path:
    """Where compiled twins are kept: ``$PKM_CACHE_DIR``, else ``$XDG_CACHE_HOME/pkm/twin`` (``~/.cache/pkm/twin``)."""
    if os.environ.get("PKM_CACHE_DIR"):
        return Path(os.environ["PKM_CACHE_DIR"])
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "pkm" / "twin"


def source(fun: cs.Function, *, follow: bool = False) -> str:
    """The C source of ``fun`` (CasADi's code generator) with the batch driver, and the path driver if ``follow``."""
    name = fun.name()
    gen = cs.CodeGenerator(f"{name}.c", {"with_header": False})
    gen.add(fun)
    sizes = lambda n, f: ", ".join(str(f(i)) for i in range(n))
    drivers = (_BATCH + (_FOLLOW if follow else "")).replace("NIN", str(fun.n_in())).replace("NOUT", str(fun.n_out()))
    drivers = drivers.replace("ISZ", sizes(fun.n_in(), fun.nnz_in)).replace("OSZ", sizes(fun.n_out(), fun.nnz_out))
    return gen.dump() + drivers.replace("NAME", name)


def compile_library(fun: cs.Function, *, follow: bool = False, directory=None) -> tuple[ctypes.CDLL | None, str]:
    """``fun`` and its drivers compiled and loaded. Returns ``(library, how)``; ``library`` is None, and ``how`` says
    why, when there is no C compiler on the PATH (``cc``, ``gcc`` or ``clang``) or it failed.

    Args:
        fun: A CasADi function with dense inputs and outputs.
        follow: Add the path driver (``fun`` is a Newton iteration: see the module doc).
        directory: Where the source and library go (default :func:`cache_dir`).
    """
    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None:
        return None, "no C compiler on the PATH: cc, gcc or clang"
    text = source(fun, follow=follow)
    folder = Path(directory) if directory is not None else cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    flags = ("-O2" if fun.n_instructions() <= LARGE else "-O0", *_FLAGS)
    digest = hashlib.sha256((text + " ".join(flags)).encode()).hexdigest()[:20]
    library = folder / f"{fun.name()}-{digest}.so"
    if not library.exists():
        with tempfile.TemporaryDirectory(dir=folder) as tmp:  # compiled aside, then moved: safe for parallel builds
            c_file = Path(tmp) / f"{fun.name()}.c"
            c_file.write_text(text)
            built = Path(tmp) / library.name
            run = subprocess.run([cc, *flags, "-o", str(built), str(c_file)], capture_output=True, text=True,
                                 check=False, timeout=900)
            if run.returncode != 0:
                return None, f"the C compiler failed: {run.stderr.strip()[-300:]}"
            os.replace(built, library)
    return ctypes.CDLL(str(library)), f"C ({Path(cc).name} {flags[0]}, {library})"


def count_operations(fun: cs.Function) -> dict[str, int]:
    """The instructions of ``fun`` by CasADi operation (``mul``, ``add``, ``sin``...; inputs, outputs and constants
    included), counted on its virtual machine's instruction list (after whatever CSE built it)."""
    op = {getattr(cs, n): n[3:].lower() for n in dir(cs) if n.startswith("OP_")}
    counts: dict[str, int] = {}
    for k in range(fun.n_instructions()):
        name = op[fun.instruction_id(k)]
        counts[name] = counts.get(name, 0) + 1
    return counts


#: numpy expressions of CasADi's scalar operations (``a``, ``b``: the operands).
_NUMPY = {
    "ADD": "{a} + {b}", "SUB": "{a} - {b}", "MUL": "{a} * {b}", "DIV": "{a} / {b}", "NEG": "-{a}", "SQ": "{a} * {a}",
    "TWICE": "2.0 * {a}", "INV": "1.0 / {a}", "ASSIGN": "{a}", "POW": "{a} ** {b}", "CONSTPOW": "{a} ** {b}",
    "SIN": "np.sin({a})", "COS": "np.cos({a})", "TAN": "np.tan({a})", "ASIN": "np.arcsin({a})",
    "ACOS": "np.arccos({a})", "ATAN": "np.arctan({a})", "ATAN2": "np.arctan2({a}, {b})", "SQRT": "np.sqrt({a})",
    "EXP": "np.exp({a})", "LOG": "np.log({a})", "FABS": "np.abs({a})", "FMIN": "np.minimum({a}, {b})",
    "FMAX": "np.maximum({a}, {b})", "FLOOR": "np.floor({a})", "CEIL": "np.ceil({a})", "FMOD": "np.fmod({a}, {b})",
    "SIGN": "np.sign({a})", "COPYSIGN": "np.copysign({a}, {b})", "HYPOT": "np.hypot({a}, {b})",
    "SINH": "np.sinh({a})", "COSH": "np.cosh({a})", "TANH": "np.tanh({a})",
    "IF_ELSE_ZERO": "np.where({a} != 0, {b}, 0.0)", "LT": "1.0 * ({a} < {b})", "LE": "1.0 * ({a} <= {b})",
    "EQ": "1.0 * ({a} == {b})", "NE": "1.0 * ({a} != {b})", "NOT": "1.0 * ({a} == 0)",
    "AND": "1.0 * (({a} != 0) & ({b} != 0))", "OR": "1.0 * (({a} != 0) | ({b} != 0))",
}


def numpy_source(fun: cs.Function) -> str:
    """Python source of ``fun`` vectorised over samples: ``def f(np, n, in0, in1, ...)`` with each input an
    ``(n, nnz)`` array, returning the outputs as ``(n, nnz)`` arrays, one numpy statement per instruction of the
    SX function (its work vector reused as the variables ``w0, w1, ...``).

    Raises:
        ValueError: ``fun`` is not an SX function, or uses an operation :data:`_NUMPY` lacks.
    """
    if not fun.is_a("SXFunction"):
        raise ValueError(f"{fun.name()}: numpy_source needs an SX function")
    names = {getattr(cs, f"OP_{k}"): k for k in _NUMPY}
    ins = ", ".join(f"in{i}" for i in range(fun.n_in()))
    lines = [f"def f(np, n, {ins}):"]
    lines += [f"    out{i} = np.zeros((n, {fun.nnz_out(i)}))" for i in range(fun.n_out())]
    for k in range(fun.n_instructions()):
        op, i, o = fun.instruction_id(k), fun.instruction_input(k), fun.instruction_output(k)
        if op == cs.OP_INPUT:
            lines.append(f"    w{o[0]} = in{i[0]}[:, {i[1]}]")
        elif op == cs.OP_OUTPUT:
            lines.append(f"    out{o[0]}[:, {o[1]}] = w{i[0]}")
        elif op == cs.OP_CONST:
            lines.append(f"    w{o[0]} = {float(fun.instruction_constant(k))!r}")
        elif op in names:
            expr = _NUMPY[names[op]].format(a=f"w{i[0]}", b=f"w{i[1]}" if len(i) > 1 else "")
            lines.append(f"    w{o[0]} = {expr}")
        else:
            op_name = next((n[3:] for n in dir(cs) if n.startswith("OP_") and getattr(cs, n) == op), op)
            raise ValueError(f"{fun.name()}: the operation {op_name} has no numpy form here")
    lines.append(f"    return [{', '.join(f'out{i}' for i in range(fun.n_out()))}]")
    return "\n".join(lines) + "\n"


def numpy_function(fun: cs.Function):
    """``fun`` vectorised over samples with numpy (see :func:`numpy_source`): ``g(*inputs) -> outputs``, each an
    ``(n, nnz)`` array."""
    import numpy as np

    namespace: dict = {}
    exec(compile(numpy_source(fun), f"<pkm numpy {fun.name()}>", "exec"), namespace)  # source built above, no input
    f = namespace["f"]
    return lambda *arrays: f(np, arrays[0].shape[0], *arrays)


def compile_function(fun: cs.Function, directory=None) -> tuple[cs.Function, str]:
    """``fun`` as compiled C loaded back as a ``casadi.Function`` (``casadi.external``) when a C compiler is present;
    else ``fun`` itself, run by CasADi's virtual machine. Returns ``(function, how)``."""
    lib, how = compile_library(fun, directory=directory)
    if lib is None:
        return fun, f"CasADi's virtual machine ({how})"
    return cs.external(fun.name(), lib._name), how


__all__ = ["cache_dir", "compile_function", "compile_library", "count_operations", "numpy_function", "numpy_source",
           "source"]
