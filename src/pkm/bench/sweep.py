"""Design sweeps on Dask: one worker against two on this machine, against the in-process loop.

The case: ``--designs`` (2,048) 3-RRR designs drawn as scrambled Sobol' points (seed 0, recorded) over
``a, b`` in ``[20, 65] cm`` and ``h`` in ``[5, 50] cm`` (``H = 1 m``), each scored by its overall and area GCI on the
closed-form CI map at ``--step`` (1 cm: a coarse grid of about 20,000 nodes). Timed in the same run:

* ``local_1``, ``local_2``: a ``LocalCluster`` of 1 and 2 single-threaded worker processes (as ``pkm.sweep`` starts
  by default), the cluster's start timed apart from the sweep (``--clusters``: which; ``--quick`` starts the
  1-worker one alone, whose table must equal the serial one as well: no speedup then, and one worker process to
  start, not two);
* ``serial``: :func:`pkm.sweep` with ``scheduler="serial"``, the chunks evaluated one after the other in this
  process (no Dask; numpy's BLAS with its default threads): the baseline, and the table the others must equal.

Reported: wall times, the speedup of 2 workers over 1 (goal >= 1.7 on 2 cores), the scheduling overhead
``(workers x wall - work) / work`` (goal <= 5 %; ``work`` is the time the workers spent evaluating designs), the
per-design cost, each worker's peak resident memory, and what 10^6 designs would take at that cost.

Usage: ``python -m pkm.bench.sweep [--json] [--quick] [--designs 2048] [--step 0.01] [--clusters 1,2]``, or
``python tools/bench_sweep.py --json``.
"""

from __future__ import annotations

import resource
import time

from pkm._optional import require
from pkm.bench import main

QUICK = {"designs": 16, "step": 0.04, "clusters": "1"}
GOAL_SPEEDUP = 1.7
GOAL_OVERHEAD = 0.05


def add_arguments(ap) -> None:
    ap.add_argument("--designs", type=int, default=2048, help="3-RRR designs (Sobol' points; default 2048)")
    ap.add_argument("--step", type=float, default=0.01, help="CI map grid step [m] (default 0.01)")
    ap.add_argument("--clusters", default="1,2", choices=("1,2", "1", "2"),
                    help="the local clusters run: of 1 and of 2 workers (default 1,2), or one of them")


def _peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # (Linux: KiB)


def _space(n: int):
    from pkm import sweeps

    return sweeps.sobol(n, seed=0, a="20cm:65cm", b="20cm:65cm", h="5cm:50cm")


def run(args) -> dict:
    require("sweeps", "the sweep benchmark")
    from dask.distributed import Client

    import pkm
    from pkm.sweeps.engine import local_cluster

    objectives = [f"gci=gci:step={args.step!r}", f"gci_area=gci_area:step={args.step!r}"]
    out: dict = {"designs": args.designs, "step_m": args.step, "objectives": objectives,
                 "space": "Sobol' (seed 0): a, b in [0.20, 0.65] m, h in [0.05, 0.50] m, H = 1 m", "runs": {}}
    results = {}
    for n in (int(k) for k in args.clusters.split(",")):
        t0 = time.perf_counter()
        with local_cluster(n) as cluster, Client(cluster) as client:  # (both closed, whatever happens)
            started = time.perf_counter() - t0
            res = pkm.sweep("rrr3", _space(args.designs), objectives, client=client, progress=False)
            rss = client.run(_peak_rss_mb)
        st = res.stats
        results[n] = res
        out["runs"][f"local_{n}"] = {
            "workers": st.workers, "cluster_start_s": started, "data_to_workers_s": st.startup_seconds,
            "wall_s": st.wall_seconds, "work_s": st.work_seconds, "overhead": st.overhead, "chunks": st.chunks,
            "chunk_size": st.chunk_size, "peak_rss_mb_per_worker": sorted(rss.values())}
    # the baseline last: OpenBLAS's idle threads in this process spin for a while after use, taking a core from
    # workers started after it
    serial = pkm.sweep("rrr3", _space(args.designs), objectives, scheduler="serial", progress=False)
    out["runs"]["serial"] = {"workers": 1, "wall_s": serial.stats.wall_seconds, "work_s": serial.stats.work_seconds,
                             "chunks": serial.stats.chunks, "peak_rss_mb_per_worker": [_peak_rss_mb()]}
    for n, res in results.items():
        out["runs"][f"local_{n}"]["equals_serial"] = res.table.equals(serial.table)
    one, two = out["runs"].get("local_1"), out["runs"].get("local_2")  # (None: not run)
    per_design = (two or out["runs"]["serial"])["work_s"] / args.designs
    overhead = two["overhead"] if two else None
    out.update({
        "failed": serial.stats.failed,
        "speedup_2_over_1": one["wall_s"] / two["wall_s"] if one and two else None, "goal_speedup": GOAL_SPEEDUP,
        "overhead_2_workers": overhead, "goal_overhead": GOAL_OVERHEAD,
        "per_design_ms": per_design * 1e3,
        "one_million_designs_core_hours": per_design * 1e6 / 3600.0,
        "one_million_designs_hours_on_100_cores": per_design * 1e6 / 3600.0 / 100.0 * (1.0 + max(overhead or 0.0, 0.0)),
    })
    return out


def table(r: dict) -> str:
    lines = [f"{r['designs']} 3-RRR designs, {', '.join(r['objectives'])} ({r['failed']} failed)",
             f"{'run':9} {'workers':>7} {'start s':>8} {'wall s':>8} {'work s':>8} {'overhead':>9} {'chunks':>7} "
             f"{'peak MB/worker':>15} {'= serial':>8}"]
    for name, x in r["runs"].items():
        lines.append(f"{name:9} {x['workers']:7d} {x.get('cluster_start_s', 0.0):8.2f} {x['wall_s']:8.2f} "
                     f"{x['work_s']:8.2f} {x.get('overhead', float('nan')):9.1%} {x['chunks']:7d} "
                     f"{' '.join(f'{m:.0f}' for m in x['peak_rss_mb_per_worker']):>15} "
                     f"{x.get('equals_serial', '-')!s:>8}")
    speedup = "-" if r["speedup_2_over_1"] is None else f"{r['speedup_2_over_1']:.2f}"
    overhead = "-" if r["overhead_2_workers"] is None else f"{r['overhead_2_workers']:.1%}"
    lines.append(f"speedup 2 workers / 1: {speedup} (goal >= {r['goal_speedup']}); overhead "
                 f"{overhead} (goal <= {r['goal_overhead']:.0%}); {r['per_design_ms']:.2f} ms a "
                 f"design: 10^6 designs = {r['one_million_designs_core_hours']:.1f} core-hours")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main("sweep"))
