"""``pkm convert IN OUT [--to FORMAT]``: every file written and what the target cannot hold printed; the result
loads back; an existing file, an unknown suffix or format, a mechanism the format cannot express: one error line."""

from __future__ import annotations

import json

import pkm
from pkm import cli


def test_convert_prints_every_file_and_what_the_format_cannot_hold(tmp_path, capsys):
    assert cli.main(["convert", "fivebar", str(tmp_path / "five.yaml")]) == 0
    text = capsys.readouterr().out
    assert f"wrote {tmp_path / 'five.yaml'}" in text and f"wrote {tmp_path / 'five.urdf'}" in text
    assert "not expressible in gepetto, left out: task: end effector 'tip_1'" in text
    back = pkm.load(tmp_path / "five.yaml")
    assert back.actuated_names == pkm.load("fivebar").actuated_names
    assert cli.main(["convert", str(tmp_path / "five.yaml"), str(tmp_path / "mj"), "--to", "mjcf", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["format"] == "mjcf" and out["files"] == [str(tmp_path / "mj" / "five.xml")]
    assert not any(d.startswith("reference configuration") for d in out["dropped"])  # (its keyframe is read back)
    assert pkm.load(tmp_path / "mj" / "five.xml").actuated_names == back.actuated_names
    assert cli.main(["convert", str(tmp_path / "mj" / "five.xml"), str(tmp_path / "again.closures.toml")]) == 0
    assert "left out" not in capsys.readouterr().out and (tmp_path / "again.urdf").is_file()


def test_what_convert_refuses_is_one_error_line(tmp_path, capsys):
    (tmp_path / "five.xml").write_text("")
    for argv, message in ((["fivebar", str(tmp_path / "five.xml")], "five.xml exists; pass --force"),
                          (["fivebar", str(tmp_path / "five.stl")], "suffix '.stl' names no format pkm writes; "
                                                                     "known: pkm (.closures.toml, .toml); mjcf"),
                          (["fivebar", str(tmp_path / "x"), "--to", "urdf"], "format 'urdf' does not exist")):
        assert cli.main(["convert", *argv]) != 0
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("pkm: error: ") and message in err[0], err
    assert cli.main(["convert", "fivebar", str(tmp_path / "five.xml"), "--force"]) == 0
    assert "<connect" in (tmp_path / "five.xml").read_text()


def test_the_help_names_every_writer_and_its_suffixes():
    """``pkm convert --help``'s formats (a table kept apart, so that the help imports no model code) are the writers'."""
    from pkm.cli.commands.convert import FORMATS
    from pkm.core.formats.writers import WRITERS

    assert list(FORMATS) == list(WRITERS)
    for name, writer in WRITERS.items():
        assert FORMATS[name].split(" ")[0] == "/".join(writer.suffixes), name
