"""``pkm transmission MECH --out DIR [--targets c,jax,warp] [--outputs NAME=J1,J2 ...] [--skip-unfit] [--serial
[--around JOINT=VALUE ...]] [--json]``: each closed sub-mechanism of a robot (:func:`pkm.transmissions`;
``--skip-unfit``: those that can be, a warning naming the others) as transmission kernels (motors <-> output joints,
velocity and effort maps, ΔM and Δh:
:mod:`pkm.core.transmissions.kernels`) written for a robot's software
(:func:`pkm.core.transmissions.targets.write_transmission`), one folder ``DIR/<transmission>`` each: C99 with a C++17
class in the method set of ros2_control's ``transmission_interface::Transmission``, a JAX module, a Warp module,
``transmission.json`` and a README (the ros2_control recipe). ``--serial`` also writes the robot's serial-equivalent
model into ``DIR`` (:func:`pkm.write_serial_equivalent`: URDF, MJCF, each sub-mechanism's files and the data file),
its box limits about the reference (or ``--around``), each with its share of its feasible region's area;
``--skip-unfit`` leaves out a loop that cannot be a transmission (``skip_unfit=True``)."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, load_mechanism


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, None, None)
    p.add_argument("--out", metavar="DIR", required=True, help="the folder to write (one folder a transmission)")
    p.add_argument("--targets", metavar="T1,T2", default="c,jax,warp",
                   help="among c (C99 and the C++17 header), jax, warp (default: all three)")
    p.add_argument("--outputs", metavar="NAME=J1,J2", action="extend", nargs="+", default=[],
                   help="a transmission's name and output joints (default: the chain rule of pkm.transmissions)")
    p.add_argument("--skip-unfit", action="store_true",
                   help="leave out, with a warning saying why, a closed sub-mechanism that cannot be a transmission "
                        "(a knee loop that moves springs too) and write the others")
    p.add_argument("--serial", action="store_true",
                   help="also write the serial-equivalent model (URDF, MJCF, data file) into DIR")
    p.add_argument("--around", metavar="JOINT=VALUE", action="extend", nargs="+", default=[],
                   help="with --serial: the point an output's box limits hold [rad or m] (default: the reference)")
    p.add_argument("--json", action="store_true", help="print JSON")


def parse_outputs(items: list[str]) -> dict[str, list[str]] | None:
    """``["left=pitch,roll", ...]`` as ``{"left": ["pitch", "roll"]}`` (None for none)."""
    from pkm.errors import InvalidInputError

    out = {}
    for item in items:
        name, _, joints = item.partition("=")
        if not name.strip() or not joints.strip():
            raise InvalidInputError("--outputs", "expected NAME=J1,J2 (a transmission's name and its output joints)",
                                    item)
        out[name.strip()] = [j.strip() for j in joints.split(",") if j.strip()]
    return out or None


def parse_around(items: list[str]) -> dict[str, float]:
    """``["ankle_pitch=0.1", ...]`` as ``{"ankle_pitch": 0.1}`` (SI: rad or m)."""
    from pkm.errors import InvalidInputError

    out = {}
    for item in items:
        name, _, value = item.partition("=")
        try:
            number = float(value)
        except ValueError:
            number = float("nan")
        if not name.strip() or not math.isfinite(number):
            raise InvalidInputError("--around", "expected JOINT=VALUE (an output joint and a finite number, rad or m)",
                                    item)
        out[name.strip()] = number
    return out


def run(args: argparse.Namespace) -> int:
    import pkm
    from pkm.core.transmissions.kernels import TransmissionKernels
    from pkm.core.transmissions.targets import TARGETS, write_transmission
    from pkm.errors import InvalidInputError

    targets = [t.strip() for t in args.targets.split(",") if t.strip()]
    if not targets or any(t not in TARGETS for t in targets):
        raise InvalidInputError("--targets", f"choose among {', '.join(TARGETS)}", args.targets)
    around = parse_around(args.around)
    if around and not args.serial:
        raise InvalidInputError("--around", "the box limits' point is for the serial-equivalent model: add --serial",
                                args.around)
    mech = load_mechanism(args)
    out: list[dict[str, Any]] = []
    found = pkm.transmissions(mech, parse_outputs(args.outputs), skip_unfit=args.skip_unfit)
    serial = pkm.serial_equivalent(mech, found, around=around) if args.serial else None  # (refusals before writing)
    for t in found:
        tk = TransmissionKernels.of(t)
        files = write_transmission(tk, Path(args.out) / t.name, targets)
        maps = t.mechanism.motor_map
        out.append({"transmission": t.name, "root": t.root, "motors": list(t.motors), "outputs": list(t.outputs),
                    "drives": list(t.drives), "constant": t.constant,
                    "motor_map": None if maps.identity else {
                        m: {d: float(c) for d, c in zip(t.drives, row) if c != 0.0}
                        for m, row in zip(t.motors, t.motor_matrix)},
                    "motor_equations": [] if maps.identity else list(maps.equations(t.drives)),
                    "folder": str(Path(args.out) / t.name), "files": sorted(files),
                    "instructions": {k: tk.function(k).n_instructions() for k in ("fk", "ik", "maps", "delta")}})
    model: dict[str, Any] | None = None
    if serial is not None:
        written = pkm.write_serial_equivalent(serial, args.out)
        model = {"files": [str(f) for f in written], "outputs": list(serial.outputs),
                 "limits": {o: list(serial.limits[o]) for o in serial.outputs if o in serial.limits},
                 "area_fraction": {t: r.area_fraction for t, r in serial.regions.items()},
                 "armature": serial.armature}
    if args.json:
        print(json.dumps({"mechanism": mech.name, "targets": targets, "transmissions": out, "serial": model},
                         indent=2))
        return 0
    for o in out:
        print(f"{o['transmission']}: motors {', '.join(o['motors'])} -> outputs {', '.join(o['outputs'])}; "
              f"{', '.join(targets)} in {o['folder']}")
        if o["motor_equations"]:
            print(f"  motors through a constant map{' (a differential: constant maps)' if o['constant'] else ''}: "
                  + "; ".join(o["motor_equations"]))
        print("  instructions: " + ", ".join(f"{k} {n}" for k, n in o["instructions"].items()))
    if serial is not None and model is not None:
        print(f"serial-equivalent model: {', '.join(Path(f).name for f in model['files'])} in {args.out}")
        for t in serial.transmissions:
            reg = serial.regions.get(t.name)
            share = "" if reg is None or reg.area_fraction is None else \
                f" ({100 * reg.area_fraction:.3g} % of the feasible region's {'area' if t.k > 1 else 'length'})"
            limits = ", ".join(f"{o} [{serial.limits[o][0]:.6g}, {serial.limits[o][1]:.6g}]" for o in t.outputs
                               if o in serial.limits) or "no limits"
            print(f"  {t.name}: {limits}{share}")
    return 0


COMMAND = Command("each closed sub-mechanism's transmission kernels (C/C++, JAX, Warp) for a robot's software",
                  add_arguments, run)
