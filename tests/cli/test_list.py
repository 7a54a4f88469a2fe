"""``pkm list``, as JSON through the installed console script and as text."""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import pkm
from pkm import cli
from pkm.mechanisms import names
from tests import bounded
from tests.cli.helpers import one_error_line, run


def test_console_script_lists_every_mechanism_as_json():
    """The installed ``pkm`` script prints every mechanism's parameters with defaults and units, SI."""
    script = Path(sys.executable).with_name("pkm")
    proc = bounded.run([str(script), "list", "--json"], cpu=60)
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)["mechanisms"]
    assert list(data) == list(names(with_files=True))  # a subprocess: the shipped registry
    assert data["delta"]["parameters"]["R"] == {**data["delta"]["parameters"]["R"], "default": 0.15, "unit": "m"}
    assert data["delta"]["actuated"] == {"motor_1": "rad", "motor_2": "rad", "motor_3": "rad"}
    assert data["prs3"]["actuated"]["slider_1"] == "m" and data["hexapod"]["task"]["beta_1"] == "rad"


def test_list_as_text_and_a_bad_option(capsys):
    """``pkm list`` names each mechanism, its task origin, a reachable pose (which ``pkm ik`` takes back as it is
    printed) and its parameters; an unknown option exits 2 with one line."""
    ok = run("list")
    assert ok.returncode == 0
    assert all(f"{m}: " in ok.stdout for m in names(with_files=True)) and "task (--pose): x [m], y [m], z [m]" in ok.stdout
    rrr3 = ok.stdout[ok.stdout.index("rrr3: "):]
    assert "task origin: the base joint A1" in rrr3
    pose = re.search(r"reference pose \(reachable\): (.*)", rrr3).group(1).split()
    assert pose == ["x=50cm", "y=28.87cm", "yaw=5deg"]
    assert cli.main(["ik", "rrr3", "--pose", *pose]) == 0 and json.loads(capsys.readouterr().out)["converged"]
    bad = run("list", "--bad")
    assert bad.returncode == 2 and "unrecognized arguments: --bad" in one_error_line(bad)


def test_list_describes_any_mech_and_names_the_robots_loaded_by_name(capsys):
    """``pkm list MECH`` takes what every other command's MECH takes (a shipped robot by name, one's own spec), as
    the ``--joints`` and ``--pose`` helps' "see 'pkm list MECH'" promise; bare ``pkm list`` ends with the names of
    the robots pkm ships and of installed packages' models; an unknown name is one error line."""
    from pkm.core.formats.catalogue import CATALOGUE

    ankle = str(Path(__file__).resolve().parents[2] / "examples" / "humanoid_ankle" / "ankle.closures.toml")
    assert cli.main(["list", "gepetto:robot_delta", ankle, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)["mechanisms"]
    assert data["gepetto:robot_delta"]["actuated"] == {"mot1_rod1": "rad", "mot1_rod2": "rad"}
    assert data[ankle]["task"] == {"ankle_pitch": "rad", "ankle_roll": "rad"} and "parameters" not in data[ankle]
    assert cli.main(["list"]) == 0
    tail = capsys.readouterr().out.split("Also loaded by name")[1]
    assert all(name in tail for name in (*CATALOGUE, "example-robot-data:cassie"))
    bad = run("list", "gepetto:nope")
    assert bad.returncode != 0 and "'gepetto:nope'" in one_error_line(bad)


def test_list_a_folder_names_what_loads_there_and_why_the_rest_does_not(tmp_path, capsys, built):
    """``pkm list FOLDER`` searches it: a closure spec (its URDF among its files, not listed apart) and an MJCF file
    two levels down are described with their format, name, joints and task, as ``pkm.load`` reads them; a URDF
    alone is named with load's error; a TOML that is no spec is left out. A single file is described alone; a
    folder with nothing pkm loads is one error line (status 1) saying what it searched for."""
    import shutil

    root = Path(__file__).resolve().parents[2]
    spec = pkm.save(built("fivebar"), tmp_path / "five" / "five.closures.toml")
    (tmp_path / "deep" / "er").mkdir(parents=True)
    mjcf = Path(shutil.copy(root / "examples" / "mjcf_fourbar" / "fourbar.xml", tmp_path / "deep" / "er"))
    lone = Path(shutil.copy(spec.parent / "five.urdf", tmp_path / "lone.urdf"))
    (tmp_path / "pyproject.toml").write_text('[project]\nname = "x"\n')
    assert cli.main(["list", str(tmp_path), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    data = out["mechanisms"]
    assert sorted(data) == sorted([str(spec), str(mjcf)])
    five, four = data[str(spec)], data[str(mjcf)]
    assert five["format"] == "pkm closure spec + URDF" and five["files"] == [str(spec), str(spec.parent / "five.urdf")]
    assert (five["name"], five["loops"], five["joints"]) == ("fivebar", 1, 4)
    assert five["actuated"] == {"motor_1": "rad", "motor_2": "rad"} and five["task"] == {"x": "m", "y": "m"}
    mech = pkm.load(mjcf)
    assert four["format"] == "MJCF file" and four["name"] == mech.name
    assert list(four["actuated"]) == list(mech.actuated_names) and four["loops"] == len(mech.spec.closures)
    assert list(out["not_loaded"]) == [str(lone)] and "pkm spec init" in out["not_loaded"][str(lone)]
    assert cli.main(["list", str(mjcf)]) == 0
    text = capsys.readouterr().out
    assert f"{mjcf}: " in text and "read from: MJCF file" in text and "not loaded" not in text.lower()
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "notes.toml").write_text("x = 1\n")
    assert cli.main(["list", str(tmp_path / "empty")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pkm loads nothing here: no closure spec, Gepetto YAML or model file" in err[0]
    assert "MJCF (.xml .mjcf)" in err[0] and "notes.toml" in err[0]
