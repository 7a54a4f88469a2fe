"""The command line's own failure and grammar: :class:`UsageError` (exit status 2) and the argparse parser that
raises it instead of printing its usage and exiting, and whose help may be computed when it is printed
(:func:`late_help`, :func:`late_epilog`: what needs an import or a model stays out of every other run)."""

from __future__ import annotations

import argparse
from collections.abc import Callable

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

    def format_help(self) -> str:
        """argparse's help, the texts given as functions (:func:`late_help`, :func:`late_epilog`) computed now."""
        for action in self._actions:
            text = getattr(action, "late_help", None)
            if text is not None:
                action.help = text()
        text = getattr(self, "late_epilog", None)
        if text is not None:
            self.epilog = text()
        return super().format_help()


def late_help(action: argparse.Action, text: Callable[[], str]) -> argparse.Action:
    """Give ``action`` the help ``text()``, computed only when the help is printed; returns ``action``."""
    action.late_help = text  # type: ignore[attr-defined]
    return action


def late_epilog(parser: argparse.ArgumentParser, text: Callable[[], str]) -> None:
    """Give ``parser`` (a :class:`Parser`) the epilog ``text()``, computed only when its help is printed, and kept as
    it is written (its own line breaks)."""
    parser.late_epilog = text  # type: ignore[attr-defined]
    parser.formatter_class = argparse.RawDescriptionHelpFormatter


def debug_option() -> Parser:
    """The parent parser of every (sub)command: ``--debug`` accepted after the command's name too."""
    debug = Parser(add_help=False)
    debug.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help="show the traceback of an error")
    return debug
