"""``pkm dynamics MECH [--pose K=V ... | --joints NAME=V ...] [--rates NAME=V ...] [--json]``: the actuator-space dynamic model
(:func:`pkm.actuator_model`) at one state: the mass matrix ``M_a``, the bias ``h_a``, the static efforts ``g_a``
(gravity's and the joint springs') and, where the mechanism has friction, the friction efforts, each entry with its
unit, by actuator name."""

from __future__ import annotations

import argparse
import json
from typing import TYPE_CHECKING, Any

import numpy as np

import pkm
from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, configuration, load_mechanism
from pkm.cli.output import outside_limits, outside_line
from pkm.cli.parsing import parse_rates
from pkm.report import jsonable

if TYPE_CHECKING:
    from pkm.core.dynamics.model import ActuatorSpaceModel


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, "optional", "optional")
    p.add_argument("--rates", metavar="NAME=V", action="extend", nargs="+", default=[],
                   help="actuated rates, e.g. motor_1=-30deg/s (rad/s, deg/s, rpm; m/s, mm/s; a number: SI) "
                        "(others zero)")
    p.add_argument("--json", action="store_true", help="print JSON (SI, with a units object)")


def _mass_unit(a: bool, b: bool) -> str:
    """The unit of ``M_a``'s entry between two actuators (revolute or not)."""
    return "kg m^2" if a and b else "kg m" if a or b else "kg"


def model_dict(mech: pkm.Mechanism, model: ActuatorSpaceModel) -> dict[str, Any]:
    """What ``pkm dynamics --json`` prints: the state and the model by actuator name, SI, with their units."""
    names = list(mech.actuated_names)
    revolute = [mech.joints[n].revolute for n in names]
    effort = {n: "N m" if r else "N" for n, r in zip(names, revolute)}
    has_friction = bool(np.any(np.asarray(mech.model.damping)) or np.any(np.asarray(mech.model.friction)))
    out = {
        "mechanism": mech.name,
        "actuated": dict(zip(names, mech.actuated_q(model.q))),
        "rates": dict(zip(names, model.qd)),
        "task": pkm.TaskMap.of(mech).named(model.q),
        "M": {a: dict(zip(names, row)) for a, row in zip(names, model.M)},
        "h": dict(zip(names, model.h)),
        "g": dict(zip(names, model.g)),
        "friction": dict(zip(names, model.friction)) if has_friction else None,
        "idle_motions": int(model.idle.shape[1]),
        "outside_limits": outside_limits(mech, model.q),
        "base": model.base,
        "units": {
            "actuated": {n: "rad" if r else "m" for n, r in zip(names, revolute)},
            "rates": {n: "rad/s" if r else "m/s" for n, r in zip(names, revolute)},
            "task": {k: "rad" if kind == "angle" else "m" for k, kind in pkm.TaskMap.of(mech).kinds.items()},
            "M": {a: {b: _mass_unit(ra, rb) for b, rb in zip(names, revolute)} for a, ra in zip(names, revolute)},
            "h": effort, "g": effort, "friction": effort,
            "note": "M_a qdd + h_a = tau_a + friction; h_a: Coriolis, centrifugal, gravity, spring and closure-drift "
                    "efforts, g_a: the static efforts (gravity and the joint springs)",
        },
    }
    return jsonable(out)


def _value(x: float, unit: str) -> str:
    return f"{x:.6g} {unit}"


def text(out: dict[str, Any]) -> str:
    """The human-readable form of :func:`model_dict`: labelled rows, each entry with its unit."""
    names = list(out["actuated"])
    units = out["units"]
    state = ", ".join(f"{n}={_value(v, units['actuated'][n])}" for n, v in out["actuated"].items())
    rates = ", ".join(f"{n}={_value(v, units['rates'][n])}" for n, v in out["rates"].items())
    lines = [f"{out['mechanism']}: the actuator-space model at {state}", f"rates: {rates}"]
    width = max(len(n) for n in names) + 2
    cells = [[_value(out["M"][a][b], units["M"][a][b]) for b in names] for a in names]
    col = max(max(len(c) for c in row) for row in cells) + 2
    lines.append("M_a (mass matrix):")
    lines.append(" " * (width + 2) + "".join(n.rjust(col) for n in names))
    lines += [f"  {a.ljust(width)}" + "".join(c.rjust(col) for c in row) for a, row in zip(names, cells)]
    for key, label in (("h", "h_a (Coriolis, centrifugal, gravity, springs, closure drift)"),
                       ("g", "g_a (static: gravity, springs)"),
                       ("friction", "friction efforts")):
        if out[key] is None:
            continue
        lines.append(f"{label}:")
        lines += [f"  {n.ljust(width)}{_value(out[key][n], units[key][n]).rjust(col)}" for n in names]
    if out["outside_limits"]:
        lines.append(outside_line(out["outside_limits"]))
    if out["base"] == "free":
        lines.append("floating base: free (no wrench on it; its motion eliminated from M_a, h_a, g_a)")
    if out["idle_motions"]:
        lines.append(f"idle motions: {out['idle_motions']} (left out of the state: their rates are those of least kinetic energy)")
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    mech = load_mechanism(args)
    q = configuration(mech, args)
    qd = parse_rates(mech, args.rates, "--rates")
    out = model_dict(mech, pkm.actuator_model(mech, q, qd))
    print(json.dumps(out, indent=2) if args.json else text(out))
    return 0


COMMAND = Command("the dynamic model in actuator space at one state: M_a, h_a, g_a, friction (units per entry)",
                  add_arguments, run)
