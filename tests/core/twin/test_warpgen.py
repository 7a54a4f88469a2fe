"""The Warp emitter (:mod:`pkm.core.twin.warpgen`): its source (float64 constants, structure-of-arrays, no adjoint),
an operation it has no form for refused, and every operation of :data:`WARP_FORMS` that a twin emits run on Warp's
CPU device against CasADi's own evaluation (one small module: about 2 s of Warp's compiler, cached afterwards); a
:class:`Loop` is one copy of its step in a loop Warp keeps, equal bit for bit to the step unrolled."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from pkm.core.twin.warpgen import Loop, launch, warp_kernel, warp_module, warp_source


def _every_operation() -> cs.Function:
    a, b, c, d = (cs.SX.sym(n) for n in "abcd")  # (c within (-1, 1), d positive: the functions' domains)
    ops = [a + b, a - b, a * b, a / b, -a, a * a, 2 * a, 1 / a, cs.sin(a), cs.cos(a), cs.tan(a), cs.asin(c),
           cs.acos(c), cs.atan(a), cs.atan2(a, b), cs.sqrt(d), cs.exp(a), cs.log(d), cs.fabs(a), cs.fmin(a, b),
           cs.fmax(a, b), cs.floor(a), cs.ceil(a), cs.sinh(a), cs.cosh(a), cs.tanh(a), cs.sign(a), cs.copysign(d, b),
           a < b, a <= b, a == b, a != b, cs.logic_not(a), cs.logic_and(a, b), cs.logic_or(a, b),
           cs.if_else(a < b, c, 0.0), d ** b, d ** 3.5, cs.constpow(d, 2.5)]
    return cs.Function("every_op", [cs.vertcat(a, b, c, d)], [cs.vertcat(*ops)], ["x"], ["y"])


def test_the_source_is_float64_structure_of_arrays_without_adjoint():
    text = warp_source(_every_operation())
    assert "@wp.kernel\ndef every_op(x: wp.array2d(dtype=wp.float64), y: wp.array2d(dtype=wp.float64)):" in text
    assert "w0 = x[0, t]" in text and "y[0, t] = " in text  # (entry-major: thread t reads column t)
    assert "wp.set_module_options({'enable_backward': False, 'max_unroll': 1})" in text
    assert "f64(2.0) * " in text  # (a bare 2.0 would be a float32 in a Warp kernel)


def test_an_operation_without_a_form_is_refused():
    x = cs.SX.sym("x")
    with pytest.raises(ValueError, match="no Warp form"):
        warp_source(cs.Function("erf", [x], [cs.erf(x)]))


def test_every_operation_matches_casadi():
    pytest.importorskip("warp")
    fun = _every_operation()
    rows = [(a, b, c, d) for a in (-1.3, 0.0, 0.7, 2.5) for b in (0.4, -2.0, 0.7, 1.5) for c in (-0.6, 0.3)
            for d in (0.2, 1.7)]
    X = np.array(rows)
    expected = np.array([np.array(fun(x)).ravel() for x in X])
    [got] = launch(warp_kernel(fun), fun, X)
    finite = np.isfinite(expected)  # (1/a and a/b at a = 0 or b = 0: infinities on both sides)
    assert np.array_equal(np.isfinite(got), finite)
    assert np.abs(got[finite] - expected[finite]).max() <= 1e-14 * max(1.0, np.abs(expected[finite]).max())


def _newton(iterations: int) -> tuple[Loop, cs.Function]:
    """A Newton solve of ``x² = a`` as a :class:`Loop` and unrolled (the transmissions' form: the smallest pivot
    ``|2x| sqrt(a)``, NaN where ``a < 0``, kept by ``fmin``; the finish scales by a third input)."""
    x, a, p, s = cs.SX.sym("x"), cs.SX.sym("a"), cs.SX.sym("pivot"), cs.SX.sym("s")
    step = cs.Function("root_step", [x, a], [x - (x * x - a) / (2 * x), cs.fabs(2 * x) * cs.sqrt(a)],
                       ["x", "a"], ["x_next", "pivot"])
    finish = cs.Function("root_finish", [x, p, s], [s * x, p], ["x", "pivot", "s"], ["y", "least"])
    y, least = step(x, a)
    for _ in range(iterations - 1):
        y, q = step(y, a)
        least = cs.fmin(least, q)
    unrolled = cs.Function("root_unrolled", [x, a, s], finish(y, least, s), ["x", "a", "s"], ["y", "least"])
    return Loop("root", step, finish, iterations), unrolled


def test_a_loop_holds_one_copy_of_its_step():
    loop, unrolled = _newton(7)
    text = warp_source(loop)
    assert "def root(x: wp.array2d(dtype=wp.float64), a: wp.array2d(dtype=wp.float64), " \
           "s: wp.array2d(dtype=wp.float64), y: wp.array2d(dtype=wp.float64)" in text
    assert text.count("for i in range(7):") == 1 and text.count("wp.abs(") == 1  # (the step once, not 7 times)
    assert warp_source(unrolled).count("wp.abs(") == 7
    assert [loop.name_in(i) for i in range(loop.n_in())] == ["x", "a", "s"] and loop.nnz_out(1) == 1
    x, p = cs.SX.sym("x"), cs.SX.sym("pivot")
    clash = cs.Function("f", [x, p], [x, p], ["x", "pivot"], ["x0", "p"])  # (names of the loop's variables)
    with pytest.raises(ValueError, match=r"\['x0', 'p'\] are the loop's own variables"):
        warp_source(Loop("clash", loop.step, clash, 3))


def test_a_loop_equals_its_step_unrolled():
    """Bit for bit (the same instructions in the same order), a NaN pivot among them (its sign bit too); and
    CasADi's values."""
    pytest.importorskip("warp")
    loop, unrolled = _newton(7)
    module = warp_module([loop, unrolled])  # (one compile)
    X = np.array([[1.0, 2.0, 3.0], [0.5, 9.0, -1.0], [3.0, -4.0, 2.0], [2.0, 2.0, 0.5]])
    got = launch(module.root, loop, *X.T[:, :, None])
    ref = launch(module.root_unrolled, unrolled, *X.T[:, :, None])
    assert all(g.tobytes() == r.tobytes() for g, r in zip(got, ref))
    assert np.isnan(got[1][2, 0]) and np.isfinite(got[1][:2]).all()
    expected = np.array([np.array(unrolled(*row)).ravel() for row in X[:2, :, None]])
    assert np.abs(got[0][:2, 0] - expected[:, 0]).max() <= 1e-15 * 3
