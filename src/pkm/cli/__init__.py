"""The ``pkm`` command line (also ``python -m pkm``).

Usage::

    pkm list [MECH | FOLDER ...] [--json]
    pkm preview MECH [--param K=V ...] [--pose K=V ... | --joints NAME=V ...] [--html FILE] [--no-wait]
    pkm ik MECH --pose K=V ... [--param K=V ...] [--branch NAME]
    pkm fk MECH --joints NAME=V ... [--param K=V ...]
    pkm dynamics MECH [--pose K=V ... | --joints NAME=V ...] [--rates NAME=V ...] [--json]
    pkm simulate MECH [--torques FILE.csv | --controller FILE.py:FN] [--duration 2s] [--dt 1ms] --out FILE
    pkm spec init MODEL [--out FILE] [--force]
    pkm report [--out DIR] [--paper NAME ...] [--no-figures] [--no-series]
    pkm bench [NAME ...] [--json] [--quick] [-- ARGS passed to each benchmark]
    pkm sweep MECH NAME=START:STOP:COUNT ... --objective SPEC ... [--out FILE.parquet] [--scheduler ADDR]
    pkm sweep plot FILE.parquet [--out DIR] [--pareto A,B]
    pkm sweep best FILE.parquet --by OBJECTIVE [--n N] [--out DIR]

MECH is anything :func:`pkm.load` takes (``pkm ik --help`` says what, from the formats' tables); a folder given to
``pkm list`` is searched for it. Where a solver asks for a seed nearer the target (``q0``), the commands that solve
take it as ``--q0 NAME=V ...`` (any joints by name).

Values are SI (m, rad, kg) unless they carry a unit: ``R=120mm``, ``beta=-11deg``, ``z=81cm``
(lengths m, cm, mm; angles rad, deg; masses kg, g), and so do joint values: ``--joints motor_1=-30deg``,
``--rates motor_3=-30deg/s`` (rad/s, deg/s, rpm; m/s, mm/s), ``--q0``, ``--v0``, read by the route the library
and the service use (:func:`pkm.units.parse_joint_value`). A parameter's units are those of its field's
metadata (``La: float = param(0.110, "m")``, stated in brackets in the docstring too); a suffix of
another kind is refused.
Tuple parameters take comma-separated values (``home=0,0,-375mm``). Task coordinates not given
to ``--pose`` keep their reference values, and so do actuated joints not given to ``--joints``.
``ik`` and ``fk`` print JSON in SI units (lengths m, angles rad).

Exit status: 0 on success, 2 when the command line is wrong (syntax, unknown names, units),
1 when pkm refuses or fails (any :class:`~pkm.errors.PkmError`: unreachable pose, invalid
parameter, no convergence). Errors print one line ``pkm: error: ...`` on stderr; ``--debug``
adds the traceback.

Modules: :mod:`~pkm.cli.app` (the parser and :func:`main`), :mod:`~pkm.cli.commands` (one module per command,
registered in :data:`~pkm.cli.commands.COMMANDS`), :mod:`~pkm.cli.command` (what a command is),
:mod:`~pkm.cli.parsing` (parameters, their units and descriptions; ``NAME=VALUE`` items),
:mod:`~pkm.cli.mechanism` (the ``MECH`` argument and its configuration), :mod:`~pkm.cli.output` (JSON, error
lines), :mod:`~pkm.cli.usage` (:class:`UsageError` and the parser that raises it).
"""

from __future__ import annotations

from pkm.cli.app import build_parser, main
from pkm.cli.command import Command
from pkm.cli.commands import COMMANDS
from pkm.cli.output import modes_dict, solution_dict, task_values
from pkm.cli.parsing import ParamInfo, attribute_docs, param_info, parse_axis, parse_joints, parse_params, parse_pose
from pkm.cli.usage import PROG, UsageError
from pkm.units import SUFFIXES, parse_quantity

__all__ = ["COMMANDS", "PROG", "SUFFIXES", "Command", "ParamInfo", "UsageError", "attribute_docs", "build_parser",
           "main", "modes_dict", "param_info", "parse_axis", "parse_joints", "parse_params", "parse_pose",
           "parse_quantity", "solution_dict", "task_values"]
