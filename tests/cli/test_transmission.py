"""``pkm transmission``: the folder a robot's software takes (C/C++, JAX, Warp), and a mechanism whose outputs it
cannot tell as one error line."""

from __future__ import annotations

import json

from pkm import cli
from tests.core.transmissions.test_kernels import KNEE


def test_transmission_writes_every_target(tmp_path, capsys):
    assert cli.main(["transmission", str(KNEE), "--out", str(tmp_path), "--name", "left_knee", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["motors"] == ["knee_motor"] and out["outputs"] == ["knee"]
    assert {f.rsplit("/", 1)[-1] for f in out["files"]} == {
        "left_knee.h", "left_knee.c", "left_knee_transmission.hpp", "example.cpp", "left_knee_jax.py",
        "left_knee_warp.py", "transmission.json", "README.md"}
    described = json.loads((tmp_path / "transmission.json").read_text())
    assert described["serial_joints"] == ["knee"] and described["kernels"]["delta"]["outputs"] == {
        "dM": 1, "dh": 1, "pivot": 1}
    assert "class LeftKneeTransmission" in (tmp_path / "left_knee_transmission.hpp").read_text()
    assert "ros2_control is not installed" in (tmp_path / "README.md").read_text()
    namespace: dict = {}
    exec(compile((tmp_path / "left_knee_jax.py").read_text(), "left_knee_jax.py", "exec"), namespace)
    assert set(namespace) >= {"fk", "ik", "maps", "delta", "fk_j_dm", "functions"}


def test_outputs_it_cannot_tell_are_one_error_line(tmp_path, capsys):
    assert cli.main(["transmission", "delta", "--out", str(tmp_path), "--targets", "c"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--outputs: delta's task is not a set of output joints" in err[0]
    assert cli.main(["transmission", str(KNEE), "--out", str(tmp_path), "--targets", "c,fortran"]) == 1
    assert "targets: choose among c, jax, warp" in capsys.readouterr().err
