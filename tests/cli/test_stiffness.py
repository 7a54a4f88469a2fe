"""``pkm stiffness``: the library's numbers (pkm.stiffness, vibration_modes) by name with units, a rigid direction
said, a load's deflection and tangent stiffness, links of a material, and one error line for a motion no spring
resists."""

from __future__ import annotations

import json

import numpy as np

import pkm
from tests.cli.helpers import one_error_line, run


def test_the_gough_stewart_with_leg_springs_prints_the_librarys_numbers():
    proc = run("stiffness", "gough_stewart", "--drives", "1e6", "--spring", "leg2=2e6", "--wrench", "fz=-2kN",
               "mx=5 N m", "--frequencies", "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    gs = pkm.load("gough_stewart")
    joints = {**{j: 1e6 for j in gs.actuated_names}, "leg2": 2e6}
    K = pkm.stiffness(gs, gs.q_reference, joints=joints)
    assert out["rank"] == 6 and out["sprung"] == joints and out["locked"] == []
    assert out["sources"] == dict.fromkeys(joints, "joints")
    assert np.allclose(out["matrix"], K.matrix, rtol=1e-12, atol=1e-9)
    d = K.deflection([0, 0, -2000.0, 5.0, 0, 0])
    assert np.allclose(out["deflection"]["exact"], d.displacement, rtol=1e-12, atol=1e-15)
    assert out["deflection"]["gap"] == d.gap and out["units"]["frequencies"] == "Hz"
    modes = pkm.vibration_modes(gs, gs.q_reference, joints=joints)
    assert np.allclose(out["frequencies"], modes.frequencies, rtol=1e-12)
    loaded = K.loaded([0, 0, -2000.0, 5.0, 0, 0])
    assert np.allclose(out["loaded_matrix"], loaded.matrix, rtol=1e-12, atol=1e-9)
    assert out["links"] == {} and out["rigid_links"] == {}


def test_links_of_a_material_are_the_librarys_and_said():
    """--links E=..,G=..: the library's stiffness with that Material (1e-12), the beams with their radius and the
    links taken rigid with their reasons; an unknown material is one error line."""
    proc = run("stiffness", "gough_stewart", "--drives", "2e6", "--links", "E=7e10,G=2.6e10", "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    gs = pkm.load("gough_stewart")
    K = pkm.stiffness(gs, gs.q_reference, joints=dict.fromkeys(gs.actuated_names, 2e6),
                      links=pkm.Material(E=7e10, G=2.6e10))
    assert np.allclose(out["matrix"], K.matrix, rtol=1e-12, atol=1e-9)
    assert out["links"]["cylinder_1"]["radius"] == gs.params.cylinder_radius and out["rigid_links"] == K.rigid_links
    text = run("stiffness", "gough_stewart", "--drives", "2e6", "--links", "steel")
    assert "compliant links: cylinder_1 (beam of radius 0.03 m" in text.stdout and "taken rigid: base" in text.stdout
    bad = run("stiffness", "gough_stewart", "--drives", "2e6", "--links", "wood")
    assert bad.returncode == 1 and "steel, aluminium" in one_error_line(bad)


def test_a_delta_is_rigid_in_rotation_and_a_free_motion_is_one_error_line():
    proc = run("stiffness", "delta", "--drives", "500")
    assert proc.returncode == 0, proc.stderr
    assert "compliance of rank 3 of 6" in proc.stdout and "pure moment [N m/rad]: inf along" in proc.stdout
    assert "springs: motor_1 500 (joints)" in proc.stdout
    bad = run("stiffness", "gough_stewart", "--drives", "1e6", "--spring", "leg1=0")
    assert bad.returncode == 1 and "no spring resists" in one_error_line(bad) and "leg1" in bad.stderr
