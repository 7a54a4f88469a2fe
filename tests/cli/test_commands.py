"""pkm.cli.commands: the registry of subcommands, walked (every command registered, documented and parsed), and
the laziness that keeps ``pkm --help`` fast."""

from __future__ import annotations

import pkgutil
import re
import sys
from importlib import import_module

import pytest

from pkm import cli
from pkm.cli import commands
from pkm.cli.command import Command
from tests import bounded


def test_every_command_module_is_registered():
    """Each module of pkm.cli.commands defines commands that are in COMMANDS (adding a command: a module, a line)."""
    registered = {id(c) for c in commands.COMMANDS.values()}
    for info in pkgutil.iter_modules(commands.__path__):
        module = import_module(f"pkm.cli.commands.{info.name}")
        defined = [v for v in vars(module).values() if isinstance(v, Command)]
        assert defined, f"pkm.cli.commands.{info.name} defines no Command"
        assert all(id(c) in registered for c in defined), f"pkm.cli.commands.{info.name}: a command not registered"


@pytest.mark.parametrize("name", list(commands.COMMANDS))
def test_every_registered_command_has_help_and_parses(name, capsys):
    """``pkm NAME --help`` (two words as typed: ``pkm sweep plot``) exits 0 and prints the command's usage."""
    command = commands.COMMANDS[name]
    assert command.help and callable(command.add_arguments) and callable(command.run)
    assert cli.main([*name.split(), "--help"]) == 0
    assert f"usage: pkm {name}" in capsys.readouterr().out


def test_help_lists_the_commands_in_registry_order(capsys):
    assert cli.main(["--help"]) == 0
    out = capsys.readouterr().out
    listed = [n.replace(" ", "-") for n in commands.COMMANDS]
    where = [re.search(rf"^    {re.escape(n)}(\s|$)", out, re.M).start() for n in listed]
    assert where == sorted(where)


def test_help_imports_no_heavy_module():
    """``pkm --help`` builds every command's parser without importing Pinocchio, matplotlib, Dask or meshcat (each
    command imports them when it runs)."""
    code = ("import sys; from pkm.cli import main; main(['--help']); "
            "print(sorted(m for m in ('pinocchio', 'matplotlib', 'dask', 'meshcat', 'pkm.viz') if m in sys.modules))")
    proc = bounded.run([sys.executable, "-c", code], cpu=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == "[]"
