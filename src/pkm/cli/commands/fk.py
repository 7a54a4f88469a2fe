"""``pkm fk MECH --joints NAME=V ... [--all]``: forward kinematics, the pose for actuated values (JSON, SI)."""

from __future__ import annotations

import argparse
import json

import pkm
from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, close_loops, load_mechanism
from pkm.cli.output import modes_dict, solution_dict
from pkm.cli.parsing import parse_joints, parse_seed


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, None, "required")
    p.add_argument("--all", action="store_true",
                   help="every assembly mode (homotopy continuation, pkm-robotics[homotopy])")


def run(args: argparse.Namespace) -> int:
    mech = load_mechanism(args)
    qa = parse_joints(mech, args.joints)
    if args.all:
        print(json.dumps(modes_dict(mech, pkm.assembly_modes(mech, qa)), indent=2))
        return 0
    res = close_loops(mech, qa, parse_seed(mech, args.q0))
    print(json.dumps(solution_dict(mech, res), indent=2))
    return 0


COMMAND = Command("forward kinematics: the pose for actuated values (JSON, SI)", add_arguments, run)
