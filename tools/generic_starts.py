"""Write the generic start systems pkm ships (src/pkm/core/modes/starts/*.json): each family of reduced equations
solved once at random complex parameters by a total-degree homotopy (see pkm.core.modes.starts).

    python tools/generic_starts.py [SIGNATURE ...]     # default: the families of the shipped mechanisms

A second solve at other random parameters (--check) must find as many generic solutions: the count is the
family's, not the draw's.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from pkm.core.modes.starts import _DIR, compute

FAMILIES = ("SE3:ssssss", "SE3:ccc")  # 6-SS/RUS/UPS platforms; 3-PRS


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("signatures", nargs="*", default=list(FAMILIES))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--check", action="store_true", help="also solve at another seed and compare the counts")
    args = ap.parse_args(argv)
    _DIR.mkdir(exist_ok=True)
    status = 0
    for sig in args.signatures:
        t0 = time.perf_counter()
        start = compute(sig, seed=args.seed)
        line = (f"{sig}: {len(start.points)} generic solutions from {start.total_degree} paths, "
                f"{start.n_failed} failed, {time.perf_counter() - t0:.1f} s")
        if args.check:
            other = compute(sig, seed=args.seed + 1)
            line += f"; seed {args.seed + 1}: {len(other.points)}"
            status |= len(other.points) != len(start.points) or other.n_failed > 0
        if start.n_failed:
            status = 1
        Path(_DIR / f"{sig.replace(':', '-')}.json").write_text(start.to_json() + "\n")
        print(line)
    return status


if __name__ == "__main__":
    raise SystemExit(main())
