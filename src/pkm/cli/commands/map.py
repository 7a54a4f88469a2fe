"""``pkm map MECH --axis NAME=START:STOP:COUNT ... [--png FILE] [--csv FILE]``: a workspace and condition-index
map over one to three task coordinates (JSON summary, PNG, CSV)."""

from __future__ import annotations

import argparse
import json

from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, load_mechanism
from pkm.cli.parsing import parse_axis, split_item
from pkm.cli.usage import UsageError
from pkm.errors import UnknownNameError
from pkm.units import SI_UNITS, parse_quantity


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, None, None)
    p.add_argument("--axis", metavar="NAME=START:STOP:COUNT", action="append", required=True,
                   help="a grid axis over a task coordinate, e.g. x=-5cm:5cm:101 (1 to 3 axes)")
    p.add_argument("--pose", metavar="K=V", action="extend", nargs="+", default=[],
                   help="the other task coordinates (default: the reference's)")
    p.add_argument("--length", metavar="L", help="characteristic length dividing the angular rates, e.g. 5cm "
                                                 "(needed when the task mixes lengths and angles)")
    p.add_argument("--branch", metavar="NAME", help="working mode of the map (see 'pkm list')")
    p.add_argument("--png", metavar="FILE", help="draw the condition index (a 3-D map: its middle slab)")
    p.add_argument("--csv", metavar="FILE", help="write one row per node")


def run(args: argparse.Namespace) -> int:
    from pkm.core.analysis.maps import workspace_map

    mech = load_mechanism(args)
    axes = dict(parse_axis(mech, item) for item in args.axis)
    if len(axes) != len(args.axis):
        raise UsageError("name each --axis once")
    fixed = {}
    for item in args.pose or []:
        name, text = split_item(item, "--pose")
        if name not in mech.task_map.kinds:
            raise UnknownNameError("task coordinate", name, list(mech.task_map.keys), mech.name)
        fixed[name] = parse_quantity(text, {mech.task_map.kinds[name]}, name, SI_UNITS[mech.task_map.kinds[name]])
    length = None if args.length is None else parse_quantity(args.length, {"length"}, "--length", "m")
    m = workspace_map(mech, axes, fixed, branch=args.branch, length=length)
    out = {"mechanism": mech.name, "axes": {n: [float(v[0]), float(v[-1]), len(v)] for n, v in m.axes},
           "nodes": int(m.reachable.size), "reachable": m.nodes, "size_SI": m.size,
           "gci_2": m.gci("2"), "gci_fro_normalized": m.gci("fro_normalized"), "how": m.how}
    if args.csv:
        out["csv"] = str(m.write_csv(args.csv))
    if args.png:
        out["png"] = str(m.figure(args.png, slab=None if len(m.axes) < 3 else len(m.axes[2][1]) // 2))
    print(json.dumps(out, indent=2))
    return 0


COMMAND = Command("a workspace and condition-index map over 1-3 task coordinates (JSON summary, PNG, CSV)", add_arguments,
                  run)
