"""Gepetto's URDF + YAML convention recognised by content, whatever the files are named; a path no reader takes is
refused saying why each declined; names a letter off are answered with the closest; exporters' "unlimited" limits
are read as none, and said so. Every model is the small RUSR four-bar of ``test_gepetto.py``, written here."""

from __future__ import annotations

import pytest

import pkm
from pkm.core.formats.gepetto import find_gepetto
from pkm.errors import SpecError, SpecNameError
from tests.core.formats.test_gepetto import RUSR_YAML, rusr_urdf


def write(folder, **files: str):
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in files.items():
        (folder / name.replace("__", ".")).write_text(text, encoding="utf-8")
    return folder


@pytest.mark.parametrize("files, load, paired", [
    ({"my_leg__urdf": rusr_urdf(), "robot__yaml": RUSR_YAML}, "", "robot.yaml read with my_leg.urdf, the folder's "
                                                                   "only URDF"),
    ({"leg__urdf": rusr_urdf(), "leg__yaml": RUSR_YAML}, "", None),
    ({"leg__urdf": rusr_urdf(), "closures__yml": RUSR_YAML}, "closures.yml", "closures.yml read with leg.urdf"),
    ({"leg__urdf": rusr_urdf(), "closures__yml": RUSR_YAML}, "leg.urdf", "leg.urdf read with closures.yml"),
    ({"leg__urdf": rusr_urdf(), "leg__txt": RUSR_YAML}, "leg.txt", None),
    ({"leg__urdf": rusr_urdf(), "leg__yaml": RUSR_YAML, "notes__yaml": "author: me\n"}, "", None),
    ({"robot__urdf": rusr_urdf(), "robot__yaml": RUSR_YAML, "leg__yaml": RUSR_YAML, "leg__urdf": rusr_urdf()}, "",
     None),
])
def test_the_convention_is_found_by_content_whatever_the_names(tmp_path, files, load, paired):
    """A folder (or its YAML, or its URDF) loads whatever the files are called; how they were paired is a note."""
    folder = write(tmp_path / "m", **files)
    mech = pkm.load(folder / load if load else folder)
    assert mech.actuated_names == ("motor",) and mech.joints["ujoint_b"].kind == "JointModelUniversal"
    assert (paired is None) == (not any("read with" in n for n in mech.notes))
    assert paired is None or any(n.startswith(paired) for n in mech.notes)


def test_a_yaml_that_is_not_the_convention_is_refused_about_yaml_naming_each_reader(tmp_path):
    folder = write(tmp_path / "m", leg__urdf=rusr_urdf(), config__yaml="solver: {tol: 1e-9}\n")
    with pytest.raises(SpecError) as info:
        pkm.load(folder / "config.yaml")
    lines = str(info.value).splitlines()
    assert lines[0].endswith("config.yaml: no reader takes it:") and "TOML:" not in str(info.value)
    assert lines[1:] == ["  Gepetto URDF + YAML: a YAML mapping without the keys closed_loop or name_mot (its keys: "
                         "solver)",
                         "  HyRoDyn URDF + submechanisms.yml: not a YAML mapping with a submechanisms list",
                         "  pkm closure spec: a YAML file: a pkm closure spec is TOML (NAME.closures.toml)",
                         "  model file (URDF, MJCF, SDF): not XML with a root element <robot>, <mujoco>, <sdf>"]
    with pytest.raises(SpecError, match=r"Gepetto URDF \+ YAML: not valid YAML: .*\n  HyRoDyn URDF \+ "
                                        r"submechanisms.yml: not valid YAML: .*\n  pkm closure spec: a YAML file"):
        pkm.load(write(tmp_path / "n", broken__yaml="closed_loop: [[a, b]\n") / "broken.yaml")
    with pytest.raises(SpecError, match=r"a folder with no YAML file in Gepetto's convention \(config.yaml: a YAML "
                                        r"mapping without.*\n  HyRoDyn URDF \+ submechanisms.yml: a folder with no "
                                        r"YAML file holding a submechanisms list\n  pkm closure spec: a folder"):
        pkm.load(folder)


