"""The twin's functions as NVIDIA Warp kernels: one sample a thread, double precision, on the CPU or a GPU.

:func:`warp_source` translates a CasADi SX function (a kernel after CSE) into a ``@wp.kernel``, as
:func:`pkm.core.twin.jaxgen.jax_source` writes JAX and :func:`pkm.core.export.emit.c_function` writes C: one
statement per instruction of the SX function's virtual machine, its work vector as the variables ``w0, w1, ...``,
each operation the Warp expression :data:`WARP_FORMS` gives it, every constant a ``wp.float64`` (a bare literal in
a Warp kernel is a float32). Arrays are structure-of-arrays: each input and output a ``wp.array2d(dtype=float64)``
of shape ``(nnz, n)`` (entry-major: thread ``t`` reads column ``t``, so that neighbouring GPU threads read
neighbouring addresses), the CasADi function's nonzeros column-major.

Warp compiles a kernel from its Python source (``inspect``), so the source is written to a real file and imported
(:func:`warp_module`: a file named by the hash of its source, under :func:`pkm.cache.cache_dir`'s ``warp``
folder); Warp then caches its own compiled module (``~/.cache/warp``). Warp (``pip install "pkm-robotics[warp]"``)
is imported by :func:`warp_module` and :func:`launch` only.

Rounding: ``+ - * /``, square roots, ``abs``, the comparisons are IEEE operations as in the C; sines, cosines,
``atan2`` are Warp's (the CPU's libm through its LLVM; CUDA's on a GPU): within a few ulp of glibc's, which the
tests bound at 1e-12 over whole kernels. ``fmin``/``fmax`` are ``wp.min``/``wp.max`` (a NaN operand is not ignored
as C's ``fmin`` ignores it), ``copysign`` ignores the sign of a zero.
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib.util
import os
import re
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import casadi as cs
import numpy as np

from pkm.core.twin.codegen import instructions

_F = "f64"
#: Warp expressions of CasADi's scalar operations (``a``, ``b``: the operands, float64 values).
WARP_FORMS = {
    "ADD": "{a} + {b}", "SUB": "{a} - {b}", "MUL": "{a} * {b}", "DIV": "{a} / {b}", "NEG": "-{a}", "SQ": "{a} * {a}",
    "TWICE": f"{_F}(2.0) * {{a}}", "INV": f"{_F}(1.0) / {{a}}", "ASSIGN": "{a}", "POW": "wp.pow({a}, {b})",
    "CONSTPOW": "wp.pow({a}, {b})", "SIN": "wp.sin({a})", "COS": "wp.cos({a})", "TAN": "wp.tan({a})",
    "ASIN": "wp.asin({a})", "ACOS": "wp.acos({a})", "ATAN": "wp.atan({a})", "ATAN2": "wp.atan2({a}, {b})",
    "SQRT": "wp.sqrt({a})", "EXP": "wp.exp({a})", "LOG": "wp.log({a})", "FABS": "wp.abs({a})",
    "FMIN": "wp.min({a}, {b})", "FMAX": "wp.max({a}, {b})", "FLOOR": "wp.floor({a})", "CEIL": "wp.ceil({a})",
    "SINH": "wp.sinh({a})", "COSH": "wp.cosh({a})", "TANH": "wp.tanh({a})",
    "HYPOT": "wp.sqrt({a} * {a} + {b} * {b})",
    "COPYSIGN": f"(wp.abs({{a}}) if {{b}} >= {_F}(0.0) else -wp.abs({{a}}))",
    "SIGN": f"({_F}(1.0) if {{a}} > {_F}(0.0) else ({_F}(-1.0) if {{a}} < {_F}(0.0) else {_F}(0.0)))",
    "IF_ELSE_ZERO": f"wp.where({{a}} != {_F}(0.0), {{b}}, {_F}(0.0))",
    "LT": f"({_F}(1.0) if {{a}} < {{b}} else {_F}(0.0))", "LE": f"({_F}(1.0) if {{a}} <= {{b}} else {_F}(0.0))",
    "EQ": f"({_F}(1.0) if {{a}} == {{b}} else {_F}(0.0))", "NE": f"({_F}(1.0) if {{a}} != {{b}} else {_F}(0.0))",
    "NOT": f"({_F}(1.0) if {{a}} == {_F}(0.0) else {_F}(0.0))",
    "AND": f"({_F}(1.0) if ({{a}} != {_F}(0.0) and {{b}} != {_F}(0.0)) else {_F}(0.0))",
    "OR": f"({_F}(1.0) if ({{a}} != {_F}(0.0) or {{b}} != {_F}(0.0)) else {_F}(0.0))",
}


def _constant(x: float) -> str:
    if np.isnan(x):
        return f"{_F}(wp.nan)"
    if np.isinf(x):
        return f"{_F}(wp.inf)" if x > 0 else f"{_F}(-wp.inf)"
    return f"{_F}({float(x)!r})"


@dataclasses.dataclass(frozen=True)
class Loop:
    """A kernel that loops over one step instead of unrolling it (a Newton solve): ``step`` ``(x, target) -> (x_next,
    p)`` run :attr:`iterations` times from the kernel's first input, the smallest ``p`` kept (``fmin``, as an
    unrolled ``cs.fmin`` keeps it), then ``finish`` ``(x, smallest p, *rest) -> outputs``. The kernel's inputs are
    ``(x0, target, *rest)``, named as ``step``'s two and ``finish``'s rest; its outputs are ``finish``'s. It answers
    the :class:`casadi.Function` queries :func:`warp_source` and :func:`launch` ask (``name``, ``n_in``, ``nnz_out``,
    ...): the same outputs as the SX function that unrolls ``step``, its instructions in the same order."""

    name_: str
    step: cs.Function
    finish: cs.Function
    iterations: int

    def _ins(self) -> list[tuple[cs.Function, int]]:
        return [(self.step, 0), (self.step, 1)] + [(self.finish, j) for j in range(2, self.finish.n_in())]

    def name(self) -> str:
        return self.name_

    def n_in(self) -> int:
        return len(self._ins())

    def name_in(self, i: int) -> str:
        f, j = self._ins()[i]
        return str(f.name_in(j))

    def nnz_in(self, i: int) -> int:
        f, j = self._ins()[i]
        return int(f.nnz_in(j))

    def n_out(self) -> int:
        return int(self.finish.n_out())

    def name_out(self, j: int) -> str:
        return str(self.finish.name_out(j))

    def nnz_out(self, j: int) -> int:
        return int(self.finish.nnz_out(j))


def _body(fun: cs.Function, read: Callable[[int, int], str], write: Callable[[int, int], str], work: str,
          indent: str) -> list[str]:
    """``fun``'s instructions as Warp statements, its work variables ``<work><k>``: input ``(i, k)`` read from
    ``read(i, k)``, output ``(j, k)`` written to ``write(j, k)`` (its structural zeros too)."""
    lines, written = [], set[tuple[int, int]]()
    for kind, value, i, o in instructions(fun, WARP_FORMS, "Warp"):
        if kind == "input":
            lines.append(f"{indent}{work}{o[0]} = {read(i[0], i[1])}")
        elif kind == "output":
            lines.append(f"{indent}{write(o[0], o[1])} = {work}{i[0]}")
            written.add((o[0], o[1]))
        elif kind == "const":
            lines.append(f"{indent}{work}{o[0]} = {_constant(float(value))}")  # type: ignore[arg-type]
        else:
            lines.append(f"{indent}{work}{o[0]} = {_rename(str(value), work)}")
    for j in range(fun.n_out()):  # (structural zeros of a dense output)
        lines += [f"{indent}{write(j, k)} = {_F}(0.0)" for k in range(fun.nnz_out(j)) if (j, k) not in written]
    return lines


def _rename(expr: str, work: str) -> str:
    """A :data:`WARP_FORMS` expression with its work variables ``w<k>`` named ``<work><k>``."""
    return expr if work == "w" else re.sub(r"\bw(\d+)\b", rf"{work}\1", expr)


def _kernel(fun: cs.Function | Loop) -> list[str]:
    """The ``@wp.kernel`` of ``fun`` (:func:`warp_source`), its lines."""
    for f in (fun.step, fun.finish) if isinstance(fun, Loop) else (fun,):
        if not f.is_a("SXFunction"):
            raise ValueError(f"{f.name()}: warp_source needs an SX function")
    ins = [f"{fun.name_in(j)}: wp.array2d(dtype=wp.float64)" for j in range(fun.n_in())]
    outs = [f"{fun.name_out(j)}: wp.array2d(dtype=wp.float64)" for j in range(fun.n_out())]
    lines = ["", "", "@wp.kernel", f"def {fun.name()}({', '.join(ins + outs)}):", "    t = wp.tid()"]
    if not isinstance(fun, Loop):
        plain = fun
        return lines + _body(plain, lambda i, k: f"{plain.name_in(i)}[{k}, t]",
                             lambda j, k: f"{plain.name_out(j)}[{k}, t]", "w", "    ")
    taken = [n for n in [*map(fun.name_in, range(fun.n_in())), *map(fun.name_out, range(fun.n_out()))]
             if n in ("t", "i", "p", "pivot") or re.fullmatch(r"[xynsw]\d+", n)]
    if taken:
        raise ValueError(f"{fun.name()}: the names {taken} are the loop's own variables")
    finish = fun.finish
    lines += [f"    x{k} = {fun.name_in(0)}[{k}, t]" for k in range(fun.nnz_in(0))]
    lines += [f"    y{k} = {fun.name_in(1)}[{k}, t]" for k in range(fun.nnz_in(1))]
    lines += [f"    pivot = {_F}(0.0)", f"    for i in range({int(fun.iterations)}):  # (one copy of the step)"]
    lines += _body(fun.step, lambda i, k: f"x{k}" if i == 0 else f"y{k}",
                   lambda j, k: f"n{k}" if j == 0 else "p", "s", "        ")
    lines += [f"        x{k} = n{k}" for k in range(fun.step.nnz_out(0))]
    lines.append("        pivot = p if i == 0 else wp.min(pivot, p)")  # (the unrolled cs.fmin's, NaN too)
    return lines + _body(finish, lambda i, k: f"x{k}" if i == 0 else "pivot" if i == 1
                         else f"{finish.name_in(i)}[{k}, t]", lambda j, k: f"{finish.name_out(j)}[{k}, t]",
                         "w", "    ")


def warp_source(funs: cs.Function | Loop | Sequence[cs.Function | Loop], *, backward: bool = False) -> str:
    """A Python module's source holding, for each function ``fun``, ``@wp.kernel def <fun's name>(in..., out...)``
    (one thread a sample; arguments named after ``fun``'s inputs and outputs, each ``(nnz, n)``: see the module
    doc). Without ``backward`` the module is compiled without Warp's adjoint code (``enable_backward`` off for this
    module only: half the compile time; differentiate with the JAX target, or ask for it to use ``wp.Tape``). A
    :class:`Loop` is one copy of its step in a ``for`` loop that Warp keeps a loop (``max_unroll`` 1 for the module:
    the transmissions' solves: the battobot ankle's module 1.94 MB -> 0.64 MB).

    Raises:
        ValueError: a function is not an SX function, or uses an operation :data:`WARP_FORMS` lacks; a
            :class:`Loop`'s input or output is named as one of its variables (``t``, ``i``, ``p``, ``pivot``,
            ``x0``, ...).
    """
    funs = [funs] if isinstance(funs, cs.Function | Loop) else list(funs)
    lines = ["# Generated by pkm (pkm.core.twin.warpgen) from CasADi functions: do not edit.", "import warp as wp",
             "", f"wp.set_module_options({{'enable_backward': {bool(backward)}, 'max_unroll': 1}})",
             f"{_F} = wp.float64"]
    for fun in funs:
        lines += _kernel(fun)
    return "\n".join(lines) + "\n"


def warp_module(funs: cs.Function | Loop | Sequence[cs.Function | Loop],
                directory: str | os.PathLike[str] | None = None, *, backward: bool = False) -> Any:
    """The Python module of :func:`warp_source` of ``funs``, written to ``directory`` (default the ``warp`` folder of
    :func:`pkm.cache.cache_dir`; the file named by the hash of its source) and imported: Warp reads a kernel's
    source from its file (it refuses source that exists only in memory) and compiles the module's kernels together,
    on their first launch (or ``wp.load_module``). Its attributes are the kernels, by the functions' names;
    ``backward``: as :func:`warp_source`.

    Raises:
        MissingDependencyError: Warp is not installed (``pip install "pkm-robotics[warp]"``).
    """
    from pkm._optional import require

    require("warp", "pkm.core.twin.warpgen (the twin's kernels on NVIDIA Warp)")
    funs = [funs] if isinstance(funs, cs.Function | Loop) else list(funs)
    text = warp_source(funs, backward=backward)
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    module_name = f"pkm_warp_{funs[0].name()}_{digest}"
    if module_name in sys.modules:
        return sys.modules[module_name]
    if directory is None:
        from pkm.cache import cache_dir

        directory = cache_dir() / "warp"
    folder = Path(directory)
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{module_name}.py"
    if not path.exists() or path.read_text() != text:
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(text)
        os.replace(tmp, path)  # (whole, whichever process writes it)
    spec = importlib.util.spec_from_file_location(module_name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    spec.loader.exec_module(module)
    return module


def warp_kernel(fun: cs.Function | Loop, directory: str | os.PathLike[str] | None = None) -> Any:
    """``fun`` as a Warp kernel (:func:`warp_module` of ``fun`` alone); launch it with :func:`launch`.

    Raises:
        MissingDependencyError: Warp is not installed (``pip install "pkm-robotics[warp]"``).
    """
    return getattr(warp_module(fun, directory), fun.name())


def launch(kernel: Any, fun: cs.Function | Loop, *arrays: np.ndarray, device: str = "cpu") -> list[np.ndarray]:
    """Run a Warp kernel of ``fun`` (:func:`warp_kernel`) on sample-major numpy inputs (each ``(n, nnz)``) on
    ``device`` (``"cpu"``, ``"cuda"``); returns the outputs sample-major (``(n, nnz)`` each). Copies in and out:
    to keep data on a GPU, launch the kernel yourself on ``(nnz, n)`` Warp arrays (``wp.from_torch`` of a PyTorch
    tensor's transpose, made contiguous, needs no copy)."""
    from pkm._optional import module

    wp = module("warp", extra="warp", what="pkm.core.twin.warpgen.launch")
    n = arrays[0].shape[0]
    ins = [wp.array(np.ascontiguousarray(np.asarray(a, dtype=np.float64).T), dtype=wp.float64, device=device)
           for a in arrays]
    outs = [wp.zeros((fun.nnz_out(j), n), dtype=wp.float64, device=device) for j in range(fun.n_out())]
    wp.launch(kernel, dim=n, inputs=ins, outputs=outs, device=device)
    return [o.numpy().T.copy() for o in outs]


__all__ = ["WARP_FORMS", "Loop", "launch", "warp_kernel", "warp_module", "warp_source"]
