"""The twin's functions on the vector units: a batch driver that runs LANES samples at once, one vector operation per
SX instruction.

CasADi's code generator (:func:`pkm.core.twin.codegen.source`) writes a function for one sample and ``NAME_batch``
calls it sample after sample: every operation runs on one double, its helpers (``casadi_fmin``, ``casadi_sq``...)
are called through the PLT, and no compiler vectorises across the calls (the body reads and writes through the
``arg``/``res`` pointer tables). Here the SX function is written again from its instruction list
(:func:`~pkm.core.twin.codegen.instructions`, as :func:`~pkm.core.twin.codegen.numpy_source` writes numpy), every
work variable a GCC/Clang vector type ``pkm_v`` of ``PKM_LANES`` doubles, so that each instruction is one vector
operation across the lanes' samples (samples innermost, structure of arrays inside the driver; nothing is left for
the compiler to prove). The driver ``NAME_simd(n, in, out)`` has ``NAME_batch``'s calling convention (each input and
output a sample-major ``n x nnz`` array; returns 0): per block it gathers ``PKM_LANES`` samples' inputs into vectors
(built in registers, not through memory), runs the body, scatters the outputs; a tail (``n`` not a multiple of the
lanes) is padded with its last sample and only its valid lanes are written.

Rounding. The scalar path is ``cc -O2`` without ``-march``: no FMA on x86-64, so no contraction. Here the library
is compiled with ``-march=native -ffp-contract=off`` (no FMA contraction across statements), and ``+ - * /``,
negations, squares, square roots, ``fabs``, ``copysign``, ``fmin``/``fmax`` (glibc's rule: ``x < y ? x : y``, the
other operand where one is a NaN), ``sign``, the comparisons and ``if_else_zero`` are exact per lane, so they give
the scalar path's bits. Every other function goes lane by lane through libm (``maths="libm"``, the default: the
calls the scalar path makes, a sine and a cosine of one value as one ``sincos``, as gcc pairs them there): the
driver is **bit for bit** ``NAME_batch`` (tested on every operation at special values, and on the 3-PRS's and the
Delta's kernels). ``maths="libmvec"`` takes glibc's vector variants instead (``_ZGVeN8v_sin``... declared here,
linked with ``-lmvec``; within about 2 ulp of libm each): faster, no longer bit for bit: inverse dynamics within
6e-16 (3-PRS) and 1.2e-15 (Delta) of the scalar path relative to each sample's largest effort, but up to 5e-14 for
the hexapod (whose closure amplifies the sines' last bits about fifty times; the scalar path's own rounding is of
that size too): over the 1e-14 the issue allows, hence not the default.

Measured (one core of a 2-core AVX-512 Xeon, gcc 12, inverse dynamics over 100,000 samples, median of 8 runs):

=========================  ==============  ===============
µs a sample                3-PRS (750 op)  hexapod (3,478)
=========================  ==============  ===============
scalar ``NAME_batch``      0.136           0.639
libm, 4 lanes (default)    0.053           0.244
libm, 8 lanes              0.059           0.272
libmvec, 8 lanes           0.037           0.147
=========================  ==============  ===============

Lanes: with AVX-512 8 for libmvec but 4 for libm: a libm call spills every live vector (the vector registers are
the caller's to save), twice the bytes at 8 lanes, and the 512-bit units clock lower (:func:`peak_gflops`: 51
GFLOP/s multiply-then-add at 8 lanes, 50 at 4). With AVX 4, else 2 (``lanes=`` forces it). Of the 3-PRS's 53 ns
about 20 are its three lane-wise ``sincos`` (glibc's scalar ``sincos``: ~7 ns a call), 12 its 38 divisions (the
divider: ~0.5 ns a lane whatever the width), 7 the gather and scatter; libmvec's sine and cosine cost ~1.5 ns a lane
together.

Compile time: the hexapod's inverse dynamics 0.6 s (``-O2``; CasADi's C: 0.45 s). gcc's register allocation on one
basic block grows faster than the block (``-O1`` on the hexapod's 52,000-instruction derivatives in one function:
37 s, 24 of them assigning registers), so a body of more than :data:`CHUNK` instructions is cut into C functions
(not inlined) that pass the values live across a cut through the work vector in memory: the derivatives in parts
of :data:`LARGE_CHUNK` compile in 7 s at ``-O2`` and run in 2.9 µs a sample (CasADi's C at ``-O0``: 1.2 s, 25 µs).
:func:`peak_gflops` measures this core's double-precision vector peak, for stating the fraction a kernel reaches.
The scatter is one loop per output: written out, one store per nonzero and lane, gcc spent most of the time on
proving those stores apart from the vectors they read (the Delta's regressor, 396 outputs: 3.9 s to compile, its
body 0.5 s of it; 0.75 s with the loops, the same bits and the same speed).
"""

