"""``pkm calibrate MECH DATA --out DIR [--model pose|position|planar|passive] [--loss L] [--max-evaluations N]
[--plot FILE.png] [--json]``: the kinematic calibration of a mechanism from a table of actuator readings and measurements
(:mod:`pkm.core.calibration.writeback`): its identifiable (base) geometric parameters estimated with their standard
deviations, the pose errors before and after, the calibrated mechanism written into ``DIR`` (a closure spec + URDF
that ``pkm.load`` reads, and ``calibration.toml`` with the actuator offsets and gains and the measurement frames).

``pkm calibrate plan MECH --poses N --out poses.csv [--model M] [--spread S] [--simulate SEED]``: N poses chosen to
maximise the observability index O1 within the joint limits and a singularity margin, the readings within ``S`` of
the reference (default 0.2 rad, or 0.2 x the characteristic length for a prismatic actuator)
(:mod:`pkm.core.calibration.poses`); with ``--simulate``, the table filled with what an instrument would measure on
a randomly perturbed robot (every joint origin within 2 mm and 0.5 degrees, noise 10 µm and 20 µrad): what ``pkm
calibrate`` then reads. A pose that robot does not reach (its loops do not close there) is left out with a warning
and the next best candidate measured instead, as a real campaign meets a pose the robot refuses
(:attr:`~pkm.core.calibration.poses.PosePlan.refused`)."""

from __future__ import annotations

import argparse
import json
import re
from typing import Any

from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, load_mechanism
from pkm.errors import InvalidInputError

KIND_HELP = "what is measured: pose (6-D), position (3-D), planar (x, y, yaw), passive (encoders on passive joints)"


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, None, None)
    p.add_argument("data", metavar="DATA", help="CSV or Parquet: m.<joint> readings and the measured columns")
    p.add_argument("--out", metavar="DIR", required=True, help="folder for the calibrated spec, URDF and calibration.toml")
    p.add_argument("--model", default="pose", choices=("pose", "position", "planar", "passive"), help=KIND_HELP)
    p.add_argument("--loss", default="linear", choices=("linear", "soft_l1", "huber", "cauchy", "arctan"),
                   help="least-squares loss: linear (Levenberg-Marquardt) or a robust one (trust-region)")
    p.add_argument("--max-evaluations", type=int, metavar="N",
                   help="the least squares' budget of residual evaluations (default 100 per estimated parameter: "
                        "pkm.core.calibration.estimate.NFEV_PER_PARAMETER)")
    p.add_argument("--plot", metavar="FILE.png", help="the residuals before and after, per pose (pkm-robotics[figures])")
    p.add_argument("--json", action="store_true", help="print the result as JSON")


def calibration_model(mech: Any, kind: str) -> Any:
    """:class:`~pkm.core.calibration.measurement.CalibrationModel` of ``--model kind``; the library's refusal of
    a ``kind`` names the option (``kind='passive'``: ``--model passive``)."""
    from pkm.core.calibration.measurement import CalibrationModel

    try:
        return CalibrationModel(mech, kind)
    except InvalidInputError as exc:
        if exc.name != "kind":
            raise
        text = str(exc).removeprefix("kind: ")
        raise InvalidInputError("--model", re.sub(r"kind='(\w+)'", r"--model \1", text), kind) from None


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from pkm.core.calibration.estimate import calibrate
    from pkm.core.calibration.writeback import read_data, write_calibrated

    mech = load_mechanism(args)
    model = calibration_model(mech, args.model)
    M, Y = read_data(model, args.data)
    cal = calibrate(model, M, Y, loss=args.loss, max_nfev=args.max_evaluations)
    spec, toml, *mjcf = write_calibrated(cal, args.out)
    out: dict[str, Any] = {"mechanism": mech.name, "model": args.model, "poses": len(M), "base": len(cal.free),
                           "chi2": cal.chi2, "evaluations": cal.nfev, "before": cal.before.as_dict(), "after": cal.after.as_dict(),
                           "estimated": {n: {"change": d, "std": s} for n, (d, s) in cal.changes().items()},
                           "unseen": list(cal.base.unseen), "spec": str(spec), "calibration": str(toml),
                           "mjcf": str(mjcf[0]) if mjcf else None}
    if args.plot:
        out["plot"] = str(_plot(cal, M, Y, Path(args.plot)))
    if args.json:
        print(json.dumps(out, indent=1))
        return 0
    print(f"{mech.name}: {len(M)} poses, {args.model} measurements, {len(cal.free)} base parameters of "
          f"{len(model.names)} (reduced chi-square {cal.chi2:.3g}, {cal.nfev} evaluations)")
    for label, acc in (("before", cal.before), ("after", cal.after)):
        text = ", ".join(f"{k} {v:.4g}" for k, v in acc.as_dict().items())
        print(f"{label}: {text} (m, rad)")
    for name, (d, s) in cal.changes().items():
        print(f"  {name:40s} {d:+.6g} +- {s:.3g}")
    print(f"out: {spec}\ncalibration: {toml}" + (f"\nmjcf: {mjcf[0]}" if mjcf else "")
          + (f"\nplot: {out['plot']}" if args.plot else ""))
    return 0


