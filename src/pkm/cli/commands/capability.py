"""``pkm capability MECH [--pose K=V ... | --joints NAME=V ...] [--kind wrench|twist|acceleration|all]
[--no-gravity] [--json]``: what the actuators can produce at a pose under their limits
(:func:`pkm.capability`): per task axis the largest value each way, the largest isotropic value per unit, the
ellipsoid's semi-axes; with ``--json`` the polytopes' vertices and half-spaces too. It prints first the limits it
holds each actuator to (the continuous effort limit for wrenches and accelerations, the velocity limit for twists)
and where each comes from (the model file, the closure spec's ``[actuators]``: ``limits`` in ``--json``), and says
so when they look like placeholders (:mod:`pkm.core.model.plausibility`).

``--axis NAME=START:STOP:COUNT`` (once or twice; ``--pose`` then fixes the other task coordinates) maps one kind's
indices over the grid instead (:func:`pkm.core.analysis.capability.capability_map`): the summary, ``--png`` the
largest isotropic value's map, ``--csv`` every node."""

from __future__ import annotations

import argparse
import json
from typing import Any

import pkm
from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, configuration, load_mechanism
from pkm.cli.output import outside_limits, outside_line


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, "optional", "optional")
    p.add_argument("--kind", choices=("wrench", "twist", "acceleration", "all"), default="all",
                   help="which capability (default all)")
    p.add_argument("--no-gravity", action="store_true", help="leave the mechanism's weight out")
    p.add_argument("--axis", metavar="NAME=START:STOP:COUNT", action="append", default=[],
                   help="map the capability over this task coordinate (once or twice)")
    p.add_argument("--png", metavar="FILE",
                   help="with --axis: draw the largest isotropic value (pkm-robotics[figures])")
    p.add_argument("--csv", metavar="FILE", help="with --axis: every node's indices")
    p.add_argument("--json", action="store_true", help="print JSON (SI, units per axis, the polytopes)")


def run(args: argparse.Namespace) -> int:
    from pkm.core.analysis.capability import KINDS, capability
    from pkm.core.model.actuators import limit_sources
    from pkm.core.model.plausibility import findings
    from pkm.report import jsonable

    mech = load_mechanism(args)
    if args.axis:
        return _map(mech, args)
    q = configuration(mech, args)
    limits = limit_sources(mech)
    out: dict[str, Any] = {"mechanism": mech.name, "task": pkm.TaskMap.of(mech).named(q),
                           "limits": {j: {f: {"value": v, "source": src} for f, (v, src) in row.items()
                                          if f != "peak_effort"} for j, row in limits.items()},
                           "placeholder_limits": any(w.kind == "limits" for w in findings(mech)),
                           "outside_limits": outside_limits(mech, q)}
    for kind in KINDS if args.kind == "all" else (args.kind,):
        c = capability(mech, q, kind, gravity=not args.no_gravity)
        P = c.polytope
        out[kind] = {"units": dict(zip(P.axes, P.units)), "along": c.along, "isotropic": c.isotropic,
                     "ellipsoid_axes": c.ellipsoid_axes, "origin_inside": c.origin_inside,
                     "vertices": P.vertices, "A": P.A, "b": P.b}
    if args.json:
        print(json.dumps(jsonable(out), indent=2))
        return 0
    pose = ", ".join(f"{k}={v:.6g}" for k, v in out["task"].items())
    print(f"{mech.name} at {pose}")
    if out["outside_limits"]:
        print(outside_line(out["outside_limits"]))
    texts: dict[str, list[str]] = {}  # (actuators with the same limits from the same places: one line)
    for j, row in limits.items():
        unit = ("N m", "rad/s") if mech.joints[j].revolute else ("N", "m/s")
        text = (f"effort {row['effort_limit'][0]:.4g} {unit[0]} ({row['effort_limit'][1]}), velocity "
                f"{row['velocity_limit'][0]:.4g} {unit[1]} ({row['velocity_limit'][1]})")
        texts.setdefault(text, []).append(j)
    for text, joints in texts.items():
        print(f"limits held ({', '.join(joints)}): {text}")
    if out["placeholder_limits"]:
        print("warning: these limits look like placeholders (every actuator's alike, powers of ten): the capability "
              "below is theirs, not a real drive's")
    for kind in KINDS:
        if kind not in out:
            continue
        r = out[kind]
        print(f"{kind}:")
        for axis, (plus, minus) in r["along"].items():
            print(f"  {axis:>8}  +{plus:.6g} / -{minus:.6g} {r['units'][axis]}")
        print("  isotropic: " + ", ".join(f"{v:.6g} {u}" for u, v in r["isotropic"].items()))
        if not r["origin_inside"]:
            print("  the actuators cannot hold the mechanism's weight here (the set excludes the origin): every "
                  "index is 0")
    return 0


def _map(mech, args: argparse.Namespace) -> int:
    import numpy as np

    from pkm.cli.parsing import parse_axis, parse_pose
    from pkm.core.analysis.capability import capability_map
    from pkm.errors import InvalidInputError
    from pkm.report import jsonable

    kind = "wrench" if args.kind == "all" else args.kind
    axes = dict(parse_axis(mech, item) for item in args.axis)
    fixed = {k: v for k, v in parse_pose(mech, args.pose)[0].items() if k not in axes} if args.pose else None
    if args.joints:
        raise InvalidInputError("--joints", "a map fixes task coordinates: give --pose for those off the axes")
    cm = capability_map(mech, axes, fixed, kind, gravity=not args.no_gravity)
    out: dict[str, Any] = {"mechanism": mech.name, "kind": kind, "nodes": int(cm.reachable.size),
                           "reachable": int(cm.reachable.sum()), "below_weight": cm.below_weight, "fixed": cm.fixed,
                           "isotropic": {u: {"min": float(np.nanmin(v)), "max": float(np.nanmax(v))}
                                         for u, v in cm.isotropic.items()} if cm.reachable.any() else {}}
    if args.png:
        out["png"] = cm.figure(args.png)
    if args.csv:
        out["csv"] = cm.write_csv(args.csv)
    print(json.dumps(jsonable(out), indent=2) if args.json else
          f"{mech.name}: {kind} capability over {out['nodes']} nodes, {out['reachable']} reachable"
          + (f" ({cm.below_weight} where the actuators cannot hold the weight: indices 0)" if cm.below_weight else "")
          + "; isotropic "
          + ", ".join(f"{v['min']:.6g} to {v['max']:.6g} {u}" for u, v in out["isotropic"].items()))
    return 0


COMMAND = Command("capability under actuator limits at a pose: wrenches, twists, accelerations (polytopes)",
                  add_arguments, run)
