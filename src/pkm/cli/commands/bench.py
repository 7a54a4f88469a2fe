"""``pkm bench [NAME ...] [--json] [--quick] [-- ARGS]``: the benchmarks of :mod:`pkm.bench`, ratios against
baselines; the arguments after ``--`` go to each benchmark."""

from __future__ import annotations

import argparse
import json
from typing import Any

from pkm.cli.command import Command
from pkm.cli.usage import Parser


def add_arguments(p: argparse.ArgumentParser) -> None:
    from pkm.bench import NAMES as BENCHMARKS

    p.epilog = "Arguments after '--' go to each benchmark, e.g. pkm bench kinematics -- -n 20."
    p.add_argument("names", metavar="NAME", nargs="*", help=f"{', '.join(BENCHMARKS)} (default: all)")
    p.add_argument("--json", action="store_true", help="print the results of all as one JSON object")
    p.add_argument("--quick", action="store_true", help="small sizes: checks that they run, in seconds")


def run(args: argparse.Namespace) -> int:
    from pkm import bench

    for n in args.names:
        bench.module(n)  # UnknownNameError listing the benchmarks
    results: dict[str, Any] = {}
    for n in args.names or bench.NAMES:
        mod = bench.module(n)
        options = bench.arguments(mod, args.extra, quick=args.quick, cls=Parser)  # UsageError if refused
        if not args.json:
            print(f"== bench {n}", flush=True)
        results[n] = mod.run(options)
        if not args.json:
            print(mod.table(results[n]), flush=True)
    if args.json:
        print(json.dumps(results, indent=2))
    return 0


COMMAND = Command("run the benchmarks (pkm.bench): ratios against baselines", add_arguments, run, passthrough=True)
