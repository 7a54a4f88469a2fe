"""pkm.core.formats.hyrodyn: a robot URDF with HyRoDyn's submechanisms.yml (DFKI; Phobos's SMURF submechanisms), its
numerical loops read as closures where HyRoDyn places them, its analytic submechanisms refused naming the type.

The model (``tests/data/hyrodyn_fourbar``, written for pkm): a crank-rocker four-bar in the x-z plane whose loop is
cut at the rocker's tip against the coupler, stating the x and z translations only (as HyRoDyn's planar ``rrPr``
example states two), and a serial wrist (type ``R``). The rocker's angle is checked against the four-bar's own
geometry (the coupler's length between the crank's and the rocker's pins, computed here from the joint angles).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm.core.formats.hyrodyn import read_hyrodyn
from pkm.core.formats.load import load_texts
from pkm.errors import SpecError, SpecNameError
from tests import fd

DATA = Path(__file__).resolve().parents[2] / "data" / "hyrodyn_fourbar"
URDF, YAML = (DATA / "fourbar.urdf").read_text(), (DATA / "submechanisms.yml").read_text()
B0, C0, D = np.array([0.05, 0.0, 0.08660254037844387]), np.array([0.22, 0.0, 0.15]), np.array([0.2, 0.0, 0.0])


def _ry(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


AXES = "            axis: [0., 0., 0., 0., 0., 1.]\n"
#: The file as written (x and z), the three translations, and all six axes with the cut at a revolute pin (the rocker's
#: tip turning about y on the rocker, tied whole to the coupler): the same four-bar each time.
VARIANTS = {
    "xz": (URDF, YAML),
    "xyz": (URDF, YAML.replace(AXES, AXES + "          - name: loopTY\n            axis: [0., 0., 0., 0., 1., 0.]\n")),
    "frame": (URDF.replace('<joint name="rocker_tip_fixed" type="fixed">', '<joint name="rocker_tip_fixed" '
                           'type="revolute"><axis xyz="0 1 0"/><limit effort="1" velocity="1"/>'),
              YAML.replace(AXES, AXES + "".join(f"          - name: r{k}\n            axis: {a}\n" for k, a in
                                                enumerate(("[1., 0., 0., 0., 0., 0.]", "[0., 1., 0., 0., 0., 0.]",
                                                           "[0., 0., 1., 0., 0., 0.]", "[0., 0., 0., 0., 1., 0.]"))))),
}


@pytest.fixture(scope="module")
def fourbar():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (its placeholder-free drives: nothing to say; any warning is not the test)
        return pkm.load(DATA)


@pytest.fixture(scope="module", params=sorted(VARIANTS))
def variant(request):
    urdf, text = VARIANTS[request.param]
    return request.param, load_texts({"fourbar.urdf": urdf, "submechanisms.yml": text})


def test_the_folder_loads_with_the_file_s_drives_outputs_and_loop(fourbar):
    mech = fourbar
    assert mech.actuated_names == ("act", "wrist") and mech.spec.task.joints == ("out", "wrist")
    (c,) = mech.spec.closures
    assert (c.type, c.frame_a, c.frame_b) == ("point", "rocker_tip", "rocker_tip_fixed_cut")
    assert any("2 translation axes of 3" in n and "implied" in n for n in mech.notes)
    assert any("jointnames not read" in n for n in mech.notes)


def test_each_variant_reads_its_closure_type(variant):
    name, mech = variant
    (c,) = mech.spec.closures
    assert c.type == ("frame" if name == "frame" else "point")
    assert any("translation axes of 3" in n for n in mech.notes) == (name == "xz")


def test_the_rocker_follows_the_four_bar_and_the_jacobian_matches_differences(variant):
    _, mech = variant
    act, out = mech.joints["act"].idx_q, mech.joints["out"].idx_q
    length = np.linalg.norm(C0 - B0)
    for theta in (-0.3, 0.0, 0.15, 0.3):
        fk = pkm.close_loops(mech, np.array([theta, 0.1]), mech.q_reference)
        assert fk.residual <= 1e-10 and abs(fk.q[act] - theta) <= 1e-12
        B, C = _ry(theta) @ B0, D + _ry(fk.q[out]) @ (C0 - D)
        assert abs(np.linalg.norm(C - B) - length) <= 1e-10 * length
        assert fd.forward_jacobian_error(mech, fk.q) <= 1e-6
    ik = pkm.solve_ik(mech, pkm.TaskMap.of(mech).value(fk.q))
    assert np.abs(mech.actuated_q(ik.q) - [0.3, 0.1]).max() <= 1e-9


def test_an_upload_reads_it_alike(fourbar):
    mech = load_texts({"fourbar.urdf": URDF, "submechanisms.yml": YAML})
    assert mech.actuated_names == fourbar.actuated_names and mech.spec.closures == fourbar.spec.closures


ANALYTIC = YAML.replace("type: NUMERICAL", "type: rrPr").split("    loop_constraints:")[0] + YAML.split(
    "            axis: [0., 0., 0., 0., 0., 1.]\n")[1]


@pytest.mark.parametrize("text, error, message", [
    (ANALYTIC, SpecError, r"type 'rrPr' without loop_constraints: its loop geometry lives in HyRoDyn's code.*"
                          r"add to it type: NUMERICAL and loop_constraints"),
    (YAML.replace("predecessor_body: rocker_tip", "predecessor_body: rocker_top"), SpecNameError,
     r"link 'rocker_top' does not exist.*predecessor_body"),
    (YAML.replace("jointnames_active: [act]", "jointnames_active: [akt]"), SpecNameError, r"joint 'akt'"),
    (YAML.replace("axis: [0., 0., 0., 1., 0., 0.]", "axis: [0., 1., 0., 0., 0., 0.]"), SpecError,
     r"constrain some rotations but not all six"),
    (YAML.replace("axis: [0., 0., 0., 1., 0., 0.]", "axis: [0., 0., 1.]"), SpecError, r"must be 6 finite numbers"),
    ("submechanisms: []\n", SpecError, r"non-empty submechanisms list"),
    (YAML.replace("successor_body: coupler", "successor: coupler"), SpecError, r"successor_body must be a link name"),
])
def test_what_pkm_cannot_read_is_refused_saying_what(text, error, message):
    with pytest.raises(error, match=message):
        read_hyrodyn(text, URDF, "fourbar.urdf", "fourbar", "submechanisms.yml")


def test_a_loop_whose_left_out_translations_remove_a_motion_is_refused():
    """With the x translation alone the loop leaves the four-bar two freedoms: a point closure would take one."""
    text = YAML.replace("          - name: loopTZ\n            axis: [0., 0., 0., 0., 0., 1.]\n", "")
    with pytest.raises(SpecError, match=r"states 1 translation axes of 3: the others are not implied"):
        load_texts({"fourbar.urdf": URDF, "submechanisms.yml": text})


def test_saved_as_a_pkm_spec_it_loads_back_the_same(fourbar, tmp_path):
    from pkm.core.model.compare import mechanism_differences

    path = pkm.save(fourbar, tmp_path / "fourbar.closures.toml")
    assert mechanism_differences(pkm.load(path), fourbar) == []


def test_a_smurf_file_is_read_as_the_pair_it_lists(fourbar, tmp_path):
    """Phobos's SMURF main file, laid out as hyrodyn's robot/leg (smurf/leg.smurf naming ../urdf/...)."""
    (tmp_path / "urdf").mkdir()
    (tmp_path / "smurf").mkdir()
    (tmp_path / "urdf" / "fourbar.urdf").write_text(URDF)
    (tmp_path / "urdf" / "submechanisms.yml").write_text(YAML)
    smurf = tmp_path / "smurf" / "fourbar.smurf"
    smurf.write_text("modelname: fourbar\nfiles:\n- ../urdf/fourbar.urdf\n- ../urdf/submechanisms.yml\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mech = pkm.load(smurf)
    assert mech.spec.closures == fourbar.spec.closures and mech.actuated_names == fourbar.actuated_names
    smurf.write_text("modelname: fourbar\nfiles:\n- ../urdf/fourbar.urdf\n")
    with pytest.raises(SpecError, match=r"HyRoDyn URDF \+ submechanisms.yml: a SMURF file listing 1 URDF and 0"):
        pkm.load(smurf)
