"""pkm.cli.app: the parser built from the registry and main's exit statuses and error lines, as ``python -m pkm``
gives them (tests.cli.helpers.run); every subcommand takes one's own closure spec file."""

from __future__ import annotations

import json

import pytest

import pkm
from tests.cli.helpers import one_error_line, run


@pytest.mark.parametrize("args,status,message", [
    (("fk", "delta", "--joints", "motor_9=1"), 2, "valid actuated joints: 'motor_1', 'motor_2', 'motor_3'"),
    (("ik", "scara", "--pose", "x=0"), 2, "mechanism 'scara' does not exist in the registry, nor is it a file"),
    (("ik", "delta", "--param", "Rb=0.1", "--pose", "z=-0.36"), 2, "parameter 'Rb' does not exist in delta"),
    (("ik", "delta", "--param", "R=3deg", "--pose", "z=-0.36"), 2, "'deg' is an angle unit but R is in [m]"),
    (("ik", "delta", "--pose", "z=-36in"), 2, "unknown unit 'in'"),
    (("ik", "delta", "--pose", "z"), 2, "'z' must read NAME=VALUE"),
    (("ik", "delta", "--param", "R=-0.1", "--pose", "z=-0.36"), 1, "R: must be"),
    (("ik", "delta", "--pose", "z=-0.36", "--branch", "up"), 2, "'knee_out', 'knee_in'"),
    (("map", "rrr3", "--axis", "x=0:1"), 2, "expected NAME=START:STOP:COUNT"),
    (("map", "rrr3", "--axis", "q=0:1:3"), 2, "valid task coordinates: 'x', 'y', 'yaw'"),
])
def test_bad_command_lines_give_one_helpful_line(args, status, message):
    """Unknown names, bad units, a missing '=' exit 2, an invalid parameter value exits 1; one line each."""
    proc = run(*args)
    assert proc.returncode == status
    assert message in one_error_line(proc)


def test_help_exits_zero():
    """``pkm --help`` prints the commands and exits 0; no command at all is a usage error (2)."""
    ok = run("--help")
    assert ok.returncode == 0 and all(c in ok.stdout for c in ("list", "preview", "ik", "fk", "report", "bench"))
    bad = run()
    assert bad.returncode == 2 and "required" in one_error_line(bad)


def test_every_subcommand_takes_a_closure_spec_file(tmp_path):
    """The toy five-bar saved as files (pkm.save) is solved, run forward and previewed from its path; --param is
    refused for a file, an unknown name says that a path is accepted."""
    from tests import fivebar

    spec = pkm.save(fivebar.build(), tmp_path / "five.closures.toml")
    ik = run("ik", str(spec), "--pose", "x=1cm", "y=34cm")
    assert ik.returncode == 0, ik.stderr
    out = json.loads(ik.stdout)
    assert out["mechanism"] == "fivebar" and out["residual"] <= 1e-9
    fk = run("fk", str(spec), "--joints", *(f"{k}={v}" for k, v in out["actuated"].items()))
    assert fk.returncode == 0, fk.stderr
    assert abs(json.loads(fk.stdout)["task"]["x"] - 0.01) < 1e-9
    page = tmp_path / "five.html"
    assert run("preview", str(spec), "--html", str(page)).returncode == 0 and page.stat().st_size > 10_000
    refused = run("ik", str(spec), "--param", "d=1", "--pose", "x=0")
    assert refused.returncode == 2 and "states its own" in refused.stderr
    unknown = run("ik", "nosuch", "--pose", "x=0")
    assert unknown.returncode != 0 and "closure spec's path" in unknown.stderr


def _subparsers():
    """``{name: parser}`` of every subcommand of :func:`pkm.cli.build_parser`."""
    import argparse

    from pkm.cli import build_parser

    ap = build_parser()
    return next(a for a in ap._actions if isinstance(a, argparse._SubParsersAction)).choices


def test_every_mech_help_names_every_input_from_the_formats_tables(monkeypatch):
    """Every subcommand taking MECH gives it the one help, read when printed from the tables: the registry, each
    source of shipped robots and installed packages' models, each registered model-file format with its suffixes;
    a format registered later is named too (no drift)."""
    import re

    from pkm.cli.mechanism import mech_help
    from pkm.core.formats.base import FORMATS, Format
    from pkm.core.formats.catalogue import CATALOGUE
    from pkm.core.formats.packages import PACKAGE_MODELS

    monkeypatch.setitem(FORMATS, "step", Format("step", (".stp", ".step"), "step", "nowhere:read"))
    text = " ".join(mech_help().split())
    for needed in [*pkm.MECHANISMS, "STEP (.stp .step)", "MJCF (.xml .mjcf)", "closure spec", "Gepetto",
                   *{n.partition(":")[0] + ":<" for n in [*CATALOGUE, *PACKAGE_MODELS]}]:
        assert needed in text, needed
    takers = 0
    for name, parser in _subparsers().items():
        helped = " ".join(re.sub(r"-\n\s*", "-", parser.format_help()).split())
        if " MECH " in helped:
            takers += 1
            assert text in helped, name
    assert takers >= 12  # (list, preview, ik, fk, map, dynamics, simulate, excite, identify, capability, export, sweep)


def test_each_command_that_solves_takes_the_seed_and_a_warning_asking_for_one_names_it(tmp_path, capsys, built):
    """The solvers' messages ask for a seed nearer the target (q0): every command that closes the loops or solves
    the IK from a seed takes ``--q0``; the toy five-bar's IK across its direct singularity (which the library warns
    of, ModeChangeWarning) says, on the command line, that the seed is ``--q0``."""
    from pkm import cli
    from pkm.errors import ModeChangeWarning

    parsers = _subparsers()
    for name in ("ik", "fk", "preview", "dynamics", "capability", "map", "simulate"):
        assert "--q0" in parsers[name].format_help(), name
    mech = built("fivebar")
    spec = pkm.save(mech, tmp_path / "five.closures.toml")
    y = pkm.TaskMap.of(mech).named(mech.q_reference)["y"] - 0.3
    with pytest.warns(ModeChangeWarning) as record:
        assert cli.main(["ik", str(spec), "--pose", f"y={y!r}"]) == 0
    assert "seed nearer the target (q0)" in str(record[0].message) and "the seed is --q0 NAME=V" in \
        str(record[0].message)
    capsys.readouterr()
