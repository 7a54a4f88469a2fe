"""Transmission kernels in batches: the humanoid ankle's motors -> outputs (FK), velocity map ``J`` and ``ΔM`` for
``n`` samples (default 10⁶) on each target, against Python's route timed in the same run.

The samples: motor positions uniform in ±0.25 rad around the reference, each warm-started from its solution a
1 kHz tick earlier (the motors 0.01 rad away: what a controller or a batch of simulated robots gives the kernel);
the fused kernel ``fk_j_dm`` (:mod:`pkm.core.transmissions.kernels`, ``--iterations`` Newton iterations, unrolled in
the C, looped in JAX and Warp: 3 by default, enough from such a warm start; the statuses are counted) on each
target, µs a sample:

* ``c_vector``: the generated C in process, its vector driver (:mod:`pkm.core.twin.simd`, several samples a vector
  instruction), on one core (``--threads``);
* ``c_scalar``: the same C, one sample after another (CasADi's C), one core;
* ``jax``: ``jax.jit(jax.vmap(f))`` of the JAX translation (the ``jax`` extra; skipped without it), on JAX's CPU
  device (its threads; ``--quick``: XLA's backend unoptimised, :data:`pkm.bench.QUICK_XLA`);
* ``warp_cpu``: the Warp kernel (the ``warp`` extra; skipped without it), one thread a sample on Warp's ``"cpu"``
  device, structure-of-arrays (a GPU: ``tools/gpu_transmissions.py``); its compile time is the module's of every
  kernel (as ``pkm transmission`` writes it);
* ``python`` (the baseline, on ``--calls`` samples): :func:`pkm.close_loops` (warm-started the same way),
  :func:`pkm.forward_jacobian` and :func:`pkm.mass_matrix` per sample (the closed-loop ``M_a``, not ``ΔM``: the
  Python route to the same inputs of a simulator step).

Every target's outputs are compared with the C's (``largest_difference``: 1e-12 expected), and the statuses
counted. Compile times (first call) are reported apart. The goal (issue 44): ≤ 0.3 µs a sample for the vector batch.

Usage: ``python -m pkm.bench.transmissions [--json] [--quick] [-n 1000000]``.
"""

from __future__ import annotations

import os
import time

import numpy as np

from pkm.bench import best_time, jax_batch, main, median_us

#: The quick run: the knee, the kernels' default iterations (the tests' kernels: their compiled C and Warp module are
#: found in the caches).
QUICK = {"n": 2000, "repeat": 1, "calls": 5, "mechanism": "knee", "iterations": 8}
MECHANISMS = {"ankle": "examples/humanoid_ankle/ankle.closures.toml", "knee": "examples/humanoid_knee/knee.closures.toml"}
SPREAD, TICK = 0.25, 0.01  # [rad]: the samples' spread around the reference, the warm start's distance
GOAL_US = 0.3


def add_arguments(ap) -> None:
    ap.add_argument("-n", type=int, default=1_000_000, help="samples (default 10^6)")
    ap.add_argument("--repeat", type=int, default=3, help="timed repeats of each batch (best kept)")
    ap.add_argument("--calls", type=int, default=200, help="samples of the Python baseline")
    ap.add_argument("--threads", type=int, default=1, help="cores of the C batches (default 1)")
    ap.add_argument("--iterations", type=int, default=3,
                    help="Newton iterations (unrolled in the C; default 3: enough from a warm start a tick away; the statuses "
                         "are counted)")
    ap.add_argument("--mechanism", choices=sorted(MECHANISMS), default="ankle",
                    help="the transmission (default the ankle; --quick: the knee)")


def _root() -> str:
    """The checkout (its ``examples``, which a wheel does not ship: the benchmark runs from a checkout)."""
    here = os.path.dirname(os.path.abspath(__file__))
    return os.path.normpath(os.path.join(here, "..", "..", ".."))


