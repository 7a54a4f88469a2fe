"""The dispatcher of model files (:mod:`pkm.core.formats.imported`): the root element decides the format before the
suffix; :func:`with_file` merges what a file states into a spec (the spec's own entries win, a closure in both is
refused); :func:`spec_skeleton` writes a spec that loads as it is exactly when the file states loops and actuators."""

from __future__ import annotations

import dataclasses
import tomllib
from pathlib import Path

import pytest

import pkm
from pkm.core.formats.base import Imported
from pkm.core.formats.imported import import_model, spec_skeleton, with_file
from pkm.core.formats.load import load_model_file
from pkm.core.model.compare import mechanism_differences
from pkm.core.model.spec import Closure, ClosureSpec, TaskSpec
from pkm.errors import SpecError

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
KNEE = EXAMPLES / "knee" / "knee.urdf"
FOURBAR = EXAMPLES / "mjcf_fourbar" / "fourbar.xml"  # (its leading comment mentions <equality><connect>)
SLIDER = EXAMPLES / "sdf_slider_crank" / "slider_crank.sdf"


@pytest.mark.parametrize("source, name, fmt", [
    (KNEE, "knee.xml", "urdf"),  # a URDF named as MJCF
    (KNEE, "knee.txt", "urdf"),
    (FOURBAR, "fourbar.urdf", "mjcf"),  # an MJCF named as URDF
    (FOURBAR, "fourbar.model", "mjcf"),
    (SLIDER, "slider.xml", "sdf"),
])
def test_the_root_element_decides_before_the_suffix(tmp_path, source, name, fmt):
    """A file is read by the format of its root element whatever its suffix (comments and the XML declaration
    skipped), and gives what the same file under its own suffix gives."""
    path = tmp_path / name
    path.write_text(source.read_text())
    imported, own = import_model(path), import_model(source)
    assert imported.format == own.format == fmt
    assert (imported.urdf, imported.closures, imported.actuated, imported.name) == \
        (own.urdf, own.closures, own.actuated, own.name)


def test_a_file_of_no_known_root_is_read_as_urdf_and_refused_saying_so(tmp_path):
    """An unknown suffix and root: the default reader (URDF) refuses it naming the root it found and the one it
    expected; text that is not XML is refused as not well-formed."""
    (tmp_path / "page.txt").write_text("<?xml version='1.0'?><!-- <robot> --><html><body/></html>")
    with pytest.raises(SpecError, match=r"page.txt: root element is <html>, expected <robot>"):
        import_model(tmp_path / "page.txt")
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(SpecError, match="not well-formed XML"):
        import_model(tmp_path / "notes.txt")


def _spec(**changes) -> ClosureSpec:
    base = ClosureSpec(mechanism="m", urdf="m.xml", end_effector=None, actuated=("a",),
                       closures=(Closure("spec_loop", "point", "f1", "f2"),), task=TaskSpec((), ("a",)),
                       reference={"a": (0.5,)}, joint_types={"j": "spherical"})
    return dataclasses.replace(base, **changes)


def _imported(**changes) -> Imported:
    base = Imported("<robot/>", (Closure("file_loop", "point", "g1", "g2"),), {"j": "universal_zy", "k": "fixed"},
                    (), "m", "mjcf", floating_base="base", reference={"a": (9.0,), "base": (0.0,) * 7})
    return dataclasses.replace(base, **changes)


def test_with_file_adds_what_the_file_states_the_spec_winning():
    """The file's loops come first, then the spec's; joint types, floating base and reference are merged with the
    spec's entries kept where both state one."""
    merged = with_file(_spec(), _imported(), "m.closures.toml")
    assert [c.name for c in merged.closures] == ["file_loop", "spec_loop"]
    assert merged.joint_types == {"j": "spherical", "k": "fixed"}
    assert merged.floating_base == "base" and with_file(_spec(floating_base="mine"), _imported(), "s").floating_base \
        == "mine"
    assert merged.reference == {"a": (0.5,), "base": (0.0,) * 7}
    assert (merged.actuated, merged.task, merged.urdf) == (("a",), TaskSpec((), ("a",)), "m.xml")


def test_with_file_returns_the_spec_itself_when_the_file_adds_nothing():
    """A file with no loops, joint types, floating base or reference (a URDF) leaves the spec object unchanged."""
    spec = _spec()
    assert with_file(spec, _imported(closures=(), joint_types={}, floating_base=None, reference={}), "s") is spec


