"""The ``pkm`` command line (also ``python -m pkm``).

Usage::

    pkm list [--json]
    pkm preview MECH [--param K=V ...] [--pose K=V ... | --joints NAME=V ...] [--html FILE] [--no-wait]
    pkm ik MECH --pose K=V ... [--param K=V ...] [--branch NAME]
    pkm fk MECH --joints NAME=V ... [--param K=V ...]
    pkm spec init MODEL [--out FILE] [--force]
    pkm report [--out DIR] [--paper NAME ...] [--no-figures] [--no-series]
    pkm bench [NAME ...] [--json] [--quick] [-- ARGS passed to each benchmark]
    pkm sweep MECH NAME=START:STOP:COUNT ... --objective SPEC ... [--out FILE.parquet] [--scheduler ADDR]
    pkm sweep plot FILE.parquet [--out DIR] [--pareto A,B]
    pkm sweep best FILE.parquet --by OBJECTIVE [--n N] [--out DIR]

Values are SI (m, rad, kg) unless they carry a unit: ``R=120mm``, ``beta=-11deg``, ``z=81cm``
(lengths m, cm, mm; angles rad, deg; masses kg, g). A parameter's units are those of its field's
metadata (``La: float = param(0.110, "m")``, stated in brackets in the docstring too); a suffix of
another kind is refused.
Tuple parameters take comma-separated values (``home=0,0,-375mm``). Task coordinates not given
to ``--pose`` keep their reference values, and so do actuated joints not given to ``--joints``.
``ik`` and ``fk`` print JSON in SI units (lengths m, angles rad).

Exit status: 0 on success, 2 when the command line is wrong (syntax, unknown names, units),
1 when pkm refuses or fails (any :class:`~pkm.errors.PkmError`: unreachable pose, invalid
parameter, no convergence). Errors print one line ``pkm: error: ...`` on stderr; ``--debug``
adds the traceback.
"""

from __future__ import annotations

import argparse
import dataclasses
import inspect
import json
import math
import os
import re
import signal
import sys
import time
import traceback
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

import pkm
from pkm.errors import ConvergenceError, InvalidInputError, PkmError, SpecError, UnitError, UnknownNameError
from pkm.report import jsonable
from pkm.units import KIND_OF_UNIT, SI_UNITS, SUFFIXES, parse_quantity, split_range

PROG = "pkm"

_UNIT = re.compile(r"\[([A-Za-z][A-Za-z0-9^ /*.-]*|-)\]")
_ITEM = re.compile(r"^([A-Za-z_]\w*(?:\s*,\s*[A-Za-z_]\w*)*):\s*(.*)$")
_UNITLESS_TYPES = ("str", "int", "bool")


class UsageError(InvalidInputError):
    """The command line is malformed (exit status 2)."""

    def __init__(self, message: str, value: object = None):
        super().__init__("usage", message, value)

    def __str__(self) -> str:
        return str(self.args[0]).removeprefix("usage: ")


# ---------------------------------------------------------------------- parameters and their units
@dataclass(frozen=True)
class ParamInfo:
    """One field of a mechanism's ``Params`` dataclass, as documented.

    Attributes:
        name: Field name.
        type: Its annotation, as written (``"float"``, ``"tuple[float, ...]"``, ``"str"``).
        default: The default value (SI; None: found for the design, such as the reference pose).
        units: The field's units from its metadata (``("m",)``, ``("m", "rad")``); empty for a field
            without one (text, integers).
        description: The docstring entry, backticks removed.
        length: The number of values of a tuple field (its metadata), None for a scalar.
    """

    name: str
    type: str
    default: Any
    units: tuple[str, ...]
    description: str
    length: int | None = None

    @property
    def unitless(self) -> bool:
        """A text, integer or boolean field: no unit by nature."""
        return self.type in _UNITLESS_TYPES

    @property
    def unit(self) -> str:
        """The units for display (``"-"`` when none)."""
        return ", ".join(self.units) or "-"

    @property
    def summary(self) -> str:
        """The first sentence of the description, units and defaults in brackets left out."""
        first = re.split(r"(?<=\.)\s", self.description, maxsplit=1)[0]
        return re.sub(r"\s+([;,)])", r"\1", re.sub(r"\s+", " ", _UNIT.sub("", first))).strip().rstrip(".")


