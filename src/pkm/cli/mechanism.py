"""The ``MECH`` argument of a command: the mechanism it names (a shipped one, its design changed by ``--param``,
or one's own closure spec file) and the configuration that ``--pose`` or ``--joints`` give; when the generic solvers
fail, a shipped mechanism's closed forms say why."""

from __future__ import annotations

import argparse

import numpy as np

import pkm
from pkm.cli.parsing import parse_joints, parse_params, parse_pose, parse_seed
from pkm.cli.usage import UsageError, late_help
from pkm.errors import ConvergenceError, PkmError


def mech_help() -> str:
    """What ``MECH`` takes: every input :func:`pkm.load` reads, from the tables that say so (the registry, the robots
    pkm ships, the installed packages' models, the model-file formats), so that it cannot drift from them."""
    from pkm.core.formats.base import FORMATS
    from pkm.core.formats.catalogue import CATALOGUE
    from pkm.core.formats.packages import PACKAGE_MODELS

    def by_source(names: list[str], what: str) -> str:
        sources = dict.fromkeys(n.partition(":")[0] for n in names)
        return ", ".join(f"{s}:<{what}> (e.g. {next(n for n in names if n.startswith(s + ':'))})" for s in sources)

    formats = ", ".join(f"{f.name.upper()} ({' '.join(f.suffixes)})" for f in FORMATS.values())
    return (f"a shipped mechanism ({', '.join(pkm.MECHANISMS)}); a robot pkm ships, "
            f"{by_source(list(CATALOGUE), 'robot')}; an installed package's model, "
            f"{by_source(list(PACKAGE_MODELS), 'model')} ('pkm list' names them all); or a path: a closure spec "
            "(NAME.closures.toml, naming its model file), a URDF + YAML in Gepetto's convention (their folder, or "
            f"either file), or a model file read by its content, {formats}: alone when it names its loops and "
            "actuated joints, else through a closure spec ('pkm spec init FILE' writes one)")


def add_mechanism_help(action: argparse.Action, before: str = "", after: str = "") -> argparse.Action:
    """Give the ``MECH`` argument ``action`` the help ``before + mech_help() + after``, computed when a help is
    printed (it reads the formats' tables: imports that ``pkm --help`` and every other run need not make)."""
    action.help = "what pkm.load takes (see the help)"
    return late_help(action, lambda: before + mech_help() + after)


def add_mechanism_arguments(p: argparse.ArgumentParser, pose: str | None, joints: str | None,
                            seed: str = "the solver's seed") -> None:
    """``MECH``, ``--param``, ``--actuated``, ``--task``, ``--q0`` and, if asked (``"required"`` or
    ``"optional"``), ``--pose`` (with ``--branch``) and ``--joints`` (exclusive when both are taken): every command
    that takes a configuration takes it alike."""
    add_mechanism_help(p.add_argument("mechanism", metavar="MECH"))
    p.add_argument("--param", metavar="K=V", action="extend", nargs="+", default=[],
                   help="a design parameter (see 'pkm list'); default: the paper's design")
    p.add_argument("--actuated", metavar="J1,J2",
                   help="the driven joints of a model file (one that names none, or in place of those it names)")
    p.add_argument("--task", metavar="FRAME[:KIND]",
                   help="the task of a model file: a frame's origin (x, y, z), or KIND: pose, or components such "
                        "as x,z (default: the actuated joints)")
    g = p.add_mutually_exclusive_group() if pose and joints else p
    if pose:
        g.add_argument("--pose", metavar="K=V", action="extend", nargs="+", required=pose == "required",
                       help="task coordinates (others keep the reference; see 'pkm list MECH')")
    if joints:
        g.add_argument("--joints", metavar="NAME=V", action="extend", nargs="+", required=joints == "required",
                       help="actuated joint values (others keep the reference; see 'pkm list MECH')")
    if pose:
        p.add_argument("--branch", metavar="NAME", help="the working mode --pose is solved on (see 'pkm list MECH')")
    if pose or joints:
        add_seed_argument(p, seed)


def add_seed_argument(p: argparse.ArgumentParser, what: str) -> None:
    """``--q0 NAME=V ...``: the seed configuration (:func:`~pkm.cli.parsing.parse_seed`), the option the messages
    of the solvers point to when they ask for a seed nearer the target."""
    p.add_argument("--q0", metavar="NAME=V", action="extend", nargs="+", default=[],
                   help=f"{what}: values of any joints, passive ones included (others keep the reference); its "
                        "assembly mode is kept")


def load_mechanism(args) -> pkm.Mechanism:
    """A shipped mechanism (its design changed by ``--param``) or one's own files (their actuated joints and task
    given by ``--actuated`` and ``--task`` where stated: :func:`pkm.load`'s ``actuated=`` and ``task=``)."""
    actuated, task = getattr(args, "actuated", None), getattr(args, "task", None)
    if args.mechanism not in pkm.MECHANISMS:
        if args.param:
            raise UsageError(f"--param sets the design of a shipped mechanism; {args.mechanism} states its own")
        return pkm.load(args.mechanism, actuated=actuated, task=task)
    if actuated is not None or task is not None:
        raise UsageError(f"--actuated and --task are for model files; {args.mechanism} states its own")
    params = parse_params(args.mechanism, args.param or [])
    return pkm.build(args.mechanism, **params) if params else pkm.load(args.mechanism)


def configuration(mech: pkm.Mechanism, args) -> np.ndarray:
    """The configuration that ``--pose`` (solved on ``--branch``) or ``--joints`` give, else the reference."""
    q0 = parse_seed(mech, getattr(args, "q0", None))
    if getattr(args, "pose", None):
        _, target = parse_pose(mech, args.pose)
        return solve_ik(mech, target, getattr(args, "branch", None), q0).q
    if getattr(args, "joints", None):
        return close_loops(mech, parse_joints(mech, args.joints), q0).q
    return mech.q_reference


def has_closed_forms(mech: pkm.Mechanism) -> bool:
    """Whether ``mech`` is a registered mechanism built from its parameters (so its closed forms apply)."""
    return mech.name in pkm.MECHANISMS and isinstance(mech.params, pkm.mechanism_module(mech.name).Params)


def solve_ik(mech: pkm.Mechanism, target, branch: str | None, q0: np.ndarray | None = None) -> pkm.SolveResult:
    """The generic IK (from the seed ``q0``, default the reference); when it fails, a shipped mechanism's closed
    form says which leg cannot reach, if one cannot."""
    from pkm.errors import UnreachableError

    try:
        return pkm.solve_ik(mech, target, q0, branch=branch)
    except (ConvergenceError, UnreachableError) as exc:
        if not has_closed_forms(mech):
            raise
        mod = pkm.mechanism_module(mech.name)
        try:
            mod.closed_form_ik(mech.params, pkm.TaskMap.of(mech).parse(target), branch)
        except UnreachableError as unreachable:
            raise unreachable from exc
        except PkmError:
            pass
        raise


def close_loops(mech: pkm.Mechanism, qa, q0: np.ndarray | None = None) -> pkm.SolveResult:
    """Generic loop closure (from the seed ``q0``, default the reference); when it fails, the paper's forward
    kinematics says if no assembly exists."""
    from pkm.errors import AssemblyError

    try:
        return pkm.close_loops(mech, qa, q0)
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
