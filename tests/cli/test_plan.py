"""``pkm plan``: the trajectory written, the cycle time printed as pkm.time_optimal returns it, bad input refused."""

from __future__ import annotations

import csv

from tests.cli.helpers import one_error_line, run


def test_plan_writes_the_trajectory_and_prints_the_cycle_time(tmp_path):
    out = tmp_path / "plan.csv"
    proc = run("plan", "delta", "--path", "adept:-0.1525,0,-0.33", "--points", "30", "--out", str(out), "--json")
    assert proc.returncode == 0, proc.stderr
    import json

    summary = json.loads(proc.stdout)
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 30 and float(rows[-1]["t"]) == summary["cycle_time_s"]
    bad = run("plan", "delta", "--path", "adept:0,0,-0.5", "--points", "30", "--out", str(out))
    assert "workspace" in one_error_line(bad) and "path point 0" in bad.stderr