@pytest.mark.parametrize("files, message", [
    ({"a__urdf": rusr_urdf(), "b__urdf": rusr_urdf(), "leg__yaml": RUSR_YAML},
     r"2 URDFs in the folder \(a.urdf, b.urdf\): none is named leg.urdf or robot.urdf; load the one that goes with "
     r"leg.yaml by its path \(pkm.load\('.*a.urdf'\)\)"),
    ({"a__urdf": rusr_urdf(), "b__yaml": RUSR_YAML, "c__yaml": RUSR_YAML},
     r"2 YAML files in Gepetto's convention in the folder \(b.yaml, c.yaml\): load the one you mean by its path"),
    ({"leg__yaml": RUSR_YAML}, "a YAML in Gepetto's convention with no URDF beside it"),
])
def test_files_that_cannot_be_paired_are_named_and_the_choice_asked_for(tmp_path, files, message):
    folder = write(tmp_path / "m", **files)
    with pytest.raises(SpecError, match=message):
        pkm.load(folder)


def test_a_urdf_beside_several_gepetto_yamls_none_of_its_name_is_declined_with_the_reason(tmp_path):
    folder = write(tmp_path / "m", a__urdf=rusr_urdf(), b__yaml=RUSR_YAML, c__yaml=RUSR_YAML)
    assert find_gepetto(folder / "a.urdf") == "a URDF beside 2 YAML files in Gepetto's convention, none named a.yaml"
    assert find_gepetto(folder / "b.yaml")[:2] == (folder / "a.urdf", folder / "b.yaml")


@pytest.mark.parametrize("spelt", ["motör", "m\u043etor", "Motor"])  # an umlaut, a Cyrillic o, a capital
def test_a_joint_spelt_with_one_different_letter_is_answered_with_the_closest(tmp_path, spelt):
    """A YAML naming ``motör`` for the URDF's ``motor``: the error names 'motor' (the URDF's joints listed too, as
    there are only five), and carries the suggestion."""
    folder = write(tmp_path / "m", robot__urdf=rusr_urdf(), robot__yaml=RUSR_YAML.replace("['motor']", f"['{spelt}']"))
    with pytest.raises(SpecNameError, match=r"did you mean 'motor'\? valid joints: 'motor', 'ujoint_b'") as info:
        pkm.load(folder)
    assert info.value.suggestions == ("motor",) and info.value.source.endswith("robot.yaml")


def test_a_joint_one_letter_off_among_sixty_is_named_without_the_sixty(tmp_path):
    urdf = rusr_urdf().replace("</robot>", "".join(
        f'<link name="extra{k}"/><joint name="free_{k}" type="revolute"><parent link="base_link"/>'
        f'<child link="extra{k}"/><axis xyz="0 0 1"/><limit effort="1" velocity="20"/></joint>' for k in range(60))
        + "</robot>")
    folder = write(tmp_path / "m", robot__urdf=urdf, robot__yaml=RUSR_YAML.replace("['ujoint_b']", "['uj\u00f6int_b']"))
    with pytest.raises(SpecNameError) as info:
        pkm.load(folder)
    assert str(info.value).endswith("joint 'ujöint_b' does not exist in " + str(folder / "robot.yaml")
                                    + " (joint_name, line 4); did you mean 'ujoint_b'? (65 valid joints)")
    assert len(info.value.valid) == 65


def test_exporters_unlimited_limits_are_read_as_none_and_said_so(tmp_path):
    folder = write(tmp_path / "m", robot__urdf=rusr_urdf(velocity="1e8", effort="1e30"), robot__yaml=RUSR_YAML)
    mech = pkm.load(folder)
    assert mech.limits == {}
    assert "joints 'motor', 'ujoint_b', 'rocker_joint': velocity limit 1e8 read as none (|x| >= 1e+06)" in mech.notes
    assert "joints 'motor', 'ujoint_b', 'rocker_joint': effort limit 1e30 read as none (|x| >= 1e+06)" in mech.notes
    with pytest.raises(SpecError, match="limit velocity: value inf is not finite"):
        pkm.load(write(tmp_path / "n", robot__urdf=rusr_urdf(velocity="inf"), robot__yaml=RUSR_YAML))
