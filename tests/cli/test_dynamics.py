"""``pkm dynamics``: the actuator-space model at one state, equal to :func:`pkm.actuator_model`'s, each entry with its
unit, by actuator name; bad input as one error line."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm import cli
from pkm.cli.commands.dynamics import _mass_unit
from tests.cli.helpers import one_error_line, run_process

ROOT = Path(__file__).resolve().parents[2]
ANKLE = ROOT / "examples" / "ankle" / "ankle.closures.toml"
RTOL = 1e-12  # the command and the library take the same route (the JSON floats are exact): only the last bits


def _json(capsys, *argv: str) -> dict:
    assert cli.main(["dynamics", *argv, "--json"]) == 0, capsys.readouterr().err
    return json.loads(capsys.readouterr().out)


def _matrix(out: dict, key: str) -> np.ndarray:
    names = list(out["actuated"])
    return np.array([[out[key][a][b] for b in names] for a in names])


def _vector(out: dict, key: str) -> np.ndarray:
    return np.array([out[key][n] for n in out["actuated"]])


def test_delta_json_equals_the_library_at_the_state_given(capsys):
    """``pkm dynamics delta --joints motor_1=-30deg --rates ...``: M_a, h_a, g_a equal pkm.actuator_model at the
    configuration closed from those values (to 1e-12 relative); units kg m^2 and N m; no friction, no idle motion."""
    out = _json(capsys, "delta", "--joints", "motor_1=-30deg", "motor_2=-0.4", "--rates", "motor_1=0.5",
                "motor_3=-1.5")
    mech = pkm.load("delta")
    qa = mech.actuated_q(mech.q_reference)
    qa[:2] = math.radians(-30), -0.4
    model = pkm.actuator_model(mech, pkm.close_loops(mech, qa).q, [0.5, 0.0, -1.5])
    assert np.allclose(_vector(out, "actuated"), qa, rtol=RTOL, atol=0)
    assert np.allclose(_matrix(out, "M"), model.M, rtol=RTOL, atol=0)
    for key, ours in (("h", model.h), ("g", model.g)):
        assert np.allclose(_vector(out, key), ours, rtol=RTOL, atol=1e-15)
    assert not np.allclose(model.h, model.g)  # (the rates count)
    assert out["units"]["M"]["motor_1"]["motor_2"] == "kg m^2" and out["units"]["h"]["motor_3"] == "N m"
    assert out["units"]["rates"]["motor_1"] == "rad/s" and out["friction"] is None and out["idle_motions"] == 0
    assert out["base"] == "fixed"


def test_pose_and_rates_with_units_are_the_si_numbers_as_in_the_library(capsys):
    """``pkm dynamics delta --pose z=-30cm --rates motor_3=-30deg/s`` (it took no --pose, and a rate unit was "not a
    number"): the state is pkm.solve_ik's at that pose, the rates -pi/6 rad/s, the model the library's given the same
    strings, to 1e-12; ``300rpm`` is 10 pi rad/s; ``--pose`` and ``--joints`` exclude each other."""
    units = _json(capsys, "delta", "--pose", "z=-30cm", "--rates", "motor_3=-30deg/s", "motor_1=300rpm")
    si = _json(capsys, "delta", "--pose", "z=-0.3", "--rates", f"motor_3={-math.pi / 6!r}",
               f"motor_1={10 * math.pi!r}")
    mech = pkm.load("delta")
    q = pkm.solve_ik(mech, {"z": -0.3}).q
    model = pkm.actuator_model(mech, q, ["300rpm", 0.0, "-30deg/s"])
    assert np.allclose(model.qd, [10 * math.pi, 0.0, -math.pi / 6], rtol=1e-15, atol=0)
    for out in (units, si):
        assert np.allclose(_vector(out, "rates"), model.qd, rtol=1e-15, atol=0)
        assert abs(out["task"]["z"] + 0.3) <= 1e-12 and np.allclose(_vector(out, "actuated"), mech.actuated_q(q))
        assert np.allclose(_vector(out, "h"), model.h, rtol=RTOL, atol=1e-15)
    assert cli.main(["dynamics", "delta", "--pose", "z=-30cm", "--joints", "motor_1=0"]) == 2
    assert "not allowed with argument --pose" in capsys.readouterr().err


def test_a_floating_base_is_said_free(tmp_path, capsys):
    """The Delta hung on a free pelvis, saved and read back: the JSON names the base's choice and equals the
    library's free-base model; the text says the base is free."""
    from tests.core.dynamics.floating import floating

    path = pkm.save(floating("delta"), tmp_path / "floating.closures.toml")
    mech = pkm.load(path)
    assert cli.main(["dynamics", str(path)]) == 0
    assert "floating base: free" in capsys.readouterr().out
    out = _json(capsys, str(path))
    model = pkm.actuator_model(mech, mech.q_reference)
    assert out["base"] == "free" and np.allclose(_matrix(out, "M"), model.M, rtol=RTOL, atol=0)


def test_a_spec_file_prints_its_idle_motions_and_the_model_at_the_reference(capsys):
    """The ankle from its file (two rods spinning idle): the text names every actuator with units and the idle
    motions; the JSON at the reference equals the library's."""
    assert cli.main(["dynamics", str(ANKLE)]) == 0
    text = capsys.readouterr().out
    assert "M_a (mass matrix)" in text and "kg m^2" in text and "N m" in text and "motor_left" in text
    assert "idle motions: 2" in text and "friction" not in text
    out = _json(capsys, str(ANKLE))
    mech = pkm.load(ANKLE)
    model = pkm.actuator_model(mech, mech.q_reference)
    assert out["idle_motions"] == 2 and list(out["actuated"]) == list(mech.actuated_names)
    assert np.allclose(_matrix(out, "M"), model.M, rtol=RTOL, atol=0)
    assert np.allclose(_vector(out, "g"), model.g, rtol=RTOL, atol=1e-15)


def test_prismatic_actuators_take_kg_and_newtons(capsys):
    out = _json(capsys, "prs3", "--rates", "slider_2=0.1")
    assert {u for row in out["units"]["M"].values() for u in row.values()} == {"kg"}
    assert set(out["units"]["h"].values()) == {"N"} and out["units"]["rates"]["slider_2"] == "m/s"
    assert (_mass_unit(True, True), _mass_unit(True, False), _mass_unit(False, True), _mass_unit(False, False)) == \
        ("kg m^2", "kg m", "kg m", "kg")


def test_friction_is_printed_where_the_actuators_have_some(tmp_path, capsys):
    """A Delta whose first motor has viscous and Coulomb friction, saved as a spec: the friction efforts at the rates
    given equal the library's and oppose the motion."""
    mech = pkm.with_actuators(pkm.load("delta"), {"motor_1": {"viscous": 0.5, "coulomb": 0.1}})
    path = tmp_path / "delta_friction.closures.toml"
    pkm.save(mech, path)
    out = _json(capsys, str(path), "--rates", "motor_1=2", "motor_2=-1")
    mech = pkm.load(path)
    model = pkm.actuator_model(mech, mech.q_reference, [2.0, -1.0, 0.0])
    assert np.allclose(_vector(out, "friction"), model.friction, rtol=RTOL, atol=1e-15)
    assert out["friction"]["motor_1"] < 0 and out["units"]["friction"]["motor_1"] == "N m"
    assert cli.main(["dynamics", str(path), "--rates", "motor_1=2"]) == 0
    assert "friction efforts:" in capsys.readouterr().out


@pytest.mark.parametrize("argv,status,message", [
    (["delta", "--rates", "motor_1=5deg"], 2, "'deg' is an angle unit but motor_1 is in [rad/s]"),
    (["delta", "--joints", "motor_9=1"], 2, "actuated joint 'motor_9' does not exist"),
    (["delta", "--rates", "motor_1"], 2, "must read NAME=VALUE"),
    (["nowhere.closures.toml"], 1, "nowhere.closures.toml"),
])
def test_bad_input_is_one_error_line(argv, status, message, capsys):
    assert cli.main(["dynamics", *argv]) == status
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("pkm: error: ") and message in err, err


def test_the_command_runs_as_a_process():
    """``python -m pkm dynamics delta --json --rates motor_1=fast``: one error line, exit status 2."""
    bad = run_process("dynamics", "delta", "--json", "--rates", "motor_1=fast")
    assert bad.returncode == 2 and "is not a number" in one_error_line(bad)


def test_a_state_outside_the_position_limits_says_so(capsys):
    """The humanoid ankle's motors at 1.1 rad (range +-1, the pitch then past its +-0.6): the model is printed, with
    the joints outside listed (the motors at the values given, as the state printed) and, as text, a warning line
    naming them."""
    spec = str(ROOT / "examples" / "humanoid_ankle" / "ankle.closures.toml")
    out = _json(capsys, spec, "--joints", "motor_left=1.1", "motor_right=1.1")
    outside = {o["joint"]: o for o in out["outside_limits"]}
    assert list(outside) == ["ankle_pitch", "motor_left", "motor_right"] and outside["ankle_pitch"]["value"] > 0.6
    for m in ("motor_left", "motor_right"):
        assert outside[m]["value"] == out["actuated"][m] and abs(outside[m]["value"] - 1.1) <= 1e-12
        assert outside[m]["limit"] == [-1.0, 1.0]
    assert cli.main(["dynamics", spec, "--joints", "motor_left=1.1", "motor_right=1.1"]) == 0
    assert "warning: outside the position limits the model states: ankle_pitch = 0.83" in capsys.readouterr().out
    assert _json(capsys, spec, "--joints", "motor_left=0.1", "motor_right=0.1")["outside_limits"] == []
