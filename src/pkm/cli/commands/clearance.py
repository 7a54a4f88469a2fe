"""``pkm clearance MECH [--pose K=V ... | --joints NAME=V ...] [--pairs N] [--json]``: the signed distances between
the mechanism's bodies at a configuration (:func:`pkm.clearance`): the smallest and its pair, whether bodies
interpenetrate, the derivative of the smallest distance with respect to the actuated coordinates, the ``--pairs``
closest pairs (all of them in JSON) with their witness points, and the pairs not checked with why."""

from __future__ import annotations

import argparse
import json
from typing import Any

from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, configuration, load_mechanism
from pkm.cli.output import outside_limits, outside_line


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, "optional", "optional")
    p.add_argument("--pairs", type=int, default=10, metavar="N", help="the N closest pairs printed (default 10)")
    p.add_argument("--json", action="store_true", help="print JSON (SI, with units): every pair")


def clearance_dict(mech: Any, q: Any) -> dict[str, Any]:
    """What ``pkm clearance`` prints and the service's clearance query returns: the library's numbers by name (SI)."""
    import pkm
    from pkm.errors import SingularityError

    c = pkm.clearance(mech, q)
    try:
        gradient: dict[str, float] | None = dict(zip(mech.actuated_names, map(float, c.gradient)))
        singular = None
    except SingularityError as exc:
        gradient, singular = None, str(exc)
    order = sorted(c.pairs, key=c.pairs.__getitem__)
    return {"mechanism": mech.name, "task": pkm.TaskMap.of(mech).named(q), "outside_limits": outside_limits(mech, q),
            "minimum": c.minimum, "closest": list(c.closest), "interferes": c.interferes, "gradient": gradient,
            **({"gradient_undefined": singular} if singular else {}),
            "pairs": [{"bodies": list(p), "distance": c.pairs[p], "witness": [list(map(float, w)) for w in c.witness[p]]}
                      for p in order],
            "excluded": [{"bodies": list(p), "reason": r} for p, r in c.excluded.items()],
            "units": {"minimum": "m", "distance": "m", "witness": "m (world frame)",
                      "gradient": "m/rad (revolute), m/m (prismatic) per actuated coordinate"}}


def run(args: argparse.Namespace) -> int:
    from pkm.errors import InvalidInputError
    from pkm.report import jsonable

    if args.pairs < 0:
        raise InvalidInputError("--pairs", "give a count of 0 or more", args.pairs)
    mech = load_mechanism(args)
    out = clearance_dict(mech, configuration(mech, args))
    if args.json:
        print(json.dumps(jsonable(out), indent=2))
        return 0
    print(_text(out, args.pairs))
    return 0


def _text(out: dict[str, Any], n: int) -> str:
    pose = ", ".join(f"{k}={v:.6g}" for k, v in out["task"].items())
    lines = [f"{out['mechanism']} at {pose}"]
    if out["outside_limits"]:
        lines.append(outside_line(out["outside_limits"]))
    a, b = out["closest"]
    lines.append(f"smallest distance {out['minimum']:.6g} m, between {a} and {b}"
                 + (": they INTERFERE (negative: penetration depth)" if out["interferes"] else ""))
    if out["gradient"] is None:
        lines.append(f"its derivative is undefined here: {out['gradient_undefined']}")
    else:
        lines.append("its derivative by the actuated coordinates [m/rad, m/m]: "
                     + ", ".join(f"{j} {g:.6g}" for j, g in out["gradient"].items()))
    lines.append(f"the {min(n, len(out['pairs']))} closest of {len(out['pairs'])} pairs checked [m]:")
    lines += [f"  {p['bodies'][0]} - {p['bodies'][1]}: {p['distance']:.6g}" for p in out["pairs"][:n]]
    if out["excluded"]:
        lines.append(f"{len(out['excluded'])} pairs not checked:")
        lines += [f"  {e['bodies'][0]} - {e['bodies'][1]}: {e['reason']}" for e in out["excluded"]]
    return "\n".join(lines)


COMMAND = Command("the signed distances between the bodies at a configuration (collision geometry), the closest pair "
                  "and its derivative", add_arguments, run)
