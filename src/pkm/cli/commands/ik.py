"""``pkm ik MECH --pose K=V ... [--branch NAME] [--all]``: inverse kinematics, every joint for a pose (JSON, SI)."""

from __future__ import annotations

import argparse
import json

import pkm
from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, load_mechanism, solve_ik
from pkm.cli.output import modes_dict, solution_dict
from pkm.cli.parsing import parse_pose, parse_seed


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, "required", None)
    p.add_argument("--all", action="store_true",
                   help="every working mode (homotopy continuation, pkm-robotics[homotopy])")


def run(args: argparse.Namespace) -> int:
    mech = load_mechanism(args)
    if args.branch is not None:
        mech.branch(args.branch)  # UnknownNameError listing the branches
    values, target = parse_pose(mech, args.pose)
    if args.all:
        print(json.dumps(modes_dict(mech, pkm.working_modes(mech, target), target=values), indent=2))
        return 0
    res = solve_ik(mech, target, args.branch, parse_seed(mech, args.q0))
    print(json.dumps(solution_dict(mech, res, target=values), indent=2))
    return 0


COMMAND = Command("inverse kinematics: every joint for a pose (JSON, SI)", add_arguments, run)