def test_with_file_refuses_a_closure_named_in_both():
    """A loop named in the spec and in the file: SpecError naming the loop and the file, asking to rename the spec's."""
    clash = _spec(closures=(Closure("file_loop", "point", "f1", "f2"),))
    with pytest.raises(SpecError, match=r"m.closures.toml: closure 'file_loop' is both in the spec and in 'm.xml'; "
                                        r"rename the spec's"):
        with_file(clash, _imported(), "m.closures.toml")


def test_the_skeleton_of_a_urdf_is_valid_toml_to_fill_in():
    """A URDF states no loops and no actuators: incomplete; the text is TOML naming the file, with an empty actuated
    list and one [[closure]] between frames of the model, which the spec loader refuses until actuated is filled."""
    text, complete = spec_skeleton(KNEE)
    raw = tomllib.loads(text)
    assert not complete and "# TODO" in text
    assert (raw["format"], raw["mechanism"], raw["urdf"], raw["actuated"]) == ("pkm.closures/1", "knee", "knee.urdf",
                                                                               [])
    frames = {f.name for f in pkm.load(KNEE.with_name("knee.closures.toml")).model.frames}
    (loop,) = raw["closure"]
    assert loop["type"] == "point" and {loop["frame_a"], loop["frame_b"]} <= frames
    with pytest.raises(SpecError, match="'actuated' must name at least one joint"):
        ClosureSpec.from_toml(text, "skeleton")


def test_the_skeleton_of_an_mjcf_file_loads_as_the_file_alone(tmp_path):
    """The four-bar states its loop and its motor: the skeleton is complete, its loop only a comment, and, written
    beside the file, it loads to the same mechanism as the file alone (pkm.core.model.compare)."""
    text, complete = spec_skeleton(FOURBAR)
    assert complete and "# TODO" not in text and "#   pin_c: point closure between pin_c_a and pin_c_b" in text
    (tmp_path / "fourbar.xml").write_text(FOURBAR.read_text())
    (tmp_path / "fourbar.closures.toml").write_text(text)
    assert mechanism_differences(pkm.load(tmp_path / "fourbar.closures.toml"), load_model_file(FOURBAR)) == []


def test_the_skeleton_of_an_sdf_file_needs_only_its_actuators(tmp_path):
    """SDF names no actuators: incomplete, with the file's two loops as comments; filling in the one TODO line gives
    a spec that loads with those loops."""
    text, complete = spec_skeleton(SLIDER)
    assert not complete and text.count("# TODO") == 1
    (tmp_path / SLIDER.name).write_text(SLIDER.read_text())
    spec = tmp_path / "slider_crank.closures.toml"
    spec.write_text("\n".join('actuated = ["crank_joint"]' if line.startswith("actuated = []") else line
                              for line in text.splitlines()))
    mech = pkm.load(spec)
    assert mech.actuated_names == ("crank_joint",) and [c.name for c in mech.spec.closures] == ["wrist", "wrist_axis"]


def test_the_skeleton_lists_the_files_drives_and_an_example_that_loads_uncommented(tmp_path):
    """``spec_skeleton`` writes each actuated joint's drive as the file states it (commented: the file's values
    count without it), else a commented example, which loads once uncommented."""
    example = Path(__file__).resolve().parents[3] / "examples" / "mjcf_fourbar" / "fourbar.xml"
    text = example.read_text().replace('<joint name="crank_joint" ', '<joint name="crank_joint" armature="0.004" ')
    (tmp_path / "geared").mkdir()
    (tmp_path / "geared" / "fourbar.xml").write_text(text)
    skeleton, _ = spec_skeleton(tmp_path / "geared" / "fourbar.xml")
    assert "# [actuators.crank_joint]\n# armature = 0.004  # (from the file)" in skeleton
    bare, complete = spec_skeleton(example)
    assert complete and "# [actuators.crank_joint]  # for example:" in bare
    head, rest = bare.split("# [actuators.crank_joint]  # for example:\n")
    block, tail = rest.split("\n\n", 1)
    filled = head + "[actuators.crank_joint]\n" + "\n".join(ln[2:] for ln in block.splitlines()) + "\n\n" + tail
    (tmp_path / "fourbar.xml").write_text(example.read_text())
    (tmp_path / "fourbar.closures.toml").write_text(filled)
    (drive,) = pkm.load(tmp_path / "fourbar.closures.toml").actuators
    assert (drive.gear_ratio, drive.peak_effort, drive.velocity_limit) == (50.0, 60.0, 6.0)
