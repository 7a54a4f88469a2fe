"""What the command line prints: solutions and mode sets as JSON (SI, by name), and the one error line of a
refusal with its exit status."""

from __future__ import annotations

import contextlib
import re
import sys
import traceback
import warnings
from collections.abc import Iterator
from typing import Any

import pkm
from pkm.cli.usage import PROG, UsageError
from pkm.errors import PkmError, PkmWarning, SpecError, UnitError, UnknownNameError
from pkm.report import jsonable


def task_values(mech: pkm.Mechanism, q) -> dict[str, float]:
    """The task coordinates of ``q`` by name (:meth:`pkm.core.TaskMap.named`; angles Z-Y-X Euler) [m, rad]."""
    return pkm.TaskMap.of(mech).named(q)


def _branch_of(mech: pkm.Mechanism, q) -> str | None:
    """The first of the mechanism's branches that ``q`` lies on, if any."""
    return next((b for b in mech.spec.branches if mech.on_branch(q, b)), None)


def outside_limits(mech: pkm.Mechanism, q) -> list[dict[str, Any]]:
    """The joints of ``q`` outside the position limits the model states, each ``{"joint", "value", "limit"}``
    [rad, m] (:meth:`pkm.core.Mechanism.limit_violations`): what every command that prints a configuration lists."""
    return [v._asdict() for v in mech.limit_violations(q)]


def outside_line(outside: list[dict[str, Any]]) -> str:
    """The text line that says :func:`outside_limits` (empty where none is outside)."""
    return "" if not outside else "warning: outside the position limits the model states: " + ", ".join(
        f"{o['joint']} = {o['value']:.6g} (limits [{o['limit'][0]:.6g}, {o['limit'][1]:.6g}])" for o in outside)


def solution_dict(mech: pkm.Mechanism, res: pkm.SolveResult, **extra) -> dict[str, Any]:
    """What ``ik`` and ``fk`` print: the solution by name, in SI, with the solver's report; ``status`` is ``"ok"``,
    or ``"outside_limits"`` where a joint lies outside the position limits the model states (``outside_limits``
    names each with its value and limits: pkm's solvers report limits, they do not enforce them)."""
    outside = outside_limits(mech, res.q)
    return jsonable({
        "mechanism": mech.name,
        "units": {"length": "m", "angle": "rad",
                  "note": "SI throughout: lengths in m, angles in rad (task angles: Z-Y-X Euler roll, pitch, yaw); "
                          "a free-flyer joint is x y z qx qy qz qw"},
        **extra,
        "actuated": dict(zip(mech.actuated_names, mech.actuated_q(res.q))),
        "task": task_values(mech, res.q),
        "joints": mech.q_to_dict(res.q),
        "residual": res.residual,
        "iterations": res.iterations,
        "converged": res.converged,
        "status": "outside_limits" if outside else "ok",
        "outside_limits": outside,
        "branch": _branch_of(mech, res.q) if mech.spec.branches else None,
        "mode": res.mode.as_dict(),
    })


def modes_dict(mech: pkm.Mechanism, modes, **extra) -> dict[str, Any]:
    """What ``ik --all`` and ``fk --all`` print: every mode by name, in SI, and the set's account; where the
    mechanism has collision geometry, each mode's ``clearance`` [m] and whether it ``interferes``."""
    return jsonable({
        "mechanism": mech.name, "units": {"length": "m", "angle": "rad"}, **extra,
        "complete": modes.complete, "summary": modes.summary(), "method": modes.method, "paths": modes.n_paths,
        "bound": modes.bound, "complex": modes.n_complex, "at_infinity": modes.n_infinite,
        "exceptional": modes.n_exceptional, "failed": [{"path": p.index, "code": p.code} for p in modes.failed],
        "reduction": modes.reduction,
        "modes": [{"label": m.label, "actuated": dict(zip(mech.actuated_names, mech.actuated_q(m.q))),
                   "task": task_values(mech, m.q), "residual": m.residual, "alpha": m.certificate.alpha,
                   "certified_within": m.certificate.radius if m.certificate.certified else None,
                   "outside_limits": outside_limits(mech, m.q),
                   **({} if m.clearance is None else {"clearance": m.clearance, "interferes": m.interferes}),
                   "branch": _branch_of(mech, m.q) if mech.spec.branches else None,
                   "mode": pkm.mode_label(mech, m.q).as_dict()} for m in modes],
    })



SEED_HINT = "on the command line the seed is --q0 NAME=V ..., any joints by name (see 'pkm list MECH')"
"""What a message of the library that asks for a seed (``q0``) gets added in a command that takes ``--q0``."""


def seed_hint(text: str) -> str:
    """``text`` with :data:`SEED_HINT` added when it asks for the library's seed ``q0`` (the solvers' failures and
    :class:`~pkm.errors.ModeChangeWarning` say "seed nearer the target (q0)")."""
    return f"{text} [{SEED_HINT}]" if re.search(r"\(q0\)|\bas q0\b", text) else text


@contextlib.contextmanager
def seed_hints() -> Iterator[None]:
    """While it is open, a :class:`~pkm.errors.PkmWarning` shown that asks for a seed carries :data:`SEED_HINT`."""
    shown = warnings.showwarning

    def show(message: Warning | str, category: type[Warning], filename: str, lineno: int, file: Any = None,
             line: str | None = None) -> None:
        if isinstance(message, PkmWarning) and message.args and isinstance(message.args[0], str):
            message.args = (seed_hint(message.args[0]), *message.args[1:])
        shown(message, category, filename, lineno, file, line)

    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = shown


def print_error(exc: PkmError, debug: bool = False, seed: bool = False) -> int:
    """Print ``pkm: error: ...`` on stderr (after the traceback with ``--debug``); return the exit status.
    ``seed``: the command takes ``--q0`` (a message asking for a seed says so, :func:`seed_hint`).

    The status is 2 when the command line is wrong (syntax, unknown names, units), 1 when pkm refuses or fails
    (invalid parameter, unreachable pose, no convergence, a broken file).
    """
    if debug:
        traceback.print_exc()
    text = seed_hint(str(exc)) if seed else str(exc)
    print(f"{PROG}: error: {text}", file=sys.stderr)
    named_wrong = isinstance(exc, UnknownNameError) and not isinstance(exc, SpecError)  # not a broken file
    return 2 if isinstance(exc, (UsageError, UnitError)) or named_wrong else 1
