"""pkm.core.twin.jaxgen: the twin's kernels translated to JAX equal their compiled C (jax.vmap over a batch of closed
states of the 3-PRS) to 1e-12; jax.jacfwd through the translated efforts equals the
derivatives kernel; every operation of the translation table equals CasADi's own evaluation.

XLA's compile time is the cost here (seconds per kernel of a few thousand instructions): one mechanism, the small
kernels, the derivatives kernel (5,759 instructions) compiled once (one sample, not vmapped)."""

from __future__ import annotations

import sys

import casadi as cs
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import pkm
from pkm.core.twin import jaxgen
from pkm.core.twin.codegen import count_operations
from pkm.core.twin.jaxgen import jax_function, jax_source
from pkm.core.twin.kernels import KERNELS, Kernels
from pkm.errors import InvalidInputError, MissingDependencyError
from tests.core.twin.test_kernels import _states

TOL = 1e-12  # absolute + relative: |jax - c| <= TOL * (1 + |c|)
N = 16


@pytest.fixture(scope="module")
def prs3():
    """The 3-PRS's kernels and N closed states, with each kernel input named in KERNELS (``target``: actuated
    coordinates near each state's, for the closure's Newton step)."""
    mech = pkm.load("prs3")
    K = Kernels(mech)
    Q, QD, QDD = _states(mech, N)
    target = np.array([mech.actuated_q(q) for q in Q]) + 1e-3
    return K, {"q": Q, "qd": QD, "qdd": QDD, "target": target}


def _close(jax_out, c_out) -> float:
    """The largest ``|jax - c| / (1 + |c|)`` over every output."""
    return max(float(np.max(np.abs(np.asarray(a) - b) / (1.0 + np.abs(b)))) for a, b in zip(jax_out, c_out))


@pytest.mark.parametrize("name", ["inverse_dynamics", "closure_newton", "velocities", "forward_jacobian",
                                  "mass_matrix"])
def test_the_jax_kernels_equal_the_compiled_c(prs3, name):
    """The batch under jax.vmap: the C batch's outputs (nonzeros, column-major) to 1e-12, in float64. (One sample
    under jax.jit is the jacfwd test's and the operations' below: each shape is an XLA compile of its own, seconds
    for these kernels; the derivatives kernel, 5,759 instructions, is checked through jax.jacfwd.)"""
    K, inputs = prs3
    arrays = [inputs[i] for i in KERNELS[name][0]]
    c_out = K.kernel(name)(*arrays)
    batch = jax.vmap(K.jax(name))(*arrays)
    assert all(o.dtype == jnp.float64 for o in batch)
    assert [o.shape for o in batch] == [c.shape for c in c_out]
    assert _close(batch, c_out) <= TOL


def test_jacfwd_through_the_efforts_equals_the_derivatives_kernel(prs3):
    """jax.jacfwd of the translated efforts in the actuated rates and accelerations equals the derivatives kernel's
    dtau_dqd and dtau_dqdd (compiled C) to 1e-12, at 4 closed states."""
    K, inputs = prs3
    Q, QD, QDD = inputs["q"][:4], inputs["qd"][:4], inputs["qdd"][:4]
    f = jax_function(K.function("inverse_dynamics"))
    jac = jax.jit(jax.jacfwd(lambda q, qd, qdd: f(q, qd, qdd)[0], argnums=(1, 2)))
    _, _, dqd, dqdd = K.kernel("inverse_dynamics_derivatives")(Q, QD, QDD)
    na = QD.shape[1]
    for k in range(len(Q)):
        jd, jdd = jac(Q[k], QD[k], QDD[k])
        for ours, c in ((jd, dqd[k]), (jdd, dqdd[k])):
            c = c.reshape(na, na, order="F")
            assert np.max(np.abs(np.asarray(ours) - c) / (1.0 + np.abs(c))) <= TOL


