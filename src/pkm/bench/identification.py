"""Identification's costs: the regressor of long trajectories in C against Python, and the second rank route.

* **Regressor**: ``pkm.regressor_batch`` over ``--samples`` states (default 10⁵, the hexapod: 7 x 248 columns, 1.4
  GB) through the compiled twin (``backend="c"``: every core), timed twice: the first call, which pays for its
  output's pages, and a second, warm one; against the Python route (:func:`pkm.regressor` per sample) timed on
  ``--python-samples`` of the same states and scaled to the batch (the ratio says how many times faster C is).
  The two agree to the stated relative difference on those samples.
* **Base parameters**: :func:`pkm.base_parameters` of the same mechanism in double precision only (drawing and
  closing the random states: most of it), then again with the 50-digit second route (the states kept).
* **End to end, the Delta**: an optimal excitation (``--iterations`` SLSQP iterations), its table written (two
  periods at 500 Hz), noise added (1e-4 rad, 1 % of each effort's range), read back through the filter, the base
  parameters (both routes) and Gautier's estimate: the issue asks 30 s at most. (Where ``--mechanism`` is the Delta,
  as in ``--quick``, the same Delta: its kernels built already.)

Compiling the kernel is timed apart (once per mechanism and machine: cached on disk).
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np

import pkm
from pkm.bench import best_time

QUICK = {"mechanism": "delta", "samples": 1000, "python_samples": 5, "no_base": True, "iterations": 1}


def add_arguments(ap: argparse.ArgumentParser) -> None:
    ap.add_argument("--mechanism", default="hexapod", help="a registered mechanism (default hexapod)")
    ap.add_argument("--samples", type=int, default=100_000, help="states of the C batch (default 10^5)")
    ap.add_argument("--python-samples", type=int, default=200, help="states timed in Python (default 200)")
    ap.add_argument("--no-base", action="store_true", help="skip the base parameters' timing")
    ap.add_argument("--iterations", type=int, default=60, help="SLSQP iterations of the end-to-end excitation")


def run(args: argparse.Namespace) -> dict[str, Any]:
    from pkm.core.identification.base import random_states
    from pkm.core.identification.regressor import _kernels, regressor, regressor_batch

    mech = pkm.load(args.mechanism)
    t0 = time.perf_counter()
    kernels = _kernels(mech)
    compile_s = time.perf_counter() - t0
    states = random_states(mech, 50, seed=0)
    idx = np.arange(args.samples) % len(states)
    Q, QD, QDD = (np.array([s[i] for s in states])[idx] for i in range(3))
    out: dict[str, Any] = {"mechanism": args.mechanism, "samples": args.samples, "na": mech.na,
                           "parameters": len(pkm.parameters(mech)), "compile_s": compile_s,
                           "c": kernels.how if kernels is not None else None}
    if kernels is not None:
        t0 = time.perf_counter()
        Y = regressor_batch(mech, Q, QD, QDD, backend="c")
        out["c_first_s"] = time.perf_counter() - t0
        del Y
        out["c_warm_s"], Y = best_time(lambda: regressor_batch(mech, Q, QD, QDD, backend="c"), 1)
        out["output_gb"] = Y.nbytes / 1e9
        m = args.python_samples
        python_s, Yp = best_time(lambda: np.vstack([regressor(mech, *s) for s in zip(Q[:m], QD[:m], QDD[:m])]), 1)
        out["python_per_sample_us"] = 1e6 * python_s / m
        out["python_batch_s"] = python_s / m * args.samples
        out["ratio_python_over_c_warm"] = out["python_batch_s"] / out["c_warm_s"]
        out["max_relative_difference"] = float(np.abs(Y[:m * mech.na] - Yp).max() / np.abs(Yp).max())
        del Y
    out.update(end_to_end(args.iterations, mech if args.mechanism == "delta" else None))
    if not args.no_base:
        out["base_double_s"], b = best_time(lambda: pkm.base_parameters(mech, precise=False), 1)
        out["base_both_routes_s"], b = best_time(lambda: pkm.base_parameters(mech), 1)
        out["n_base"], out["routes_agree"] = len(b), b.routes_agree
    return out


def end_to_end(iterations: int, delta: pkm.Mechanism | None = None) -> dict[str, Any]:
    """The Delta from excitation to estimate (module doc), timed by stage [s]: ``delta``, the one the regressor's
    timing took (its kernels built), or loaded here."""
    import tempfile
    from pathlib import Path

    from pkm.core.identification.excitation import write_csv
    from pkm.core.identification.measurements import read_table

    t0 = time.perf_counter()
    delta = pkm.load("delta") if delta is None else delta
    e = pkm.excite(delta, max_iter=iterations)
    t1 = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        cols = read_table(write_csv(delta, e, str(Path(folder) / "run.csv"), periods=2, dt=0.002))
    rng = np.random.default_rng(0)
    for j in delta.actuated_names:
        cols[f"q.{j}"] = cols[f"q.{j}"] + 1e-4 * rng.standard_normal(len(cols["time"]))
        cols[f"tau.{j}"] = cols[f"tau.{j}"] + 0.01 * np.ptp(cols[f"tau.{j}"]) * rng.standard_normal(len(cols["time"]))
    t2 = time.perf_counter()
    data = pkm.measurements(delta, cols, cutoff=2.0)
    base = pkm.base_parameters(delta)
    est = pkm.estimate(delta, data.Q, data.QD, data.QDD, data.TAU, base=base)
    t3 = time.perf_counter()
    z = (est.values - base.values) / est.std
    return {"e2e_excite_s": t1 - t0, "e2e_table_s": t2 - t1, "e2e_estimate_s": t3 - t2, "e2e_total_s": t3 - t0,
            "e2e_condition": e.condition, "e2e_largest_z": float(np.abs(z).max())}


def table(r: dict[str, Any]) -> str:
    lines = [f"identification: {r['mechanism']}, {r['na']} actuators, {r['parameters']} parameters"]
    if r.get("c") is None:
        lines.append("  no compiled regressor (no C compiler, or a mechanism the twin cannot build)")
    else:
        lines += [f"  compile (or load from the cache)  {r['compile_s']:8.2f} s",
                  f"  regressor, {r['samples']} samples ({r['output_gb']:.2f} GB)",
                  f"    C, first call                  {r['c_first_s']:8.3f} s",
                  f"    C, warm                        {r['c_warm_s']:8.3f} s",
                  f"    Python (scaled from a subset)  {r['python_batch_s']:8.3f} s "
                  f"({r['python_per_sample_us']:.0f} us a sample)",
                  f"    ratio Python / C warm          {r['ratio_python_over_c_warm']:8.1f}",
                  f"    largest relative difference    {r['max_relative_difference']:8.1e}"]
    lines += [f"  end to end, the Delta: {r['e2e_total_s']:.2f} s (excitation {r['e2e_excite_s']:.2f}, table "
              f"{r['e2e_table_s']:.2f}, filter + base parameters + estimate {r['e2e_estimate_s']:.2f}); condition "
              f"number {r['e2e_condition']:.3g}, largest error {r['e2e_largest_z']:.2f} deviations"]
    if "n_base" in r:
        lines += [f"  base parameters: {r['n_base']} (routes agree: {r['routes_agree']})",
                  f"    double precision only          {r['base_double_s']:8.2f} s",
                  f"    again with the 50-digit route  {r['base_both_routes_s']:8.2f} s (the random states kept)"]
    return "\n".join(lines)


if __name__ == "__main__":
    from pkm.bench import main

    raise SystemExit(main("identification"))