def attribute_docs(cls: type) -> dict[str, str]:
    """``{field: description}`` from the ``Attributes:`` section of a Google-style class docstring.

    An entry may name several fields (``Ixx3, Iyy3, Izz3: ...``); continuation lines are joined.
    """
    lines = inspect.cleandoc(cls.__doc__ or "").splitlines()
    try:
        start = next(i for i, ln in enumerate(lines) if ln.strip() == "Attributes:") + 1
    except StopIteration:
        return {}
    base = len(lines[start - 1]) - len(lines[start - 1].lstrip())
    out: dict[str, str] = {}
    names: list[str] = []
    indent = None
    for ln in lines[start:]:
        if not ln.strip():
            continue
        ind = len(ln) - len(ln.lstrip())
        if ind <= base:
            break
        if indent is None:
            indent = ind
        m = _ITEM.match(ln.strip()) if ind == indent else None
        if m:
            names = [n.strip() for n in m.group(1).split(",")]
            for n in names:
                out[n] = m.group(2).strip()
        else:
            for n in names:
                out[n] += " " + ln.strip()
    return out


def param_info(mechanism: str) -> dict[str, ParamInfo]:
    """The parameters of ``mechanism`` with their defaults, their units (the fields' metadata, see
    :func:`pkm.mechanisms._common.param`) and their descriptions (the class docstring).

    Raises:
        UnknownNameError: ``mechanism`` is not one of :data:`pkm.MECHANISMS`.
    """
    cls = pkm.mechanism_module(mechanism).Params
    docs = attribute_docs(cls)
    defaults = cls()
    out = {}
    for f in dataclasses.fields(cls):
        text = docs.get(f.name, "").replace("``", "")
        units = tuple(f.metadata.get("units", ()))
        ftype = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", str(f.type))
        out[f.name] = ParamInfo(f.name, ftype, getattr(defaults, f.name), units, text, f.metadata.get("length"))
    return out


def _kinds(units: Sequence[str]) -> set[str | None]:
    return {KIND_OF_UNIT.get(u) for u in units}


def _split(item: str, what: str) -> tuple[str, str]:
    name, eq, value = item.partition("=")
    if not eq or not name.strip() or not value.strip():
        raise UsageError(f"{what} {item!r} must read NAME=VALUE (e.g. R=120mm)")
    return name.strip(), value.strip()


def parse_params(mechanism: str, items: Sequence[str]) -> dict[str, Any]:
    """``--param`` items ``NAME=VALUE`` as keyword arguments of the mechanism's ``Params`` (SI).

    Raises:
        UsageError: Missing ``=``, a bad number or unit, or the wrong number of tuple entries.
        UnknownNameError: A name that is not a parameter (the valid names listed).
    """
    info = param_info(mechanism)
    out: dict[str, Any] = {}
    for item in items:
        name, text = _split(item, "--param")
        if name not in info:
            raise UnknownNameError("parameter", name, list(info), mechanism)
        p = info[name]
        if p.type == "str":
            out[name] = text
        elif p.type == "int":
            try:
                out[name] = int(text)
            except ValueError:
                raise UsageError(f"{name}={text!r}: {name} takes an integer") from None
        elif p.type == "bool":
            if text.lower() not in ("true", "false", "1", "0"):
                raise UsageError(f"{name}={text!r}: {name} takes true or false")
            out[name] = text.lower() in ("true", "1")
        elif p.length is not None:
            parts = text.split(",")
            if len(parts) != p.length:
                raise UsageError(f"{name} takes {p.length} comma-separated values, got {len(parts)} in {text!r}")
            per = [{KIND_OF_UNIT.get(u)} for u in p.units] if len(p.units) == len(parts) else \
                [_kinds(p.units)] * len(parts)
            out[name] = tuple(parse_quantity(s, k, name, p.unit) for s, k in zip(parts, per))
        else:
            out[name] = parse_quantity(text, _kinds(p.units), name, p.unit)
    return out


# ---------------------------------------------------------------------- mechanisms, poses, joints
def _joint_kind(mech: pkm.Mechanism, name: str) -> str:
    return "angle" if mech.joints[name].revolute else "length"


def task_values(mech: pkm.Mechanism, q) -> dict[str, float]:
    """The task coordinates of ``q`` by name (:meth:`pkm.core.TaskMap.named`; angles Z-Y-X Euler) [m, rad]."""
    return mech.task_map.named(q)


