"""``pkm bench``: one benchmark, all of them quick, and the arguments after ``--``."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pkm import bench
from pkm.bench import NAMES as BENCHMARKS
from pkm.mechanisms import names
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


#: What a quick run of a benchmark must show beyond running (its JSON, as ``pkm bench --quick --json`` prints it).
CHECKS = {
    "batch": lambda r: r["mechanisms"]["prs3"]["bit_for_bit"],
    "designs": lambda r: r["gough_stewart"]["largest_difference"] <= 1e-12,
    "sweep": lambda r: len(r["runs"]) > 1 and all(v["equals_serial"] for k, v in r["runs"].items() if k != "serial"),
    "kinematics": lambda r: [row["mechanism"] for row in r] == list(names()) and {row["samples"] for row in r} == {3},
    "workspace": lambda r: r[0]["generic_reach_agrees"] and all(
        c["sample_reach_agrees"] and c["sample_max_ci_difference"] <= 1e-9 for c in r) and max(
        r[0]["generic_max_ci_difference"], r[1]["generic_gci_difference"]) <= 1e-9,
    "dynamics": lambda r: r["max_force_difference_to_baseline_N"]["pkm"] < 1e-9,
    "stiffness": lambda r: r["max_relative_difference"] < 1e-9 and r["map"]["with_stiffness"] > 0,
    "clearance": lambda r: r["max_difference_m"] <= 1e-9 and r["map"]["within_limits"] > 0,
    "time_optimal": lambda r: abs(r["cycle_time_s"] - r["cycle_time_core_s"]) <= 1e-6 and (
        "skipped" in r["ankle"] or (r["ankle"]["holds"] and r["ankle"]["labels_equal"]
                                    and r["ankle"]["efforts_difference"] <= 1e-10
                                    and r["ankle"]["route"].startswith("kernels"))),
}


#: Benchmarks whose quick run a test module of their own makes, its result JSON-ready and checked further than
#: :data:`CHECKS` could: not run a second time here.
OWN_TESTS = {"simulation": "tests/bench/test_simulation.py", "simulation_speed": "tests/bench/test_simulation_speed.py"}


def test_bench_lists_every_benchmark_module():
    assert sorted(BENCHMARKS) == ["assembly", "batch", "clearance", "designs", "dynamics", "export", "hexapod", "identification",
                                  "kinematics", "opcount", "serve", "simulation", "simulation_speed", "stiffness",
                                  "sweep", "time_optimal", "transmissions", "twin", "workspace"]
    assert set(CHECKS) <= set(BENCHMARKS) - set(OWN_TESTS) and set(OWN_TESTS) <= set(BENCHMARKS)
    root = Path(__file__).resolve().parents[2]
    for name, path in OWN_TESTS.items():  # (each runs it quick and round-trips its result through JSON)
        text = (root / path).read_text()
        assert f"arguments({name}" in text and "quick=True" in text and "json.loads(json.dumps(" in text, path


@pytest.mark.parametrize("name", [n for n in BENCHMARKS if n not in OWN_TESTS])
def test_each_benchmark_runs_quick(name):
    """What ``pkm bench --quick`` runs, one benchmark a test, in this process (the suite's workers share them, their
    imports and compiled kernels; ``pkm bench --quick`` itself runs from the installed wheel in CI: .ci/wheel):
    the JSON-ready result of its quick sizes, and the checks of :data:`CHECKS` (those of :data:`OWN_TESTS`: there)."""
    mod = bench.module(name)
    result = json.loads(json.dumps(mod.run(bench.arguments(mod, quick=True))))
    assert result and mod.table(result)
    assert CHECKS.get(name, bool)(result), result


def test_bench_refuses_arguments_a_benchmark_does_not_take():
    bad = run("bench", "kinematics", "--", "--samples", "3")
    assert bad.returncode == 2 and "unrecognized arguments: --samples" in one_error_line(bad)
