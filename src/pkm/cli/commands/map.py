"""``pkm map MECH --axis NAME=START:STOP:COUNT ... [--q0 NAME=V ...] [--index wrench|twist|acceleration
[--no-gravity]] [--stiffness [--drives K] [--spring NAME=K ...] [--frequency]] [--png FILE] [--csv FILE]``: a
workspace and condition-index map over one to three task coordinates (JSON summary, PNG, CSV);
with ``--index``, the capability under actuator limits at every reachable node as well
(:func:`pkm.core.analysis.capability.map_capability`: the largest value along each task axis each way and the
largest isotropic value per unit; the PNG and CSV are then the capability's); with ``--stiffness``, the principal
stiffnesses (and with ``--frequency`` the first natural frequency) at every reachable node
(:func:`pkm.core.compliance.maps.stiffness_map`; the CSV is then theirs). A mechanism with collision geometry gets its
interference at every reachable node as well (on a grid of at most 100,000 nodes; ``--collisions``: any;
``--no-collisions``: not): the JSON counts the nodes within the joints'
limits and those of them free of interference (with their sizes) and gives the smallest clearance; the CSV has a
``clearance``, ``within_limits`` and ``interferes`` column, the PNG marks the nodes outside the limits and those
that interfere."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

import numpy as np

import pkm
from pkm.cli.command import Command
from pkm.cli.commands.stiffness import add_spring_arguments, springs
from pkm.cli.mechanism import add_mechanism_arguments, add_seed_argument, load_mechanism
from pkm.cli.parsing import parse_axis, parse_seed, parse_task
from pkm.cli.usage import UsageError
from pkm.units import parse_quantity


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, None, None)
    p.add_argument("--axis", metavar="NAME=START:STOP:COUNT", action="append", required=True,
                   help="a grid axis over a task coordinate, e.g. x=-5cm:5cm:101 (1 to 3 axes)")
    p.add_argument("--pose", metavar="K=V", action="extend", nargs="+", default=[],
                   help="the other task coordinates (default: the reference's)")
    p.add_argument("--length", metavar="L", help="characteristic length dividing the angular rates, e.g. 5cm "
                                                 "(default where the task mixes lengths and angles: the mechanism's "
                                                 "characteristic length, said on stderr)")
    p.add_argument("--branch", metavar="NAME", help="working mode of the map (see 'pkm list')")
    add_seed_argument(p, "the configuration the map starts from (its working mode is the map's; default: the "
                         "reference, or the branch's)")
    p.add_argument("--index", choices=("wrench", "twist", "acceleration"),
                   help="the capability under the actuators' limits at every reachable node (pkm capability's)")
    p.add_argument("--no-gravity", action="store_true", help="with --index: leave the mechanism's weight out")
    p.add_argument("--stiffness", action="store_true",
                   help="the principal stiffnesses at every reachable node (pkm stiffness's; springs below)")
    add_spring_arguments(p)
    p.add_argument("--frequency", action="store_true", help="with --stiffness: the first natural frequency too")
    p.add_argument("--png", metavar="FILE", help="draw the condition index (a 3-D map: its middle slab); with "
                                                 "--index, the largest isotropic value (1 or 2 axes)")
    p.add_argument("--csv", metavar="FILE", help="write one row per node")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--collisions", action="store_true", help="the interference of a mechanism with collision "
                   "geometry on a grid of any size (by default on grids of at most 100,000 nodes)")
    g.add_argument("--no-collisions", action="store_true",
                   help="leave out the interference of a mechanism with collision geometry (its clearance per node)")


def run(args: argparse.Namespace) -> int:
    from pkm.core.analysis.maps import COLLISION_NODES, workspace_map
    from pkm.core.collision.interference import checks_collisions

    mech = load_mechanism(args)
    axes = dict(parse_axis(mech, item) for item in args.axis)
    if len(axes) != len(args.axis):
        raise UsageError("name each --axis once")
    fixed = parse_task(mech, args.pose or [])
    length = None if args.length is None else parse_quantity(args.length, {"length"}, "--length", "m")
    if length is None and (length := pkm.TaskMap.of(mech).default_length(None)) is not None:
        print(f"note: the task mixes lengths and angles: the angular rates divided by the mechanism's "
              f"characteristic length L = {length:.6g} m (--length to change it)", file=sys.stderr)
    if args.index and args.png and len(axes) > 2:
        raise UsageError("--index draws one or two axes: leave --png out of a 3-D map (its CSV has every node)")
    if args.stiffness and args.index:
        raise UsageError("one of --index and --stiffness a map")
    if not args.stiffness and (args.frequency or args.spring or args.drives is not None):
        raise UsageError("--frequency, --spring and --drives go with --stiffness")
    if args.stiffness and args.png:
        raise UsageError("--stiffness writes its CSV (--csv), no figure yet")
    m = workspace_map(mech, axes, fixed, branch=args.branch, length=length, seed=parse_seed(mech, args.q0),
                      configurations=bool(args.index or args.stiffness),
                      collisions=True if args.collisions else False if args.no_collisions else None)
    out: dict[str, Any] = {"mechanism": mech.name, "axes": {n: [float(v[0]), float(v[-1]), len(v)] for n, v in m.axes},
                           "length_SI": length, "nodes": int(m.reachable.size), "reachable": m.nodes, "size_SI": m.size, "size_unit": m.size_unit,
                           "gci_2": m.gci("2"), "gci_fro_normalized": m.gci("fro_normalized"), "how": m.how}
    if m.clearance is not None and m.within_limits is not None and m.interferes is not None:
        out["interference"] = {
            "within_limits": int(m.within_limits.sum()), "size_within_limits_SI": m.measure(m.within_limits),
            "interfering": int(m.interferes.sum()), "interference_free_within_limits": int(m.feasible.sum()),
            "size_interference_free_SI": m.measure(m.feasible),
            "smallest_clearance_m": float(np.nanmin(m.clearance)) if m.nodes else None}
    elif not args.no_collisions and checks_collisions(mech):
        out["interference"] = (f"not computed: {m.reachable.size} nodes, more than {COLLISION_NODES} (--collisions "
                               "computes it)")
    figures: Any = m
    if args.index:
        from pkm.core.analysis.capability import map_capability

        figures = map_capability(mech, m, args.index, gravity=not args.no_gravity)
        out["capability"] = {"kind": args.index, "regular": int(figures.reachable.sum()), **figures.summary()}
    if args.stiffness:
        from pkm.core.compliance.maps import stiffness_map
        from pkm.report import jsonable

        figures = stiffness_map(mech, m, joints=springs(mech, args), frequencies=args.frequency)
        out["stiffness"] = jsonable(figures.summary())
    if args.csv:
        out["csv"] = str(figures.write_csv(args.csv))
    if args.png:
        out["png"] = str(figures.figure(args.png) if args.index else
                         m.figure(args.png, slab=None if len(m.axes) < 3 else len(m.axes[2][1]) // 2))
    print(json.dumps(out, indent=2))
    return 0


COMMAND = Command("a workspace, condition-index and capability map over 1-3 task coordinates (JSON, PNG, CSV)",
                  add_arguments, run)
