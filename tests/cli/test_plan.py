"""``pkm plan``: the trajectory written, the cycle time printed as pkm.time_optimal returns it, bad input refused."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

import pkm
from pkm import cli
from pkm.motion import load_motions

ANKLE = Path(__file__).resolve().parents[2] / "examples" / "humanoid_ankle" / "ankle.closures.toml"


def test_plan_writes_the_trajectory_and_prints_the_cycle_time(tmp_path, capsys):
    out = tmp_path / "plan.csv"
    argv = ["plan", "delta", "--path", "adept:-0.1525,0,-0.33", "--points", "30", "--out", str(out)]
    assert cli.main([*argv, "--json"]) == 0, capsys.readouterr().err
    summary = json.loads(capsys.readouterr().out)
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 30 and float(rows[-1]["t"]) == summary["cycle_time_s"]
    assert sum(summary["active_segments"].values()) + summary["switch_segments"] == 29
    assert summary["switch_segments"] <= 2  # (the law's switches: TimeOptimal.inactive)
    motion = load_motions(summary["written"]["motion"])["plan"]  # (the motors' motion, read back)
    t = np.array([float(r["t"]) for r in rows])
    qa = np.array([[float(r[f"motor_{i}"]) for i in (1, 2, 3)] for r in rows])
    assert motion.space == "actuated" and np.abs(motion.sample(t)[1] - qa).max() <= 1e-12
    status = cli.main(["plan", "delta", "--path", "adept:0,0,-0.5", "--points", "30", "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert status != 0 and err.startswith("pkm: error: path point 0") and "workspace" in err
    assert len(err.splitlines()) == 1


def test_a_path_across_position_limits_exits_non_zero_naming_the_joint(tmp_path, capsys):
    """The humanoid ankle's pitch to 0.8 rad (range +-0.6; the motors to 1.047 rad, range +-1): one error line
    naming the check point, the joint, its value and its limits; nothing written."""
    path = tmp_path / "p.csv"
    path.write_text("ankle_pitch,ankle_roll\n0,0\n0.4,0\n0.8,0\n")
    out = tmp_path / "o.csv"
    status = cli.main(["plan", str(ANKLE), "--path", str(path), "--points", "12", "--out", str(out)])
    err = capsys.readouterr().err.strip()
    assert status == 1 and len(err.splitlines()) == 1 and not out.exists()
    assert err.startswith("pkm: error: segment 8 (s = 0.772727): position limit of ankle_pitch: ankle_pitch = "
                          "0.618182 rad, outside its limits [-0.6, 0.6] rad")


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


def test_a_path_csv_names_a_pose_as_pose_does(tmp_path):
    """A Gough-Stewart path headed ``x,y,z,roll,pitch,yaw`` (as ``--pose`` and ``pkm list`` name the task) reads as
    the same waypoints headed with the task's values ``x,y,z,qx,qy,qz,qw`` (the quaternions of those angles)."""
    from pkm.cli.commands.plan import read_path

    mech = pkm.load("gough_stewart")
    task = pkm.TaskMap.of(mech)
    poses = [task.named(mech.q_reference), dict(task.named(mech.q_reference), x=0.01, roll=0.05)]
    values = [task.parse(p) for p in poses]
    for name, header, rows in (("named.csv", task.keys, [[p[k] for k in task.keys] for p in poses]),
                               ("values.csv", task.value_names, values)):
        (tmp_path / name).write_text(",".join(header) + "\n" + "\n".join(",".join(map(repr, map(float, r)))
                                                                           for r in rows) + "\n")
    (named, space), (given, space_given) = read_path(mech, str(tmp_path / "named.csv")), read_path(
        mech, str(tmp_path / "values.csv"))
    assert space == space_given == "task" and task.keys != task.value_names
    assert np.allclose(named, given, rtol=0, atol=1e-15)
    assert not np.allclose(named[1, 3:], named[0, 3:])  # (the roll of the second waypoint is in its quaternion)
