#!/usr/bin/env python3
"""Operation count of the 3-PRS inverse dynamics (symbolic twin) next to the published ones.

The twin is :func:`pkm.mechanisms.prs3_dynamics.twin`: the same algorithm as the numeric routes,
on CasADi SX, after common-subexpression elimination. Counted as SYMORO counts: * / and squares as
multiplications, + - as additions, negations free, sin/cos/sqrt/atan2 apart. Three modes: geometry
and inertia symbolic; inertia symbolic (Table 2 geometry); all numeric (Table 2). P- and R-actuated
(R needs inclined rails: gamma = 1.2 rad for the R rows).

Usage: ``python tools/bench_opcount.py [--json]``.
"""

from __future__ import annotations

import argparse
import json

from pkm.mechanisms.prs3 import Prs3Params
from pkm.mechanisms.prs3_dynamics import BOUNDARY, MODES, operation_count
from pkm.papers.prs3 import PUBLISHED_COUNTS


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", action="store_true", help="print JSON instead of a table")
    args = ap.parse_args()
    designs = {"P": Prs3Params(), "R": Prs3Params(actuation="R", gamma=1.2)}
    ours = [operation_count(designs[a], mode=m) for a in ("P", "R") for m in MODES]
    result = {
        "boundary": BOUNDARY,
        "published": {k: {"mul_div": m, "add_sub": a} for k, (m, a) in PUBLISHED_COUNTS.items()},
        "ours": [{"actuation": c.actuation, "mode": c.mode, "mul_div": c.mul, "add_sub": c.add,
                  "functions": c.functions,
                  "ratio_to_paper": {"mul_div": round(c.mul / 860, 3), "add_sub": round(c.add / 680, 3)}}
                 for c in ours],
        "goals": {"inertial": {"mul_div": 700, "add_sub": 550}, "numeric": {"mul_div": 550, "add_sub": 450}},
    }
    if args.json:
        print(json.dumps(result, indent=2))
        return
    print(f"{'source':38s} {'mult/div':>9s} {'add/sub':>8s}  functions")
    for k, (m, a) in PUBLISHED_COUNTS.items():
        print(f"{k:38s} {m:9d} {a:8d}")
    for c in ours:
        fn = ", ".join(f"{v} {k}" for k, v in c.functions.items())
        print(f"{'pkm, ' + c.actuation + '-actuated, ' + c.mode:38s} {c.mul:9d} {c.add:8d}  {fn}")
    print(f"\nboundary: {BOUNDARY}")


if __name__ == "__main__":
    main()
