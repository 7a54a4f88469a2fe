"""The ``MECH`` argument of a command: the mechanism it names (a shipped one, its design changed by ``--param``,
or one's own closure spec file) and the configuration that ``--pose`` or ``--joints`` give; when the generic solvers
fail, a shipped mechanism's closed forms say why."""

from __future__ import annotations

import argparse

import numpy as np

import pkm
from pkm.cli.parsing import parse_joints, parse_params, parse_pose
from pkm.cli.usage import UsageError
from pkm.errors import ConvergenceError, PkmError


def shipped() -> str:
    """The shipped mechanisms' names, for the help of ``MECH``."""
    return ", ".join(pkm.MECHANISMS)


def add_mechanism_arguments(p: argparse.ArgumentParser, pose: str | None, joints: str | None) -> None:
    """``MECH``, ``--param`` and, if asked (``"required"`` or ``"optional"``), ``--pose`` and ``--joints`` (exclusive
    when both are taken)."""
    mechs = shipped()
    p.add_argument("mechanism", metavar="MECH", help=f"one of {mechs}, or a closure spec file "
                                                     "(path/to/my.closures.toml, naming its URDF)")
    p.add_argument("--param", metavar="K=V", action="extend", nargs="+", default=[],
                   help="a design parameter (see 'pkm list'); default: the paper's design")
    g = p.add_mutually_exclusive_group() if pose and joints else p
    if pose:
        g.add_argument("--pose", metavar="K=V", action="extend", nargs="+", required=pose == "required",
                       help="task coordinates (others keep the reference; see 'pkm list')")
    if joints:
        g.add_argument("--joints", metavar="NAME=V", action="extend", nargs="+", required=joints == "required",
                       help="actuated joint values (others keep the reference; see 'pkm list')")


def load_mechanism(args) -> pkm.Mechanism:
    """A shipped mechanism (its design changed by ``--param``) or one's own closure spec file."""
    if args.mechanism not in pkm.MECHANISMS:
        if args.param:
            raise UsageError(f"--param sets the design of a shipped mechanism; {args.mechanism} states its own")
        return pkm.load(args.mechanism)
    params = parse_params(args.mechanism, args.param or [])
    return pkm.build(args.mechanism, **params) if params else pkm.load(args.mechanism)


def configuration(mech: pkm.Mechanism, args) -> np.ndarray:
    """The configuration that ``--pose`` (solved on ``--branch``) or ``--joints`` give, else the reference."""
    if args.pose:
        _, target = parse_pose(mech, args.pose)
        return solve_ik(mech, target, getattr(args, "branch", None)).q
    if args.joints:
        return close_loops(mech, parse_joints(mech, args.joints)).q
    return mech.q_reference


def has_closed_forms(mech: pkm.Mechanism) -> bool:
    """Whether ``mech`` is a registered mechanism built from its parameters (so its closed forms apply)."""
    return mech.name in pkm.MECHANISMS and isinstance(mech.params, pkm.mechanism_module(mech.name).Params)


def solve_ik(mech: pkm.Mechanism, target, branch: str | None) -> pkm.SolveResult:
    """The generic IK; when it fails, a shipped mechanism's closed form says which leg cannot reach, if one cannot."""
    from pkm.errors import UnreachableError

    try:
        return pkm.solve_ik(mech, target, branch=branch)
    except (ConvergenceError, UnreachableError) as exc:
        if not has_closed_forms(mech):
            raise
        mod = pkm.mechanism_module(mech.name)
        try:
            mod.closed_form_ik(mech.params, mech.task_map.parse(target), branch)
        except UnreachableError as unreachable:
            raise unreachable from exc
        except PkmError:
            pass
        raise


def close_loops(mech: pkm.Mechanism, qa) -> pkm.SolveResult:
    """Generic loop closure; when it fails, the paper's forward kinematics says if no assembly exists."""
    from pkm.errors import AssemblyError

    try:
        return pkm.close_loops(mech, qa)
    except ConvergenceError as exc:
        if not has_closed_forms(mech):
            raise
        mod = pkm.mechanism_module(mech.name)
        if mod.closed_form_fk is not None:
            try:
                mod.closed_form_fk(mech.params, qa)
            except AssemblyError as none:
                raise none from exc
            except PkmError:
                pass
        raise
