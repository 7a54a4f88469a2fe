"""The subcommands of ``pkm``: one module each (``sweep`` and its ``plot``, ``best`` share one), registered in
:data:`COMMANDS`, which :func:`pkm.cli.build_parser` and :func:`pkm.cli.main` iterate.

Adding a command is one module defining a :class:`~pkm.cli.command.Command` and one line here. A module imports
what its command needs inside its functions, so that ``pkm --help`` stays fast.
"""

from __future__ import annotations

from pkm.cli.command import Command
from pkm.cli.commands import (
    bench,
    calibrate,
    capability,
    clearance,
    convert,
    dynamics,
    excite,
    export,
    fk,
    identify,
    ik,
    plan,
    preview,
    report,
    serve,
    simulate,
    spec,
    stiffness,
    sweep,
    transmission,
)
from pkm.cli.commands import list as list_
from pkm.cli.commands import map as map_

COMMANDS: dict[str, Command] = {
    "list": list_.COMMAND,
    "preview": preview.COMMAND,
    "ik": ik.COMMAND,
    "fk": fk.COMMAND,
    "map": map_.COMMAND,
    "dynamics": dynamics.COMMAND,
    "simulate": simulate.COMMAND,
    "plan": plan.COMMAND,
    "excite": excite.COMMAND,
    "identify": identify.COMMAND,
    "calibrate": calibrate.COMMAND,
    "calibrate plan": calibrate.PLAN,
    "capability": capability.COMMAND,
    "stiffness": stiffness.COMMAND,
    "clearance": clearance.COMMAND,
    "export": export.COMMAND,
    "convert": convert.COMMAND,
    "spec": spec.COMMAND,
    "report": report.COMMAND,
    "serve": serve.COMMAND,
    "transmission": transmission.COMMAND,
    "bench": bench.COMMAND,
    "sweep": sweep.COMMAND,
    "sweep plot": sweep.PLOT,
    "sweep best": sweep.BEST,
}
"""Name as typed (``"sweep plot"``: two words, also ``sweep-plot``) -> command, in the order of ``pkm --help``."""

__all__ = ["COMMANDS"]
