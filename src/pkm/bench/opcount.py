"""Operation count of the 3-PRS inverse dynamics (symbolic twin) next to the published ones.

The twin is :func:`pkm.mechanisms.prs3.dynamics.twin`: the same algorithm as the numeric routes,
on CasADi SX, after common-subexpression elimination. Counted as SYMORO counts: * / and squares as
multiplications, + - as additions, negations free, sin/cos/sqrt/atan2 apart. Three modes: geometry
and inertia symbolic; inertia symbolic (Table 2 geometry); all numeric (Table 2). P- and R-actuated
(R needs inclined rails: gamma = 1.2 rad for the R rows).

Usage: ``python -m pkm.bench.opcount [--json]``.
"""

from __future__ import annotations

from pkm.bench import main
from pkm.mechanisms.prs3 import Prs3Params
from pkm.mechanisms.prs3.dynamics import BOUNDARY, MODES, operation_count
from pkm.papers.prs3 import PUBLISHED_COUNTS

QUICK: dict = {}  # the counts take about 2 s: no smaller size


def add_arguments(ap) -> None:
    pass


def run(args) -> dict:
    designs = {"P": Prs3Params(), "R": Prs3Params(actuation="R", gamma=1.2)}
    ours = [operation_count(designs[a], mode=m) for a in ("P", "R") for m in MODES]
    return {
        "boundary": BOUNDARY,
        "published": {k: {"mul_div": m, "add_sub": a} for k, (m, a) in PUBLISHED_COUNTS.items()},
        "ours": [{"actuation": c.actuation, "mode": c.mode, "mul_div": c.mul, "add_sub": c.add,
                  "functions": c.functions,
                  "ratio_to_paper": {"mul_div": round(c.mul / 860, 3), "add_sub": round(c.add / 680, 3)}}
                 for c in ours],
        "goals": {"inertial": {"mul_div": 700, "add_sub": 550}, "numeric": {"mul_div": 550, "add_sub": 450}},
    }


def table(result: dict) -> str:
    lines = [f"{'source':38s} {'mult/div':>9s} {'add/sub':>8s}  functions"]
    for k, v in result["published"].items():
        lines.append(f"{k:38s} {v['mul_div']:9d} {v['add_sub']:8d}")
    for c in result["ours"]:
        fn = ", ".join(f"{v} {k}" for k, v in c["functions"].items())
        lines.append(f"{'pkm, ' + c['actuation'] + '-actuated, ' + c['mode']:38s} {c['mul_div']:9d} "
                     f"{c['add_sub']:8d}  {fn}")
    lines.append(f"\nboundary: {result['boundary']}")
    return "\n".join(lines)


if __name__ == "__main__":
    raise SystemExit(main("opcount"))
