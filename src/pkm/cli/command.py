"""One subcommand of ``pkm``: its help line, the arguments it adds to its parser and the function that runs it.

Each command module defines one (``COMMAND``); :data:`pkm.cli.commands.COMMANDS` registers it under its name.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True)
class Command:
    """A subcommand, as :func:`pkm.cli.build_parser` and :func:`pkm.cli.main` use it.

    Attributes:
        help: Its line in ``pkm --help``.
        add_arguments: Adds its arguments to its parser (and its epilog, its own actions).
        run: Runs it on the parsed command line; returns the exit status (0), or raises a
            :class:`~pkm.errors.PkmError` (the status of :func:`pkm.cli.output.print_error`).
        passthrough: Whether it takes the arguments after ``--`` (given as ``args.extra``).
    """

    help: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]
    passthrough: bool = False