from __future__ import annotations

import ctypes
import functools
import os
import shutil
import statistics
import subprocess
import time
from collections.abc import Callable

import casadi as cs
import numpy as np

from pkm.core.export.emit import c_constant
from pkm.core.twin.codegen import C_INT, C_REAL_P, compile_library, instructions, pointers

#: A function of more instructions is cut into parts of this many, each its own C function (:func:`_body`): gcc's
#: register allocation on one basic block grows faster than the block (``-O1`` on the hexapod's 52,000-instruction
#: derivatives in one function: 37 s, 24 of them assigning registers).
CHUNK = 4000
#: Above this many instructions the parts are of :data:`LARGE_CHUNK` (the 52,000 instructions: 6 s at ``-O2``).
LARGE = 20_000
LARGE_CHUNK = 1000
#: The ways math functions run: lane by lane through libm (bit for bit the scalar path's), or glibc's libmvec
#: (faster, within about 2 ulp a call).
MATHS = ("libm", "libmvec")

_OPT = ("-march=native", "-ffp-contract=off", "-fno-math-errno")

_PRELUDE = r"""/* pkm SIMD driver (pkm.core.twin.simd) TARGET */
#define _GNU_SOURCE  /* sincos */
#include <math.h>
#include <string.h>
#ifndef PKM_LANES
#if defined(__AVX512F__)
#define PKM_LANES @WIDEST@
#elif defined(__AVX__)
#define PKM_LANES 4
#else
#define PKM_LANES 2
#endif
#endif
typedef double pkm_v __attribute__((vector_size(8 * PKM_LANES)));
typedef long long pkm_m __attribute__((vector_size(8 * PKM_LANES)));
#define PKM_EACH _Pragma("GCC unroll 8") for (int l = 0; l < PKM_LANES; ++l)
static inline pkm_v pkm_splat(double c) { pkm_v r; PKM_EACH r[l] = c; return r; }
static inline pkm_v pkm_sel(pkm_m m, pkm_v a, pkm_v b) { return (pkm_v) ((m & (pkm_m) a) | (~m & (pkm_m) b)); }
static inline pkm_v pkm_bool(pkm_m m) { return (pkm_v) (m & (pkm_m) pkm_splat(1.0)); }
static inline pkm_v pkm_fabs(pkm_v a) { return (pkm_v) ((pkm_m) a & ~(pkm_m) pkm_splat(-0.0)); }
static inline pkm_v pkm_copysign(pkm_v a, pkm_v b) {
  pkm_m s = (pkm_m) pkm_splat(-0.0); return (pkm_v) (((pkm_m) a & ~s) | ((pkm_m) b & s));
}
/* glibc's fmin/fmax on x86-64: minsd/maxsd when ordered (x < y ? x : y), the other operand when one is a NaN */
static inline pkm_v pkm_fmin(pkm_v a, pkm_v b) { pkm_v r = pkm_sel(a < b, a, b); r = pkm_sel(a != a, b, r); return pkm_sel(b != b, a, r); }
static inline pkm_v pkm_fmax(pkm_v a, pkm_v b) { pkm_v r = pkm_sel(a > b, a, b); r = pkm_sel(a != a, b, r); return pkm_sel(b != b, a, r); }
/* casadi_sign: x < 0 ? -1 : x > 0 ? 1 : x */
static inline pkm_v pkm_sign(pkm_v a) {
  pkm_v z = pkm_splat(0.0); return pkm_sel(a < z, pkm_splat(-1.0), pkm_sel(a > z, pkm_splat(1.0), a));
}
static inline pkm_v pkm_sqrt(pkm_v a) { pkm_v r; PKM_EACH r[l] = sqrt(a[l]); return r; }
/* lane by lane through libm: the lanes stored, the calls made, the results loaded as one vector */
#define PKM_LANEWISE1(name, f) static inline pkm_v name(pkm_v a) { \
    double x[PKM_LANES], r[PKM_LANES]; pkm_v v; memcpy(x, &a, sizeof x); \
    PKM_EACH r[l] = f(x[l]); memcpy(&v, r, sizeof v); return v; }
#define PKM_LANEWISE2(name, f) static inline pkm_v name(pkm_v a, pkm_v b) { \
    double x[PKM_LANES], y[PKM_LANES], r[PKM_LANES]; pkm_v v; memcpy(x, &a, sizeof x); memcpy(y, &b, sizeof y); \
    PKM_EACH r[l] = f(x[l], y[l]); memcpy(&v, r, sizeof v); return v; }
static inline void pkm_sincos_l(pkm_v a, pkm_v* s, pkm_v* c) {
  double x[PKM_LANES], rs[PKM_LANES], rc[PKM_LANES]; memcpy(x, &a, sizeof x);
  PKM_EACH sincos(x[l], &rs[l], &rc[l]);
  memcpy(s, rs, sizeof rs); memcpy(c, rc, sizeof rc);
}
"""

