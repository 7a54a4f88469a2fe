"""``pkm simulate MECH (--torques FILE.csv | --controller FILE.py:FN) --out FILE [...]``: a forward simulation
(:func:`pkm.simulate`) under a table of efforts or a controller of one's own, its samples written as Parquet or CSV
(:mod:`pkm.core.dynamics.samples`), its figure drawn (:mod:`pkm.viz.simulation`), and a summary printed. The initial
state: ``--pose`` or ``--joints`` (as every command takes a configuration) or ``--q0``, and ``--v0`` (rates, units
allowed: ``motor_1=30deg/s``).

The torque table is a CSV file whose header is ``t`` then the actuated joints' names in actuated order (``pkm list``
names them): the time [s], then the efforts [N m or N], interpolated linearly between rows and held outside them.
The controller is a function ``FN(t, q, v) -> efforts`` of a Python file, imported from its path: ``t`` the time [s],
``q`` the whole configuration (nq), ``v`` the joint rates (nv), the efforts in actuated order.
"""

from __future__ import annotations

import argparse
import csv
import importlib.util
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, close_loops, configuration, load_mechanism
from pkm.cli.parsing import parse_rates, parse_seed
from pkm.errors import InvalidInputError, UnknownNameError
from pkm.units import parse_quantity

if TYPE_CHECKING:
    from pkm.core.dynamics.simulate import Simulation
    from pkm.core.model.mechanism import Mechanism


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, "optional", "optional", "alone, the initial configuration (actuated joints set the "
                                                       "state, passive ones the closure's seed); with --pose or "
                                                       "--joints, the solver's seed")
    drive = p.add_mutually_exclusive_group()  # (neither: no effort, the mechanism released)
    drive.add_argument("--torques", metavar="FILE.csv", help="efforts over time: a CSV whose header is t and the "
                                                             "actuated joints' names (time [s], efforts [N m or N])")
    drive.add_argument("--controller", metavar="FILE.py:FN", help="a function FN(t, q, v) -> efforts of a Python "
                                                                  "file (q: all joints, v: their rates)")
    p.add_argument("--duration", metavar="T", default="2s", help="simulated time (s, ms, us; default 2s)")
    p.add_argument("--dt", metavar="DT", default="1ms", help="sample period, the RK4 step (default 1ms)")
    p.add_argument("--method", choices=("rk4", "radau"), default="rk4", help="integrator (default rk4)")
    p.add_argument("--v0", metavar="NAME=V", action="extend", nargs="+", default=[],
                   help="initial actuated rates, e.g. motor_1=30deg/s (rad/s, deg/s, rpm; m/s, mm/s; a number: SI) "
                        "(others zero)")
    p.add_argument("--no-friction", action="store_true", help="leave the joints' friction out")
    p.add_argument("--no-limits", action="store_true", help="do not stop at position or speed limits")
    p.add_argument("--no-saturate", action="store_true", help="apply the efforts asked for beyond the actuators' "
                                                              "limits (default: clip them; the summary counts them)")
    p.add_argument("--out", metavar="FILE", required=True,
                   help="the samples: Parquet (pkm-robotics[sweeps]), or CSV when FILE ends in .csv")
    p.add_argument("--plot", metavar="FILE.png",
                   help="draw positions, speeds, efforts and energies (pkm-robotics[figures])")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")


def read_torques(mech: Mechanism, path: str) -> tuple[np.ndarray, np.ndarray]:
    """``(times (N,) [s], efforts (N, na))`` of a torque table (module doc).

    Raises:
        InvalidInputError: no such file, a header other than ``t`` and the actuated names in order, a row of the
            wrong length or not numbers, no row.
    """
    expected = ["t", *mech.actuated_names]
    file = Path(path)
    if not file.is_file():
        raise InvalidInputError("--torques", f"{path}: no such file", path)
    try:
        with file.open(newline="", encoding="utf-8") as fh:
            rows = [row for row in csv.reader(fh) if row and any(c.strip() for c in row)]
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise InvalidInputError("--torques", f"{path}: not a readable CSV file ({exc})", path) from None
    header = [c.strip() for c in rows[0]] if rows else []
    if header != expected:
        raise InvalidInputError("--torques", f"{path}: the header must read {','.join(expected)} (time [s], then the "
                                             f"efforts in actuated order), got {','.join(header) or 'nothing'}", header)
    values = []
    for k, row in enumerate(rows[1:], start=2):
        if len(row) != len(expected):
            raise InvalidInputError("--torques", f"{path}, line {k}: {len(row)} values, expected {len(expected)}", row)
        try:
            values.append([float(c) for c in row])
        except ValueError:
            raise InvalidInputError("--torques", f"{path}, line {k}: not numbers: {','.join(row)}", row) from None
    if not values:
        raise InvalidInputError("--torques", f"{path}: no row of values under the header", path)
    table = np.array(values)
    return table[:, 0], table[:, 1:]


