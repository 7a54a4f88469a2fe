"""CasADi SX functions written as plain C99: one ``static void`` function each, its work variables as locals.

CasADi's own code generator writes a library around each function (memory management entry points, sparsity
tables, ``casadi_int``/``casadi_real`` types, unused ``iw``/``w``/``mem`` arguments) that a strict
``-Wall -Wextra -Werror -pedantic`` build rejects and that a controller does not want in its symbol table. The
functions here are written from the SX instruction list instead (as :func:`pkm.core.twin.codegen.numpy_source`
writes numpy): ``static void NAME(const double* in0, ..., double* out0, ...)``, each input and output a dense
column-major array, only ``<math.h>`` needed, no state.
"""

from __future__ import annotations

import math

import casadi as cs

from pkm.core.twin.codegen import instructions

#: C expressions of CasADi's scalar operations (``a``, ``b``: the operands).
_C = {
    "ADD": "{a} + {b}", "SUB": "{a} - {b}", "MUL": "{a} * {b}", "DIV": "{a} / {b}", "NEG": "-{a}", "SQ": "{a} * {a}",
    "TWICE": "2.0 * {a}", "INV": "1.0 / {a}", "ASSIGN": "{a}", "POW": "pow({a}, {b})", "CONSTPOW": "pow({a}, {b})",
    "SIN": "sin({a})", "COS": "cos({a})", "TAN": "tan({a})", "ASIN": "asin({a})", "ACOS": "acos({a})",
    "ATAN": "atan({a})", "ATAN2": "atan2({a}, {b})", "SQRT": "sqrt({a})", "EXP": "exp({a})", "LOG": "log({a})",
    "FABS": "fabs({a})", "FMIN": "fmin({a}, {b})", "FMAX": "fmax({a}, {b})", "FLOOR": "floor({a})",
    "CEIL": "ceil({a})", "FMOD": "fmod({a}, {b})", "COPYSIGN": "copysign({a}, {b})", "HYPOT": "hypot({a}, {b})",
    "SINH": "sinh({a})", "COSH": "cosh({a})", "TANH": "tanh({a})",
    "SIGN": "({a} > 0.0 ? 1.0 : ({a} < 0.0 ? -1.0 : 0.0))",
    "IF_ELSE_ZERO": "({a} != 0.0 ? {b} : 0.0)", "LT": "({a} < {b} ? 1.0 : 0.0)", "LE": "({a} <= {b} ? 1.0 : 0.0)",
    "EQ": "({a} == {b} ? 1.0 : 0.0)", "NE": "({a} != {b} ? 1.0 : 0.0)", "NOT": "({a} == 0.0 ? 1.0 : 0.0)",
    "AND": "({a} != 0.0 && {b} != 0.0 ? 1.0 : 0.0)", "OR": "({a} != 0.0 || {b} != 0.0 ? 1.0 : 0.0)",
}


def c_constant(x: float) -> str:
    """``x`` as a C double literal that reads back to the same double (``INFINITY``, ``NAN`` from ``<math.h>``)."""
    if math.isnan(x):
        return "NAN"
    if math.isinf(x):
        return "INFINITY" if x > 0 else "(-INFINITY)"
    text = repr(float(x))
    return text if any(c in text for c in ".eE") else text + ".0"


def c_function(fun: cs.Function, name: str) -> str:
    """The C99 source of ``static void name(const double* <in>, ..., double* <out>, ...)`` computing ``fun`` (an SX
    function with dense outputs), arguments named after ``fun``'s inputs and outputs.

    Raises:
        ValueError: ``fun`` is not an SX function, has a sparse output, or uses an operation :data:`_C` lacks.
    """
    if not fun.is_a("SXFunction"):
        raise ValueError(f"{fun.name()}: c_function needs an SX function")
    for j in range(fun.n_out()):
        if fun.nnz_out(j) != fun.numel_out(j):
            raise ValueError(f"{fun.name()}: output {fun.name_out(j)} is sparse; densify it")
    ins = [f"const double* {fun.name_in(j)}" for j in range(fun.n_in())]
    outs = [f"double* {fun.name_out(j)}" for j in range(fun.n_out())]
    body: list[str] = []
    used: set[int] = set()
    read: set[int] = set()
    written: set[int] = set()
    for kind, value, i, o in instructions(fun, _C, "C"):
        if kind == "input":
            body.append(f"w{o[0]} = {fun.name_in(i[0])}[{i[1]}];")
            read.add(i[0])
        elif kind == "output":
            body.append(f"{fun.name_out(o[0])}[{o[1]}] = w{i[0]};")
            written.add(o[0])
            continue
        else:
            body.append(f"w{o[0]} = {c_constant(value) if kind == 'const' else value};")  # type: ignore[arg-type]
        used.add(o[0])
    declare = []
    ordered = sorted(used)
    for at in range(0, len(ordered), 16):
        declare.append("double " + ", ".join(f"w{j}" for j in ordered[at:at + 16]) + ";")
    declare += [f"(void) {fun.name_in(j)};" for j in range(fun.n_in()) if j not in read]
    declare += [f"(void) {fun.name_out(j)};" for j in range(fun.n_out()) if j not in written]
    signature = f"static void {name}({', '.join(ins + outs)})"
    return signature + " {\n" + "".join(f"  {line}\n" for line in declare + body) + "}\n"


__all__ = ["c_constant", "c_function"]