#: libmvec's vector variants (x86-64 vector function ABI: ``b`` SSE2, ``c`` AVX, ``d`` AVX2, ``e`` AVX-512).
_MVEC1 = ("sin", "cos", "tan", "asin", "acos", "atan", "exp", "log", "sinh", "cosh", "tanh", "erf", "log1p", "expm1",
          "asinh", "acosh", "atanh")
_MVEC2 = ("pow", "atan2", "hypot")
_LIBM1 = (*_MVEC1, "floor", "ceil")
_LIBM2 = (*_MVEC2, "fmod", "remainder")

_MVEC_ISA = r"""
#if defined(__x86_64__) && PKM_LANES == 8 && defined(__AVX512F__)
#define PKM_MVEC(f, k) _ZGVeN8##k##_##f
#elif defined(__x86_64__) && PKM_LANES == 4 && defined(__AVX2__)
#define PKM_MVEC(f, k) _ZGVdN4##k##_##f
#elif defined(__x86_64__) && PKM_LANES == 4 && defined(__AVX__)
#define PKM_MVEC(f, k) _ZGVcN4##k##_##f
#elif defined(__x86_64__) && PKM_LANES == 2
#define PKM_MVEC(f, k) _ZGVbN2##k##_##f
#endif
#ifdef PKM_MVEC
#define PKM_VECTOR_MATH 1
"""

#: Vector C of CasADi's scalar operations (``a``, ``b``: the operands), as CasADi's code generator writes them.
_VEC = {
    "ADD": "{a} + {b}", "SUB": "{a} - {b}", "MUL": "{a} * {b}", "DIV": "{a} / {b}", "NEG": "-{a}", "SQ": "{a} * {a}",
    "TWICE": "2.0 * {a}", "INV": "1.0 / {a}", "ASSIGN": "{a}", "POW": "pkm_pow({a}, {b})",
    "CONSTPOW": "pkm_pow({a}, {b})", "SQRT": "pkm_sqrt({a})", "FABS": "pkm_fabs({a})", "FMIN": "pkm_fmin({a}, {b})",
    "FMAX": "pkm_fmax({a}, {b})", "COPYSIGN": "pkm_copysign({a}, {b})", "SIGN": "pkm_sign({a})",
    "IF_ELSE_ZERO": "pkm_sel({a} != pkm_splat(0.0), {b}, pkm_splat(0.0))",
    "LT": "pkm_bool({a} < {b})", "LE": "pkm_bool({a} <= {b})", "EQ": "pkm_bool({a} == {b})",
    "NE": "pkm_bool({a} != {b})", "NOT": "pkm_bool({a} == pkm_splat(0.0))",
    "AND": "pkm_bool(({a} != pkm_splat(0.0)) & ({b} != pkm_splat(0.0)))",
    "OR": "pkm_bool(({a} != pkm_splat(0.0)) | ({b} != pkm_splat(0.0)))",
    **{f.upper(): f"pkm_{f}({{a}})" for f in _LIBM1}, **{f.upper(): f"pkm_{f}({{a}}, {{b}})" for f in _LIBM2},
}
_VEC = {k: v for k, v in _VEC.items() if hasattr(cs, f"OP_{k}")}


