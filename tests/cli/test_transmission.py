"""``pkm transmission``: the folder a robot's software takes (C/C++, JAX, Warp), one a transmission, and what it
refuses as one error line."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm import cli
from tests.core.transmissions.robots import FILES

KNEE = FILES["humanoid_knee"]


def test_transmission_writes_every_target(tmp_path, capsys):
    assert cli.main(["transmission", str(KNEE), "--out", str(tmp_path), "--outputs", "left_knee=knee", "--serial",
                     "--around", "knee=0.3", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    serial = out["serial"]  # (--serial: the serial-equivalent model beside the kernels, its box about knee = 0.3)
    assert [Path(f).name for f in serial["files"]] == ["humanoid_knee_serial.urdf", "humanoid_knee_serial.xml",
                                                       "humanoid_knee_left_knee.urdf",
                                                       "humanoid_knee_left_knee.closures.toml",
                                                       "humanoid_knee_transmissions.json"]
    model = pin.buildModelFromUrdf(str(tmp_path / "humanoid_knee_serial.urdf"))
    lower, upper = serial["limits"]["knee"]
    assert 0.0 <= lower < 0.3 < upper <= 1.5 and 0.99 <= serial["area_fraction"]["left_knee"] <= 1.0
    assert [model.names[1], model.lowerPositionLimit[0], model.upperPositionLimit[0]] == ["knee", lower, upper]
    data = json.loads((tmp_path / "humanoid_knee_transmissions.json").read_text())
    assert data["transmissions"][0]["around"] == [0.3] and data["transmissions"][0]["lower"] == [lower]
    [t] = out["transmissions"]
    assert t["transmission"] == "left_knee" and t["motors"] == ["knee_motor"] and t["outputs"] == ["knee"]
    assert t["files"] == sorted(["left_knee.h", "left_knee.c", "left_knee_transmission.hpp", "example.cpp",
                                 "left_knee_jax.py", "left_knee_warp.py", "transmission.json", "README.md"])
    folder = tmp_path / "left_knee"
    described = json.loads((folder / "transmission.json").read_text())
    assert described["motors"] == ["knee_motor"] and described["kernels"]["delta"]["outputs"] == {
        "dM": 1, "dh": 1, "pivot": 1}
    assert "class LeftKneeTransmission" in (folder / "left_knee_transmission.hpp").read_text()
    assert "ros2_control is not installed" in (folder / "README.md").read_text()
    namespace: dict = {}
    exec(compile((folder / "left_knee_jax.py").read_text(), "left_knee_jax.py", "exec"), namespace)
    assert set(namespace) >= {"fk", "ik", "maps", "delta", "fk_j_dm", "functions"}
    if importlib.util.find_spec("jax") is not None:  # (the written module runs: the velocity map at the reference)
        from tests.core.transmissions.test_kernels import knee

        tk = knee()
        import jax

        fs, ref = namespace["functions"](), tk.mech.q_reference
        J = fs["maps"](ref)[0]
        assert abs(float(J[0]) - float(tk.run("maps", ref)[0][0])) <= 1e-12
        qm = tk.mech.actuated_q(ref) + 0.1  # (fk's loop and its derivative at the solution: J there)
        q, qo, status, _ = tk.run("fk", ref, qm)
        assert status[0] == 0 and np.abs(np.asarray(fs["fk"](ref, qm)[1]) - qo).max() <= 1e-12
        dqo = jax.jacfwd(lambda x: fs["fk"](ref, x)[1])(qm)
        assert abs(float(dqo[0, 0]) - float(tk.run("maps", q)[0][0])) <= 1e-12


def test_what_it_refuses_is_one_error_line(tmp_path, capsys):
    assert cli.main(["transmission", "rrr3", "--out", str(tmp_path), "--outputs", "x=nope", "--targets", "c"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "joint 'nope' does not exist in rrr3" in err[0]
    assert cli.main(["transmission", "rrr3", "--out", str(tmp_path), "--outputs", "x=elbow_1", "--targets", "c"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "transmission 'x'" in err[0], err
    assert cli.main(["transmission", str(KNEE), "--out", str(tmp_path), "--targets", "c,fortran"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--targets: choose among c, jax, warp" in err[0]
    assert cli.main(["transmission", str(KNEE), "--out", str(tmp_path), "--around", "knee=0.3"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--around" in err[0] and "add --serial" in err[0]
    assert cli.main(["transmission", str(KNEE), "--out", str(tmp_path), "--serial", "--around", "knee=x"]) == 1
    assert "expected JOINT=VALUE" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


def test_skip_unfit_writes_the_transmissions_of_a_robot_one_of_whose_loops_is_none(tmp_path, capsys):
    """MuJoCo Menagerie's Cassie, whose knee loops are no transmission (tests/test_menagerie_robots.py): with
    --skip-unfit its two foot four-bars are written, a warning naming each knee loop left out."""
    with pytest.warns(pkm.errors.PkmWarning, match="'right-tarsus'.*left out"):
        assert cli.main(["transmission", "menagerie:cassie", "--out", str(tmp_path), "--targets", "c",
                         "--skip-unfit", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert [(t["motors"], t["outputs"]) for t in out["transmissions"]] == [
        (["left-foot"], ["left-foot-crank"]), (["right-foot"], ["right-foot-crank"])]
    assert (tmp_path / "left-foot-crank" / "left_foot_crank.c").is_file()


def test_a_loop_that_is_no_transmission_names_skip_unfit(tmp_path, capsys):
    """Gepetto's cassie_like: its knee loop cannot be a transmission whatever its outputs; the refusal names
    --skip-unfit, which leaves it out (and the serial model then refuses to leave that loop open)."""
    robot = "gepetto:cassie_like"
    assert cli.main(["transmission", robot, "--out", str(tmp_path), "--targets", "c"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no choice of outputs" in err[0] and "--skip-unfit" in err[0]
    with pytest.warns(pkm.errors.PkmWarning, match="left out"):
        code = cli.main(["transmission", robot, "--out", str(tmp_path), "--targets", "c", "--skip-unfit", "--serial"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1 and len(err) == 1 and "closures ['loop2'] belong to no transmission" in err[0]
    assert not any(tmp_path.iterdir())  # (refused before anything is written)
