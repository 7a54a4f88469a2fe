"""``pkm calibrate plan`` and ``pkm calibrate``: the 3-PRS calibrated end to end from the command line (poses chosen,
measurements simulated on a perturbed robot, the estimate, the calibrated spec written and loaded back, the residual
figure), in process; bad input as one error line."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import pkm
from pkm import cli

ROOT = Path(__file__).resolve().parents[2]


def test_plan_simulate_calibrate_write_load(tmp_path, capsys) -> None:
    pytest.importorskip("matplotlib")
    data = tmp_path / "data.csv"
    assert cli.main(["calibrate", "plan", "prs3", "--poses", "12", "--out", str(data),  # (the default spread)
                     "--simulate", "3"]) == 0
    assert "12 poses" in capsys.readouterr().out
    out = tmp_path / "out"
    assert cli.main(["calibrate", "prs3", str(data), "--out", str(out), "--plot", str(tmp_path / "r.png"),
                     "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["base"] == 34 and result["before"]["position_rms"] > 1e-3
    assert result["after"]["position_rms"] < 3e-5 and 0.3 < result["chi2"] < 3.0 and result["evaluations"] < 100
    assert pkm.load(result["spec"]).name == "prs3" and (tmp_path / "r.png").stat().st_size > 1000
    assert "knee_1.pitch" in result["unseen"]


def test_bad_table_is_one_error_line(tmp_path, capsys) -> None:
    table = tmp_path / "bad.csv"
    rows = ["m.slider_1,m.slider_2,m.slider_3,x,y,z,roll,pitch,yaw"]
    rows += [",".join(map(str, [0.13, 0.13, 0.13, 0.0, 0.0, 0.7, 0.0, 0.0, 0.0]))] * 3
    rows.append(",".join(map(str, [0.13, 0.13, 0.13, 0.0, 0.0, 700.0, 0.0, 0.0, 0.0])))
    table.write_text("\n".join(rows) + "\n")
    assert cli.main(["calibrate", "prs3", str(table), "--out", str(tmp_path / "o")]) != 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("pkm: error: ") and "row 4, column 'z'" in err[0] and "mm" in err[0]


def test_the_budget_and_the_spread_are_options_whose_help_states_the_defaults(capsys) -> None:
    """Issue 52: the least squares' budget (a fixed 200) could not be reached from the command line."""
    from pkm.core.calibration.estimate import NFEV_PER_PARAMETER
    from pkm.core.calibration.poses import SPREAD

    for argv in (["calibrate", "--help"], ["calibrate", "plan", "--help"]):
        assert cli.main(argv) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert f"--max-evaluations N the least squares' budget of residual evaluations (default {NFEV_PER_PARAMETER} " in text
    assert f"(default {SPREAD:g} rad for a revolute actuator, {SPREAD:g} x the mechanism's characteristic" in text


def test_a_model_the_mechanism_cannot_measure_names_the_option(tmp_path, capsys) -> None:
    """The humanoid ankle has no end effector: ``--model pose`` (the default) is refused naming ``--model passive``,
    the option of the command line (the library's message names ``kind='passive'``)."""
    assert cli.main(["calibrate", "plan", str(ROOT / "examples/humanoid_ankle/ankle.closures.toml"), "--poses", "5",
                     "--out", str(tmp_path / "d.csv")]) == 1
    err = capsys.readouterr().err
    assert "use --model passive with encoders on passive joints" in err and "kind=" not in err, err


def test_a_pose_the_simulated_robot_does_not_reach_is_left_out_with_a_warning(tmp_path, capsys, monkeypatch) -> None:
    """Issue 52: ``pkm calibrate plan hexapod --simulate 1`` failed where the perturbed robot did not reach an
    O1-chosen pose. A 3-PRS perturbed by 1 cm and 1 degree stands in (the hexapod's plan takes 10 s): the pose it
    does not reach is said, left out and replaced, and the table holds the 12 poses asked for (each measured on
    that robot: ``simulate`` refuses a pose it does not reach)."""
    from pkm.core.calibration import estimate

    far = estimate.perturbed
    monkeypatch.setattr(estimate, "perturbed", lambda model, seed=0: far(model, seed, length=0.01, angle=0.02))
    data = tmp_path / "data.csv"
    with pytest.warns(pkm.errors.PkmWarning, match=r"the robot does not reach 1 of the 13 poses"):
        assert cli.main(["calibrate", "plan", "prs3", "--poses", "12", "--out", str(data), "--simulate", "4"]) == 0
    assert "12 poses of 48 candidates (1 more left out: the perturbed robot does not reach them)" in \
        capsys.readouterr().out
    assert len(data.read_text().splitlines()) == 13