def parse_pose(mech: pkm.Mechanism, items: Sequence[str]) -> tuple[dict[str, float], Any]:
    """``--pose`` items as (named values, target for :func:`pkm.solve_ik`); others keep the reference.

    Raises:
        UnitError: a bad number or unit; UsageError: a missing ``=``.
        UnknownNameError: A name that is not a task coordinate.
    """
    task = mech.task_map
    values = task.named(mech.q_reference)
    for item in items:
        name, text = _split(item, "--pose")
        if name not in values:
            raise UnknownNameError("task coordinate", name, list(values), mech.name)
        kind = task.kinds[name]
        values[name] = parse_quantity(text, {kind}, name, SI_UNITS[kind])
    return values, values


def parse_joints(mech: pkm.Mechanism, items: Sequence[str]) -> np.ndarray:
    """``--joints`` items ``NAME=VALUE`` as actuated coordinates; actuated joints not named keep the reference.

    Raises:
        UsageError: Missing ``=`` or a bad number or unit.
        UnknownNameError: A name that is not an actuated joint.
    """
    qa = mech.actuated_q(mech.q_reference)
    names = list(mech.actuated_names)
    for item in items:
        name, text = _split(item, "--joints")
        if name not in names:
            raise UnknownNameError("actuated joint", name, names, mech.name)
        kind = _joint_kind(mech, name)
        qa[names.index(name)] = parse_quantity(text, {kind}, name, SI_UNITS[kind])
    return qa


def _mechanism(args) -> pkm.Mechanism:
    """A shipped mechanism (its design changed by ``--param``) or one's own closure spec file."""
    if args.mechanism not in pkm.MECHANISMS:
        if args.param:
            raise UsageError(f"--param sets the design of a shipped mechanism; {args.mechanism} states its own")
        return pkm.load(args.mechanism)
    params = parse_params(args.mechanism, args.param or [])
    return pkm.build(args.mechanism, **params) if params else pkm.load(args.mechanism)


def _branch_of(mech: pkm.Mechanism, q) -> str | None:
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
                   "branch": _branch_of(mech, m.q) if mech.spec.branches else None} for m in modes],
    })


# ---------------------------------------------------------------------- commands
def cmd_list(args) -> int:
    data: dict[str, dict[str, Any]] = {}
    for name, entry in pkm.MECHANISMS.items():
        mech = pkm.load(name)
        data[name] = {
            "title": entry.title,
            "actuated": {j: SI_UNITS[_joint_kind(mech, j)] for j in mech.actuated_names},
            "task": {k: SI_UNITS[kind] for k, kind in mech.task_map.kinds.items()},
            "task_origin": entry.origin,
            "reference_pose": mech.task_map.named(mech.q_reference),
            "branches": list(mech.spec.branches),
            "default_branch": mech.spec.default_branch,
            "parameters": {p.name: {"default": p.default, "unit": p.unit, "type": p.type,
                                    "description": p.description} for p in param_info(name).values()},
        }
    if args.json:
        print(json.dumps(jsonable({"units": "SI (m, rad, kg) unless a parameter says otherwise",
                                    "mechanisms": data}), indent=2))
        return 0

    def named(m: dict[str, str]) -> str:
        return ", ".join(f"{k} [{u}]" for k, u in m.items())

    for name, d in data.items():
        branches = ", ".join(b + (" (default)" if b == d["default_branch"] else "") for b in d["branches"])
        print(f"{name}: {d['title']}")
        print(f"  actuated (--joints): {named(d['actuated'])}")
        print(f"  task (--pose): {named(d['task'])}")
        print(f"  task origin: {d['task_origin']}")
        print("  reference pose (reachable): " + " ".join(f"{k}={_fmt_value(v, d['task'][k])}"
                                                       for k, v in d["reference_pose"].items()))
        if branches:
            print(f"  branches (--branch): {branches}")
        print("  parameters (--param NAME=VALUE, SI unless a unit suffix is given):")
        infos = param_info(name).values()
        rows = [(p.name, _fmt_default(p.default), p.unit, p.summary) for p in infos]
        w = [max(len(r[i]) for r in rows) for i in range(3)]
        for r in rows:
            print(f"    {r[0].ljust(w[0])}  {r[1].ljust(w[1])}  {r[2].ljust(w[2])}  {r[3]}")
        print()
    return 0


