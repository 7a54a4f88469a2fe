"""The loaders (:mod:`pkm.core.formats.load`): :func:`load_path` tries :data:`READERS` in order and loads with the
first that takes the path (the same mechanism as that reader's own route), or lists why each declined, one line
each; a model file alone must name its actuators, else the message says how to write a spec."""

from __future__ import annotations

from pathlib import Path

import pytest

from pkm.core.formats.load import READERS, load_gepetto, load_hyrodyn, load_model_file, load_path
from pkm.core.model.builder import from_files
from pkm.core.model.compare import mechanism_differences
from pkm.errors import SpecError

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
FOURBAR = EXAMPLES / "mjcf_fourbar" / "fourbar.xml"
GEPETTO = EXAMPLES / "gepetto_fivebar"
KNEE = EXAMPLES / "knee"
HYRODYN = Path(__file__).resolve().parents[2] / "data" / "hyrodyn_fourbar"


def _takers(path: Path) -> list[int]:
    return [k for k, reader in enumerate(READERS) if not isinstance(reader.claim(path), str)]


def test_the_readers_are_tried_in_their_stated_order():
    """Gepetto's convention first, then HyRoDyn's, then a closure spec, then a model file: the order the module
    documents."""
    assert [r.name for r in READERS] == ["Gepetto URDF + YAML", "HyRoDyn URDF + submechanisms.yml", "pkm closure spec",
                                         "model file (URDF, MJCF, SDF)"]


def _gepetto(_path: Path):
    return load_gepetto(GEPETTO / "robot.urdf", GEPETTO / "robot.yaml")


@pytest.mark.parametrize("path, taker, route", [
    (GEPETTO, 0, _gepetto),
    (GEPETTO / "robot.yaml", 0, _gepetto),
    (HYRODYN, 1, lambda _: load_hyrodyn(HYRODYN / "fourbar.urdf", HYRODYN / "submechanisms.yml")),
    (HYRODYN / "fourbar.urdf", 1, lambda _: load_hyrodyn(HYRODYN / "fourbar.urdf", HYRODYN / "submechanisms.yml")),
    (KNEE / "knee.closures.toml", 2, from_files),
    (FOURBAR, 3, load_model_file),
], ids=["gepetto folder", "gepetto yaml", "hyrodyn folder", "hyrodyn urdf", "spec", "mjcf"])
def test_the_first_reader_that_takes_a_path_loads_it(path, taker, route):
    """Which readers take the path (each one's claim): the first is the expected one, and load_path gives the same
    mechanism as that reader's own loader (pkm.core.model.compare)."""
    assert _takers(path)[0] == taker
    assert mechanism_differences(load_path(path), route(path)) == []


def test_a_closure_spec_is_recognised_by_its_content_whatever_its_suffix(tmp_path):
    """A spec saved as .cfg (TOML with a format key, beside its URDF) is taken by the spec reader alone and loads as
    the same spec named .toml; TOML without the key is declined saying which key it lacks."""
    for name in ("knee.urdf", "knee.closures.toml"):
        (tmp_path / name).write_text((KNEE / name).read_text())
    (tmp_path / "knee.cfg").write_text((KNEE / "knee.closures.toml").read_text())
    assert _takers(tmp_path / "knee.cfg") == [2]
    assert mechanism_differences(load_path(tmp_path / "knee.cfg"), from_files(KNEE / "knee.closures.toml")) == []
    (tmp_path / "other.cfg").write_text("x = 1\n")
    assert READERS[2].claim(tmp_path / "other.cfg") == 'TOML without the key format = "pkm.closures/1"'


@pytest.mark.parametrize("name, content, reasons", [
    ("page.txt", "<html/>", {2: "not TOML", 3: "XML whose root element is <html>"}),
    ("data.bin", b"\xff\xfe\x00abc", {2: "not a readable text file", 3: "not XML"}),
    ("plain.txt", "x = 1\n", {2: "TOML without the key format", 3: "not XML"}),
])
def test_a_path_no_reader_takes_lists_each_readers_reason_on_its_own_line(tmp_path, name, content, reasons):
    """The SpecError's first line names the path; then exactly one line per reader, in order, '  <reader>: <why>'
    (the model-file line naming every root element it knows)."""
    path = tmp_path / name
    path.write_bytes(content) if isinstance(content, bytes) else path.write_text(content)
    with pytest.raises(SpecError) as info:
        load_path(path)
    lines = str(info.value).splitlines()
    assert lines[0] == f"{path}: no reader takes it:" and len(lines) == 1 + len(READERS)
    for reader, line in zip(READERS, lines[1:]):
        assert line.startswith(f"  {reader.name}: ") and len(line) > len(reader.name) + 4
    for k, why in reasons.items():
        assert lines[1 + k].startswith(f"  {READERS[k].name}: {why}"), lines[1 + k]
    assert all(root in lines[4] for root in ("<robot>", "<mujoco>", "<sdf>"))


def test_nothing_at_the_path_is_said_before_any_reader_is_tried(tmp_path):
    """A missing path: 'no such file or folder', not the readers' list."""
    with pytest.raises(SpecError, match=r"missing\.xml: no such file or folder$"):
        load_path(tmp_path / "missing.xml")


@pytest.mark.parametrize("path, fmt", [(EXAMPLES / "sdf_slider_crank" / "slider_crank.sdf", "SDF"),
                                       (KNEE / "knee.urdf", "URDF")])
def test_a_model_file_without_actuators_says_to_write_a_spec(path, fmt):
    """SDF never names actuators, a URDF neither: load_model_file (and load_path, which hands it the file) says
    which spec to write beside it and the command that writes one."""
    for load in (load_model_file, load_path):
        with pytest.raises(SpecError, match="names no actuated joint") as info:
            load(path)
        message = str(info.value)
        assert f"the {fmt} file names no actuated joint" in message
        assert f"urdf = '{path.name}' and actuated = [...]" in message and f"`pkm spec init {path}`" in message


def test_a_model_file_alone_is_its_loops_and_actuators_with_the_actuators_as_task():
    """The MJCF four-bar alone: its actuator driven, the task its actuated joint, no end effector, its loop from the
    file and its reference assembled (the spec states only the file's own reference)."""
    mech = load_model_file(FOURBAR)
    assert mech.actuated_names == ("crank_joint",) and mech.spec.end_effector is None
    assert mech.spec.task.joints == ("crank_joint",) and mech.spec.task.components == ()
    assert [c.name for c in mech.spec.closures] == ["pin_c"] and mech.spec.description.endswith("(MJCF)")


def test_a_gepetto_yaml_must_be_paired_with_a_urdf():
    """load_gepetto with an MJCF model: refused, naming both files and the convention."""
    with pytest.raises(SpecError, match=r"fourbar.xml: the model beside robot.yaml is MJCF, not URDF: Gepetto's "
                                        r"convention pairs a YAML with a URDF"):
        load_gepetto(FOURBAR, GEPETTO / "robot.yaml")
