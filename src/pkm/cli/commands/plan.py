"""``pkm plan MECH --path PATH [--payload KG] [--limits K=V,...] [--points N] --out FILE [--motion FILE.toml]
[--plot FILE.png]``: the time-optimal motion along a path (:func:`pkm.time_optimal`), written as a table (CSV, or
Parquet) and as a ``pkm.motion`` file (the actuated joints' ``hermite`` laws: positions and rates at the plan's
times), its speed profile drawn with the active limit marked, and the cycle time printed.

``--path`` is a CSV of waypoints whose header names the task's coordinates as ``--pose`` does (``pkm list`` names
them: a pose as ``x y z roll pitch yaw``), or its values (a pose as ``x y z qx qy qz qw``), or the actuated
joints' (a path in actuator space) [m, rad], a ``pkm.motion`` case ``FILE.toml:CASE``, or
``adept:X,Y,Z`` (the 25/305/25 mm cycle from the point X, Y, Z [m, or with units: ``adept:0,0,-35cm``] along +x). ``--limits`` takes ``peak``,
``omega0``, ``speed``, ``acceleration`` (:func:`pkm.core.timing.limits.parse_limits`).
"""

from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

import pkm
from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, load_mechanism
from pkm.errors import InvalidInputError
from pkm.units import parse_quantity

if TYPE_CHECKING:
    from pkm.core.model.mechanism import Mechanism
    from pkm.core.timing.solve import TimeOptimal


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, None, None)
    p.add_argument("--path", metavar="PATH", required=True,
                   help="waypoints (CSV, header: the task's coordinates as --pose names them, its values, or the "
                        "actuated joints'), a motion case "
                        "FILE.toml:CASE, or adept:X,Y,Z")
    p.add_argument("--coordinates", metavar="A,B,C", help="a motion case's coordinates as the task's names, in the "
                                                          "file's order (the 3-PRS's z,beta,phi: z,pitch,roll)")
    p.add_argument("--payload", metavar="KG", default="0", help="a point mass at the end effector, e.g. 500g [kg]")
    p.add_argument("--limits", metavar="K=V,...", default="",
                   help="peak=N m, omega0=rad/s (a linear motor line), speed=rad/s, acceleration=rad/s^2, units "
                        "allowed (speed=300rpm) (default: the drives' own peak efforts and speed limits)")
    p.add_argument("--points", metavar="N", type=int, default=1000, help="grid points along the path (default 1000)")
    p.add_argument("--out", metavar="FILE", required=True, help="the trajectory: CSV when FILE ends in .csv, else "
                                                                "Parquet (pkm-robotics[sweeps])")
    p.add_argument("--motion", metavar="FILE.toml", help="the motors' motion as a pkm.motion file (hermite laws of "
                                                         "the actuated joints; default: FILE of --out with the "
                                                         "suffix .motion.toml)")
    p.add_argument("--plot", metavar="FILE.png",
                   help="the speed profile, the active limit marked (pkm-robotics[figures])")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")


def read_path(mech: Mechanism, text: str, coordinates: str | None = None) -> tuple[object, str]:
    """``(path, space)`` from ``--path`` (module doc); ``coordinates``: a motion case's coordinates renamed
    (``--coordinates``).

    Raises:
        InvalidInputError: no such file, a header that names neither the task's values nor the actuated joints, a
            value that is not a number.
    """
    from pkm.core.timing.path import adept_waypoints

    if text.startswith("adept:"):
        start = [parse_quantity(v.strip(), {"length"}, "--path adept:X,Y,Z", "m") for v in text[6:].split(",")]
        task_values = pkm.TaskMap.of(mech).value_names
        if task_values != ("x", "y", "z"):
            raise InvalidInputError("--path", "the adept cycle is a path of a task x, y, z", task_values)
        return adept_waypoints(start), "task"
    file, case = text.rsplit(":", 1) if ".toml:" in text else (text, "")
    if file.endswith(".toml"):
        from pkm.core.timing.path import motion_path
        from pkm.motion import load_motions

        motions = load_motions(file)
        if case not in motions:
            raise InvalidInputError("--path", f"name a case: FILE.toml:CASE, one of {sorted(motions)}", text)
        names = tuple(coordinates.split(",")) if coordinates else None
        return motion_path(mech, motions[case], names), motions[case].space
    path = Path(file)
    if not path.is_file():
        raise InvalidInputError("--path", f"{file}: no such file", file)
    with path.open(newline="", encoding="utf-8") as fh:
        rows = [r for r in csv.reader(fh) if r and any(c.strip() for c in r)]
    header = tuple(c.strip() for c in rows[0]) if rows else ()
    task = pkm.TaskMap.of(mech)
    spaces = {tuple(task.keys): "named", tuple(task.value_names): "task", tuple(mech.actuated_names): "actuated"}
    if header not in spaces:
        named = "" if task.keys == task.value_names else f", {','.join(task.keys)} (task, as --pose names it)"
        raise InvalidInputError("--path", f"{file}: the header must read {','.join(task.value_names)} "
                                          f"(task){named} or {','.join(mech.actuated_names)} (actuated)", header)
    try:
        values = np.array([[float(c) for c in r] for r in rows[1:]])
    except ValueError as exc:
        raise InvalidInputError("--path", f"{file}: {exc}", file) from None
    if spaces[header] == "named":  # (a pose by x y z roll pitch yaw, as --pose and 'pkm list' name it)
        return np.array([task.parse(dict(zip(header, row))) for row in values]), "task"
    return values, spaces[header]