def _functions(maths: str) -> str:
    """The C of the lane-wise (libm) math helpers, and with ``maths="libmvec"`` libmvec's declarations replacing
    those it has where the lanes have a variant."""
    text = "".join(f"PKM_LANEWISE1(pkm_{f}_l, {f})\n" for f in _LIBM1)
    text += "".join(f"PKM_LANEWISE2(pkm_{f}_l, {f})\n" for f in _LIBM2)
    lanewise = "".join(f"#define pkm_{f} pkm_{f}_l\n" for f in (*_LIBM1, *_LIBM2))
    if maths == "libm":
        return text + lanewise + "#define PKM_VECTOR_MATH 0\n"
    vector = "".join(f"pkm_v PKM_MVEC({f}, v)(pkm_v);\n#define pkm_{f} PKM_MVEC({f}, v)\n" for f in _MVEC1)
    vector += "".join(f"pkm_v PKM_MVEC({f}, vv)(pkm_v, pkm_v);\n#define pkm_{f} PKM_MVEC({f}, vv)\n" for f in _MVEC2)
    rest = "".join(f"#define pkm_{f} pkm_{f}_l\n" for f in ("floor", "ceil", "fmod", "remainder"))
    return text + _MVEC_ISA + vector + rest + "#else\n" + lanewise + "#define PKM_VECTOR_MATH 0\n#endif\n"


