"""``pkm ik``: SI JSON equal to the paper's closed form; an unreachable pose names the leg."""

from __future__ import annotations

import json

import numpy as np

from pkm.mechanisms import delta as D
from tests.cli.helpers import one_error_line, run


def test_ik_prints_si_json_matching_the_closed_form():
    """``pkm ik delta --pose x=2cm z=-360mm --param R=120mm``: converged, SI, motors equal to the paper's IK."""
    proc = run("ik", "delta", "--pose", "x=2cm", "z=-360mm", "--param", "R=120mm", "--branch", "knee_out")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["units"]["length"] == "m" and out["units"]["angle"] == "rad"
    assert out["converged"] and out["residual"] < 1e-9 and out["branch"] == "knee_out"
    assert out["target"] == {"x": 0.02, "y": 0.0, "z": -0.36}
    assert np.allclose([out["task"][k] for k in "xyz"], [0.02, 0.0, -0.36], atol=1e-9)
    expected = D.inverse_kinematics(D.DeltaParams(R=0.12), [0.02, 0.0, -0.36], "knee_out")
    assert np.allclose(list(out["actuated"].values()), expected, atol=1e-8)
    assert out["joints"]["motor_1"] == out["actuated"]["motor_1"] and "knee_1" in out["joints"]


def test_ik_of_an_unreachable_pose_names_the_leg():
    """An unreachable pose exits 1 with one line naming the leg; with --debug the traceback comes first."""
    proc = run("ik", "delta", "--pose", "z=-1")
    assert proc.returncode == 1
    assert "pose unreachable: leg 1 misses by" in one_error_line(proc)
    debug = run("--debug", "ik", "delta", "--pose", "z=-1")
    assert debug.returncode == 1 and debug.stderr.startswith("Traceback")
    assert "UnreachableError" in debug.stderr and debug.stderr.strip().splitlines()[-1].startswith("pkm: error: pose")
