"""Batches near the machine's limit: the inverse-dynamics kernel on the vector units and on every core, against the
scalar driver, this core's measured vector peak and JAX, all in one run.

For the 3-PRS, the Delta and the hexapod, ``-n`` (100,000) closed states along a smooth path of every actuator
(as :mod:`pkm.bench.twin`), each route timed on the same arrays (median of ``--repeat``):

* ``scalar``: the CasADi-generated C, sample after sample (``NAME_batch``), one thread: the baseline;
* ``vector``: the vector driver (:mod:`pkm.core.twin.simd`: one vector instruction per SX instruction across
  ``lanes`` samples, libm lane by lane), one thread; its results compared with the scalar driver's bit for bit;
* ``driver_2_threads``: the vector driver on two halves of the batch at once (two threads, C only), and its scaling
  over one thread; ``kernels_2_threads``: :meth:`pkm.Kernels.inverse_dynamics` with ``threads=2`` (its checks and
  the fallback test included), against ``threads=1``;
* ``jax``: the kernel translated to JAX (:meth:`pkm.Kernels.jax`) under ``jax.jit(jax.vmap(...))`` on JAX's default
  device (the CPU here; the same code on a GPU where JAX has one), after its compile, when JAX is installed; its
  largest difference to the C (``--quick``: XLA's backend unoptimised, :data:`pkm.bench.QUICK_XLA`: a check that it
  runs and agrees, not its time).

Flops a sample are the kernel's ``+ - * /`` (squares and doublings counted as one, negations free: the
papers' count, :meth:`pkm.Kernels.operation_count`); the achieved GFLOP/s are over this core's vector peak
measured by :func:`pkm.core.twin.simd.peak_gflops` (independent multiply-then-add chains, no FMA: what the drivers
run; the FMA peak is stated too). Goals (the issue's): 3-PRS <= 0.06 µs, hexapod <= 0.3 µs a sample on one core;
the vector driver on 2 threads >= 1.8x one.

Usage: ``python -m pkm.bench.batch [--json] [--quick] [-n 100000] [--repeat 9] [--mechanisms prs3,delta,hexapod]``.
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from pkm.bench import jax_batch, main
from pkm.bench.twin import _path

QUICK = {"n": 1024, "repeat": 1, "mechanisms": "prs3"}
MECHANISMS = ("prs3", "delta", "hexapod")
GOALS_US = {"prs3": 0.06, "hexapod": 0.3}
GOAL_SCALING = 1.8


def add_arguments(ap) -> None:
    ap.add_argument("-n", type=int, default=100_000, help="samples (default 100,000)")
    ap.add_argument("--repeat", type=int, default=9, help="timed repeats of each route (median kept)")
    ap.add_argument("--mechanisms", default=",".join(MECHANISMS), help="which, comma-separated (default all three)")


def _median(fn, repeat: int) -> float:
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _jax(K, args, repeat: int, reference: np.ndarray, quick: bool = False) -> dict:
    from pkm._optional import missing

    if missing("jax"):
        return {"skipped": 'JAX is not installed (pip install "pkm-robotics[jax]")'}
    import jax

    fn = K.jax("inverse_dynamics")
    arrays = [jax.device_put(a) for a in args]
    t0 = time.perf_counter()
    f = jax_batch(fn, arrays, quick)  # (quick: compiled here, unoptimised)
    out = f(*arrays)[0].block_until_ready()
    compile_s = time.perf_counter() - t0
    seconds = _median(lambda: f(*arrays)[0].block_until_ready(), repeat)
    return {"device": str(jax.devices()[0]), "compile_s": compile_s, "us": seconds / len(args[0]) * 1e6,
            "largest_difference": float(np.max(np.abs(np.asarray(out) - reference)))}


def _scalar(kernel, arrays: list[np.ndarray]) -> list[np.ndarray]:
    """The scalar driver (``NAME_batch``) on the whole batch, one thread."""
    from pkm.core.twin.codegen import pointers

    n = len(arrays[0])
    outs = [np.empty((n, s)) for s in kernel.out_size]
    kernel._batch(n, pointers(arrays), pointers(outs))
    return outs


def _halves(driver, arrays: list[np.ndarray], out_size: list[int]):
    """A call of ``driver`` on each half of the batch at once, on two threads (ctypes releases the GIL)."""
    from concurrent.futures import ThreadPoolExecutor

    from pkm.core.twin.codegen import pointers

    n = len(arrays[0])
    outs = [np.empty((n, s)) for s in out_size]

    def part(lo: int, hi: int) -> int:
        return int(driver(hi - lo, pointers(a[lo:] for a in arrays), pointers(o[lo:] for o in outs)))

    pool = ThreadPoolExecutor(1)

    def both() -> None:
        other = pool.submit(part, 0, n // 2)
        part(n // 2, n)
        other.result()

    return both


def run(args) -> dict:
    import pkm
    from pkm.core.twin.simd import SimdKernel, peak_gflops, time_per_sample

    peak = peak_gflops()
    out: dict = {"n": args.n, "peak_gflops": peak, "mechanisms": {}}
    for name in args.mechanisms.split(","):
        mech = pkm.load(name)
        qa, qd, qdd = _path(mech, args.n)
        Q = pkm.Kernels(mech).close_loops_path(qa).q
        K1, K2 = pkm.Kernels(mech, threads=1), pkm.Kernels(mech, threads=2)
        kernel = K1.kernel("inverse_dynamics")
        count = K1.operation_count("inverse_dynamics")
        flops = count.mul + count.add
        ins = [Q, qd, qdd]
        scalar_s = statistics.median(time_per_sample(kernel._batch, ins, kernel.out_size) for _ in range(args.repeat))
        vec = SimdKernel(kernel.fun)
        vector_s = statistics.median(time_per_sample(vec.driver, ins, kernel.out_size) for _ in range(args.repeat))
        same = all(np.array_equal(a, b, equal_nan=True) for a, b in zip(_scalar(kernel, ins), vec(*ins)))
        halves = _halves(vec.driver, ins, kernel.out_size)
        driver_2_s = _median(halves, args.repeat) / args.n
        tau1 = K1.inverse_dynamics(Q, qd, qdd)
        one_s = _median(lambda: K1.inverse_dynamics(Q, qd, qdd), args.repeat) / args.n  # noqa: B023 (run now)
        two_s = _median(lambda: K2.inverse_dynamics(Q, qd, qdd), args.repeat) / args.n  # noqa: B023
        lanes = int(vec.how.rsplit(" lanes", 1)[0].rsplit(" ", 1)[1])
        row = {"flops": flops, "lanes": lanes, "scalar_us": scalar_s * 1e6, "vector_us": vector_s * 1e6,
               "vector_over_scalar": scalar_s / vector_s, "bit_for_bit": same,
               "driver_2_threads_us": driver_2_s * 1e6, "scaling_2": vector_s / driver_2_s,
               "kernels_1_thread_us": one_s * 1e6, "kernels_2_threads_us": two_s * 1e6,
               "kernels_scaling_2": one_s / two_s,
               "vector_gflops": flops / vector_s / 1e9,
               "fraction_of_peak": flops / vector_s / 1e9 / peak.get("mul_add", float("nan")),
               "goal_us": GOALS_US.get(name), "jax": _jax(K1, ins, args.repeat, tau1, args.quick)}
        out["mechanisms"][name] = row
    out["goal_scaling"] = GOAL_SCALING
    return out


def table(r: dict) -> str:
    p = r["peak_gflops"]
    lines = [f"inverse dynamics, {r['n']} samples; this core's vector peak ({p.get('lanes', 0):.0f} lanes): "
             f"{p.get('mul_add', float('nan')):.1f} GFLOP/s multiply-then-add, {p.get('fma', float('nan')):.1f} "
             f"with FMA",
             f"{'':8} {'flops':>6} {'lanes':>5} {'scalar us':>9} {'vector us':>9} {'x':>5} {'bits':>5} "
             f"{'2 thr us':>8} {'scale':>5} {'pkm.Kernels 1/2 thr us':>22} {'GFLOP/s':>7} {'of peak':>7} "
             f"{'jax us':>7} {'goal us':>7}"]
    for name, x in r["mechanisms"].items():
        jax_us = x["jax"].get("us")
        lines.append(f"{name:8} {x['flops']:6d} {x['lanes']:5d} {x['scalar_us']:9.3f} {x['vector_us']:9.3f} "
                     f"{x['vector_over_scalar']:5.1f} {'same' if x['bit_for_bit'] else 'DIFF':>5} "
                     f"{x['driver_2_threads_us']:8.3f} {x['scaling_2']:5.2f} "
                     f"{x['kernels_1_thread_us']:10.3f} /{x['kernels_2_threads_us']:6.3f} ({x['kernels_scaling_2']:.2f}x) "
                     f"{x['vector_gflops']:7.1f} "
                     f"{x['fraction_of_peak']:7.0%} {'-' if jax_us is None else f'{jax_us:.3f}':>7} "
                     f"{'-' if x['goal_us'] is None else x['goal_us']:>7}")
    lines.append(f"goals: 3-PRS <= 0.06 us, hexapod <= 0.3 us a sample on one core; 2 threads >= "
                 f"{r['goal_scaling']}x one")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main("batch"))
