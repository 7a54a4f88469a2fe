"""pkm.core.twin.simd: the vector batch driver equals the scalar CasADi-generated one (``NAME_batch``) bit for bit
(libm lane by lane), on every operation it writes (special values included, at 2, 4 and 8 lanes) and on the
3-PRS's and the Delta's kernels over 37 samples (a tail); with libmvec to 1e-14 relative; non-finite inputs give
the scalar path's non-finite outputs."""

from __future__ import annotations

import itertools
import shutil

import casadi as cs
import numpy as np
import pytest

import pkm
from pkm.core.twin import codegen, simd
from pkm.core.twin.kernels import Kernels
from tests.core.twin.test_kernels import _states

pytestmark = pytest.mark.skipif(not (shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")),
                                reason="no C compiler")


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    """Bit for bit (any NaN equal to any NaN)."""
    return bool(np.all((a.view(np.int64) == b.view(np.int64)) | (np.isnan(a) & np.isnan(b))))


@pytest.fixture(scope="module")
def kernels():
    """The kernels of the 3-PRS and the Delta, with 37 closed states each (37 = 4 * 9 + 1 = 8 * 4 + 5: a tail)."""
    out = {}
    for name in ("prs3", "delta"):
        mech = pkm.load(name)
        Q, QD, QDD = _states(mech, 37, seed=2)
        A = np.array([mech.actuated_q(q) for q in Q])
        out[name] = (Kernels(mech), {"inverse_dynamics": (Q, QD, QDD), "mass_and_bias": (Q, QD),
                                     "closure_newton": (Q + 1e-3, A)})
    return out


def _scalar(driver, out_size: list[int], args: tuple[np.ndarray, ...]) -> list[np.ndarray]:
    """A scalar batch driver (``NAME_batch``) on one thread."""
    ins = [np.ascontiguousarray(a, dtype=float) for a in args]
    outs = [np.empty((len(ins[0]), s)) for s in out_size]
    assert driver(codegen.C_INT(len(ins[0])), codegen.pointers(ins), codegen.pointers(outs)) == 0
    return outs


@pytest.mark.parametrize("name", ["prs3", "delta"])
@pytest.mark.parametrize("kernel", ["inverse_dynamics", "mass_and_bias", "closure_newton"])
def test_the_vector_driver_equals_the_scalar_one_bit_for_bit(kernels, name, kernel):
    """libm lane by lane: every output of 37 samples (the last block padded) the scalar driver's, bit for bit."""
    K, args = kernels[name]
    k = K.kernel(kernel)
    vec = simd.SimdKernel(k.fun)
    assert vec.lib is not None, vec.how
    assert simd.lanes(vec.lib, k.fun.name()) == simd.lanes() and "lane-wise libm" in vec.how
    for a, b in zip(_scalar(k._batch, k.out_size, args[kernel]), vec(*args[kernel])):
        assert a.shape == b.shape and _same(a, b)


@pytest.mark.parametrize("name", ["prs3", "delta"])
def test_with_libmvec_the_efforts_agree_to_1e_14(kernels, name):
    """libmvec's sines and cosines (within 4 ulp each, not glibc's scalar ones): efforts and mass matrices per
    sample within 1e-14 of the scalar driver's, relative to the sample's largest entry."""
    K, args = kernels[name]
    for kernel in ("inverse_dynamics", "mass_and_bias"):
        k = K.kernel(kernel)
        vec = simd.SimdKernel(k.fun, maths="libmvec")
        assert vec.lib is not None, vec.how
        for a, b in zip(_scalar(k._batch, k.out_size, args[kernel]), vec(*args[kernel])):
            assert np.all(np.abs(a - b).max(axis=1) <= 1e-14 * np.abs(a).max(axis=1))


def test_non_finite_inputs_give_the_scalar_paths_non_finite_outputs(kernels):
    """NaN and infinite configuration entries, rates and accelerations: no crash, the scalar path's outputs (NaN
    where it has NaN; an entry that does not enter the efforts leaves them finite in both); a NaN configuration, an
    infinite rate, a NaN acceleration make every effort of their sample NaN."""
    K, args = kernels["prs3"]
    k = K.kernel("inverse_dynamics")
    Q, QD, QDD = (a[:11].copy() for a in args["inverse_dynamics"])
    Q[0, 0], Q[3, 2], QD[5, 1], QDD[9, 0], Q[10] = np.nan, np.inf, -np.inf, np.nan, np.nan
    expected = _scalar(k._batch, k.out_size, (Q, QD, QDD))
    got = simd.SimdKernel(k.fun)(Q, QD, QDD)
    assert all(_same(a, b) for a, b in zip(expected, got))
    assert not np.isfinite(got[0][[5, 9, 10]]).any(axis=1).any() and np.isfinite(got[0][[1, 2, 4]]).all()


def _every_operation() -> cs.Function:
    x, y = cs.SX.sym("x"), cs.SX.sym("y")
    e = [x + y, x - y, x * y, x / y, -x, x * x, 2 * x, 1 / x, x ** y, cs.constpow(x, 3), cs.sqrt(x), cs.fabs(x),
         cs.fmin(x, y), cs.fmax(x, y), cs.copysign(x, y), cs.sign(x), cs.if_else(x, y, 0, True), x < y, x <= y,
         x == y, x != y, cs.logic_not(x), cs.logic_and(x, y), cs.logic_or(x, y), cs.sin(x), cs.cos(x), cs.tan(x),
         cs.asin(x), cs.acos(x), cs.atan(x), cs.atan2(x, y), cs.exp(x), cs.log(x), cs.sinh(x), cs.cosh(x),
         cs.tanh(x), cs.floor(x), cs.ceil(x), cs.fmod(x, y), cs.hypot(x, y), cs.erf(x), cs.log1p(x), cs.expm1(x),
         cs.asinh(x), cs.acosh(x), cs.atanh(x), cs.sin(y), cs.cos(y) * cs.sin(x)]
    return cs.Function("pkm_every_op", [x, y], [cs.vertcat(*e)])


def test_every_operation_is_the_scalar_paths_bit_for_bit(tmp_path):
    """Each operation the driver writes, on every pair of special values (±0, ±1, ±inf, NaN, a subnormal, 1e300)
    and 60 random pairs, at 2, 4 and 8 lanes: CasADi's C (fmin/fmax's NaN rule, sign, if_else_zero, the
    comparisons, sincos) bit for bit; n = 0 writes nothing."""
    fun = _every_operation()
    special = [0.0, -0.0, 1.0, -1.0, 0.5, -2.5, np.inf, -np.inf, np.nan, 1e-310, 3.0, 1e300]
    X = np.vstack([np.array(list(itertools.product(special, special))),
                   3 * np.random.default_rng(0).standard_normal((60, 2))])
    ins = (X[:, :1].copy(), X[:, 1:].copy())
    lib, _ = codegen.compile_library(fun, directory=tmp_path)
    assert lib is not None
    expected = _scalar(lib.pkm_every_op_batch, [fun.nnz_out(0)], ins)[0]
    for lanes in (2, 4, 8):
        vec = simd.SimdKernel(fun, tmp_path, lanes=lanes)
        assert simd.lanes(vec.lib, fun.name()) == lanes
        got = vec(*ins)[0]
        bad = [str(fun.sx_out(0)[j]) for j in range(got.shape[1]) if not _same(got[:, j], expected[:, j])]
        assert not bad, (lanes, bad)
    empty = vec(np.zeros((0, 1)), np.zeros((0, 1)))[0]
    assert empty.shape == (0, fun.nnz_out(0))


def test_the_source_and_its_refusals():
    """The driver and its lane query in the source, no placeholder left; an MX function, a sparse output, an
    unknown maths or lane count refused; peak_gflops measures both chains."""
    fun = _every_operation()
    text = simd.simd_source(fun, "f")
    assert "int f_simd(long long n, const double** in, double** out)" in text and "int f_simd_lanes(void)" in text
    assert "@" not in text.split("#include <string.h>")[1]
    m = cs.MX.sym("m")
    with pytest.raises(ValueError, match="needs an SX function"):
        simd.simd_source(cs.Function("mx", [m], [2 * m]))
    x = cs.SX.sym("x", 2)
    with pytest.raises(ValueError, match="sparse"):
        simd.simd_source(cs.Function("sp", [x], [cs.SX(cs.Sparsity.diag(2), x)]))
    with pytest.raises(ValueError, match="maths"):
        simd.simd_source(fun, maths="svml")
    with pytest.raises(ValueError, match="lanes"):
        simd.simd_source(fun, lanes=3)
    assert simd.widest() in (2, 4, 8) and simd.lanes() <= simd.widest()
    peak = simd.peak_gflops(2, seconds=0.01)
    assert peak["lanes"] == 2 and peak["mul_add"] > 0 and peak["fma"] > 0


def test_a_long_function_is_cut_into_parts(tmp_path):
    """chunk=50: the body in parts passing live values through the work vector; the same bits as one part."""
    fun = _every_operation()
    X = 2 * np.random.default_rng(1).standard_normal((13, 2))
    ins = (X[:, :1].copy(), X[:, 1:].copy())
    whole = simd.SimdKernel(fun, tmp_path)(*ins)[0]
    assert "pkm_every_op_simd_1(x, y, W)" in simd.simd_source(fun, chunk=50)
    assert _same(simd.SimdKernel(fun, tmp_path, chunk=50)(*ins)[0], whole)


def test_kernels_run_large_batches_on_the_vector_driver_bit_for_bit_on_any_thread_count(monkeypatch):
    """``Kernels`` takes the vector driver from VECTOR_SAMPLES samples (what runs says so): 300 samples' efforts
    are the scalar driver's (``vector=False``) bit for bit, split over one thread or two."""
    from pkm.core.twin import kernels as kmod

    mech = pkm.load("prs3")
    Q, QD, QDD = (np.repeat(a, 10, axis=0)[:300] for a in _states(mech, 30, seed=4))
    scalar = Kernels(mech, vector=False).inverse_dynamics(Q, QD, QDD)
    one = Kernels(mech, threads=1)
    assert _same(one.inverse_dynamics(Q, QD, QDD), scalar)
    assert "the vector driver" in one.how["inverse_dynamics"]
    monkeypatch.setattr(kmod, "THREAD_SAMPLES", 100)  # (300 samples in two chunks)
    assert _same(Kernels(mech, threads=2).inverse_dynamics(Q, QD, QDD), scalar)
    with pytest.raises(pkm.errors.InvalidInputError, match="threads"):
        Kernels(mech, threads=0)


def _child_batch(queue) -> None:  # (module level: the fork runs it)
    mech = pkm.load("prs3")
    Q, QD, QDD = (np.repeat(a, 400, axis=0) for a in _states(mech, 12, seed=5))
    queue.put(Kernels(mech).inverse_dynamics(Q, QD, QDD).shape)


def test_a_forked_child_splits_its_batches_over_threads_of_its_own(monkeypatch):
    """After the parent split a batch over its thread pool, a child forked from it (multiprocessing's default on
    Linux) splits its own batch: it has a pool of its own (the parent's threads do not exist in the child)."""
    import multiprocessing

    from pkm.core.twin import kernels as kmod

    monkeypatch.setattr(kmod, "THREAD_SAMPLES", 1000)
    mech = pkm.load("prs3")
    Q, QD, QDD = (np.repeat(a, 400, axis=0) for a in _states(mech, 12, seed=5))
    Kernels(mech, threads=2).inverse_dynamics(Q, QD, QDD)  # (the parent's pool started)
    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    child = context.Process(target=_child_batch, args=(queue,))
    child.start()
    child.join(60)
    hung = child.is_alive()
    if hung:
        child.kill()
    assert not hung and child.exitcode == 0 and queue.get(timeout=5) == (4800, 3)
