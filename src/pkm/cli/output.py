"""What the command line prints: solutions and mode sets as JSON (SI, by name), and the one error line of a
refusal with its exit status."""

from __future__ import annotations

import sys
import traceback
from typing import Any

import pkm
from pkm.cli.usage import PROG, UsageError
from pkm.errors import PkmError, SpecError, UnitError, UnknownNameError
from pkm.report import jsonable


def task_values(mech: pkm.Mechanism, q) -> dict[str, float]:
    """The task coordinates of ``q`` by name (:meth:`pkm.core.TaskMap.named`; angles Z-Y-X Euler) [m, rad]."""
    return mech.task_map.named(q)


def _branch_of(mech: pkm.Mechanism, q) -> str | None:
    """The first of the mechanism's branches that ``q`` lies on, if any."""
    return next((b for b in mech.spec.branches if mech.on_branch(q, b)), None)


def solution_dict(mech: pkm.Mechanism, res: pkm.SolveResult, **extra) -> dict[str, Any]:
    """What ``ik`` and ``fk`` print: the solution by name, in SI, with the solver's report."""
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
        "branch": _branch_of(mech, res.q) if mech.spec.branches else None,
        "mode": res.mode.as_dict(),
    })


def modes_dict(mech: pkm.Mechanism, modes, **extra) -> dict[str, Any]:
    """What ``ik --all`` and ``fk --all`` print: every mode by name, in SI, and the set's account."""
    return jsonable({
        "mechanism": mech.name, "units": {"length": "m", "angle": "rad"}, **extra,
        "complete": modes.complete, "summary": modes.summary(), "method": modes.method, "paths": modes.n_paths,
        "bound": modes.bound, "complex": modes.n_complex, "at_infinity": modes.n_infinite,
        "exceptional": modes.n_exceptional, "failed": [{"path": p.index, "code": p.code} for p in modes.failed],
        "reduction": modes.reduction,
        "modes": [{"label": m.label, "actuated": dict(zip(mech.actuated_names, mech.actuated_q(m.q))),
                   "task": task_values(mech, m.q), "residual": m.residual, "alpha": m.certificate.alpha,
                   "certified_within": m.certificate.radius if m.certificate.certified else None,
                   "outside_limits": list(m.outside_limits),
                   "branch": _branch_of(mech, m.q) if mech.spec.branches else None,
                   "mode": pkm.mode_label(mech, m.q).as_dict()} for m in modes],
    })



def print_error(exc: PkmError, debug: bool = False) -> int:
    """Print ``pkm: error: ...`` on stderr (after the traceback with ``--debug``); return the exit status.

    The status is 2 when the command line is wrong (syntax, unknown names, units), 1 when pkm refuses or fails
    (invalid parameter, unreachable pose, no convergence, a broken file).
    """
    if debug:
        traceback.print_exc()
    print(f"{PROG}: error: {exc}", file=sys.stderr)
    named_wrong = isinstance(exc, UnknownNameError) and not isinstance(exc, SpecError)  # not a broken file
    return 2 if isinstance(exc, (UsageError, UnitError)) or named_wrong else 1
