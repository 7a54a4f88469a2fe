"""``pkm clearance``: the library's numbers by name with units, the closest pairs and the pairs left out, and one
error line for a mechanism whose files carry no collision geometry."""

from __future__ import annotations

import json
import re

import numpy as np

import pkm
from tests.cli.helpers import one_error_line, run


def test_the_gough_stewart_prints_the_librarys_numbers():
    proc = run("clearance", "gough_stewart", "--pose", "yaw=0.9", "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    gs = pkm.load("gough_stewart")
    q = pkm.solve_ik(gs, pkm.TaskMap.of(gs).retract(pkm.TaskMap.of(gs).value(gs.q_reference),
                                                      [0, 0, 0, 0, 0, 0.9])).q
    c = pkm.clearance(gs, q)
    assert abs(out["minimum"] - c.minimum) <= 1e-12 and len(out["pairs"]) == len(c.pairs) == 66
    assert out["pairs"][0]["distance"] == out["minimum"] and out["interferes"] is False
    assert np.allclose(list(out["gradient"].values()), c.gradient, rtol=1e-9, atol=1e-12)
    assert {tuple(e["bodies"]) for e in out["excluded"]} == set(c.excluded) and out["units"]["minimum"] == "m"


def test_no_collision_geometry_is_one_error_line(tmp_path):
    """The Gough-Stewart's files without their <collision> elements."""
    gs = pkm.load("gough_stewart")
    (tmp_path / "gough_stewart.urdf").write_text(re.sub(r"<collision.*?</collision>", "", gs.urdf, flags=re.DOTALL))
    (tmp_path / "gough_stewart.closures.toml").write_text(gs.spec.to_toml())
    bad = run("clearance", str(tmp_path / "gough_stewart.closures.toml"))
    assert bad.returncode == 1 and "no collision geometry" in one_error_line(bad)