def _every_operation() -> cs.Function:
    """(x, y) -> every operation of the table once (x in (-1, 1), y > 0), and the constants inf and nan."""
    x, y = cs.SX.sym("x"), cs.SX.sym("y")
    exprs = [x + y, x - y, x * y, x / y, -x, x * x, x + x, 1 / x, x ** y, cs.constpow(x, 2.5), cs.sin(x), cs.cos(x),
             cs.tan(x), cs.asin(x), cs.acos(x), cs.atan(x), cs.atan2(x, y), cs.sqrt(y), cs.exp(x), cs.log(y),
             cs.fabs(x), cs.fmin(x, y), cs.fmax(x, y), cs.floor(x), cs.ceil(x), cs.fmod(x, y), cs.sign(x),
             cs.copysign(y, x), cs.hypot(x, y), cs.sinh(x), cs.cosh(x), cs.tanh(x), cs.asinh(x), cs.acosh(y + 1),
             cs.atanh(x), cs.expm1(x), cs.log1p(y), cs.if_else(x < y, cs.sin(y), 0), x < y, x <= y, x == y, x != y,
             cs.logic_not(x), cs.logic_and(x, y), cs.logic_or(x, y - y), cs.SX(cs.inf), cs.SX(-cs.inf),
             cs.SX(float("nan"))]
    return cs.Function("ops", [x, y], [cs.vertcat(*exprs), x * y], ["x", "y"], ["all", "xy"])


def test_every_operation_of_the_table_equals_casadi():
    """The table's forms (comparisons and logic as 1.0/0.0, if_else_zero as jnp.where), the constants inf and nan,
    at points either side of the comparisons: CasADi's own evaluation to 1e-15 (NaN where it gives NaN)."""
    fun = _every_operation()
    used = {k.upper() for k in count_operations(fun)} - {"INPUT", "OUTPUT", "CONST"}
    assert used == set(jaxgen._JAX) - {"ASSIGN"}  # (ASSIGN: a copy, not reached from SX expressions)
    f = jax_function(fun)
    for x, y in ((0.3, 1.7), (-0.6, 0.4), (0.5, 0.5), (0.0, 2.0)):
        ref = np.array(fun(x, y)[0]).ravel()
        ours, xy = f(jnp.array([x]), jnp.array([y]))
        np.testing.assert_allclose(np.asarray(ours), ref, rtol=1e-15, atol=1e-15, equal_nan=True)
        assert float(xy[0]) == x * y


def test_the_source_is_one_statement_per_instruction_and_the_inputs_are_checked():
    """jax_source: one line per instruction (and the def and return); an input of the wrong size (which JAX's
    indexing would clamp silently) or the wrong number of inputs is refused; an MX function is refused."""
    fun = _every_operation()
    text = jax_source(fun)
    assert text.startswith("def f(jnp, in0, in1):") and "jnp.inf" in text and "jnp.nan" in text
    assert len(text.splitlines()) == fun.n_instructions() + 2
    f = jax_function(fun)
    with pytest.raises(InvalidInputError, match=r"expected one sample of shape \(1,\)"):
        f(jnp.zeros(2), jnp.ones(1))
    with pytest.raises(InvalidInputError, match="takes 2 inputs"):
        f(jnp.zeros(1))
    assert f(np.array([1]), np.array([2]))[1].dtype == jnp.float64  # (integers computed as floats)
    m = cs.MX.sym("m")
    with pytest.raises(ValueError, match="needs an SX function"):
        jax_source(cs.Function("mx", [m], [cs.sin(m)]))


def test_without_jax_the_extra_is_named(monkeypatch):
    """jax_function raises MissingDependencyError naming pip install "pkm-robotics[jax]" when JAX cannot be imported;
    jax_source needs no JAX."""
    monkeypatch.setitem(sys.modules, "jax", None)
    fun = _every_operation()
    assert jax_source(fun)
    with pytest.raises(MissingDependencyError, match=r'pip install "pkm-robotics\[jax\]"') as info:
        jax_function(fun)
    assert info.value.extra == "jax"
