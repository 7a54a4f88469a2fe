"""``pkm sweep MECH NAME=RANGE ... --objective SPEC ...``: a design sweep on Dask (objectives of every design,
Parquet results); ``pkm sweep plot FILE`` and ``pkm sweep best FILE --by OBJ`` read its results."""

from __future__ import annotations

import argparse
import json

import numpy as np

import pkm
from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_help
from pkm.cli.parsing import parse_params, split_item
from pkm.cli.usage import UsageError
from pkm.report import jsonable


def _objective_names() -> list[str]:
    from pkm.sweeps.objectives import OBJECTIVES

    return list(OBJECTIVES)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.epilog = ("Objectives: " + ", ".join(_objective_names()) + "; options as gci:step=1cm, a column name as "
                "label=SPEC, or path/to/file.py:function. A killed sweep run again with the same --out resumes.")
    add_mechanism_help(p.add_argument("mechanism", metavar="MECH"), after=" (a model read from files: its joint "
                       "origins JOINT.x ... JOINT.yaw are the parameters)")
    p.add_argument("parameters", metavar="NAME=RANGE", nargs="*",
                   help="grid: a=30cm:80cm:11 (START:STOP:COUNT) or a=0.3; sampled: a=30cm:80cm (LOW:HIGH)")
    p.add_argument("--objective", metavar="SPEC", action="append", required=True, help="an objective (repeat)")
    p.add_argument("--sample", choices=("grid", "sobol", "lhs"), default="grid", help="how to draw the designs")
    p.add_argument("--n", type=int, help="designs to draw (sobol, lhs)")
    p.add_argument("--seed", type=int, help="the samples' seed (default: drawn and recorded in the results)")
    p.add_argument("--table", metavar="FILE", help="explicit designs: a .csv (header of parameter names) or .parquet")
    p.add_argument("--fixed", metavar="K=V", action="extend", nargs="+", default=[],
                   help="parameters not swept (default: the paper's design)")
    p.add_argument("--out", metavar="FILE", help="the results, .parquet (resumed if it holds this sweep's parts)")
    p.add_argument("--scheduler", metavar="ADDR", help="a Dask scheduler (tcp://host:8786), or 'serial' (this "
                                                       "process); default: a local cluster, one worker per core")
    p.add_argument("--workers", type=int, help="local workers (default: one per core); with --scheduler, wait for")
    p.add_argument("--chunk", type=int, help="designs per task (default: about 32 tasks per worker)")
    p.add_argument("--overwrite", action="store_true", help="replace an output that holds another sweep")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    from pkm import sweeps

    axes = dict(split_item(item, "sweep") for item in args.parameters)
    if len(axes) != len(args.parameters):
        raise UsageError("name each swept parameter once")
    if args.table:
        if axes:
            raise UsageError("--table gives the designs; name no NAME=... ranges beside it")
        space = sweeps.table(args.table)
    elif args.sample == "grid":
        if args.n is not None or args.seed is not None:
            raise UsageError("--n and --seed are for --sample sobol or lhs (a grid's size is its axes')")
        space = sweeps.grid(**axes)
    else:
        if args.n is None:
            raise UsageError(f"--sample {args.sample} needs --n (the number of designs)")
        draw = sweeps.sobol if args.sample == "sobol" else sweeps.latin_hypercube
        space = draw(args.n, seed=args.seed, **axes)
    if args.fixed and args.mechanism not in pkm.MECHANISMS:
        raise UsageError(f"--fixed sets the design of a shipped mechanism; {args.mechanism} states its own")
    fixed = parse_params(args.mechanism, args.fixed) if args.fixed else {}  # (tuples and units as --param's)
    res = sweeps.sweep(args.mechanism, space, args.objective, out=args.out, fixed=fixed or None,
                       scheduler=args.scheduler, workers=args.workers, chunk_size=args.chunk,
                       progress=False if args.no_progress else None, overwrite=args.overwrite)
    try:
        res.check()  # every design failed: one line naming them (their table is written already)
    except sweeps.SweepError as exc:
        kept = f"; each design's error is in {args.out}" if args.out else "; --out FILE.parquet keeps each design's"
        raise sweeps.SweepError(f"{exc}{kept}", args.out) from None
    st = res.stats
    best = {}
    for c, o in res.objectives.items():
        rows = res.best(c, 1) if o["sense"] and not np.isnan(res.column(c)).all() else []  # (none: no value of it)
        best[c] = rows[0] if rows else None
    out = {"mechanism": res.manifest["family"], "designs": len(res), "failed": st.failed,
           "evaluated_now": st.evaluated, "space": res.manifest["space"], "out": args.out,
           "workers": st.workers, "wall_seconds": st.wall_seconds, "work_seconds": st.work_seconds, "best": best}
    print(json.dumps(jsonable(out), indent=2))
    return 0


def add_plot_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("results", metavar="FILE", help="a sweep's .parquet results")
    p.add_argument("--out", metavar="DIR", default=".", help="where to write the PNGs (default: .)")
    p.add_argument("--pareto", metavar="A,B", help="objectives of the Pareto fronts (default: all with a sense)")


def run_plot(args: argparse.Namespace) -> int:
    from pkm import sweeps

    pareto = [n.strip() for n in args.pareto.split(",")] if args.pareto else None
    paths = sweeps.plot(args.results, args.out, pareto)
    print(json.dumps([str(p) for p in paths], indent=2))
    return 0


def add_best_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("results", metavar="FILE", help="a sweep's .parquet results")
    p.add_argument("--by", metavar="OBJECTIVE", required=True, help="the objective column to rank by (its sense)")
    p.add_argument("--n", type=int, default=3, help="how many (default: 3)")
    p.add_argument("--out", metavar="DIR", default="best", help="where to write them (default: best/)")
    p.add_argument("--mechanism", metavar="SPEC", help="the files of a loaded mechanism the sweep varied")


def run_best(args: argparse.Namespace) -> int:
    from pkm import sweeps

    paths = sweeps.write_best(args.results, args.by, args.out, n=args.n, mechanism=args.mechanism)
    print(json.dumps([str(p) for p in paths], indent=2))
    return 0


COMMAND = Command("a design sweep on Dask: objectives of every design, Parquet results ('pkm sweep plot', "
                  "'pkm sweep best' read them)", add_arguments, run)
PLOT = Command("(pkm sweep plot FILE) parameter-objective plots and Pareto fronts of a sweep's results",
               add_plot_arguments, run_plot)
BEST = Command("(pkm sweep best FILE --by OBJ) the best designs as closure specs for pkm preview", add_best_arguments,
               run_best)
