"""``pkm spec init``: a closure spec from an MJCF file, and from a URDF once filled in."""

from __future__ import annotations

from pathlib import Path

import pkm
from tests.cli.helpers import one_error_line, run


def test_spec_init_writes_a_spec_that_loads_once_filled_in(tmp_path):
    """From an MJCF file (loops and actuators stated) the spec loads as written; from a URDF it parses, lists the
    model's joints and frames, and loads once its TODO lines are filled in; an existing file is kept."""
    examples = Path(__file__).resolve().parents[2] / "examples"
    for src in (examples / "mjcf_fourbar" / "fourbar.xml", examples / "ankle" / "ankle.urdf"):
        (tmp_path / src.name).write_text(src.read_text())
    mj = run("spec", "init", str(tmp_path / "fourbar.xml"))
    assert mj.returncode == 0 and "TODO" not in mj.stdout, mj.stderr
    assert pkm.load(tmp_path / "fourbar.closures.toml").actuated_names == ("crank_joint",)
    ur = run("spec", "init", str(tmp_path / "ankle.urdf"))
    assert ur.returncode == 0 and "TODO" in ur.stdout, ur.stderr
    text = (tmp_path / "ankle.closures.toml").read_text()
    assert "motor_left" in text and "foot_ball_left" in text
    filled = text.replace("actuated = []", 'actuated = ["motor_left", "motor_right"]').replace(
        'frame_a = "shank"', 'frame_a = "rod_end_left"').replace('frame_b = "rod_end_right"', 'frame_b = "foot_ball_left"')
    filled += '\n[[closure]]\nname = "loop2"\ntype = "point"\nframe_a = "rod_end_right"\nframe_b = "foot_ball_right"\n'
    filled += '[joint_types]\nrod_ball_left = "spherical"\nrod_ball_right = "spherical"\n'
    (tmp_path / "ankle.closures.toml").write_text(filled.replace("# [joint_types]", "#"))
    mech = pkm.load(tmp_path / "ankle.closures.toml")
    assert pkm.diagnose(mech, mech.q_reference).idle_motions == 2
    again = run("spec", "init", str(tmp_path / "ankle.urdf"))
    assert again.returncode == 2 and "--force" in one_error_line(again)
