"""pkm.viz.interference: a snapshot of the Gough-Stewart with 9.5 cm legs turned 1.2 rad, whose rods cross in three
pairs, colours exactly those legs' drawn links red and marks pkm.clearance's witness points; the legend says each
pair and its depth; without interference the closest pair is marked in black; collisions=False, an animation or a
mechanism without geometry: nothing added."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm import viz
from pkm.viz.interference import CLOSEST_COLOR, INTERFERENCE_COLOR
from tests.viz.helpers import TOL, by_path, decode, matrix


@pytest.fixture(scope="module")
def turned():
    thick = pkm.build("gough_stewart", cylinder_radius=0.095, rod_radius=0.095)
    return thick, pkm.solve_ik(thick, {"yaw": 1.2}).q


def test_interfering_bodies_are_red_and_the_witness_points_marked(turned):
    mech, q = turned
    c = pkm.clearance(mech, q)
    hits = sorted(p for p, d in c.pairs.items() if d < 0.0)
    assert len(hits) == 3
    page = viz.snapshot_html(mech, q)
    objects, transforms = by_path(decode(page), "set_object"), by_path(decode(page), "set_transform")
    red = {p for p, o in objects.items() if o["object"]["materials"][0]["color"] == INTERFERENCE_COLOR}
    joints = {f"leg{n[-1]}" for p in hits for n in p}  # (rod_k rides on leg k's prismatic joint, "legk")
    scene = viz.Scene.from_mechanism(mech)
    coloured = {b.path for b in scene.bodies if b.path in red}
    assert len(coloured) == 6 and coloured == {b.path for b in scene.bodies if b.role == "link" and b.joint in joints}
    for a, b in hits:
        path = f"{viz.ROOT}/clearance/{a}-{b}"
        for side, p in zip("ab", c.witness[(a, b)]):
            assert np.abs(matrix(transforms[f"{path}/{side}"])[:3, 3] - p).max() <= TOL
        assert objects[f"{path}/bar"]["object"]["geometries"][0]["height"] == pytest.approx(-c.pairs[(a, b)])
        assert f"{a} and {b} interpenetrate by {-c.pairs[(a, b)]:.3g} m" in page
    plain = decode(viz.snapshot_html(mech, q, collisions=False))
    assert not any("/clearance/" in o["path"] or o["object"]["materials"][0]["color"] == INTERFERENCE_COLOR
                   for o in plain if o["type"] == "set_object")
    animated = decode(viz.snapshot_html(mech, trajectory=np.array([q, q])))
    assert not any("/clearance/" in o.get("path", "") for o in animated)


def test_without_interference_the_closest_pair_is_marked_and_without_geometry_nothing(turned):
    mech, _ = turned
    c = pkm.clearance(mech, mech.q_reference)
    page = viz.snapshot_html(mech)
    objects = by_path(decode(page), "set_object")
    a, b = c.closest
    assert objects[f"{viz.ROOT}/clearance/{a}-{b}/a"]["object"]["materials"][0]["color"] == CLOSEST_COLOR
    assert f"closest: {a} and {b}, {c.minimum:.3g} m apart" in page
    knee = pkm.load(Path(__file__).resolve().parents[2] / "examples" / "knee" / "knee.closures.toml")  # (no geometry)
    assert not any("/clearance/" in p for p in by_path(decode(viz.snapshot_html(knee)), "set_object"))