def _fmt_value(v: float, unit: str) -> str:
    """A task value for the eye, in the unit a user would type: cm or deg (``pkm ik --pose`` takes them back)."""
    x, suffix = (v * 100.0, "cm") if unit == "m" else (math.degrees(v), "deg") if unit == "rad" else (v, "")
    return f"{round(x, 6) + 0.0:.4g}{suffix}"  # (rounded, + 0.0: no "-0" nor "1e-15")


def _fmt_default(v: Any) -> str:
    if v is None:
        return "found"
    if isinstance(v, tuple):
        return ",".join(_fmt_default(x) for x in v)
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def _configuration(mech: pkm.Mechanism, args) -> np.ndarray:
    if args.pose:
        _, target = parse_pose(mech, args.pose)
        return _solve_ik(mech, target, getattr(args, "branch", None)).q
    if args.joints:
        return _close_loops(mech, parse_joints(mech, args.joints)).q
    return mech.q_reference


def _has_closed_forms(mech: pkm.Mechanism) -> bool:
    """Whether ``mech`` is a registered mechanism built from its parameters (so its closed forms apply)."""
    return mech.name in pkm.MECHANISMS and isinstance(mech.params, pkm.mechanism_module(mech.name).Params)


def _solve_ik(mech: pkm.Mechanism, target, branch: str | None) -> pkm.SolveResult:
    """The generic IK; when it fails, a shipped mechanism's closed form says which leg cannot reach, if one cannot."""
    from pkm.errors import UnreachableError

    try:
        return pkm.solve_ik(mech, target, branch=branch)
    except (ConvergenceError, UnreachableError) as exc:
        if not _has_closed_forms(mech):
            raise
        mod = pkm.mechanism_module(mech.name)
        try:
            mod.closed_form_ik(mech.params, mech.task_map.parse(target), branch)
        except UnreachableError as unreachable:
            raise unreachable from exc
        except PkmError:
            pass
        raise


def _close_loops(mech: pkm.Mechanism, qa) -> pkm.SolveResult:
    """Generic loop closure; when it fails, the paper's forward kinematics says if no assembly exists."""
    from pkm.errors import AssemblyError

    try:
        return pkm.close_loops(mech, qa)
    except ConvergenceError as exc:
        if not _has_closed_forms(mech):
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


def cmd_preview(args) -> int:
    mech = _mechanism(args)
    q = _configuration(mech, args)
    from pkm import viz

    if args.html:
        path = viz.write_html(args.html, mech, q)
        print(f"wrote {path}")
        return 0
    vis = viz.show(mech, q)
    if args.no_wait:
        print(f"viewer: {vis.url()}", flush=True)
        return 0  # the server stops with this process (meshcat's atexit hook)

    def stop(signum, frame):
        raise KeyboardInterrupt

    previous = {s: signal.signal(s, stop) for s in (signal.SIGTERM, signal.SIGHUP)}
    try:
        print(f"viewer: {vis.url()}", flush=True)
        print("press Ctrl-C to quit", file=sys.stderr, flush=True)
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        return 0
    finally:  # SIGTERM, SIGHUP or Ctrl-C: the meshcat server goes too, and frees its ports
        viz.close(vis)
        for s, handler in previous.items():
            signal.signal(s, handler)


def cmd_ik(args) -> int:
    mech = _mechanism(args)
    if args.branch is not None:
        mech.branch(args.branch)  # UnknownNameError listing the branches
    values, target = parse_pose(mech, args.pose)
    if args.all:
        print(json.dumps(modes_dict(mech, pkm.working_modes(mech, target), target=values), indent=2))
        return 0
    res = _solve_ik(mech, target, args.branch)
    print(json.dumps(solution_dict(mech, res, target=values), indent=2))
    return 0


def cmd_fk(args) -> int:
    mech = _mechanism(args)
    qa = parse_joints(mech, args.joints)
    if args.all:
        print(json.dumps(modes_dict(mech, pkm.assembly_modes(mech, qa)), indent=2))
        return 0
    res = _close_loops(mech, qa)
    print(json.dumps(solution_dict(mech, res), indent=2))
    return 0


