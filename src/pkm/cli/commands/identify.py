"""``pkm identify MECH data.csv --out identified.closures.toml [--tie-legs] [--consistent] [--validate other.csv]
[--cutoff HZ] [--plot FILE.png] [--json]``: the dynamic parameters of a mechanism from its measurements (a table of
``time``, ``q.<joint>``, ``tau.<joint>``: :mod:`pkm.core.identification.measurements`): the base parameters by
Gautier's weighted least squares with each one's relative standard deviation, with ``--consistent`` the physically
consistent estimate (cvxpy and Clarabel: ``pkm[identify]``), written as a spec and URDF that ``pkm.load`` reads; with
``--validate`` the identified model's efforts against a second table."""

from __future__ import annotations

import argparse
import json
from typing import Any

from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, load_mechanism


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, None, None)
    p.add_argument("data", metavar="DATA", help="measurements: CSV or Parquet with time, q.<joint>, tau.<joint>")
    p.add_argument("--out", metavar="FILE.closures.toml", required=True, help="the identified spec (URDF beside it)")
    p.add_argument("--tie-legs", action="store_true", help="one parameter set per kind of leg")
    p.add_argument("--consistent", action="store_true", help="physically consistent estimate (pkm[identify])")
    p.add_argument("--validate", metavar="OTHER", help="a second table to predict")
    p.add_argument("--cutoff", type=float, help="the zero-phase filter's cutoff [Hz] (default: a tenth of the rate)")
    p.add_argument("--plot", metavar="FILE.png", help="measured against predicted efforts (pkm[figures])")
    p.add_argument("--json", action="store_true", help="print the result as JSON")


def run(args: argparse.Namespace) -> int:
    from pkm._optional import require
    from pkm.core.identification.base import base_parameters
    from pkm.core.identification.estimate import estimate
    from pkm.core.identification.export import standard_from_base, validate, write_identified
    from pkm.core.identification.measurements import measurements
    from pkm.report import jsonable

    mech = load_mechanism(args)
    if args.consistent:
        require("identify", "the physically consistent estimate (pkm identify --consistent)")
    if args.plot:
        require("figures", "the figure of an identified model (pkm.viz.identification)")
    data = measurements(mech, args.data, cutoff=args.cutoff)
    base = base_parameters(mech, tie_legs=args.tie_legs)
    ls = estimate(mech, data.Q, data.QD, data.QDD, data.TAU, base=base)
    model: Any = ls
    if args.consistent:
        from pkm.core.identification.consistent import consistent_estimate

        model = consistent_estimate(mech, data.Q, data.QD, data.QDD, data.TAU, base=base, ls=ls)
        theta = model.theta
    else:
        theta = standard_from_base(mech, base, ls.values)
    out: dict[str, Any] = {
        "mechanism": mech.name, "samples": len(data), "cutoff_hz": data.cutoff, "method": ls.method,
        "consistent": bool(args.consistent), "routes_agree": base.routes_agree,
        "base": [{"name": n, "value": float(v), "std": float(s), "relative_std_percent": float(r)}
                 for n, v, s, r in zip(base.names, ls.values, ls.std, ls.relative_std)],
        "residual_rms": dict(zip(mech.actuated_names, ls.residual_rms.tolist())),
        "out": str(write_identified(mech, theta, args.out)),
    }
    if args.consistent:
        out["smallest_pseudo_inertia_eigenvalue"] = model.smallest_eigenvalue
    check = data
    if args.validate:
        check = measurements(mech, args.validate, cutoff=args.cutoff)
    v = validate(mech, model, check)
    out["validation" if args.validate else "fit"] = {
        "rms": dict(zip(mech.actuated_names, v.rms.tolist())),
        "relative_percent": dict(zip(mech.actuated_names, v.relative.tolist()))}
    if args.plot:
        from pkm.viz.identification import fit_figure

        out["plot"] = str(fit_figure(mech, v, args.plot, title="validation" if args.validate else "fit"))
    if args.json:
        print(json.dumps(jsonable(out), indent=2))
        return 0
    print(f"{mech.name}: {len(base)} base parameters from {len(data)} samples ({ls.method}"
          f"{', physically consistent' if args.consistent else ''}); the two rank routes "
          f"{'agree' if base.routes_agree else 'DISAGREE'}")
    width = max(len(n) for n in base.names)
    for row in out["base"]:
        print(f"  {row['name'].ljust(width)}  {row['value']: .6g}  ± {row['std']:.2g} "
              f"({row['relative_std_percent']:.3g} %)")
    key = "validation" if args.validate else "fit"
    print(f"{key}: relative RMS " + ", ".join(f"{n} {r:.3g} %" for n, r in out[key]["relative_percent"].items()))
    print(f"out: {out['out']}" + (f"\nplot: {out['plot']}" if args.plot else ""))
    return 0


COMMAND = Command("the dynamic parameters from measurements: base parameters, a consistent estimate, a spec",
                  add_arguments, run)

