"""``pkm capability MECH [--pose K=V ... | --joints NAME=V ...] [--kind wrench|twist|acceleration|all]
[--no-gravity] [--json]``: what the actuators can produce at a pose under their limits
(:func:`pkm.capability`): per task axis the largest value each way, the largest isotropic value per unit, the
ellipsoid's semi-axes; with ``--json`` the polytopes' vertices and half-spaces too."""

from __future__ import annotations

import argparse
import json
from typing import Any

from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, configuration, load_mechanism


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, "optional", "optional")
    p.add_argument("--kind", choices=("wrench", "twist", "acceleration", "all"), default="all",
                   help="which capability (default all)")
    p.add_argument("--no-gravity", action="store_true", help="leave the mechanism's weight out")
    p.add_argument("--json", action="store_true", help="print JSON (SI, units per axis, the polytopes)")


def run(args: argparse.Namespace) -> int:
    from pkm.core.analysis.capability import KINDS, capability
    from pkm.report import jsonable

    mech = load_mechanism(args)
    q = configuration(mech, args)
    out: dict[str, Any] = {"mechanism": mech.name, "task": mech.task_map.named(q)}
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
    for kind in KINDS:
        if kind not in out:
            continue
        r = out[kind]
        print(f"{kind}:")
        for axis, (plus, minus) in r["along"].items():
            print(f"  {axis:>8}  +{plus:.6g} / -{minus:.6g} {r['units'][axis]}")
        print("  isotropic: " + ", ".join(f"{v:.6g} {u}" for u, v in r["isotropic"].items()))
    return 0


COMMAND = Command("capability under actuator limits at a pose: wrenches, twists, accelerations (polytopes)",
                  add_arguments, run)
