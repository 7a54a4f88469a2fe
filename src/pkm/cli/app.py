"""The ``pkm`` parser, built from the registry of commands, and :func:`main`, which runs one and turns a refusal
into one error line and an exit status (see :mod:`pkm.cli`)."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

import pkm
from pkm.cli.commands import COMMANDS
from pkm.cli.output import print_error, seed_hints
from pkm.cli.usage import PROG, Parser, UsageError, debug_option
from pkm.errors import PkmError


def _parser_name(name: str) -> str:
    """The subparser of a command typed as two words (``sweep plot``) is one word (``sweep-plot``)."""
    return name.replace(" ", "-")


def build_parser() -> argparse.ArgumentParser:
    """The ``pkm`` argument parser: one subparser per command of :data:`~pkm.cli.commands.COMMANDS`."""
    ap = Parser(prog=PROG, description="Parallel kinematic machines on Pinocchio: the papers' mechanisms, "
                                       "their kinematics and the papers' results.",
                epilog="Values are SI (m, rad, kg) unless a unit is given: R=120mm, beta=-11deg, z=81cm.")
    ap.add_argument("--debug", action="store_true", help="show the traceback of an error")
    ap.add_argument("--version", action="version", version=f"pkm {pkm.__version__}")
    debug = debug_option()
    sub = ap.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, command in COMMANDS.items():
        prog = f"{PROG} {name}" if " " in name else None  # (None: argparse's own, "pkm list")
        p = sub.add_parser(_parser_name(name), parents=[debug], help=command.help, prog=prog)
        command.add_arguments(p)
        p.set_defaults(func=command.run)
    return ap


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``pkm`` command line; returns the exit status (see :mod:`pkm.cli`)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    extra: list[str] = []
    if "--" in argv:  # the rest goes to the command that takes it (the benchmarks)
        k = argv.index("--")
        argv, extra = argv[:k], argv[k + 1:]
    two = " ".join(argv[:2])
    if " " in two and two in COMMANDS:  # 'pkm sweep plot' is the parser's sweep-plot
        argv = [_parser_name(two)] + argv[2:]
    debug = "--debug" in argv
    seed = False  # (whether the command takes --q0)
    try:
        try:
            args = build_parser().parse_args(argv)
        except SystemExit as exc:  # --help, --version
            return int(exc.code or 0)
        command = {_parser_name(n): c for n, c in COMMANDS.items()}[args.command]
        if extra and not command.passthrough:
            takers = " or ".join(repr(f"{PROG} {n}") for n, c in COMMANDS.items() if c.passthrough)
            raise UsageError(f"arguments after '--' are only for {takers}, got {extra}")
        args.extra = extra
        seed = hasattr(args, "q0")
        if not seed:
            return args.func(args)
        with seed_hints():
            return args.func(args)
    except PkmError as exc:
        return print_error(exc, debug, seed)
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into head & co.
        sys.stdout = open(os.devnull, "w")
        return 0
