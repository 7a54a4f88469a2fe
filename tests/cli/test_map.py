"""``pkm map``: the summary, the CSV and the figure of a workspace map."""

from __future__ import annotations

import csv
import json
import math

import pkm
from pkm import cli
from tests.cli.helpers import run
from tests.papers.figures import inspected


def test_map_prints_a_summary_and_writes_the_figure_and_the_numbers(tmp_path):
    """``pkm map`` with units on the axes: the summary's GCI is the mean of the CSV's CIs; the PNG exists."""
    proc = run("map", "rrr3", "--axis", "x=30cm:70cm:41", "--axis", "y=10cm:50cm:41", "--pose", "yaw=0deg",
               "--length", "5.7735cm", "--png", str(tmp_path / "m.png"), "--csv", str(tmp_path / "m.csv"))
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["nodes"] == 41 * 41 and 0 < out["reachable"] <= out["nodes"]
    rows = list(csv.DictReader((tmp_path / "m.csv").open()))
    assert len(rows) == 41 * 41 and sum(int(r["reachable"]) for r in rows) == out["reachable"]
    ci = [float(r["ci_2"]) for r in rows if r["reachable"] == "1"]
    assert math.isclose(sum(ci) / len(ci), out["gci_2"], rel_tol=1e-12)
    assert (tmp_path / "m.png").stat().st_size > 10_000


def test_the_map_figure_passes_the_figure_check(tmp_path, capsys):
    """The PNG of ``pkm map`` (in process, coarse): a caption naming the mechanism, units on both axes, a colour bar,
    the white of unreachable nodes in a legend."""
    with inspected(paper=False) as found:
        assert cli.main(["map", "rrr3", "--axis", "x=0cm:100cm:21", "--axis", "y=-10cm:90cm:21", "--pose", "yaw=0deg",
                         "--length", "5.7735cm", "--png", str(tmp_path / "m.png")]) == 0
    assert found == {"m": []}


def test_map_index_adds_the_capability(tmp_path):
    """``pkm map --index wrench``: the capability's ranges in the summary, its CSV (one row per node, the isotropic
    value's range the summary's) and its figure."""
    proc = run("map", "delta", "--axis", "x=-10cm:10cm:11", "--axis", "y=-5cm:5cm:6", "--pose", "z=-35cm",
               "--index", "wrench", "--csv", str(tmp_path / "w.csv"), "--png", str(tmp_path / "w.png"))
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    cap = out["capability"]
    assert cap["kind"] == "wrench" and cap["regular"] == out["reachable"] == 66 and cap["units"]["x"] == "N"
    rows = list(csv.DictReader((tmp_path / "w.csv").open()))
    iso = [float(r["isotropic [N]"]) for r in rows if r["reachable"] == "1.0"]
    assert len(rows) == 66 and [min(iso), max(iso)] == cap["isotropic"]["N"]
    assert (tmp_path / "w.png").stat().st_size > 10_000


def test_the_map_starts_from_the_seed_given(monkeypatch):
    """``pkm map --q0 NAME=V``: the map's seed configuration (its working mode), as :func:`workspace_map` takes it."""
    import numpy as np
    import pytest

    import pkm
    from pkm.core.analysis import maps

    class Seen(Exception):
        pass

    def seen(mech, axes, fixed, **kw):
        raise Seen(kw["seed"])

    monkeypatch.setattr(maps, "workspace_map", seen)
    with pytest.raises(Seen) as got:
        cli.main(["map", "rrr3", "--axis", "x=30cm:70cm:3", "--q0", "elbow_2=-40deg"])
    mech = pkm.load("rrr3")
    want = mech.q_reference.copy()
    want[mech.joints["elbow_2"].idx_q] = np.radians(-40.0)
    assert np.array_equal(got.value.args[0], want)


def test_the_map_of_a_mechanism_with_collision_geometry_marks_interference(tmp_path, capsys):
    """The Gough-Stewart with 9.5 cm legs turned 1 rad (in process, 5 x 5): the summary's counts are the CSV's
    (within the limits, interfering, free of both), the figure passes the check with its marks in the legend."""
    args = ["map", "gough_stewart", "--param", "cylinder_radius=9.5cm", "rod_radius=9.5cm", "--axis",
              "x=-15cm:15cm:5", "--axis", "y=-15cm:15cm:5", "--pose", "yaw=1", "--length", "0.5"]
    with inspected(paper=False) as found:
        assert cli.main([*args, "--png", str(tmp_path / "m.png"), "--csv", str(tmp_path / "m.csv")]) == 0
    assert found == {"m": []}
    out = json.loads(capsys.readouterr().out)["interference"]
    rows = [r for r in csv.DictReader((tmp_path / "m.csv").open()) if r["reachable"] == "1"]
    inside = [r for r in rows if r["within_limits"] == "1"]
    free = [r for r in inside if r["interferes"] == "0"]
    assert (out["within_limits"], out["interference_free_within_limits"]) == (len(inside), len(free)) == (20, 7)
    assert out["interfering"] == sum(float(r["clearance"]) < 0.0 for r in rows) > 0
    assert math.isclose(out["size_interference_free_SI"], 7 * 0.075 ** 2, rel_tol=1e-12)
    assert out["smallest_clearance_m"] == min(float(r["clearance"]) for r in rows)


def test_a_mixed_task_defaults_to_the_characteristic_length_and_says_so():
    """A 3-RRR map (its task: x, y, yaw) without ``--length``: the mechanism's characteristic length, said on stderr
    and in the summary, and the same map as with that ``--length`` given."""
    L = pkm.load("rrr3").characteristic_length
    axes = ("--axis", "x=45cm:55cm:3")
    default, given = run("map", "rrr3", *axes), run("map", "rrr3", *axes, "--length", f"{L!r}")
    assert default.returncode == 0 and given.returncode == 0, default.stderr + given.stderr
    assert f"characteristic length L = {L:.6g} m (--length to change it)" in default.stderr
    assert "characteristic length" not in given.stderr
    a, b = json.loads(default.stdout), json.loads(given.stdout)
    assert a["length_SI"] == b["length_SI"] == L and a["gci_2"] == b["gci_2"] and a["reachable"] == b["reachable"] > 0
