"""The command line's own failure and grammar: :class:`UsageError` (exit status 2) and the argparse parser that
raises it instead of printing its usage and exiting."""

from __future__ import annotations

import argparse

from pkm.errors import InvalidInputError

PROG = "pkm"
"""The command's name, as its error lines and its usage print it."""


class UsageError(InvalidInputError):
    """The command line is malformed (exit status 2)."""

    def __init__(self, message: str, value: object = None):
        super().__init__("usage", message, value)

    def __str__(self) -> str:
        return str(self.args[0]).removeprefix("usage: ")


class Parser(argparse.ArgumentParser):
    """argparse that raises :class:`UsageError` instead of printing usage and exiting."""

    def error(self, message: str):
        raise UsageError(f"{message} (see '{self.prog} --help')")


def debug_option() -> Parser:
    """The parent parser of every (sub)command: ``--debug`` accepted after the command's name too."""
    debug = Parser(add_help=False)
    debug.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help="show the traceback of an error")
    return debug
