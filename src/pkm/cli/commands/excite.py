"""``pkm excite MECH [--duration 10s] [--harmonics 5] [--periods 1] [--dt 2ms] --out excitation.csv [--plot FILE.png]
[--tie-legs] [--json]``: an optimal excitation trajectory (:func:`pkm.core.identification.excitation.excite`: a
Fourier series per actuator minimising the base regressor's condition number within the limits), written as a
samples table (``time``, ``q.<joint>``, ``qd.<joint>``, ``qdd.<joint>``, ``tau.<joint>``: what a robot is to follow,
and the efforts the model expects) that ``pkm identify`` reads back once ``tau`` holds measured efforts."""

from __future__ import annotations

import argparse
import json

from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, load_mechanism
from pkm.errors import InvalidInputError
from pkm.units import parse_quantity


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, None, None)
    p.add_argument("--duration", metavar="T", default="10s", help="the period of the series (s, ms; default 10s)")
    p.add_argument("--harmonics", type=int, default=5, help="harmonics per actuator (default 5)")
    p.add_argument("--samples", type=int, default=60, help="samples per period for the optimisation (default 60)")
    p.add_argument("--periods", type=int, default=1, help="periods written (default 1)")
    p.add_argument("--dt", metavar="DT", default="2ms", help="the table's sample period (default 2ms)")
    p.add_argument("--iterations", type=int, default=60, help="SLSQP iterations at most (default 60)")
    p.add_argument("--amplitude", type=float, help="largest excursion from the reference [rad or m, SI]")
    p.add_argument("--tie-legs", action="store_true", help="condition the tied base parameters (legs alike)")
    p.add_argument("--out", metavar="FILE.csv", required=True, help="the samples table")
    p.add_argument("--motion", metavar="FILE.toml", help="also write the series as a motion file (pkm.motion)")
    p.add_argument("--plot", metavar="FILE.png", help="draw positions, rates and efforts (pkm-robotics[figures])")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")


def run(args: argparse.Namespace) -> int:
    from pkm._optional import require
    from pkm.core.identification.base import require_precise
    from pkm.core.identification.excitation import excite, write_csv

    mech = load_mechanism(args)
    require_precise(mech, "pkm identify, which reads pkm excite's table,")  # (before the excitation: minutes)
    period = parse_quantity(args.duration, {"time"}, "--duration", "s")
    dt = parse_quantity(args.dt, {"time"}, "--dt", "s")
    if not dt > 0.0:
        raise InvalidInputError("--dt", f"expected a positive sample period, got {args.dt}", args.dt)
    if args.plot:
        require("figures", "the figure of an excitation (pkm.viz.identification)")
    e = excite(mech, period=period, harmonics=args.harmonics, samples=args.samples, tie_legs=args.tie_legs,
               amplitude=args.amplitude, max_iter=args.iterations)
    bounds = {j: (float(lo), float(hi)) for j, (lo, hi) in zip(e.joints, () if e.bounds is None else e.bounds)}
    out = {"mechanism": mech.name, "period_s": e.period, "harmonics": int(e.a.shape[1]),
           "condition_start": e.condition_start, "condition": e.condition, "margins": e.margins, "bounds": bounds,
           "shrunk": e.shrunk, "out": write_csv(mech, e, args.out, periods=args.periods, dt=dt)}
    if args.motion:
        from pkm.core.identification.excitation import write_motion

        out["motion"] = write_motion(mech, e, args.motion, periods=args.periods, dt=dt)
    if args.plot:
        from pkm.viz.identification import excitation_figure

        out["plot"] = str(excitation_figure(mech, e, args.plot))
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        print(f"{mech.name}: excitation of period {e.period:g} s, {out['harmonics']} harmonics; condition number "
              f"{e.condition_start:.4g} -> {e.condition:.4g}")
        units = {j: "rad" if mech.joints[j].revolute else "m" for j in e.joints}
        print("position bounds (the tighter of the joint limits and the amplitude about the reference): "
              + ", ".join(f"{j} [{lo:.4g}, {hi:.4g}] {units[j]}" for j, (lo, hi) in bounds.items()))
        print("margins (joint, speed, effort: fraction of each bound left; singularity: the smallest distance over "
              "its bound): " + ", ".join(f"{k} {v:.3g}" for k, v in e.margins.items()))
        for key in ("out", "motion", "plot"):
            if key in out:
                print(f"{key}: {out[key]}")
    return 0


COMMAND = Command("an optimal excitation trajectory for identification: a samples table to follow, a figure",
                  add_arguments, run)
