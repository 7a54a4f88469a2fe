"""``pkm bench``: one benchmark, all of them quick, and the arguments after ``--``."""

from __future__ import annotations

import json

from pkm.bench import NAMES as BENCHMARKS
from tests.cli.helpers import one_error_line, run


def test_bench_runs_a_benchmark_and_refuses_an_unknown_one(tmp_path):
    """``pkm bench opcount --json`` (about 2 s) prints its JSON under its name, from any directory; an unknown
    benchmark exits 2 listing them."""
    proc = run("bench", "opcount", "--json", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert list(out) == ["opcount"] and out["opcount"]
    bad = run("bench", "speed")
    line = one_error_line(bad)
    assert bad.returncode == 2 and ", ".join(repr(n) for n in BENCHMARKS) in line


def test_bench_quick_runs_every_benchmark_and_refuses_bad_arguments(tmp_path):
    """``pkm bench --quick --json`` runs every one (shipped in the package, so from any directory) with small
    sizes; arguments a benchmark does not take exit 2 with one line."""
    proc = run("bench", "--quick", "--json", cwd=tmp_path, cpu=400)  # (44 s of CPU alone)
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert sorted(out) == sorted(BENCHMARKS) == ["assembly", "batch", "designs", "dynamics", "export", "hexapod",
                                                 "identification", "kinematics", "opcount", "serve", "simulation",
                                                 "simulation_speed", "sweep", "time_optimal", "transmissions", "twin", "workspace"]
    assert out["batch"]["mechanisms"]["prs3"]["bit_for_bit"]
    assert out["designs"]["gough_stewart"]["largest_difference"] <= 1e-12
    assert all(r["equals_serial"] for k, r in out["sweep"]["runs"].items() if k != "serial")
    assert [r["samples"] for r in out["kinematics"]] == [3] * 5  # one row per shipped mechanism
    assert out["dynamics"]["max_force_difference_to_baseline_N"]["pkm"] < 1e-9
    assert abs(out["time_optimal"]["cycle_time_s"] - out["time_optimal"]["cycle_time_core_s"]) <= 1e-6
    bad = run("bench", "kinematics", "--", "--samples", "3")
    assert bad.returncode == 2 and "unrecognized arguments: --samples" in one_error_line(bad)
