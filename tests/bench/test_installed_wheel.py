"""The benchmarks an installed wheel cannot run say so and why, as the wheel's ``pkm bench --quick`` shows (.ci/wheel:
its environment has only the sweeps and figures extras, and no examples/ folder)."""

from __future__ import annotations

import sys
import types

from pkm.bench import time_optimal, transmissions


def test_time_optimal_without_toppra_is_skipped_naming_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "toppra", None)  # (blocked: pkm._optional counts it missing)
    result = time_optimal.run(types.SimpleNamespace(n=10, repeat=1))
    assert result == {"skipped": 'pip install "pkm-robotics[plan]" (missing: toppra)'}
    assert time_optimal.table(result) == f"time-optimal planning: skipped ({result['skipped']})"


def test_transmissions_without_the_examples_folder_is_skipped(monkeypatch, tmp_path):
    monkeypatch.setattr(transmissions, "_root", lambda: str(tmp_path))
    result = transmissions.run(types.SimpleNamespace(mechanism="ankle", iterations=3, n=10, threads=1, repeat=1,
                                                     calls=5))
    assert result == {"skipped": "examples/ absent (an installed wheel)"}
    assert transmissions.table(result) == "transmissions: skipped (examples/ absent (an installed wheel))"