def samples(tk, n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``(Q0, QM)``: ``n`` motor positions and, for each, its closed configuration a tick earlier (the warm start)."""
    rng = np.random.default_rng(seed)
    qm_ref = tk.mech.actuated_q(tk.mech.q_reference)
    QM = qm_ref + rng.uniform(-SPREAD, SPREAD, (n, tk.k))
    before = QM - TICK * rng.choice([-1.0, 1.0], (n, tk.k))
    from pkm.core.transmissions.kernels import ITERATIONS, TransmissionKernels

    cold = tk if tk.iterations >= ITERATIONS else TransmissionKernels(tk.mech, tk.outputs, name=tk.name)
    Q0 = cold.run("fk", np.tile(tk.mech.q_reference, (n, 1)), before)[0]
    return Q0, QM


def run(args) -> dict:
    import pkm
    from pkm.core.transmissions.kernels import TransmissionKernels
    from pkm.core.twin.kernels import _Kernel

    path = os.path.join(_root(), MECHANISMS[args.mechanism])
    if not os.path.exists(path):
        return {"skipped": "examples/ absent (an installed wheel)"}
    mech = pkm.load(path)
    [t] = pkm.transmissions(mech)
    tk = TransmissionKernels.of(t, iterations=args.iterations)
    fun = tk.function("fk_j_dm")
    n = args.n
    Q0, QM = samples(tk, n)
    out: dict = {"mechanism": args.mechanism, "samples": n, "kernel": "fk_j_dm", "iterations": tk.iterations,
                 "instructions": fun.n_instructions(), "threads": args.threads, "cores": os.cpu_count(),
                 "us_per_sample": {}, "compile_s": {}, "largest_difference": {}, "skipped": {}}
    us, comp, diff = out["us_per_sample"], out["compile_s"], out["largest_difference"]
    ref: list[np.ndarray] = []
    for label, vector in (("c_vector", True), ("c_scalar", False)):
        t0 = time.perf_counter()
        kernel = _Kernel(fun, False, True, None, vector, args.threads)
        kernel(Q0[:300], QM[:300])
        comp[label] = time.perf_counter() - t0

        def batch(kernel: _Kernel = kernel) -> list[np.ndarray]:
            return kernel(Q0, QM)

        wall, outs = best_time(batch, args.repeat)
        us[label] = wall / n * 1e6
        if not ref:
            ref = outs
            out["status_counts"] = {int(s): int(c) for s, c in zip(*np.unique(outs[-1], return_counts=True))}
            out["how"] = kernel.how
        else:
            diff[label] = max(float(np.abs(a - b).max()) for a, b in zip(outs, ref))
    try:
        import jax

        fn = tk.jax("fk_j_dm")
        t0 = time.perf_counter()
        g = jax_batch(fn, (Q0, QM), args.quick)  # (quick: compiled here, unoptimised)
        jax.block_until_ready(g(Q0, QM))
        comp["jax"] = time.perf_counter() - t0
        wall, outs = best_time(lambda: jax.block_until_ready(g(Q0, QM)), args.repeat)
        us["jax"] = wall / n * 1e6
        diff["jax"] = max(float(np.abs(np.asarray(a) - b).max()) for a, b in zip(outs, ref))
    except ImportError as e:  # (MissingDependencyError is one)
        out["skipped"]["jax"] = str(e)
    try:
        import warp as wp

        from pkm.core.transmissions.kernels import KERNELS
        from pkm.core.twin.warpgen import warp_module

        wp.config.log_level = wp.LOG_WARNING  # (Warp prints its start to stdout: --json)
        t0 = time.perf_counter()  # (the module of every kernel, as pkm transmission writes it)
        kern = getattr(warp_module([tk.looped(k) for k in KERNELS]), fun.name())
        ins: list = [wp.array(np.ascontiguousarray(a.T), dtype=wp.float64, device="cpu") for a in (Q0, QM)]
        outs_w = [wp.zeros((fun.nnz_out(j), n), dtype=wp.float64, device="cpu") for j in range(fun.n_out())]
        wp.launch(kern, dim=n, inputs=ins, outputs=outs_w, device="cpu")
        wp.synchronize()
        comp["warp_cpu"] = time.perf_counter() - t0

        def launch() -> None:
            wp.launch(kern, dim=n, inputs=ins, outputs=outs_w, device="cpu")
            wp.synchronize()

        wall, _ = best_time(launch, args.repeat)
        us["warp_cpu"] = wall / n * 1e6
        diff["warp_cpu"] = max(float(np.abs(o.numpy().T - b).max()) for o, b in zip(outs_w, ref))
    except ImportError as e:
        out["skipped"]["warp_cpu"] = str(e)
    m = min(n, args.calls)

    def python(i: int) -> None:
        q = pkm.close_loops(mech, QM[i], Q0[i]).q
        pkm.forward_jacobian(mech, q)
        pkm.mass_matrix(mech, q)

    us["python"] = median_us(python, [(i,) for i in range(m)], m)
    out["ratio_python_to"] = {k: us["python"] / v for k, v in us.items() if k != "python"}
    out["goal_us"] = {"c_vector": GOAL_US}
    return out


def table(result: dict) -> str:
    if isinstance(result.get("skipped"), str):
        return f"transmissions: skipped ({result['skipped']})"
    lines = [f"{result['mechanism']}: fk_j_dm ({result['instructions']} instructions, {result['iterations']} Newton "
             f"iterations), {result['samples']} samples, statuses {result['status_counts']}",
             f"{'target':10s} {'us/sample':>10s} {'python/x':>10s} {'compile s':>10s} {'max diff':>10s}"]
    for k, v in result["us_per_sample"].items():
        r = result["ratio_python_to"].get(k, 1.0)
        c = result["compile_s"].get(k, float("nan"))
        d = result["largest_difference"].get(k, 0.0)
        lines.append(f"{k:10s} {v:10.4f} {r:10.1f} {c:10.2f} {d:10.1e}")
    lines += [f"{k}: skipped ({v})" for k, v in result["skipped"].items()]
    lines.append(f"goal: c_vector <= {GOAL_US} us a sample, {result['threads']} core(s)")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main("transmissions"))
