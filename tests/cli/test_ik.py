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


def test_the_seed_the_solvers_suggest_is_an_option(capsys):
    """The solvers' messages suggest a seed nearer the target (``q0``): ``--q0 NAME=V`` sets any joint of the
    seed, passive ones included (units allowed), in ``pkm ik`` and ``pkm fk``; the answer is the library's from
    that seed (here the 3-RRR's leg 2 in its other elbow), and a joint that is not one is named."""
    import math

    import pkm
    from pkm import cli

    mech = pkm.load("rrr3")
    elbow = mech.joints["elbow_2"].idx_q
    q0 = mech.q_reference.copy()
    q0[elbow] = -q0[elbow]
    pose = ["x=50cm", "y=28.87cm", "yaw=5deg"]
    assert cli.main(["ik", "rrr3", "--pose", *pose, "--q0", f"elbow_2={math.degrees(q0[elbow])!r}deg"]) == 0
    got = json.loads(capsys.readouterr().out)
    want = pkm.solve_ik(mech, {"x": 0.5, "y": 0.2887, "yaw": math.radians(5.0)}, q0)
    assert np.allclose([got["joints"][n] for n in mech.joints], want.q, rtol=0, atol=1e-9)
    assert abs(got["joints"]["elbow_2"] - mech.q_reference[elbow]) > 1.0  # (the seed's elbow, not the reference's)
    qa = [f"{n}={float(v)!r}" for n, v in zip(mech.actuated_names, want.q[mech.act_q])]
    seed = [f"{n}={round(float(want.q[j.idx_q]), 2)!r}" for n, j in mech.joints.items()]  # (near, not on it)
    assert cli.main(["fk", "rrr3", "--joints", *qa, "--q0", *seed]) == 0
    fk = json.loads(capsys.readouterr().out)
    assert abs(fk["joints"]["elbow_2"] - want.q[elbow]) < 1e-9
    bad = run("fk", "rrr3", "--joints", *qa, "--q0", "elbow_9=1")
    assert bad.returncode != 0 and "'elbow_9'" in one_error_line(bad)


def test_a_solution_outside_the_limits_is_not_plain_ok(capsys):
    """``pkm ik ankle.closures.toml --pose ankle_pitch=0.8``: converged, but its status is outside_limits and each
    joint outside its MJCF range (the pitch +-0.6, the motors +-1) is named with its value (the motors': the
    ankle's closed form, another route) and limits; a pose inside them is ok with none."""
    from pkm import cli
    from tests.test_humanoid import EXAMPLES, ankle_closed_form

    spec = str(EXAMPLES / "humanoid_ankle" / "ankle.closures.toml")
    assert cli.main(["ik", spec, "--pose", "ankle_pitch=0.8"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["converged"] and out["status"] == "outside_limits"
    outside = {o["joint"]: o for o in out["outside_limits"]}
    assert list(outside) == ["ankle_pitch", "motor_left", "motor_right"]
    assert outside["ankle_pitch"]["limit"] == [-0.6, 0.6] and abs(outside["ankle_pitch"]["value"] - 0.8) <= 1e-9
    motors = [outside[m]["value"] for m in ("motor_left", "motor_right")]
    assert np.allclose(motors, ankle_closed_form(0.8, 0.0), atol=1e-9) and min(motors) > 1.03
    assert all(outside[m]["limit"] == [-1.0, 1.0] for m in ("motor_left", "motor_right"))
    assert cli.main(["ik", spec, "--pose", "ankle_pitch=0.3"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "ok" and out["outside_limits"] == []