def load_controller(spec: str) -> Any:
    """The function ``FN`` of ``FILE.py:FN``, its file imported from its path (as a module of its own name).

    Raises:
        InvalidInputError: not ``FILE.py:FN``, no such file, or importing it raised; UnknownNameError: the file
            has no such function (its functions listed).
    """
    path, colon, name = spec.rpartition(":")
    if not colon or not path or not name.isidentifier():
        raise InvalidInputError("--controller", f"expected FILE.py:FUNCTION, got {spec!r}", spec)
    file = Path(path)
    if not file.is_file():
        raise InvalidInputError("--controller", f"{path}: no such file", path)
    module_name = f"pkm_controller_{file.stem}" if file.stem.isidentifier() else "pkm_controller"
    loader = importlib.util.spec_from_file_location(module_name, file)
    if loader is None or loader.loader is None:
        raise InvalidInputError("--controller", f"{path}: not a Python file", path)
    module = importlib.util.module_from_spec(loader)
    sys.modules[module_name] = module  # (dataclasses and pickling look the module up)
    try:
        loader.loader.exec_module(module)
    except Exception as exc:
        sys.modules.pop(module_name, None)
        raise InvalidInputError("--controller", f"importing {path} raised {type(exc).__name__}: {exc}", path) from exc
    fn = getattr(module, name, None)
    if not callable(fn):
        functions = [k for k, v in vars(module).items() if callable(v) and not k.startswith("_")
                     and getattr(v, "__module__", None) == module_name]
        raise UnknownNameError("function", name, functions, path)
    return fn


def summary(mech: Mechanism, sim: Simulation, written: dict[str, str]) -> dict[str, Any]:
    """What ``pkm simulate`` prints: samples, final time, the event, the energies and their balance [J], the samples
    whose efforts are at the actuators' limits (``saturated``, the actuators with any)."""
    from pkm.core.dynamics.samples import energy_balance
    from pkm.report import jsonable

    energy = sim.energy
    event = None if sim.event is None else {"kind": sim.event.kind, "time": sim.event.time, "detail": sim.event.detail}
    return jsonable({
        "mechanism": mech.name, "method": sim.method, "samples": len(sim), "final_time": float(sim.time[-1]),
        "event": event, "energy_start": float(energy[0]), "energy_end": float(energy[-1]),
        "work": float(sim.work[-1]), "dissipated": float(sim.dissipated[-1]), "energy_balance": energy_balance(sim),
        "saturated": {k: n for k, n in sim.saturated.items() if n}, **written,
        "units": {"final_time": "s", "energy_start": "J", "energy_end": "J", "work": "J", "dissipated": "J",
                  "energy_balance": "J", "note": "energy_balance = E(end) - E(0) - work + dissipated: the "
                                                "integration's error, and the trapezoidal rule's of work and "
                                                "dissipated"},
    })


def text(out: dict[str, Any]) -> str:
    """The human-readable form of :func:`summary`."""
    lines = [f"{out['mechanism']}: {out['samples']} samples ({out['method']}), final time {out['final_time']:.6g} s"]
    if out["event"] is not None:
        e = out["event"]
        lines.append(f"stopped early at {e['time']:.6g} s: {e['kind']} ({e['detail']})")
    lines.append(f"energy: E(0) {out['energy_start']:.6g} J, E(end) {out['energy_end']:.6g} J, work "
                 f"{out['work']:.6g} J, dissipated {out['dissipated'] + 0.0:.6g} J")
    lines.append(f"energy balance E(end) - E(0) - work + dissipated: {out['energy_balance']:.3g} J")
    if out["saturated"]:
        lines.append(f"efforts at the actuators' limits (samples of {out['samples']}): "
                     + ", ".join(f"{k} {n}" for k, n in out["saturated"].items()))
    lines += [f"{key}: {out[key]}" for key in ("out", "plot") if key in out]
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    import pkm
    from pkm._optional import require
    from pkm.core.dynamics import samples

    if not args.out.lower().endswith(".csv"):  # (the missing extras named before the run, not after)
        require("sweeps", "writing a simulation as Parquet (or give a .csv path)", ("pyarrow",))
    if args.plot:
        require("figures", "the figure of a simulation (pkm.viz.simulation)")
    mech = load_mechanism(args)
    duration = parse_quantity(args.duration, {"time"}, "--duration", "s")
    dt = parse_quantity(args.dt, {"time"}, "--dt", "s")
    q0 = None
    seed = parse_seed(mech, args.q0)
    if args.pose or args.joints:  # the initial configuration as every command takes one
        q0 = configuration(mech, args)
    elif seed is not None:  # the actuators named set the state; the passive joints named, the closure's seed
        qa = mech.actuated_q(seed)
        seed[mech.act_q] = mech.q_reference[mech.act_q]
        q0 = close_loops(mech, qa, seed).q
    v0 = parse_rates(mech, args.v0, "--v0")
    drive: dict[str, Any] = {}
    if args.torques is not None:
        drive["torques"] = read_torques(mech, args.torques)
    elif args.controller is not None:
        drive["controller"] = load_controller(args.controller)
    sim = pkm.simulate(mech, q0, v0, duration, dt, method=args.method, friction=not args.no_friction,
                       limits=not args.no_limits, saturate=not args.no_saturate, **drive)
    written = {"out": str(samples.write(mech, sim, args.out))}
    if args.plot:
        from pkm.viz.simulation import plot

        written["plot"] = str(plot(mech, sim, args.plot))
    out = summary(mech, sim, written)
    print(json.dumps(out, indent=2) if args.json else text(out))
    return 0


COMMAND = Command("a forward simulation under a torque table or a controller: samples to Parquet or CSV, a figure",
                  add_arguments, run)
