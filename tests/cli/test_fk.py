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
    assert all(m["interferes"] == (m["clearance"] < 0.0) for m in ik["modes"])  # (its links' collision geometry)


def test_ik_all_says_which_modes_interfere(capsys):
    """``pkm ik gough_stewart --all`` at the reference pose (its legs written as capsules): each mode's clearance and
    whether it interferes, the library's (1e-12 m: the pose read back from its angles), in process."""
    import pkm
    from pkm import cli

    pytest.importorskip("bertini")
    assert cli.main(["ik", "gough_stewart", "--pose", "x=0", "--all"]) == 0
    modes = json.loads(capsys.readouterr().out)["modes"]
    gs = pkm.load("gough_stewart")
    expected = pkm.working_modes(gs, pkm.TaskMap.of(gs).value(gs.q_reference))
    assert all(m["interferes"] == (m["clearance"] < 0.0) for m in modes)
    np.testing.assert_allclose(sorted(m["clearance"] for m in modes), sorted(m.clearance for m in expected), rtol=0,
                               atol=1e-12)  # (as sets: modes equally far from the reference come in either order)
    assert 0 < sum(m["interferes"] for m in modes) < len(modes) == 64
