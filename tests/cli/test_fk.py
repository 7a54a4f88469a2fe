"""``pkm fk``: the pose of the paper's forward kinematics; ``--all`` (with ``ik --all``): every mode."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from pkm.mechanisms import delta as D
from tests.cli.helpers import run


def test_fk_prints_the_pose_of_the_closed_form():
    """``pkm fk delta --joints motor_1=-50deg``: the platform position equals the paper's sphere intersection."""
    proc = run("fk", "delta", "--joints", "motor_1=-50deg")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    qa = list(out["actuated"].values())
    assert math.isclose(qa[0], math.radians(-50), rel_tol=1e-12) and out["converged"]
    assert np.allclose([out["task"][k] for k in "xyz"], D.forward_kinematics(D.DeltaParams(), qa), atol=1e-9)


def test_fk_and_ik_all_print_every_mode_and_the_sets_account():
    """``pkm fk --all`` / ``pkm ik --all``: every mode (homotopy continuation) with the set's account, SI."""
    pytest.importorskip("bertini")
    fk = json.loads(run("fk", "delta", "--joints", "motor_1=0.1", "--all").stdout)
    assert fk["complete"] and fk["paths"] == 8 and len(fk["modes"]) == 2 and not fk["failed"]
    assert {round(m["actuated"]["motor_1"], 12) for m in fk["modes"]} == {0.1}
    # (the other solutions read as what they are, not as an error; the counts those of the JSON's fields)
    assert fk["summary"].startswith("2 real assembly mode(s); the polynomial system's other solutions, which are no "
                                    f"assembly mode: {fk['complex']} complex, {fk['exceptional']} exceptional")
    ik = json.loads(run("ik", "prs3", "--pose", "z=90cm", "pitch=3deg", "--all").stdout)
    assert ik["complete"] and len(ik["modes"]) == 8
    assert all(abs(m["task"]["z"] - 0.9) < 1e-9 for m in ik["modes"])
