"""The twin's functions as JAX: a kernel inside a JAX program, under ``jax.jit``, ``jax.vmap`` and ``jax.grad``.

:func:`jax_source` translates a CasADi SX function (a kernel of :class:`~pkm.core.twin.kernels.Kernels`, after CSE)
into Python, as :func:`pkm.core.twin.codegen.numpy_source` writes numpy and :func:`pkm.core.export.emit.c_function`
writes C: one statement per instruction of the SX function's virtual machine, its work vector as the variables
``w0, w1, ...``, each operation written as the ``jax.numpy`` expression :data:`_JAX` gives it (numpy's forms with
``jnp``: comparisons as ``1.0 * (a < b)``, CasADi's ``if_else_zero`` as ``jnp.where``). The function is written for ONE sample,
each input and output a 1-D array of the CasADi function's nonzeros (column-major, as the C takes them); batches are
``jax.vmap``'s, derivatives ``jax.grad``'s and ``jax.jacfwd``'s, the device JAX's (a GPU where JAX has one).
:func:`jax_function` runs the source and returns it under ``jax.jit``::

    f = jax_function(pkm.Kernels(mech).function("inverse_dynamics"))
    tau, pivot = jax.vmap(f)(Q, QD, QDD)  # (n, nq), (n, na), (n, na) -> (n, na), (n, 1)

This is pkm's own translation of the twin (no third-party converter); JAX (``pip install "pkm-robotics[jax]"``) is
imported when :func:`jax_function` is called, never by :func:`jax_source`.

Precision: the kernels are double-precision, as their C; :func:`jax_function` turns JAX's 64-bit mode on
(``jax.config.update("jax_enable_x64", True)``, process-wide) unless told not to. Constants are written as Python
floats (weakly typed): float32 inputs compute in float32.

Compile time: XLA compiles the straight-line program one scalar operation per instruction, about 1 ms each on a CPU
(the 3-PRS's efforts, 750 instructions: 0.5 s; its derivatives, 5,759: 5 s for one sample, 8 s vmapped): functions of
tens of thousands of instructions (a hexapod's derivatives) make slow XLA compiles, once per input shape.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import casadi as cs

from pkm.core.twin.codegen import NUMPY_FORMS, instructions, python_constant
from pkm.errors import InvalidInputError

#: ``jax.numpy`` expressions of CasADi's scalar operations: numpy's (:data:`pkm.core.twin.codegen.NUMPY_FORMS`)
#: with ``jnp`` for ``np``.
_JAX = {k: v.replace("np.", "jnp.") for k, v in NUMPY_FORMS.items()}


def jax_source(fun: cs.Function) -> str:
    """Python source of ``fun`` for one sample: ``def f(jnp, in0, in1, ...)`` with each input a 1-D array of its
    nonzeros, returning a tuple of 1-D outputs (``jnp.stack`` of their nonzeros, column-major), one ``jax.numpy``
    statement per instruction of the SX function (its work vector reused as the variables ``w0, w1, ...``).

    Raises:
        ValueError: ``fun`` is not an SX function, or uses an operation :data:`_JAX` lacks.
    """
    if not fun.is_a("SXFunction"):
        raise ValueError(f"{fun.name()}: jax_source needs an SX function")
    ins = ", ".join(f"in{i}" for i in range(fun.n_in()))
    lines = [f"def f(jnp, {ins}):"]
    written: set[tuple[int, int]] = set()
    for kind, value, i, o in instructions(fun, _JAX, "JAX"):
        if kind == "input":
            lines.append(f"    w{o[0]} = in{i[0]}[{i[1]}]")
        elif kind == "output":  # (bound now: the work variable may be reused afterwards)
            lines.append(f"    out{o[0]}_{o[1]} = w{i[0]}")
            written.add((o[0], o[1]))
        elif kind == "const":
            assert isinstance(value, float)
            lines.append(f"    w{o[0]} = {python_constant(value, 'jnp')}")
        else:
            lines.append(f"    w{o[0]} = {value}")
    outs = []
    for j in range(fun.n_out()):
        entries = [f"out{j}_{k}" if (j, k) in written else "0.0" for k in range(fun.nnz_out(j))]
        outs.append(f"jnp.stack([{', '.join(entries)}])" if entries else "jnp.zeros(0)")
    lines.append(f"    return ({', '.join(outs)},)")
    return "\n".join(lines) + "\n"


def jax_function(fun: cs.Function, *, x64: bool = True) -> Callable[..., tuple[Any, ...]]:
    """``fun`` as a jitted JAX function of one sample (see :func:`jax_source`): ``g(*inputs) -> outputs``, each a
    1-D array of nonzeros (column-major); ``jax.vmap(g)`` takes and returns ``(n, nnz)`` arrays.

    Args:
        fun: An SX function (:meth:`pkm.Kernels.function`).
        x64: Turn JAX's 64-bit mode on (``jax.config.update("jax_enable_x64", True)``), process-wide: the kernels
            are double precision, as their C. It changes JAX's default dtype for the whole program (``jnp.zeros``
            is float64 after it); with False the mode is left as it is (without it, inputs are float32 and so is
            every result).

    The first call for each input shape (and the first under each transformation: ``jax.vmap``, ``jax.grad``) traces
    and compiles, about 1 ms of XLA per instruction: slow for functions of tens of thousands of instructions.

    Raises:
        MissingDependencyError: JAX is not installed (``pip install "pkm-robotics[jax]"``).
        ValueError: ``fun`` is not an SX function, or uses an operation :data:`_JAX` lacks.
    """
    from pkm._optional import module

    what = "pkm.core.twin.jaxgen.jax_function (the twin's kernels as JAX functions)"
    jax = module("jax", extra="jax", what=what)
    jnp = module("jax.numpy", extra="jax", what=what)
    namespace: dict = {}
    exec(compile(jax_source(fun), f"<pkm jax {fun.name()}>", "exec"), namespace)  # source built above, no input
    f = namespace["f"]
    sizes = [fun.nnz_in(i) for i in range(fun.n_in())]
    names = [fun.name_in(i) for i in range(fun.n_in())]
    if x64:
        jax.config.update("jax_enable_x64", True)

    def kernel(*args: Any) -> tuple[Any, ...]:
        if len(args) != len(sizes):
            raise InvalidInputError(fun.name(), f"takes {len(sizes)} inputs ({', '.join(names)}), got {len(args)}")
        arrays = []
        for name, size, x in zip(names, sizes, args):
            a = jnp.asarray(x)
            if a.shape != (size,):  # (checked when traced: an index out of bounds would be clamped silently)
                raise InvalidInputError(name, f"expected one sample of shape ({size},) (jax.vmap for a batch), "
                                              f"got {a.shape}", x)
            arrays.append(a if jnp.issubdtype(a.dtype, jnp.floating) else a.astype(float))
        return f(jnp, *arrays)

    kernel.__name__ = kernel.__qualname__ = fun.name()
    kernel.__doc__ = f"{fun.name()}({', '.join(names)}) -> ({', '.join(fun.name_out())}): see pkm.core.twin.jaxgen"
    return jax.jit(kernel)


__all__ = ["jax_function", "jax_source"]