def _body(fun: cs.Function, name: str, maths: str, chunk: int = 0) -> str:
    """``static void NAME_simd_block(const pkm_v* x, pkm_v* y)``: ``fun`` on one vector of samples, its inputs'
    entries one after the other in ``x``, the outputs' in ``y``; a sine and a cosine of one value as one ``sincos``
    (libm: what gcc makes of the scalar code), each on its own (libmvec). The work variables are locals; a function
    of more than ``chunk`` instructions (default :data:`CHUNK`, :data:`LARGE_CHUNK` above :data:`LARGE`) is cut into functions of ``chunk`` instructions
    (not inlined: the register allocator's time grows faster than the block), the values live from one to the next
    passed through the work vector ``W`` in memory."""
    chunk = chunk or (CHUNK if fun.n_instructions() <= LARGE else LARGE_CHUNK)
    ops = [fun.instruction_id(k) for k in range(fun.n_instructions())]
    listing = list(instructions(fun, _VEC, "vector C"))
    part = [k // chunk for k in range(len(listing))]
    parts = part[-1] + 1 if listing else 1
    in_at = np.concatenate([[0], np.cumsum([fun.nnz_in(j) for j in range(fun.n_in())])]).astype(int)
    out_at = np.concatenate([[0], np.cumsum([fun.nnz_out(j) for j in range(fun.n_out())])]).astype(int)
    # the values: (work variable, how many times it was written before); a sine and a cosine of one value (in one
    # part) pair up
    version: dict[int, int] = {}
    trig: dict[tuple[int, int, int], dict[int, int]] = {}
    reads: list[set[int]] = [set() for _ in range(parts)]  # per part: work variables read before written in it
    writes: list[set[int]] = [set() for _ in range(parts)]
    for k, (kind, _, i, o) in enumerate(listing):
        if kind == "op" and ops[k] in (cs.OP_SIN, cs.OP_COS):
            trig.setdefault((i[0], version.get(i[0], 0), part[k]), {}).setdefault(ops[k], k)
        if kind in ("op", "output"):
            reads[part[k]].update(j for j in i[:1 if kind == "output" else 2] if j not in writes[part[k]])
        if kind != "output":
            version[o[0]] = version.get(o[0], 0) + 1
            writes[part[k]].add(o[0])
    live_out: list[set[int]] = [set() for _ in range(parts)]  # per part: what a later part reads of it
    for c in range(parts - 2, -1, -1):
        live_out[c] = reads[c + 1] | (live_out[c + 1] - writes[c + 1])
    pairs = {} if maths != "libm" else {min(d.values()): d for d in trig.values() if len(d) == 2}
    later = {d[op]: k for k, d in pairs.items() for op in d if d[op] != k}
    lines: list[list[str]] = [[] for _ in range(parts)]
    for k, (kind, value, i, o) in enumerate(listing):
        out = lines[part[k]]
        if kind == "input":
            out.append(f"w{o[0]} = x[{in_at[i[0]] + i[1]}];")
        elif kind == "output":
            out.append(f"y[{out_at[o[0]] + o[1]}] = w{i[0]};")
        elif kind == "const":
            out.append(f"w{o[0]} = pkm_splat({c_constant(value)});")  # type: ignore[arg-type]
        elif k in pairs:
            s, c = pairs[k][cs.OP_SIN], pairs[k][cs.OP_COS]
            out.append(f"pkm_sincos_l(w{i[0]}, &s{s}, &c{c});")
            out.append(f"w{o[0]} = {'s' if k == s else 'c'}{k};")
        elif k in later:
            out.append(f"w{o[0]} = {'s' if ops[k] == cs.OP_SIN else 'c'}{k};")
        else:
            out.append(f"w{o[0]} = {value};")
    texts = []
    for c in range(parts):
        temps = sorted(f"{'s' if ops[k] == cs.OP_SIN else 'c'}{k}" for d in pairs.values() for k in d.values()
                       if part[k] == c)
        names = [f"w{j}" for j in sorted(reads[c] | writes[c])] + temps
        body = [f"pkm_v {', '.join(names[at:at + 16])};" for at in range(0, len(names), 16)]
        body += [f"w{j} = W[{j}];" for j in sorted(reads[c])]
        body += lines[c] + [f"W[{j}] = w{j};" for j in sorted(writes[c] & live_out[c])]
        signature = (f"static void {name}_simd_block(const pkm_v* restrict x, pkm_v* restrict y)" if parts == 1 else
                     f"static __attribute__((noinline)) void {name}_simd_{c}(const pkm_v* restrict x, "
                     f"pkm_v* restrict y, pkm_v* restrict W)")
        texts.append(signature + " {\n" + "".join(f"  {line}\n" for line in body) + "}\n")
    if parts > 1:
        size = 1 + max((o[0] for kind, _, _, o in listing if kind != "output"), default=0)
        calls = "".join(f"  {name}_simd_{c}(x, y, W);\n" for c in range(parts))
        texts.append(f"static void {name}_simd_block(const pkm_v* restrict x, pkm_v* restrict y) {{\n"
                     f"  pkm_v W[{size}];\n{calls}}}\n")
    return "\n".join(texts)


_DRIVER = r"""
#if PKM_LANES == 8
#define PKM_GATHER(p, s, nz, i) (pkm_v) { p[s[0] * nz + i], p[s[1] * nz + i], p[s[2] * nz + i], p[s[3] * nz + i], \
                                          p[s[4] * nz + i], p[s[5] * nz + i], p[s[6] * nz + i], p[s[7] * nz + i] }
#elif PKM_LANES == 4
#define PKM_GATHER(p, s, nz, i) (pkm_v) { p[s[0] * nz + i], p[s[1] * nz + i], p[s[2] * nz + i], p[s[3] * nz + i] }
#else
#define PKM_GATHER(p, s, nz, i) (pkm_v) { p[s[0] * nz + i], p[s[1] * nz + i] }
#endif

int NAME_simd_steps(long long n, const double** in, double** out, const long long* steps) {
  /* steps[j]: input j's stride (NULL: every input its size; 0: one value for every sample, a design) */
  pkm_v x[@NX@], y[@NY@];
  for (long long k = 0; k < n; k += PKM_LANES) {
    const int m = n - k < PKM_LANES ? (int) (n - k) : PKM_LANES;
    long long s[PKM_LANES];  /* the lanes' samples: a tail padded with its last one */
    for (int l = 0; l < PKM_LANES; ++l) s[l] = k + (l < m ? l : m - 1);
@GATHER@    NAME_simd_block(x, y);
    if (m == PKM_LANES) PKM_EACH {  /* scatter the valid lanes */
@SCATTER@    } else for (int l = 0; l < m; ++l) {
@SCATTER@    }
  }
  return 0;
}

int NAME_simd(long long n, const double** in, double** out) { return NAME_simd_steps(n, in, out, 0); }

int NAME_simd_lanes(void) { return PKM_LANES; }
int NAME_simd_vector_math(void) { return PKM_VECTOR_MATH; }
"""


def simd_source(fun: cs.Function, name: str | None = None, *, maths: str = "libm", lanes: int | None = None,
                chunk: int | None = None) -> str:
    """The C source of ``fun``'s vector batch driver ``int NAME_simd(long long n, const double** in, double**
    out)`` (``NAME`` default ``fun.name()``; the calling convention of ``NAME_batch``, returns 0) and
    ``NAME_simd_steps(n, in, out, steps)`` (each input's stride, as ``NAME_batch_steps``: 0 for a design), with
    ``int NAME_simd_lanes(void)`` (the lanes compiled in) and ``int NAME_simd_vector_math(void)`` (1 when libmvec's
    functions are in). See the module doc.

    Args:
        fun: An SX function, inputs and outputs dense.
        name: The C name.
        maths: ``"libm"`` (lane by lane: bit for bit the scalar path) or ``"libmvec"`` (glibc's vector functions
            where the lanes have them; link with ``-lmvec``).
        lanes: Force the lanes (2, 4 or 8) instead of the preprocessor's choice.
        chunk: Cut the body into C functions of this many instructions (default :data:`CHUNK`).

    Raises:
        ValueError: ``fun`` is not an SX function, has a sparse input or output, uses an operation without a vector
            form here, or ``maths``/``lanes`` is not one of the above.
    """
    if not fun.is_a("SXFunction"):
        raise ValueError(f"{fun.name()}: simd_source needs an SX function")
    if maths not in MATHS:
        raise ValueError(f"maths: use one of {MATHS}, not {maths!r}")
    if lanes not in (None, 2, 4, 8):
        raise ValueError(f"lanes: use 2, 4 or 8, not {lanes!r}")
    for j in range(fun.n_in()):
        if fun.nnz_in(j) != fun.numel_in(j):
            raise ValueError(f"{fun.name()}: input {fun.name_in(j)} is sparse; densify it")
    for j in range(fun.n_out()):
        if fun.nnz_out(j) != fun.numel_out(j):
            raise ValueError(f"{fun.name()}: output {fun.name_out(j)} is sparse; densify it")
    name = name or fun.name()
    gather, scatter, at = "", "", 0
    for j in range(fun.n_in()):
        nz = fun.nnz_in(j)
        if nz:
            gather += (f"    if (in[{j}]) {{\n      const double* p = in[{j}];\n"
                       f"      const long long st = steps ? steps[{j}] : {nz};\n"
                       + "".join(f"      x[{at + i}] = PKM_GATHER(p, s, st, {i});\n" for i in range(nz))
                       + f"    }} else for (int i = 0; i < {nz}; ++i) x[{at} + i] = pkm_splat(0.0);\n")
        at += nz
    nx, at = at, 0
    for j in range(fun.n_out()):
        nz = fun.nnz_out(j)
        if nz:
            scatter += (f"      if (out[{j}]) {{\n        double* p = out[{j}] + (k + l) * {nz};\n"
                        f"        for (int i = 0; i < {nz}; ++i) p[i] = y[{at} + i][l];\n      }}\n")
        at += nz
    driver = (_DRIVER.replace("@GATHER@", gather).replace("@SCATTER@", scatter).replace("@NX@", str(max(nx, 1)))
              .replace("@NY@", str(max(at, 1))).replace("NAME", name))
    prelude = _PRELUDE.replace("TARGET", _target()).replace("@WIDEST@", str(_widest(maths)))
    if lanes is not None:
        prelude = prelude.replace("#ifndef PKM_LANES\n", f"#define PKM_LANES {lanes}\n#ifndef PKM_LANES\n", 1)
    return prelude + _functions(maths) + "\n" + _body(fun, name, maths, chunk or 0) + driver


def _widest(maths: str) -> int:
    """The lanes with AVX-512: 8 with libmvec, 4 with lane-wise libm (the module doc)."""
    return 8 if maths == "libmvec" else 4


@functools.lru_cache(maxsize=1)
def _target() -> str:
    """The instruction sets ``cc -march=native`` compiles for (its predefined ``__AVX*__``, ``__SSE*__``,
    ``__FMA__`` macros): written into the source, so that a library cached on another machine is not loaded."""
    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None:
        return "target unknown"
    try:
        run = subprocess.run([cc, "-march=native", "-dM", "-E", "-x", "c", os.devnull], capture_output=True,
                             text=True, check=False, timeout=60)
    except (OSError, subprocess.SubprocessError):
        return "target unknown"
    macros = sorted(line.split()[1] for line in run.stdout.splitlines()
                    if line.startswith("#define __") and any(s in line for s in ("__AVX", "__SSE", "__FMA__",
                                                                                  "__ARM_NEON", "__aarch64__")))
    return "target " + " ".join(m.strip("_") for m in macros)


def simd_library(fun: cs.Function, directory: str | os.PathLike[str] | None = None, *, maths: str = "libm",
                 lanes: int | None = None, chunk: int | None = None) -> tuple[ctypes.CDLL | None, str]:
    """``fun``'s vector batch driver (:func:`simd_source`) compiled (``-O2 -march=native -ffp-contract=off
    -fno-math-errno``) and loaded, cached by source hash as
    :func:`~pkm.core.twin.codegen.compile_library` caches. Returns ``(library, how)``; ``library`` None, and ``how``
    saying why, without a C compiler or when it failed. With ``maths="libmvec"`` a library that does not link
    against libmvec is built with libm instead, and ``how`` says so."""
    text = simd_source(fun, maths=maths, lanes=lanes, chunk=chunk)
    # (every symbol resolved at link time: a glibc whose libmvec lacks a variant fails here, not at the first call)
    link = ("-Wl,--no-as-needed", "-lmvec", "-Wl,-z,defs") if maths == "libmvec" else ()
    lib, how = compile_library(fun, directory=directory, text=text, flags=("-O2", *_OPT, *link))
    if lib is None and maths == "libmvec":
        libm = simd_source(fun, maths="libm", lanes=lanes, chunk=chunk)
        lib, how2 = compile_library(fun, directory=directory, text=libm, flags=("-O2", *_OPT))
        how = f"{how2}; libm, not libmvec ({how})"
    if lib is not None:
        width = getattr(lib, f"{fun.name()}_simd_lanes")()
        vector = getattr(lib, f"{fun.name()}_simd_vector_math")()
        how = f"{how}, {width} lanes, {'libmvec' if vector else 'lane-wise libm'}"
    return lib, how


def lanes(lib: ctypes.CDLL | None = None, name: str | None = None, *, maths: str = "libm") -> int:
    """The lanes compiled into ``lib`` (the driver of the function ``name``, from :func:`simd_library`); without
    them, the lanes a driver with ``maths`` gets on this machine (``cc -march=native``): with AVX-512 8 (libmvec)
    or 4 (libm), with AVX 4, else 2."""
    if lib is not None and name is not None:
        return int(getattr(lib, f"{name}_simd_lanes")())
    return min(widest(), _widest(maths))


def widest() -> int:
    """The widest vector of doubles this machine's ``cc -march=native`` has: 8 (AVX-512), 4 (AVX) or 2."""
    target = _target().split()
    return 8 if "AVX512F" in target else 4 if "AVX" in target else 2


class SimdKernel:
    """``fun``'s vector driver, called on sample-major arrays on the calling thread (one core): ``kernel(*inputs)``
    returns the outputs, each ``n x nnz``; :attr:`how` says what was compiled (or why not: :attr:`lib` None).

    Args:
        fun: An SX function, inputs and outputs dense.
        directory: Where the library goes (default :func:`pkm.core.twin.codegen.cache_dir`).
        maths: ``"libm"`` or ``"libmvec"`` (:func:`simd_source`).
        lanes: Force the lanes (2, 4 or 8).
        chunk: Cut the body into C functions of this many instructions (:func:`simd_source`).
    """

    def __init__(self, fun: cs.Function, directory: str | os.PathLike[str] | None = None, *, maths: str = "libm",
                 lanes: int | None = None, chunk: int | None = None):
        self.fun = fun
        self.lib, self.how = simd_library(fun, directory, maths=maths, lanes=lanes, chunk=chunk)
        self.out_size = [fun.nnz_out(i) for i in range(fun.n_out())]
        if self.lib is not None:
            self.driver = getattr(self.lib, f"{fun.name()}_simd")
            self.driver.argtypes = [C_INT, ctypes.POINTER(C_REAL_P), ctypes.POINTER(C_REAL_P)]
            self.driver.restype = ctypes.c_int

    def __call__(self, *arrays: np.ndarray) -> list[np.ndarray]:
        if self.lib is None:
            raise RuntimeError(f"no compiled vector driver for {self.fun.name()}: {self.how}")
        ins = [np.ascontiguousarray(a, dtype=float) for a in arrays]
        n = ins[0].shape[0]
        outs = [np.empty((n, s)) for s in self.out_size]
        if self.driver(n, pointers(ins), pointers(outs)):
            raise RuntimeError(f"the vector driver of {self.fun.name()} failed")
        return outs


_PEAK = r"""
/* independent chains x = x * m + a, CHAINS of them, each a vector of PKM_LANES doubles: 2 flops a lane a step */
typedef double pkm_v __attribute__((vector_size(8 * PKM_LANES)));
double pkm_peak(long long steps) {
  pkm_v x[CHAINS], m, a;
  for (int l = 0; l < PKM_LANES; ++l) { m[l] = 0.999999; a[l] = 1e-6 * (l + 1); }
  for (int c = 0; c < CHAINS; ++c) for (int l = 0; l < PKM_LANES; ++l) x[c][l] = 0.5 + 0.01 * c + 0.001 * l;
  for (long long s = 0; s < steps; ++s) {
#pragma GCC unroll 64
    for (int c = 0; c < CHAINS; ++c) x[c] = x[c] * m + a;
  }
  double sum = 0.0;
  for (int c = 0; c < CHAINS; ++c) for (int l = 0; l < PKM_LANES; ++l) sum += x[c][l];
  return sum;
}
"""


def peak_gflops(lanes: int | None = None, seconds: float = 0.2, directory: str | os.PathLike[str] | None = None
                ) -> dict[str, float]:
    """This core's double-precision vector peak [GFLOP/s], measured on independent chains ``x = x * m + a`` of
    ``lanes``-wide vectors (default :func:`widest`): ``"mul_add"`` compiled with ``-ffp-contract=off`` (a multiply
    and an add, each its own instruction: what the vector drivers run), ``"fma"`` with contraction (one fused
    multiply-add: 2 flops an instruction). Best of 5 runs of about ``seconds / 5`` each, on the calling thread;
    ``{}`` without a C compiler. Returns also ``"lanes"``."""
    width = lanes or widest()
    result: dict[str, float] = {"lanes": float(width)}
    for key, chains, contract in (("mul_add", 24, "off"), ("fma", 16, "fast")):
        text = f"#define PKM_LANES {width}\n#define CHAINS {chains}\n/* {_target()} */" + _PEAK
        x = cs.SX.sym("x")
        fun = cs.Function(f"pkm_peak_{key}", [x], [x])  # (compile_library names the library after it)
        lib, _ = compile_library(fun, directory=directory, text=text,
                                 flags=("-O2", "-march=native", f"-ffp-contract={contract}"))
        if lib is None:
            return {}
        lib.pkm_peak.argtypes, lib.pkm_peak.restype = [ctypes.c_longlong], ctypes.c_double
        steps = 10_000
        while True:  # calibrate: a run of about seconds / 5
            t = _timed(lib.pkm_peak, steps)
            if t >= seconds / 20 or steps > 1 << 40:
                break
            steps *= 4
        steps = max(int(steps * seconds / 5 / t), 1)
        best = min(_timed(lib.pkm_peak, steps) for _ in range(5))
        result[key] = 2.0 * width * chains * steps / best / 1e9
    return result


def _timed(fn: Callable[..., object], *args: object) -> float:
    t = time.perf_counter()
    fn(*args)
    return time.perf_counter() - t


def time_per_sample(driver: Callable[..., object], arrays: list[np.ndarray], out_size: list[int],
                    repeat: int = 7) -> float:
    """The median wall time of ``driver(n, in, out)`` (a ``NAME_batch`` or ``NAME_simd`` ctypes function) on the
    sample-major ``arrays``, per sample [s]: one core (the calling thread)."""
    ins = [np.ascontiguousarray(a, dtype=float) for a in arrays]
    n = ins[0].shape[0]
    outs = [np.empty((n, s)) for s in out_size]
    in_p, out_p = pointers(ins), pointers(outs)
    driver(n, in_p, out_p)  # (warm: pages touched)
    return statistics.median(_timed(driver, n, in_p, out_p) for _ in range(repeat)) / n


__all__ = ["CHUNK", "LARGE", "LARGE_CHUNK", "MATHS", "SimdKernel", "lanes", "peak_gflops", "simd_library", "simd_source",
           "time_per_sample", "widest"]
