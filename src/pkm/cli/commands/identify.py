"""``pkm identify MECH data.csv --out identified.closures.toml [--tie-legs] [--consistent] [--validate other.csv]
[--cutoff HZ] [--plot FILE.png] [--json]``: the dynamic parameters of a mechanism from its measurements (a table of
``time``, ``q.<joint>``, ``tau.<joint>``: :mod:`pkm.core.identification.measurements`): the base parameters by
Gautier's weighted least squares with each one's relative standard deviation, with ``--consistent`` the physically
consistent estimate (cvxpy and Clarabel: ``pkm-robotics[identify]``), written as a spec and URDF that ``pkm.load``
reads; with ``--validate`` the identified model's efforts against a second table.

The table printed (and ``base`` in ``--json``) holds, per base parameter, its value in the model written (``value``:
``P θ`` of the spec and URDF saved, so the consistent estimate's with ``--consistent``; an effort offset is not
written, a drive's negative friction is written as 0), then the least-squares estimate, its standard deviation and
relative standard deviation (``--json``: also its ``effort_share`` and whether it is ``poor``ly identified,
:mod:`pkm.core.identification.estimate`); the fit (or ``--validate``'s prediction) is the estimate's, its effort
offsets included; the samples used, the decimation and the filter's cutoff are printed, and the estimate's warnings
(:class:`~pkm.errors.PoorIdentificationWarning`: too few equations, poorly identified parameters)."""

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
    p.add_argument("--consistent", action="store_true", help="physically consistent estimate (pkm-robotics[identify])")
    p.add_argument("--validate", metavar="OTHER", help="a second table to predict")
    p.add_argument("--cutoff", type=float,
                   help="the zero-phase filter's cutoff [Hz] (default: a tenth of the sampling rate); the filtered "
                        "rows are then decimated to one in rate / (2 cutoff) and 3 cutoff periods left out at each "
                        "end: a low cutoff keeps few rows (the rows kept are reported)")
    p.add_argument("--plot", metavar="FILE.png", help="measured against predicted efforts (pkm-robotics[figures])")
    p.add_argument("--json", action="store_true", help="print the result as JSON")


def run(args: argparse.Namespace) -> int:
    import warnings

    import pkm
    from pkm._optional import require
    from pkm.core.identification.base import base_parameters, require_precise
    from pkm.core.identification.estimate import POOR_EFFORT_SHARE, POOR_RELATIVE_STD, estimate
    from pkm.core.identification.export import identified_mechanism, standard_from_base, validate
    from pkm.core.identification.measurements import measurements
    from pkm.core.identification.regressor import parameters
    from pkm.core.model.plausibility import require_physical
    from pkm.errors import InvalidInputError, NonPhysicalInertiaError, PoorIdentificationWarning, SpecError
    from pkm.report import jsonable

    mech = load_mechanism(args)
    require_precise(mech, "pkm identify")  # (before the measurements are read: the rank needs the twin's regressor)
    if args.consistent:
        require("identify", "the physically consistent estimate (pkm identify --consistent)")
    if args.plot:
        require("figures", "the figure of an identified model (pkm.viz.identification)")
    data = measurements(mech, args.data, cutoff=args.cutoff)
    base = base_parameters(mech, tie_legs=args.tie_legs)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PoorIdentificationWarning)  # (printed below, from ls.warnings)
        ls = estimate(mech, data.Q, data.QD, data.QDD, data.TAU, base=base)
    model: Any = ls
    if args.consistent:
        from pkm.core.identification.consistent import consistent_estimate

        model = consistent_estimate(mech, data.Q, data.QD, data.QDD, data.TAU, base=base, ls=ls)
        theta = model.theta
    else:
        theta = standard_from_base(mech, base, ls.values)
    try:
        identified = identified_mechanism(mech, theta, source=args.out)  # (what a warning is about: the file written)
        # (it loads for its kinematics; a model written from an estimate must be real)
        require_physical(identified, f"writing the identified model {args.out}")
    except (SpecError, InvalidInputError, NonPhysicalInertiaError) as exc:
        if args.consistent:
            raise
        raise InvalidInputError("--consistent", f"the least-squares estimate is no real mechanism and cannot be "
                                                f"written ({exc}); --consistent writes the physically consistent "
                                                f"estimate", None) from None
    written = base.map @ parameters(identified).values  # the model written, as written (no offset, friction >= 0)
    out: dict[str, Any] = {
        "mechanism": mech.name, "samples": len(data), "table_rows": data.table_rows, "decimate": data.decimate,
        "equations": ls.rows, "cutoff_hz": data.cutoff, "method": ls.method,
        "consistent": bool(args.consistent), "routes_agree": base.routes_agree,
        "base": [{"name": n, "value": float(w), "least_squares": float(v), "std": float(s),
                  "relative_std_percent": float(r), "effort_share": float(e), "poor": bool(p)}
                 for n, w, v, s, r, e, p in zip(base.names, written, ls.values, ls.std, ls.relative_std,
                                                ls.effort_share, ls.poor)],
        "residual_rms": dict(zip(mech.actuated_names, ls.residual_rms.tolist())),
        "warnings": list(ls.warnings),
        "out": str(pkm.save(identified, args.out)),
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
    print(f"{mech.name}: {len(base)} base parameters from {len(data)} samples ({ls.rows} equations): one row in "
          f"{data.decimate} of {data.table_rows} kept, filtered at {data.cutoff:.4g} Hz (its transients left out at "
          f"each end); the two rank routes {'agree' if base.routes_agree else 'DISAGREE'}")
    estimate_name = "physically consistent estimate" if args.consistent else f"least squares ({ls.method})"
    print(f"the model written ({estimate_name}); least squares ({ls.method}) ± standard deviation (relative), "
          f"'!' poorly identified (above {POOR_RELATIVE_STD:g} % and a deviation worth more than "
          f"{100 * POOR_EFFORT_SHARE:g} % of the efforts):")
    width = max(len(n) for n in base.names)
    for row in out["base"]:
        flag = "!" if row["poor"] else " "
        print(f"  {row['name'].ljust(width)}  {row['value']: .6g}  ({row['least_squares']: .6g} ± {row['std']:.2g}, "
              f"{row['relative_std_percent']:.3g} %){flag}")
    key = "validation" if args.validate else "fit"
    print(f"{key} of the {estimate_name} (its effort offsets included: the model written has none): relative RMS " + ", ".join(f"{n} {r:.3g} %" for n, r in out[key]["relative_percent"].items()))
    for w in ls.warnings:
        print(f"warning: {w}")
    print(f"out: {out['out']}" + (f"\nplot: {out['plot']}" if args.plot else ""))
    return 0


COMMAND = Command("the dynamic parameters from measurements: base parameters, a consistent estimate, a spec",
                  add_arguments, run)

