"""Generated C and its drivers (:mod:`pkm.core.twin.codegen`) on tiny CasADi functions: the compiled function, its
batch driver and its path driver (a Newton iteration for square roots, known in closed form) equal CasADi's own
evaluation; libraries are cached by source under ``cache_dir()`` (``$PKM_CACHE_DIR/twin``); the numpy fallback and
the operation count agree with CasADi. (A twin's compiled efforts and the no-compiler route: ``test_tree.py``.)"""

from __future__ import annotations

import ctypes
import math
import re
import shutil

import casadi as cs
import numpy as np
import pytest

from pkm.core.twin import codegen

needs_cc = pytest.mark.skipif(not (shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")),
                              reason="no C compiler: compile_library returns None (tested in test_tree.py)")


def _tiny() -> cs.Function:
    """(x (2), y (1)) -> (x0 sin(x1) / y, [x0 + y, x1 * x1]): two inputs, two outputs, a division and a sine."""
    x, y = cs.SX.sym("x", 2), cs.SX.sym("y")
    return cs.Function("tiny", [x, y], [x[0] * cs.sin(x[1]) / y, cs.vertcat(x[0] + y, x[1] * x[1])])


def _newton_sqrt() -> cs.Function:
    """One Newton step for q^2 = t: (q, t) -> (q_next, |q_next^2 - t|, 2 q_next)."""
    q, t = cs.SX.sym("q"), cs.SX.sym("t")
    nxt = q - (q * q - t) / (2 * q)
    return cs.Function("nsqrt", [q, t], [nxt, cs.fabs(nxt * nxt - t), 2 * nxt])


def _doubles(a) -> ctypes.Array:
    a = np.ascontiguousarray(a, dtype=float).ravel()
    return (ctypes.c_double * a.size)(*a)


def test_the_source_holds_the_function_and_its_drivers():
    """source() has the function, its batch driver and, with follow, its path driver, every placeholder of the
    templates replaced by the function's name and sizes."""
    text = codegen.source(_tiny())
    assert "int tiny_batch(" in text and "_follow(" not in text and "tiny_isz[] = {2, 1}" in text
    assert "tiny_osz[] = {1, 2}" in text
    follow = codegen.source(_newton_sqrt(), follow=True)
    assert "int nsqrt_follow(" in follow and "int nsqrt_batch(" in follow
    drivers = text.split("/* pkm drivers */")[1] + follow.split("/* pkm drivers */")[1]
    assert not re.search("NAME|NIN|NOUT|ISZ|OSZ", drivers)


@needs_cc
def test_compiled_function_and_batch_driver_equal_casadi(tmp_path):
    """compile_function loads the C back as a casadi.Function equal to the SX one (1e-15); the batch driver, called
    through ctypes on 5 sample-major inputs, gives the same 5 outputs; a second compile reuses the cached library."""
    fun = _tiny()
    compiled, how = codegen.compile_function(fun, tmp_path)
    assert how.startswith("C (")
    rng = np.random.default_rng(0)
    X, Y = rng.normal(size=(5, 2)), rng.uniform(0.5, 2.0, size=(5, 1))
    for x, y in zip(X, Y):
        for a, b in zip(compiled(x, y), fun(x, y)):
            assert np.abs(np.array(a) - np.array(b)).max() <= 1e-15 * max(1.0, np.abs(np.array(b)).max())
    libraries = list(tmp_path.glob("tiny-*.so"))
    lib, _ = codegen.compile_library(fun, directory=tmp_path)
    assert len(libraries) == 1 and list(tmp_path.glob("tiny-*.so")) == libraries
    out0, out1 = (ctypes.c_double * 5)(), (ctypes.c_double * 10)()
    x_in, y_in = _doubles(X), _doubles(Y)  # (sample-major, kept alive while the driver runs)
    ins = (codegen.C_REAL_P * 2)(ctypes.cast(x_in, codegen.C_REAL_P), ctypes.cast(y_in, codegen.C_REAL_P))
    outs = (codegen.C_REAL_P * 2)(ctypes.cast(out0, codegen.C_REAL_P), ctypes.cast(out1, codegen.C_REAL_P))
    lib.tiny_batch.restype = ctypes.c_int
    assert lib.tiny_batch(codegen.C_INT(5), ins, outs) == 0
    expected0 = X[:, 0] * np.sin(X[:, 1]) / Y[:, 0]
    expected1 = np.column_stack([X[:, 0] + Y[:, 0], X[:, 1] ** 2])
    assert np.abs(np.array(out0[:]) - expected0).max() <= 1e-15 * 4
    assert np.abs(np.array(out1[:]).reshape(5, 2) - expected1).max() <= 1e-15 * 4


@needs_cc
def test_the_path_driver_iterates_newton_from_each_previous_solution(tmp_path):
    """nsqrt_follow over targets 2, 3, 10 from q0 = 1: each q is sqrt(target) (1e-15 relative), its residual under
    tol, the warm-started second target in fewer iterations than the first; with max_iter 1 it stops after one."""
    lib, _ = codegen.compile_library(_newton_sqrt(), follow=True, directory=tmp_path)
    fun = lib.nsqrt_follow
    fun.restype = ctypes.c_int

    def run(targets, max_iter):
        n = len(targets)
        q, r, p = (ctypes.c_double * n)(), (ctypes.c_double * n)(), (ctypes.c_double * n)()
        its = (codegen.C_INT * n)()
        assert fun(codegen.C_INT(n), _doubles([1.0]), _doubles(targets), q, r, p, its, codegen.C_INT(max_iter),
                   ctypes.c_double(1e-14)) == 0
        return np.array(q[:]), np.array(r[:]), np.array(p[:]), list(its)

    targets = [2.0, 3.0, 10.0]
    q, r, p, its = run(targets, 50)
    assert np.abs(q - np.sqrt(targets)).max() <= 1e-15 * math.sqrt(10.0) and r.max() <= 1e-14
    assert np.abs(p - 2 * q).max() <= 1e-15 * 8 and its[1] < its[0]
    q1, r1, _, its1 = run([2.0], 1)
    assert its1 == [1] and q1[0] == 1.5 and r1[0] == 0.25


@needs_cc
def test_a_compiler_error_is_reported_not_raised(tmp_path):
    """Source that does not compile: (None, "the C compiler failed: <its message>"), no library left behind."""
    lib, how = codegen.compile_library(_tiny(), directory=tmp_path, text="this is not C;\n")
    assert lib is None and how.startswith("the C compiler failed: ") and "error" in how
    assert not list(tmp_path.glob("*.so"))


def test_libraries_are_kept_under_pkm_cache_dir(tmp_path, monkeypatch):
    """cache_dir() is the folder twin of $PKM_CACHE_DIR, read at each call (not at import)."""
    monkeypatch.setenv("PKM_CACHE_DIR", str(tmp_path / "a"))
    assert codegen.cache_dir() == tmp_path / "a" / "twin"
    monkeypatch.setenv("PKM_CACHE_DIR", str(tmp_path / "b"))
    assert codegen.cache_dir() == tmp_path / "b" / "twin"


def test_the_numpy_fallback_equals_casadi_and_refuses_mx():
    """numpy_function over 6 samples equals CasADi's evaluation of each (1e-15); an MX function is refused."""
    fun = _tiny()
    rng = np.random.default_rng(1)
    X, Y = rng.normal(size=(6, 2)), rng.uniform(0.5, 2.0, size=(6, 1))
    out0, out1 = codegen.numpy_function(fun)(X, Y)
    for k in range(6):
        a, b = fun(X[k], Y[k])
        assert abs(out0[k, 0] - float(a)) <= 1e-15 and np.abs(out1[k] - np.array(b).ravel()).max() <= 1e-15
    m = cs.MX.sym("m")
    with pytest.raises(ValueError, match="numpy_source needs an SX function"):
        codegen.numpy_source(cs.Function("mx", [m], [2 * m]))


def test_operations_are_counted_by_kind():
    """x * y + sin(x): one mul, one add, one sin, two inputs and one output, counted from CasADi's instruction list."""
    x, y = cs.SX.sym("x"), cs.SX.sym("y")
    counts = codegen.count_operations(cs.Function("c", [x, y], [x * y + cs.sin(x)]))
    assert counts == {"input": 2, "mul": 1, "sin": 1, "add": 1, "output": 1}


def test_the_numpy_route_writes_infinite_and_nan_constants():
    """Constants inf, -inf and NaN (a kernel's guard values) were written as bare names the generated Python did not
    know; they are numpy's now."""
    x = cs.SX.sym("x")
    f = cs.Function("f", [x], [cs.vertcat(x + 1.5, cs.SX(cs.inf) * x, cs.SX(float("nan")), -cs.inf)])
    out = codegen.numpy_function(f)(np.ones((2, 1)))[0]
    assert np.array_equal(out, np.tile([2.5, np.inf, np.nan, -np.inf], (2, 1)), equal_nan=True)
