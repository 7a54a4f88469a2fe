"""pkm.bench.sweep without a cluster: its design space (Sobol', seed 0, the stated bounds), its memory probe, its
options, and its table written from a result of the shape ``run`` returns. (``tests/cli/test_bench.py`` runs it
quick.)"""

from __future__ import annotations

import numpy as np

from pkm.bench import arguments
from pkm.bench import sweep as bench_sweep
from pkm.sweeps.family import RegisteredFamily


def test_the_space_is_the_stated_sobol_draw():
    """n 3-RRR designs, a and b in [0.20, 0.65] m, h in [0.05, 0.50] m, seed 0 recorded: the same draw twice."""
    family = RegisteredFamily("rrr3")
    designs = bench_sweep._space(16).designs(family.units)
    assert designs.names == ("a", "b", "h") and len(designs) == 16 and designs.seed == 0
    lo, hi = designs.values.min(axis=0), designs.values.max(axis=0)
    assert np.all(lo >= [0.20, 0.20, 0.05]) and np.all(hi <= [0.65, 0.65, 0.50])
    np.testing.assert_array_equal(bench_sweep._space(16).designs(family.units).values, designs.values)


def test_the_peak_memory_is_in_megabytes():
    """ru_maxrss (KiB on Linux) / 1024: this Python process holds tens of MB, not bytes nor GB-sized numbers."""
    assert 10.0 < bench_sweep._peak_rss_mb() < 100_000.0


def test_options_and_quick_sizes():
    """2048 designs at a 1 cm step on clusters of 1 and 2 workers by default; --quick 16 at 4 cm on the 1-worker one;
    the goals are 1.7 (speedup) and 5 % (overhead)."""
    full = arguments(bench_sweep, [])
    assert (full.designs, full.step, full.clusters) == (2048, 0.01, "1,2")
    quick = arguments(bench_sweep, ["--quick"])
    assert (quick.designs, quick.step, quick.clusters) == (16, 0.04, "1")
    assert (bench_sweep.GOAL_SPEEDUP, bench_sweep.GOAL_OVERHEAD) == (1.7, 0.05)


def test_the_table_has_a_line_per_run_and_the_verdict():
    """One line per run (the serial baseline without start time or overhead), then the speedup, overhead and cost."""
    run = {"workers": 1, "cluster_start_s": 1.0, "wall_s": 10.0, "work_s": 9.5, "overhead": 0.05, "chunks": 32,
           "peak_rss_mb_per_worker": [150.0], "equals_serial": True}
    result = {"designs": 64, "objectives": ["gci=gci:step=0.04"], "failed": 0,
              "runs": {"local_1": run, "local_2": {**run, "workers": 2, "wall_s": 5.5, "peak_rss_mb_per_worker":
                                                  [140.0, 150.0]},
                       "serial": {"workers": 1, "wall_s": 9.0, "work_s": 9.0, "chunks": 2,
                                  "peak_rss_mb_per_worker": [300.0]}},
              "speedup_2_over_1": 10.0 / 5.5, "goal_speedup": 1.7, "overhead_2_workers": 0.05, "goal_overhead": 0.05,
              "per_design_ms": 148.4, "one_million_designs_core_hours": 41.2}
    lines = bench_sweep.table(result).splitlines()
    assert lines[0] == "64 3-RRR designs, gci=gci:step=0.04 (0 failed)"
    assert [ln.split()[0] for ln in lines[2:5]] == ["local_1", "local_2", "serial"]
    assert lines[3].split()[-3:] == ["140", "150", "True"] and lines[4].split()[-2:] == ["300", "-"]
    assert "nan" in lines[4] and lines[-1].startswith("speedup 2 workers / 1: 1.82 (goal >= 1.7); overhead 5.0%")
    del result["runs"]["local_1"]  # (--clusters 2, as --quick: no speedup)
    assert bench_sweep.table({**result, "speedup_2_over_1": None}).splitlines()[-1].startswith(
        "speedup 2 workers / 1: - (goal >= 1.7); overhead 5.0%")