def cmd_spec_init(args) -> int:
    from pathlib import Path

    from pkm.core.formats.imported import spec_skeleton

    model = Path(args.model)
    out = Path(args.out) if args.out else model.with_name(f"{model.stem}.closures.toml")
    if out.exists() and not args.force:
        raise UsageError(f"{out} exists; pass --force to overwrite it")
    if out.resolve().parent != model.resolve().parent:
        raise UsageError(f"write the spec beside the model ({model.resolve().parent}): its urdf path is relative")
    text, complete = spec_skeleton(model)
    out.write_text(text, encoding="utf-8")
    print(f"wrote {out}" + ("" if complete else ": fill in the lines marked TODO"))
    return 0


def parse_axis(mech: pkm.Mechanism, item: str) -> tuple[str, np.ndarray]:
    """An ``--axis`` item ``NAME=START:STOP:COUNT`` (units allowed on START and STOP) as ``(name, values)`` in SI.

    Raises:
        UsageError: not of that form; UnitError: a bad number or unit; UnknownNameError: not a task coordinate.
    """
    name, text = _split(item, "--axis")
    task = mech.task_map
    if name not in task.kinds:
        raise UnknownNameError("task coordinate", name, list(task.keys), mech.name)
    try:
        a, b, count = split_range(text, name)
    except InvalidInputError:
        raise UsageError(f"--axis {item!r}: expected NAME=START:STOP:COUNT, e.g. x=-5cm:5cm:101") from None
    kind = task.kinds[name]
    start, stop = (parse_quantity(t, {kind}, name, SI_UNITS[kind]) for t in (a, b))
    return name, np.linspace(start, stop, count)


