"""The twin's kernels against the hand-written 3-PRS and MuJoCo (issue 15): ``python tools/bench_twin.py --json``.

The benchmark ships in the package (:mod:`pkm.bench.twin`, also ``pkm bench twin``); this script runs it."""

from pkm.bench import main

if __name__ == "__main__":
    raise SystemExit(main("twin"))
