"""``pkm plan``: the trajectory written, the cycle time printed as pkm.time_optimal returns it, bad input refused."""

from __future__ import annotations

import csv
import json

import numpy as np

import pkm
from pkm import cli
from pkm.motion import load_motions


def test_plan_writes_the_trajectory_and_prints_the_cycle_time(tmp_path, capsys):
    out = tmp_path / "plan.csv"
    argv = ["plan", "delta", "--path", "adept:-0.1525,0,-0.33", "--points", "30", "--out", str(out)]
    assert cli.main([*argv, "--json"]) == 0, capsys.readouterr().err
    summary = json.loads(capsys.readouterr().out)
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 30 and float(rows[-1]["t"]) == summary["cycle_time_s"]
    assert sum(summary["active_segments"].values()) == 29
    motion = load_motions(summary["written"]["motion"])["plan"]  # (the motors' motion, read back)
    t = np.array([float(r["t"]) for r in rows])
    qa = np.array([[float(r[f"motor_{i}"]) for i in (1, 2, 3)] for r in rows])
    assert motion.space == "actuated" and np.abs(motion.sample(t)[1] - qa).max() <= 1e-12
    status = cli.main(["plan", "delta", "--path", "adept:0,0,-0.5", "--points", "30", "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert status != 0 and err.startswith("pkm: error: path point 0") and "workspace" in err
    assert len(err.splitlines()) == 1


def test_the_path_point_and_the_payload_take_units(tmp_path, capsys):
    """``adept:X,Y,Z`` takes lengths (``-33cm``) and ``--payload`` a mass (``500g``), as every value of the command
    line does: a unit of another kind is refused before any planning, naming it."""
    from pkm.cli.commands.plan import read_path

    mech = pkm.load("delta")
    (with_units, _), (si, _) = read_path(mech, "adept:-15.25cm,0mm,-33cm"), read_path(mech, "adept:-0.1525,0,-0.33")
    assert np.allclose(np.asarray(with_units), np.asarray(si), rtol=1e-15, atol=0)
    out = str(tmp_path / "plan.csv")
    for argv, says in ((["--path", "adept:0,0,-5deg"], "'deg' is an angle unit"),
                       (["--path", "adept:0,0,-0.33", "--payload", "5mm"], "'mm' is a length unit but --payload")):
        assert cli.main(["plan", "delta", *argv, "--out", out]) != 0
        assert says in capsys.readouterr().err
