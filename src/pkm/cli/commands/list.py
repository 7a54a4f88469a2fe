"""``pkm list [MECH ...] [--json]``: the mechanisms (every shipped one, or those named: any MECH), their joints, task
and parameters (units, defaults), and the names of the other models ``pkm.load`` takes by name."""

from __future__ import annotations

import argparse
import json
import math
from typing import Any

import pkm
from pkm.cli.command import Command
from pkm.cli.mechanism import mech_help
from pkm.cli.parsing import joint_kind, param_info
from pkm.report import jsonable
from pkm.units import SI_UNITS


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("mechanisms", metavar="MECH", nargs="*",
                   help="the mechanisms to describe (default: every shipped one, then the names of the third-party "
                        "robots pkm ships and of the models of installed packages): " + mech_help())
    p.add_argument("--json", action="store_true", help="print JSON")


def describe(name: str) -> dict[str, Any]:
    """What ``pkm list`` says of the mechanism ``name`` (any MECH): its actuated joints and task coordinates with
    their units, a reachable pose, its working modes; a shipped mechanism's title and parameters too."""
    mech = pkm.load(name)
    entry = pkm.MECHANISMS.get(name)
    frame = f"the frame {mech.spec.end_effector!r} in the world frame" if mech.spec.end_effector else "joint outputs"
    out: dict[str, Any] = {"title": entry.title if entry else mech.spec.description,
                           "actuated": {j: SI_UNITS[joint_kind(mech, j)] for j in mech.actuated_names},
                           "task": {k: SI_UNITS[kind] for k, kind in mech.task_map.kinds.items()},
                           "task_origin": entry.origin if entry else frame,
                           "reference_pose": mech.task_map.named(mech.q_reference),
                           "branches": list(mech.spec.branches),
                           "default_branch": mech.spec.default_branch}
    if entry:
        out["parameters"] = {p.name: {"default": p.default, "unit": p.unit, "type": p.type,
                                      "description": p.description} for p in param_info(name).values()}
    return out


def run(args: argparse.Namespace) -> int:
    from pkm.core.formats.catalogue import CATALOGUE
    from pkm.core.formats.packages import PACKAGE_MODELS

    data = {name: describe(name) for name in (args.mechanisms or pkm.MECHANISMS)}
    others: dict[str, str] = {} if args.mechanisms else {**{n: e.description for n, e in CATALOGUE.items()},
                                         **{n: e.description for n, e in PACKAGE_MODELS.items()}}
    if args.json:
        print(json.dumps(jsonable({"units": "SI (m, rad, kg) unless a parameter says otherwise",
                                   "mechanisms": data, **({"by_name": others} if others else {})}), indent=2))
        return 0

    def named(m: dict[str, str]) -> str:
        return ", ".join(f"{k} [{u}]" for k, u in m.items())

    for name, d in data.items():
        branches = ", ".join(b + (" (default)" if b == d["default_branch"] else "") for b in d["branches"])
        print(f"{name}: {d['title']}" if d["title"] else f"{name}:")
        print(f"  actuated (--joints): {named(d['actuated'])}")
        print(f"  task (--pose): {named(d['task'])}")
        print(f"  task origin: {d['task_origin']}")
        print("  reference pose (reachable): " + " ".join(f"{k}={_fmt_value(v, d['task'][k])}"
                                                       for k, v in d["reference_pose"].items()))
        if branches:
            print(f"  branches (--branch): {branches}")
        if "parameters" in d:
            print("  parameters (--param NAME=VALUE, SI unless a unit suffix is given):")
            rows = [(p.name, _fmt_default(p.default), p.unit, p.summary) for p in param_info(name).values()]
            w = [max(len(r[i]) for r in rows) for i in range(3)]
            for r in rows:
                print(f"    {r[0].ljust(w[0])}  {r[1].ljust(w[1])}  {r[2].ljust(w[2])}  {r[3]}")
        print()
    if others:
        print("Also loaded by name (pkm list NAME describes one):")
        width = max(len(name) for name in others)
        for name, what in others.items():
            print(f"  {name.ljust(width)}  {what}")
    return 0


def _fmt_value(v: float, unit: str) -> str:
    """A task value for the eye, in the unit a user would type: cm or deg (``pkm ik --pose`` takes them back)."""
    x, suffix = (v * 100.0, "cm") if unit == "m" else (math.degrees(v), "deg") if unit == "rad" else (v, "")
    return f"{round(x, 6) + 0.0:.4g}{suffix}"  # (rounded, + 0.0: no "-0" nor "1e-15")


def _fmt_default(v: Any) -> str:
    if v is None:
        return "found"
    if isinstance(v, tuple):
        return ",".join(_fmt_default(x) for x in v)
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


COMMAND = Command("the mechanisms (or MECH), their joints, task and parameters (units, defaults)", add_arguments, run)
