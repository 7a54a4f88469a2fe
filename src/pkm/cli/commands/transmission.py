"""``pkm transmission MECH --out DIR [--targets c,jax,warp] [--outputs J1,J2] [--name NAME] [--json]``: a closed
sub-mechanism's transmission kernels (motors <-> output joints, velocity and effort maps, ΔM and Δh) written for a
robot's software (:func:`pkm.core.transmissions.targets.write_transmission`): C99 with a C++17 class in the method
set of ros2_control's ``transmission_interface::Transmission``, a JAX module, a Warp module, ``transmission.json``
and a README (the ros2_control recipe).

``MECH`` is the sub-mechanism (its actuated joints the motors); the outputs are ``--outputs``, else its task when
the task is joints only (the shipped ankle and knee: their serial joints)."""

from __future__ import annotations

import argparse
import json
from typing import Any

from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, load_mechanism


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, None, None)
    p.add_argument("--out", metavar="DIR", required=True, help="the folder to write (created)")
    p.add_argument("--targets", metavar="T1,T2", default="c,jax,warp",
                   help="among c (C99 and the C++17 header), jax, warp (default: all three)")
    p.add_argument("--outputs", metavar="J1,J2",
                   help="the output joints (default: the task's joints, when the task is joints only)")
    p.add_argument("--name", help="the transmission's name, the C prefix (default: the mechanism's name)")
    p.add_argument("--json", action="store_true", help="print JSON")


def outputs_of(mech: Any, given: str | None) -> tuple[str, ...]:
    """The output joints: ``given`` (comma-separated), else the task's joints when the task is joints only."""
    from pkm.errors import InvalidInputError

    if given:
        return tuple(s.strip() for s in given.split(",") if s.strip())
    task = mech.spec.task
    if task.components or task.frames or not task.joints or mech.spec.task_is_actuated:
        raise InvalidInputError("--outputs", f"{mech.name}'s task is not a set of output joints: name them "
                                             f"(its joints: {', '.join(mech.joints)})")
    return tuple(task.joints)


def run(args: argparse.Namespace) -> int:
    from pkm.core.transmissions.kernels import TransmissionKernels
    from pkm.core.transmissions.targets import write_transmission

    mech = load_mechanism(args)
    targets = [t.strip() for t in args.targets.split(",") if t.strip()]
    tk = TransmissionKernels(mech, outputs_of(mech, args.outputs), name=args.name)
    files = write_transmission(tk, args.out, targets)
    out = {"transmission": tk.name, "motors": list(tk.motors), "outputs": list(tk.outputs), "targets": targets,
           "files": [str(f) for f in files.values()],
           "instructions": {k: tk.function(k).n_instructions() for k in ("fk", "ik", "maps", "delta", "fk_j_dm")}}
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(f"{tk.name}: motors {', '.join(tk.motors)} -> outputs {', '.join(tk.outputs)}; "
          f"{', '.join(targets)} in {args.out} ({', '.join(files)})")
    print("  instructions: " + ", ".join(f"{k} {n}" for k, n in out["instructions"].items()))
    return 0


COMMAND = Command("a closed sub-mechanism's transmission kernels (C/C++, JAX, Warp) for a robot's software",
                  add_arguments, run)
