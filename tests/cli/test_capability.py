"""``pkm capability``: the library's capability at the pose asked, as JSON and as text; bad input as one line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm import cli
from pkm.errors import ImplausibleModelWarning
from tests.cli.helpers import one_error_line, run


def test_json_is_the_librarys(capsys, tmp_path):
    assert cli.main(["capability", "prs3", "--pose", "z=0.8", "pitch=2deg", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    mech = pkm.load("prs3")
    q = pkm.solve_ik(mech, {"z": 0.8, "pitch": np.radians(2.0)}).q
    for kind in ("wrench", "twist", "acceleration"):
        c = pkm.capability(mech, q, kind)
        assert out[kind]["along"]["pitch"] == [c.along["pitch"][0], c.along["pitch"][1]]
        assert out[kind]["units"]["z"] == c.polytope.units[0]
        assert np.allclose(out[kind]["vertices"], c.polytope.vertices, rtol=1e-12, atol=0)
    assert out["limits"]["slider_1"]["effort_limit"] == {"value": 310.0, "source": "file prs3.urdf"}
    assert out["placeholder_limits"] is False
    assert cli.main(["capability", "delta", "--kind", "twist"]) == 0
    text = capsys.readouterr().out
    assert "twist:" in text and "m/s" in text and "wrench:" not in text
    # the limits held and where they come from (issue 41: 1000 N m and 100 rad/s were placeholders, unsaid); one
    # changed by the spec (pkm.with_actuators writes there) says so, and placeholders are said to be
    assert "limits held (motor_1, motor_2, motor_3): effort 3.9 N m (file delta.urdf), velocity 2.974 rad/s " \
           "(file delta.urdf)" in text
    with pytest.warns(ImplausibleModelWarning):
        spec = pkm.save(pkm.with_actuators(pkm.load("delta"), {j: {"effort_limit": 100.0, "velocity_limit": 10.0}
                                                               for j in ("motor_1", "motor_2", "motor_3")}),
                        tmp_path / "d.closures.toml")
    with pytest.warns(ImplausibleModelWarning):
        assert cli.main(["capability", str(spec), "--kind", "twist"]) == 0
    text = capsys.readouterr().out
    assert "effort 100 N m (spec), velocity 10 rad/s (spec)" in text and "look like placeholders" in text


def test_a_mechanism_without_limits_is_one_error_line():
    fourbar = Path(__file__).resolve().parents[2] / "examples" / "mjcf_fourbar" / "fourbar.xml"  # (a motor, no range)
    line = one_error_line(run("capability", str(fourbar), "--kind", "wrench"))
    assert "effort limit" in line and "crank_joint" in line


def test_a_map_over_two_axes(tmp_path, capsys):
    """``--axis`` twice with ``--pose`` fixing the third: the summary, its CSV rows (one per node) and the PNG."""
    png, table = tmp_path / "map.png", tmp_path / "map.csv"
    argv = ["capability", "delta", "--axis", "x=-10cm:10cm:3", "--axis", "y=-5cm:5cm:2", "--pose", "z=-35cm",
            "--csv", str(table), "--json"]
    assert cli.main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["nodes"] == out["reachable"] == 6 and list(out["fixed"]) == ["z"]
    assert abs(out["fixed"]["z"] + 0.35) <= 1e-15  # (35 cm in metres: 0.35000000000000003)
    lines = table.read_text().splitlines()
    assert len(lines) == 7 and "isotropic [N]" in lines[0]
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return
    assert cli.main([*argv[:-1], "--png", str(png)]) == 0 and png.stat().st_size > 1000