def columns(plan: TimeOptimal) -> dict[str, np.ndarray]:
    """The trajectory's columns: ``t``, ``s``, ``sd``, ``sdd``, per actuated joint ``NAME``, ``NAME.rate``,
    ``NAME.acceleration``, ``NAME.effort`` (SI), then the path's values."""
    cols = {"t": plan.time, "s": plan.s, "sd": plan.sd, "sdd": np.append(plan.sdd, plan.sdd[-1])}
    for i, name in enumerate(plan.limits.names):
        cols[name] = plan.qa[:, i]
        cols[f"{name}.rate"] = plan.qa_rate[:, i]
        cols[f"{name}.acceleration"] = plan.qa_acceleration[:, i]
        cols[f"{name}.effort"] = plan.efforts[:, i]
    names = pkm.TaskMap.of(plan.mech).value_names if plan.path.space == "task" else ()
    for i, name in enumerate(names):
        cols[f"path.{name}"] = plan.coefficients.y[:, i]
    return cols


def write(plan: TimeOptimal, out: str) -> Path:
    from pkm.core.dynamics.samples import write_csv

    cols = columns(plan)
    path = Path(out)
    if path.suffix.lower() == ".csv":
        return write_csv(cols, path)
    from pkm._optional import module

    pa = module("pyarrow", extra="sweeps", what="writing a plan as Parquet (or give a .csv path)")
    pq = module("pyarrow.parquet", extra="sweeps", what="writing a plan as Parquet (or give a .csv path)")
    path.parent.mkdir(parents=True, exist_ok=True)
    pq.write_table(pa.table({k: pa.array(v) for k, v in cols.items()}), path)
    return path


def plot(plan: TimeOptimal, out: str) -> Path:
    """The speed profile ``sd(s)``, each segment coloured by its active limit."""
    from pkm._plot import figure, save

    fig, ax = figure(size=(7.0, 4.0))
    kinds = sorted(set(plan.active))
    colours = {k: f"C{i}" for i, k in enumerate(kinds)}
    for i, kind in enumerate(plan.active):
        ax.plot(plan.s[i:i + 2], plan.sd[i:i + 2], color=colours[kind], lw=2)
    for kind in kinds:
        ax.plot([], [], color=colours[kind], label=kind)
    ax.set_xlabel("path parameter s [-]")
    ax.set_ylabel("path speed ds/dt [1/s]")
    ax.set_title(f"{plan.mech.name}: cycle {plan.cycle_time * 1e3:.2f} ms, payload {plan.payload:g} kg")
    ax.legend(title="active limit", fontsize=8)
    target = Path(out)
    return save(fig, target.parent, target.stem)


def run(args: argparse.Namespace) -> int:
    import pkm
    from pkm._optional import require
    from pkm.core.timing.limits import parse_limits

    if not args.out.lower().endswith(".csv"):
        require("sweeps", "writing a plan as Parquet (or give a .csv path)", ("pyarrow",))
    if args.plot:
        require("figures", "the figure of a plan")
    mech = load_mechanism(args)
    path, space = read_path(mech, args.path, args.coordinates)
    from pkm.core.timing.coefficients import with_payload

    payload = parse_quantity(args.payload, {"mass"}, "--payload", "kg")
    limits = parse_limits(with_payload(mech, payload), args.limits)
    plan = pkm.time_optimal(mech, path, payload=payload, limits=limits, points=args.points, space=space)
    from pkm.motion import write_motion

    written = {"out": str(write(plan, args.out))}
    motion = args.motion or str(Path(args.out).with_suffix(".motion.toml"))
    written["motion"] = str(write_motion(motion, tuple(mech.actuated_names), "plan", plan.time, plan.qa,
                                         plan.qa_rate, space="actuated", mechanism=mech.name,
                                         description=f"time-optimal motion along {args.path} (pkm plan), payload "
                                                     f"{plan.payload:g} kg, cycle {plan.cycle_time:.6g} s"))
    if args.plot:
        written["plot"] = str(plot(plan, args.plot))
    switches = set(plan.inactive)  # (no limit active: the law's switches, TimeOptimal.inactive)
    held = [k for i, k in enumerate(plan.active) if i not in switches]
    counts = {k: held.count(k) for k in sorted(set(held))}
    out = {"mechanism": mech.name, "cycle_time_s": plan.cycle_time, "payload_kg": plan.payload,
           "points": len(plan.s), "active_segments": counts, "switch_segments": len(switches), "written": written}
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        print(f"cycle time: {plan.cycle_time:.6g} s ({mech.name}, payload {plan.payload:g} kg, {len(plan.s)} points)")
        print("active limits (segments): " + ", ".join(f"{k}: {v}" for k, v in counts.items())
              + f"; switches (none active): {len(switches)}")
        for k, v in written.items():
            print(f"{k}: {v}")
    return 0


COMMAND = Command("the time-optimal motion along a path under the actuators' limits: trajectory, figure, cycle time",
                  add_arguments, run)
