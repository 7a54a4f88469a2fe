"""``pkm transmission MECH --out DIR [--targets c,jax,warp] [--outputs NAME=J1,J2 ...] [--skip-unfit] [--json]``: each
closed sub-mechanism of a robot (:func:`pkm.transmissions`; ``--skip-unfit``: those that can be, a warning naming
the others) as transmission kernels (motors <-> output joints, velocity and effort maps, ΔM and Δh:
:mod:`pkm.core.transmissions.kernels`) written for a robot's software
(:func:`pkm.core.transmissions.targets.write_transmission`), one folder ``DIR/<transmission>`` each: C99 with a C++17
class in the method set of ros2_control's ``transmission_interface::Transmission``, a JAX module, a Warp module,
``transmission.json`` and a README (the ros2_control recipe)."""

from __future__ import annotations

import argparse
import json
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


def run(args: argparse.Namespace) -> int:
    import pkm
    from pkm.core.transmissions.kernels import TransmissionKernels
    from pkm.core.transmissions.targets import TARGETS, write_transmission
    from pkm.errors import InvalidInputError

    targets = [t.strip() for t in args.targets.split(",") if t.strip()]
    if not targets or any(t not in TARGETS for t in targets):
        raise InvalidInputError("--targets", f"choose among {', '.join(TARGETS)}", args.targets)
    mech = load_mechanism(args)
    out: list[dict[str, Any]] = []
    for t in pkm.transmissions(mech, parse_outputs(args.outputs), skip_unfit=args.skip_unfit):
        tk = TransmissionKernels.of(t)
        files = write_transmission(tk, Path(args.out) / t.name, targets)
        out.append({"transmission": t.name, "root": t.root, "motors": list(t.motors), "outputs": list(t.outputs),
                    "folder": str(Path(args.out) / t.name), "files": sorted(files),
                    "instructions": {k: tk.function(k).n_instructions() for k in ("fk", "ik", "maps", "delta")}})
    if args.json:
        print(json.dumps({"mechanism": mech.name, "targets": targets, "transmissions": out}, indent=2))
        return 0
    for o in out:
        print(f"{o['transmission']}: motors {', '.join(o['motors'])} -> outputs {', '.join(o['outputs'])}; "
              f"{', '.join(targets)} in {o['folder']}")
        print("  instructions: " + ", ".join(f"{k} {n}" for k, n in o["instructions"].items()))
    return 0


COMMAND = Command("each closed sub-mechanism's transmission kernels (C/C++, JAX, Warp) for a robot's software",
                  add_arguments, run)
