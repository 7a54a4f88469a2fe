"""``pkm stiffness MECH [--pose K=V ... | --joints NAME=V ...] [--spring NAME=K ...] [--drives K] [--links L]
[--wrench K=V ...] [--frequencies] [--json]``: the end effector's stiffness at a configuration (:func:`pkm.stiffness`):
the springs
counted (``--spring``: a joint's stiffness, SI: N m/rad for a revolute, N/m for a prismatic joint; ``--drives``: every
actuated joint's not named; the drives' own servo stiffness, the spec's ``[actuators.<joint>] stiffness``, and the
spec's ``[springs]`` too) with where each came from, the actuated joints held rigid, the compliance's rank,
the 6 x 6 stiffness where it has rank 6 and the principal stiffnesses; with ``--wrench`` (``fx fy fz`` [N, or kN,
mN], ``mx my mz`` [N m]) the exact deflection and the first-order one with their gap, and the tangent stiffness there
(:meth:`Stiffness.loaded <pkm.core.compliance.stiffness.Stiffness.loaded>`); with ``--frequencies`` the natural
frequencies (:func:`pkm.vibration_modes`). ``--links``: ``spec`` (default: the spec's ``[links.<link>]``
compliances, else rigid), ``rigid``, ``steel``, ``aluminium`` or ``E=<Pa>[,G=<Pa>]``: every link whose collision
geometry is one cylinder or capsule a beam of that material (:class:`pkm.Material`), the others rigid and said."""

from __future__ import annotations

import argparse
import json
from typing import TYPE_CHECKING, Any

import numpy as np

from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, configuration, load_mechanism
from pkm.cli.output import outside_limits, outside_line
from pkm.cli.parsing import split_item

if TYPE_CHECKING:
    from pkm.core.compliance.stiffness import Links

WRENCH = ("fx", "fy", "fz", "mx", "my", "mz")
TWIST_UNITS = ("m", "m", "m", "rad", "rad", "rad")


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, "optional", "optional")
    add_spring_arguments(p)
    p.add_argument("--wrench", metavar="K=V", action="extend", nargs="+", default=[],
                   help="a load at the end effector's origin, world axes: fx fy fz (N, kN), mx my mz (N m)")
    p.add_argument("--links", metavar="L", default="spec",
                   help="the links: spec (default: the spec's [links] compliances, else rigid), rigid, steel, "
                        "aluminium, or E=PA[,G=PA]: beams of their collision cylinders and capsules")
    p.add_argument("--frequencies", action="store_true", help="the natural frequencies too")
    p.add_argument("--json", action="store_true", help="print JSON (SI, with units)")


def add_spring_arguments(p: argparse.ArgumentParser) -> None:
    """``--spring NAME=K`` and ``--drives K``: the joints' stiffnesses (``pkm stiffness``, ``pkm map --stiffness``)."""
    p.add_argument("--spring", metavar="NAME=K", action="extend", nargs="+", default=[],
                   help="a joint's stiffness, SI (N m/rad, N/m); 0 frees it")
    p.add_argument("--drives", metavar="K", type=float,
                   help="every actuated joint's stiffness not given by --spring (SI); default: each drive's own "
                        "servo stiffness (the spec's [actuators.<joint>] stiffness), else rigid")


def springs(mech, args: argparse.Namespace) -> dict[str, float]:
    """``{joint: stiffness}`` of ``--drives`` and ``--spring`` (SI)."""
    from pkm.units import parse_quantity

    out = {j: float(args.drives) for j in mech.actuated_names} if args.drives is not None else {}
    for item in args.spring:
        name, value = split_item(item, "--spring")
        out[name] = parse_quantity(value, {None}, f"--spring {name}")
    return out


def _wrench(args: argparse.Namespace) -> np.ndarray | None:
    from pkm.errors import InvalidInputError
    from pkm.units import parse_quantity

    if not args.wrench:
        return None
    W = np.zeros(6)
    for item in args.wrench:
        name, value = split_item(item, "--wrench")
        if name not in WRENCH:
            raise InvalidInputError("--wrench", f"{name!r} is no wrench component: {', '.join(WRENCH)}", name)
        W[WRENCH.index(name)] = parse_quantity(value, {"force" if name[0] == "f" else "torque"}, f"--wrench {name}")
    return W


def links(value: str) -> Links | None:
    """``--links``: ``spec``, ``rigid``, a material's name or ``E=PA[,G=PA]`` (:func:`pkm.core.compliance.links.as_links`)."""
    from pkm.core.compliance.links import as_links
    from pkm.errors import InvalidInputError
    from pkm.units import parse_quantity

    if "=" not in value:
        return as_links(value)
    moduli: dict[str, float] = {}
    for item in value.split(","):
        name = item.partition("=")[0].strip()
        if "=" not in item or name not in ("E", "G") or name in moduli:
            raise InvalidInputError("--links", "spec, rigid, steel, aluminium, or E=PA[,G=PA] (moduli in Pa)", value)
        moduli[name] = parse_quantity(split_item(item, "--links")[1], {None}, f"--links {name}")
    return as_links(moduli)


