"""``pkm export c``: the folder a user builds, the summary, ``--check`` (strict build, compared with pkm), and a
mechanism it cannot export as one error line."""

from __future__ import annotations

import json
import shutil

import pytest

from pkm import cli
from tests.cli.helpers import one_error_line, run
from tests.test_acceptance import ACCEPTANCE


@pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler (cc)")
def test_export_and_check(tmp_path, capsys):
    assert cli.main(["export", "c", str(ACCEPTANCE["knee"][0]), "--out", str(tmp_path / "k"), "--name", "knee_c",
                     "--check", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["name"] == "knee_c" and {f.rsplit("/", 1)[-1] for f in out["files"]} == {
        "knee_c.h", "knee_c.c", "Makefile", "CMakeLists.txt", "main.c", "README.md"}
    worst = {k: v for k, v in out["check"]["largest_difference"].items() if k != "status"}
    assert max(worst.values()) <= 1e-12 and out["check"]["largest_difference"]["status"] == 0
    assert "malloc" not in out["check"]["undefined_symbols"]
    assert out["mode_ids"] == {"fk": {"REFERENCE": 0}, "ik": {"REFERENCE": 0}} and out["check"]["mode_ids"] == []
    assert cli.main(["export", "c", "rrr3", "--out", str(tmp_path / "r")]) == 0
    text = capsys.readouterr().out
    assert "C library rrr3" in text and "fk_step" in text and (tmp_path / "r" / "rrr3.h").exists()
    assert "RRR3_FK_MODE_REFERENCE = 0, RRR3_IK_MODE_REFERENCE = 0, RRR3_IK_MODE_MODE1 = 0" in text


def test_a_mechanism_it_cannot_export_is_one_error_line(tmp_path):
    spec = ACCEPTANCE["ankle"][0]
    shutil.copy(spec.parent / "ankle.urdf", tmp_path)
    (tmp_path / spec.name).write_text(spec.read_text().replace('joints = ["ankle_pitch", "ankle_roll"]',
                                                                'joints = ["ankle_pitch"]'))
    line = one_error_line(run("export", "c", str(tmp_path / spec.name), "--out", str(tmp_path / "out")))
    assert "cannot be exported to C" in line and "do not fix every joint" in line
