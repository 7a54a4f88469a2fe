"""``pkm report [--out DIR] [--paper NAME ...] [--no-figures] [--no-series]``: reproduce the papers
(summary.json, report.md, figures)."""

from __future__ import annotations

import argparse

from pkm.cli.command import Command
from pkm.cli.usage import UsageError


def add_arguments(p: argparse.ArgumentParser) -> None:
    from pkm.papers import names as paper_names

    p.add_argument("--out", metavar="DIR", default="out", help="output directory (default: out)")
    p.add_argument("--paper", metavar="NAME", action="append", help=f"only these papers ({', '.join(paper_names())})")
    p.add_argument("--no-figures", action="store_true", help="skip the figures")
    p.add_argument("--no-series", action="store_true", help="skip the CSV series")


def run(args: argparse.Namespace) -> int:
    from pkm import papers, report

    names = tuple(args.paper) if args.paper else papers.names()
    for n in names:
        papers.module(n)  # UnknownNameError listing the papers
    if len(set(names)) != len(names):
        raise UsageError(f"name each paper once, got {list(names)}")
    result = report.run(args.out, names, figures=not args.no_figures, series=not args.no_series)
    print(report.format_table(result))
    return 0


COMMAND = Command("reproduce the papers: summary.json, report.md, figures", add_arguments, run)
