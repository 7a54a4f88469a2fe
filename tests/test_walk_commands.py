"""``tools/walk_commands.py`` (run by CI: every documented command on every shipped mechanism with its defaults)
walks every command: each subcommand of ``pkm --help`` and each ``pkm X`` of the docs' fenced lines has a recipe,
so that a new command cannot be left out of the walk; its verdicts are right on known cases; one cell runs."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from pkm.cli.commands import COMMANDS

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))
import walk_commands  # (tools/ is no package: imported from its folder)


def test_every_command_and_every_documented_command_has_a_recipe():
    import argparse

    from pkm.cli.app import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    assert {walk_commands.command_of([name]) for name in sub.choices} == set(walk_commands.RECIPES) == set(COMMANDS)
    lines = list(walk_commands.documented_lines())
    documented = {walk_commands.command_of(argv) for _, line, _ in lines for argv in walk_commands.split_line(line)}
    assert len(lines) >= 20 and {"calibrate plan", "sweep plot", "sweep best", "identify"} <= documented
    assert documented <= set(COMMANDS), documented - set(COMMANDS)  # (a documented command pkm does not have)
    for recipe in walk_commands.RECIPES.values():  # (a skipped command says why; a run one has steps)
        assert bool(recipe.skip) != bool(recipe.steps), recipe


def test_a_documented_line_splits_into_its_commands():
    line = "pkm excite delta --out exc.csv && pkm identify delta exc.csv --consistent   # the tour's"
    assert walk_commands.split_line(line) == [["excite", "delta", "--out", "exc.csv"],
                                              ["identify", "delta", "exc.csv", "--consistent"]]
    assert walk_commands.command_of(["calibrate", "plan", "delta"]) == "calibrate plan"
    assert walk_commands.command_of(["sweep-best", "d.parquet"]) == "sweep best"
    assert walk_commands.command_of(["calibrate", "delta", "d.csv"]) == "calibrate"


def _proc(code: int, out: str = "", err: str = "") -> subprocess.CompletedProcess:
    return subprocess.CompletedProcess([], code, out, err)


def test_the_verdicts():
    judge = walk_commands.judge
    assert judge(_proc(0, '{"status": "ok"}')) == ("ok", "")
    assert judge(_proc(0, '{"status": "outside_limits"}'))[0] == "FAILED"  # (a success past a limit)
    assert judge(_proc(1, err="pkm: error: no convergence; give a seed with --q0 NAME=V")) == (
        "refused", "no convergence; give a seed with --q0 NAME=V")
    assert judge(_proc(1, err="pkm: error: the solver did not converge"))[0] == "refused*"  # (no fix named)
    assert judge(_proc(1, err="Traceback (most recent call last):\n  ...\nValueError: x"))[0] == "FAILED"
    assert judge(_proc(1, err="ValueError: x"))[0] == "FAILED"  # (no pkm error line)
    assert judge(_proc(-9))[0] == "FAILED"


def test_one_cell_runs(tmp_path):
    info = walk_commands.mechanism_info("rrr3")
    cell = walk_commands.run_cell(walk_commands.Cell("fk", "rrr3"),
                                  [walk_commands.fill(s, info) for s in walk_commands.RECIPES["fk"].steps])
    assert (cell.verdict, cell.argv[:2]) == ("ok", ["fk", "rrr3"]), cell
