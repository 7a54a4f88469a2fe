"""Every assembly mode by homotopy continuation against a multistart Newton with the same time (issue 17):
``python tools/bench_assembly.py --json``.

The benchmark ships in the package (:mod:`pkm.bench.assembly`, also ``pkm bench assembly``); this script runs it."""

from pkm.bench import main

if __name__ == "__main__":
    raise SystemExit(main("assembly"))