def cmd_map(args) -> int:
    from pkm.core.maps import task_map

    mech = _mechanism(args)
    axes = dict(parse_axis(mech, item) for item in args.axis)
    if len(axes) != len(args.axis):
        raise UsageError("name each --axis once")
    fixed = {}
    for item in args.pose or []:
        name, text = _split(item, "--pose")
        if name not in mech.task_map.kinds:
            raise UnknownNameError("task coordinate", name, list(mech.task_map.keys), mech.name)
        fixed[name] = parse_quantity(text, {mech.task_map.kinds[name]}, name, SI_UNITS[mech.task_map.kinds[name]])
    length = None if args.length is None else parse_quantity(args.length, {"length"}, "--length", "m")
    m = task_map(mech, axes, fixed, branch=args.branch, length=length)
    out = {"mechanism": mech.name, "axes": {n: [float(v[0]), float(v[-1]), len(v)] for n, v in m.axes},
           "nodes": int(m.reachable.size), "reachable": m.nodes, "size_SI": m.size,
           "gci_2": m.gci("2"), "gci_fro_normalized": m.gci("fro_normalized"), "how": m.how}
    if args.csv:
        out["csv"] = str(m.write_csv(args.csv))
    if args.png:
        out["png"] = str(m.figure(args.png, slab=None if len(m.axes) < 3 else len(m.axes[2][1]) // 2))
    print(json.dumps(out, indent=2))
    return 0


def cmd_report(args) -> int:
    from pkm import papers, report

    names = tuple(args.paper) if args.paper else papers.names()
    for n in names:
        papers.module(n)  # UnknownNameError listing the papers
    if len(set(names)) != len(names):
        raise UsageError(f"name each paper once, got {list(names)}")
    result = report.run(args.out, names, figures=not args.no_figures, series=not args.no_series)
    print(report.format_table(result))
    return 0


def cmd_bench(args) -> int:
    from pkm import bench

    for n in args.names:
        bench.module(n)  # UnknownNameError listing the benchmarks
    results: dict[str, Any] = {}
    for n in args.names or bench.NAMES:
        mod = bench.module(n)
        options = bench.arguments(mod, args.extra, quick=args.quick, cls=_Parser)  # UsageError if refused
        if not args.json:
            print(f"== bench {n}", flush=True)
        results[n] = mod.run(options)
        if not args.json:
            print(mod.table(results[n]), flush=True)
    if args.json:
        print(json.dumps(results, indent=2))
    return 0


def cmd_sweep(args) -> int:
    from pkm import sweeps

    axes = dict(_split(item, "sweep") for item in args.parameters)
    if len(axes) != len(args.parameters):
        raise UsageError("name each swept parameter once")
    if args.table:
        if axes:
            raise UsageError("--table gives the designs; name no NAME=... ranges beside it")
        space = sweeps.table(args.table)
    elif args.sample == "grid":
        if args.n is not None or args.seed is not None:
            raise UsageError("--n and --seed are for --sample sobol or lhs (a grid's size is its axes')")
        space = sweeps.grid(**axes)
    else:
        if args.n is None:
            raise UsageError(f"--sample {args.sample} needs --n (the number of designs)")
        draw = sweeps.sobol if args.sample == "sobol" else sweeps.latin_hypercube
        space = draw(args.n, seed=args.seed, **axes)
    if args.fixed and args.mechanism not in pkm.MECHANISMS:
        raise UsageError(f"--fixed sets the design of a shipped mechanism; {args.mechanism} states its own")
    fixed = parse_params(args.mechanism, args.fixed) if args.fixed else {}  # (tuples and units as --param's)
    res = sweeps.sweep(args.mechanism, space, args.objective, out=args.out, fixed=fixed or None,
                       scheduler=args.scheduler, workers=args.workers, chunk_size=args.chunk,
                       progress=False if args.no_progress else None, overwrite=args.overwrite)
    try:
        res.check()  # every design failed: one line naming them (their table is written already)
    except sweeps.SweepError as exc:
        kept = f"; each design's error is in {args.out}" if args.out else "; --out FILE.parquet keeps each design's"
        raise sweeps.SweepError(f"{exc}{kept}", args.out) from None
    st = res.stats
    best = {}
    for c, o in res.objectives.items():
        rows = res.best(c, 1) if o["sense"] and not np.isnan(res.column(c)).all() else []  # (none: no value of it)
        best[c] = rows[0] if rows else None
    out = {"mechanism": res.manifest["family"], "designs": len(res), "failed": st.failed,
           "evaluated_now": st.evaluated, "space": res.manifest["space"], "out": args.out,
           "workers": st.workers, "wall_seconds": st.wall_seconds, "work_seconds": st.work_seconds, "best": best}
    print(json.dumps(jsonable(out), indent=2))
    return 0


def cmd_sweep_plot(args) -> int:
    from pkm import sweeps

    pareto = [n.strip() for n in args.pareto.split(",")] if args.pareto else None
    paths = sweeps.plot(args.results, args.out, pareto)
    print(json.dumps([str(p) for p in paths], indent=2))
    return 0


def cmd_sweep_best(args) -> int:
    from pkm import sweeps

    paths = sweeps.write_best(args.results, args.by, args.out, n=args.n, mechanism=args.mechanism)
    print(json.dumps([str(p) for p in paths], indent=2))
    return 0


# ---------------------------------------------------------------------- parser
class _Parser(argparse.ArgumentParser):
    """argparse that raises :class:`UsageError` instead of printing usage and exiting."""

    def error(self, message: str):
        raise UsageError(f"{message} (see '{self.prog} --help')")


def _objective_names() -> list[str]:
    from pkm.sweeps.objectives import OBJECTIVES

    return list(OBJECTIVES)


def build_parser() -> argparse.ArgumentParser:
    """The ``pkm`` argument parser (one subparser per command)."""
    mechs = ", ".join(pkm.MECHANISMS)
    ap = _Parser(prog=PROG, description="Parallel kinematic machines on Pinocchio: the papers' mechanisms, "
                                        "their kinematics and the papers' results.",
                 epilog="Values are SI (m, rad, kg) unless a unit is given: R=120mm, beta=-11deg, z=81cm.")
    ap.add_argument("--debug", action="store_true", help="show the traceback of an error")
    ap.add_argument("--version", action="version", version=f"pkm {pkm.__version__}")
    debug = _Parser(add_help=False)
    debug.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help="show the traceback of an error")
    sub = ap.add_subparsers(dest="command", metavar="COMMAND", required=True)

    p = sub.add_parser("list", parents=[debug], help="the mechanisms, their joints, task and parameters (units, defaults)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_list)

    def mech_args(p, pose: str | None, joints: str | None):
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

    p = sub.add_parser("preview", parents=[debug], help="show a configuration in the meshcat viewer or as HTML")
    mech_args(p, "optional", "optional")
    p.add_argument("--html", metavar="FILE", help="write a self-contained HTML scene instead of opening the viewer")
    p.add_argument("--no-wait", action="store_true", help="return once the viewer is up instead of waiting for Ctrl-C")
    p.set_defaults(func=cmd_preview)

    p = sub.add_parser("ik", parents=[debug], help="inverse kinematics: every joint for a pose (JSON, SI)")
    mech_args(p, "required", None)
    p.add_argument("--branch", metavar="NAME", help="working mode the solution must lie on (see 'pkm list')")
    p.add_argument("--all", action="store_true", help="every working mode (homotopy continuation, pkm[homotopy])")
    p.set_defaults(func=cmd_ik)

    p = sub.add_parser("fk", parents=[debug], help="forward kinematics: the pose for actuated values (JSON, SI)")
    mech_args(p, None, "required")
    p.add_argument("--all", action="store_true", help="every assembly mode (homotopy continuation, pkm[homotopy])")
    p.set_defaults(func=cmd_fk)

    p = sub.add_parser("map", parents=[debug], help="a workspace and condition-index map over 1-3 task coordinates "
                                                  "(JSON summary, PNG, CSV)")
    mech_args(p, None, None)
    p.add_argument("--axis", metavar="NAME=START:STOP:COUNT", action="append", required=True,
                   help="a grid axis over a task coordinate, e.g. x=-5cm:5cm:101 (1 to 3 axes)")
    p.add_argument("--pose", metavar="K=V", action="extend", nargs="+", default=[],
                   help="the other task coordinates (default: the reference's)")
    p.add_argument("--length", metavar="L", help="characteristic length dividing the angular rates, e.g. 5cm "
                                                 "(needed when the task mixes lengths and angles)")
    p.add_argument("--branch", metavar="NAME", help="working mode of the map (see 'pkm list')")
    p.add_argument("--png", metavar="FILE", help="draw the condition index (a 3-D map: its middle slab)")
    p.add_argument("--csv", metavar="FILE", help="write one row per node")
    p.set_defaults(func=cmd_map)

    p = sub.add_parser("spec", parents=[debug], help="closure specs: 'pkm spec init MODEL' writes one to fill in")
    spec_sub = p.add_subparsers(dest="spec_command", metavar="ACTION", required=True)
    p = spec_sub.add_parser("init", parents=[debug], help="write a commented closure spec for a URDF, MJCF or SDF file")
    p.add_argument("model", metavar="MODEL", help="the model file (.urdf, .xml MJCF, .sdf)")
    p.add_argument("--out", metavar="FILE", help="where to write it (default: MODEL's folder, <stem>.closures.toml)")
    p.add_argument("--force", action="store_true", help="overwrite an existing file")
    p.set_defaults(func=cmd_spec_init)

    from pkm.papers import names as paper_names

    p = sub.add_parser("report", parents=[debug], help="reproduce the papers: summary.json, report.md, figures")
    p.add_argument("--out", metavar="DIR", default="out", help="output directory (default: out)")
    p.add_argument("--paper", metavar="NAME", action="append", help=f"only these papers ({', '.join(paper_names())})")
    p.add_argument("--no-figures", action="store_true", help="skip the figures")
    p.add_argument("--no-series", action="store_true", help="skip the CSV series")
    p.set_defaults(func=cmd_report)

    from pkm.bench import NAMES as BENCHMARKS

    p = sub.add_parser("bench", parents=[debug], help="run the benchmarks (pkm.bench): ratios against baselines",
                       epilog="Arguments after '--' go to each benchmark, e.g. pkm bench kinematics -- -n 20.")
    p.add_argument("names", metavar="NAME", nargs="*", help=f"{', '.join(BENCHMARKS)} (default: all)")
    p.add_argument("--json", action="store_true", help="print the results of all as one JSON object")
    p.add_argument("--quick", action="store_true", help="small sizes: checks that they run, in seconds")
    p.set_defaults(func=cmd_bench, extra=[])

    p = sub.add_parser("sweep", parents=[debug], help="a design sweep on Dask: objectives of every design, Parquet "
                                                      "results ('pkm sweep plot', 'pkm sweep best' read them)",
                       epilog="Objectives: " + ", ".join(_objective_names()) + "; options as gci:step=1cm, a "
                              "column name as label=SPEC, or path/to/file.py:function. A killed sweep run again "
                              "with the same --out resumes.")
    p.add_argument("mechanism", metavar="MECH", help=f"one of {mechs}, or a closure spec file (its URDF joint "
                                                     "origins JOINT.x ... JOINT.yaw are the parameters)")
    p.add_argument("parameters", metavar="NAME=RANGE", nargs="*",
                   help="grid: a=30cm:80cm:11 (START:STOP:COUNT) or a=0.3; sampled: a=30cm:80cm (LOW:HIGH)")
    p.add_argument("--objective", metavar="SPEC", action="append", required=True, help="an objective (repeat)")
    p.add_argument("--sample", choices=("grid", "sobol", "lhs"), default="grid", help="how to draw the designs")
    p.add_argument("--n", type=int, help="designs to draw (sobol, lhs)")
    p.add_argument("--seed", type=int, help="the samples' seed (default: drawn and recorded in the results)")
    p.add_argument("--table", metavar="FILE", help="explicit designs: a .csv (header of parameter names) or .parquet")
    p.add_argument("--fixed", metavar="K=V", action="extend", nargs="+", default=[],
                   help="parameters not swept (default: the paper's design)")
    p.add_argument("--out", metavar="FILE", help="the results, .parquet (resumed if it holds this sweep's parts)")
    p.add_argument("--scheduler", metavar="ADDR", help="a Dask scheduler (tcp://host:8786), or 'serial' (this "
                                                       "process); default: a local cluster, one worker per core")
    p.add_argument("--workers", type=int, help="local workers (default: one per core); with --scheduler, wait for")
    p.add_argument("--chunk", type=int, help="designs per task (default: about 32 tasks per worker)")
    p.add_argument("--overwrite", action="store_true", help="replace an output that holds another sweep")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_sweep)

    p = sub.add_parser("sweep-plot", parents=[debug], prog=f"{PROG} sweep plot",
                       help="(pkm sweep plot FILE) parameter-objective plots and Pareto fronts of a sweep's results")
    p.add_argument("results", metavar="FILE", help="a sweep's .parquet results")
    p.add_argument("--out", metavar="DIR", default=".", help="where to write the PNGs (default: .)")
    p.add_argument("--pareto", metavar="A,B", help="objectives of the Pareto fronts (default: all with a sense)")
    p.set_defaults(func=cmd_sweep_plot)

    p = sub.add_parser("sweep-best", parents=[debug], prog=f"{PROG} sweep best",
                       help="(pkm sweep best FILE --by OBJ) the best designs as closure specs for pkm preview")
    p.add_argument("results", metavar="FILE", help="a sweep's .parquet results")
    p.add_argument("--by", metavar="OBJECTIVE", required=True, help="the objective column to rank by (its sense)")
    p.add_argument("--n", type=int, default=3, help="how many (default: 3)")
    p.add_argument("--out", metavar="DIR", default="best", help="where to write them (default: best/)")
    p.add_argument("--mechanism", metavar="SPEC", help="the files of a loaded mechanism the sweep varied")
    p.set_defaults(func=cmd_sweep_best)
    return ap


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``pkm`` command line; returns the exit status (see the module doc)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    extra: list[str] = []
    if "--" in argv:  # the rest goes to the benchmarks
        k = argv.index("--")
        argv, extra = argv[:k], argv[k + 1:]
    if argv[:1] == ["sweep"] and argv[1:2] in (["plot"], ["best"]):  # 'pkm sweep plot' is the parser's sweep-plot
        argv = [f"sweep-{argv[1]}"] + argv[2:]
    debug = "--debug" in argv
    try:
        try:
            args = build_parser().parse_args(argv)
        except SystemExit as exc:  # --help, --version
            return int(exc.code or 0)
        if extra and args.command != "bench":
            raise UsageError(f"arguments after '--' are only for 'pkm bench', got {extra}")
        args.extra = extra
        return args.func(args)
    except PkmError as exc:
        if debug:
            traceback.print_exc()
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        named_wrong = isinstance(exc, UnknownNameError) and not isinstance(exc, SpecError)  # not a broken file
        return 2 if isinstance(exc, (UsageError, UnitError)) or named_wrong else 1
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into head & co.
        sys.stdout = open(os.devnull, "w")
        return 0


__all__ = ["SUFFIXES", "ParamInfo", "UsageError", "attribute_docs", "build_parser", "main", "param_info",
           "parse_joints", "parse_params", "parse_pose", "parse_quantity", "solution_dict", "task_values"]
