"""tests.cli.helpers: a command line run in the test's process reads as ``python -m pkm`` run as a process, and
leaves nothing of its run behind."""

from __future__ import annotations

import logging
import os
import signal
import warnings

import pkm
from pkm.cli.command import Command
from pkm.cli.commands import COMMANDS
from tests.cli.helpers import run, run_process


def test_a_run_in_process_prints_and_exits_as_the_process(tmp_path, built):
    """The toy five-bar's IK across its direct singularity: exit status, stdout (the JSON) and stderr (the
    library's ModeChangeWarning with the command line's hint, shown as the interpreter shows it, not recorded by
    the test runner) equal the process's; a second run shows the warning again, as a fresh process does."""
    mech = built("fivebar")
    spec = pkm.save(mech, tmp_path / "five.closures.toml")
    y = pkm.TaskMap.of(mech).named(mech.q_reference)["y"] - 0.3
    args = ("ik", str(spec), "--pose", f"y={y!r}")
    process = run_process(*args)
    assert process.returncode == 0 and "ModeChangeWarning: " in process.stderr and "--q0 NAME=V" in process.stderr
    for _ in range(2):
        here = run(*args)
        assert (here.returncode, here.stdout, here.stderr) == (process.returncode, process.stdout, process.stderr)


def test_what_a_command_changes_is_put_back_and_what_main_lets_through_is_a_traceback(tmp_path, monkeypatch):
    """A command that runs in ``cwd``, warns, changes the environment, a signal handler, the warning filters and
    logging, then raises: its output, the traceback and exit status 1 (as the interpreter ends the process), and
    none of its changes left; a ``SystemExit`` with a message: the message on stderr, status 1."""
    def command(args):
        print(os.getcwd())
        warnings.warn("said", UserWarning, stacklevel=1)
        os.environ["PKM_TEST_LEFT"] = "1"
        signal.signal(signal.SIGTERM, lambda signum, frame: None)
        warnings.simplefilter("error")
        logging.getLogger().addHandler(logging.StreamHandler())
        logging.getLogger().setLevel(logging.DEBUG)
        raise RuntimeError("boom")

    monkeypatch.setitem(COMMANDS, "list", Command("a test's", lambda p: None, command))
    before = (os.getcwd(), dict(os.environ), signal.getsignal(signal.SIGTERM), list(warnings.filters),
              warnings.showwarning, logging.getLogger().level, list(logging.getLogger().handlers))
    proc = run("list", cwd=tmp_path)
    assert proc.returncode == 1 and proc.stdout == f"{tmp_path}\n"
    assert "UserWarning: said" in proc.stderr and "Traceback (most recent call last)" in proc.stderr
    assert proc.stderr.strip().splitlines()[-1] == "RuntimeError: boom"
    assert (os.getcwd(), dict(os.environ), signal.getsignal(signal.SIGTERM), list(warnings.filters),
            warnings.showwarning, logging.getLogger().level, list(logging.getLogger().handlers)) == before

    def leave(args):
        raise SystemExit("gone")

    monkeypatch.setitem(COMMANDS, "list", Command("a test's", lambda p: None, leave))
    proc = run("list")
    assert (proc.returncode, proc.stdout, proc.stderr) == (1, "", "gone\n")