def run(args: argparse.Namespace) -> int:
    import pkm
    from pkm.core.compliance.links import law_fields
    from pkm.errors import StiffnessError
    from pkm.report import jsonable

    mech = load_mechanism(args)
    q = configuration(mech, args)
    joints = springs(mech, args)
    K = pkm.stiffness(mech, q, joints=joints, links=links(args.links))
    out: dict[str, Any] = {"mechanism": mech.name, "task": pkm.TaskMap.of(mech).named(q),
                           "outside_limits": outside_limits(mech, q), "sprung": dict(K.sprung),
                           "sources": dict(K.sources),
                           "locked": list(K.locked), "rank": K.rank, "compliance": K.compliance,
                           "links": {n: law_fields(v) for n, v in K.links.items()}, "rigid_links": dict(K.rigid_links)}
    try:
        out["matrix"] = K.matrix
    except StiffnessError as exc:
        out["matrix"], out["rigid"] = None, str(exc)
    for load in ("force", "moment"):
        k, directions = K.principal(load)
        out[f"principal_{load}"] = {"stiffness": k, "directions": directions.T}
    W = _wrench(args)
    if W is not None:
        loaded = K.loaded(W)
        d = loaded.deflection
        out["wrench"] = W
        out["deflection"] = {"exact": d.displacement, "first_order": d.first_order, "gap": d.gap,
                             "load_steps": d.load_steps, "outside_limits": list(d.outside_limits)}
        try:
            out["loaded_matrix"] = loaded.matrix
        except StiffnessError:
            out["loaded_matrix"] = None
        out["loaded_compliance"] = loaded.compliance
    if args.frequencies:
        modes = K.vibration_modes()
        out["frequencies"] = modes.frequencies
        out["free_motions"] = modes.free
    out["units"] = {"compliance": "m/N, m/(N m); rad/N, rad/(N m)", "matrix": "N/m, N/rad; N m/m, N m/rad",
                    "principal_force": "N/m", "principal_moment": "N m/rad", "wrench": "N, N m",
                    "deflection": "m, rad (rotation vector, world axes)", "frequencies": "Hz",
                    "loaded_matrix": "N/m, N/rad; N m/m, N m/rad", "loaded_compliance": "m/N, m/(N m); rad/N, rad/(N m)",
                    "links": "m (radius), Pa (E, G)",
                    "sprung": "N m/rad (revolute), N/m (prismatic)"}
    if args.json:
        print(json.dumps(jsonable(out), indent=2))
        return 0
    print(_text(out))
    return 0


def _text(out: dict[str, Any]) -> str:
    pose = ", ".join(f"{k}={v:.6g}" for k, v in out["task"].items())
    lines = [f"{out['mechanism']} at {pose}"]
    if out["outside_limits"]:
        lines.append(outside_line(out["outside_limits"]))
    lines.append("springs: " + (", ".join(f"{j} {k:.6g} ({out['sources'][j]})" for j, k in out["sprung"].items())
                                or "none")
                 + "; held rigid: " + (", ".join(out["locked"]) or "none"))
    if out["links"]:
        lines.append("compliant links: " + ", ".join(
            f"{n} (beam of radius {v['radius']:.4g} m, E {v['E']:.4g} Pa)" if "radius" in v else f"{n} (6 x 6)"
            for n, v in out["links"].items())
                     + ("; taken rigid: " + "; ".join(f"{n} ({why})" for n, why in out["rigid_links"].items())
                        if out["rigid_links"] else ""))
    if out["matrix"] is None:
        lines.append(f"compliance of rank {out['rank']} of 6: {out['rigid']}")
    else:
        lines.append("stiffness at the end effector's origin, world axes, rows and columns (x, y, z, rx, ry, rz) "
                     "[N/m, N/rad; N m/m, N m/rad]:")
        lines += ["  " + " ".join(f"{v:12.5g}" for v in row) for row in out["matrix"]]
    for load, unit in (("force", "N/m"), ("moment", "N m/rad")):
        p = out[f"principal_{load}"]
        lines.append(f"principal stiffnesses under a pure {load} [{unit}]: "
                     + ", ".join(f"{k:.6g} along ({d[0]:.3f}, {d[1]:.3f}, {d[2]:.3f})"
                                 for k, d in zip(p["stiffness"], p["directions"])))
    if "deflection" in out:
        d = out["deflection"]
        lines.append("deflection (dx, dy, dz [m]; rx, ry, rz [rad]): exact "
                     + " ".join(f"{v:.6g}" for v in d["exact"]) + "; first order "
                     + " ".join(f"{v:.6g}" for v in d["first_order"]) + f" (gap {d['gap']:.3g})")
        if d["outside_limits"]:
            lines.append("warning: the deflected configuration is outside the position limits of "
                         + ", ".join(d["outside_limits"]))
        if out["loaded_matrix"] is not None:
            lines.append("tangent stiffness under the load (the geometric stiffness included), same rows and columns:")
            lines += ["  " + " ".join(f"{v:12.5g}" for v in row) for row in out["loaded_matrix"]]
    if "frequencies" in out:
        lines.append("natural frequencies [Hz]: " + ", ".join(f"{f:.6g}" for f in out["frequencies"])
                     + (f" ({out['free_motions']} motions no spring resists: free)" if out["free_motions"] else ""))
    return "\n".join(lines)


COMMAND = Command("the end effector's stiffness, deflection under a load and natural frequencies (joint springs)",
                  add_arguments, run)