def _plot(cal: Any, M: Any, Y: Any, path: Any) -> Any:
    import numpy as np

    from pkm._optional import module

    plt = module("matplotlib.pyplot", extra="figures", what="pkm calibrate --plot")
    model = cal.model
    fig, ax = plt.subplots(figsize=(8, 4))
    for label, x in (("before", None), ("after", cal.x)):
        r, _ = model.residual(model.measure(x, M), Y)
        ax.semilogy(np.arange(1, len(M) + 1), np.linalg.norm(r, axis=1), "o-", label=label)
    ax.set_xlabel("pose")
    ax.set_ylabel("residual norm [m, rad]")
    ax.set_title(f"{model.mech.name}: {model.kind} residuals")
    ax.legend()
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)
    return path


def add_plan_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, None, None)
    p.add_argument("--poses", type=int, required=True, help="how many poses")
    p.add_argument("--out", metavar="FILE.csv", required=True, help="the table of readings (and measurements)")
    p.add_argument("--model", default="pose", choices=("pose", "position", "planar", "passive"), help=KIND_HELP)
    p.add_argument("--spread", type=float,
                   help="largest change of a reading from the reference [rad or m] (default 0.2 rad for a revolute "
                        "actuator, 0.2 x the mechanism's characteristic length for a prismatic one: "
                        "pkm.core.calibration.poses.SPREAD)")
    p.add_argument("--simulate", type=int, metavar="SEED", help="fill in simulated measurements of a perturbed robot")


def run_plan(args: argparse.Namespace) -> int:
    from pkm.core.calibration.estimate import perturbed, simulate
    from pkm.core.calibration.poses import calibration_poses
    from pkm.core.calibration.writeback import write_data

    mech = load_mechanism(args)
    model = calibration_model(mech, args.model)
    x = model.parameters.nominal if args.simulate is None else perturbed(model, args.simulate)
    reachable = None if args.simulate is None else lambda m: bool(model.reaches(x, m)[0])
    chosen = calibration_poses(model, args.poses, spread=args.spread, reachable=reachable)
    y = simulate(model, x, chosen.readings, seed=args.simulate or 0,
                 sigma=None if args.simulate is not None else {"m": 0.0, "rad": 0.0})
    path = write_data(model, args.out, chosen.readings, y)
    refused = (f" ({len(chosen.refused)} more left out: the perturbed robot does not reach them)"
               if len(chosen.refused) else "")
    print(f"{mech.name}: {len(chosen.readings)} poses of {chosen.candidates} candidates{refused}, log O1 "
          f"{chosen.o1:.4g}, O4 {chosen.o4:.3g}, {len(chosen.base)} base parameters; "
          + ("measurements simulated (perturbed robot, seed " + str(args.simulate) + ")" if args.simulate is not None
             else "measured columns hold the nominal model's predictions: replace them with the instrument's")
          + f"\nout: {path}")
    return 0


COMMAND = Command("kinematic calibration: base geometric parameters estimated from measured poses, the calibrated "
                  "mechanism written back ('pkm calibrate plan' chooses the poses)", add_arguments, run)
PLAN = Command("(pkm calibrate plan MECH --poses N --out FILE.csv) calibration poses maximising O1", add_plan_arguments,
               run_plan)
