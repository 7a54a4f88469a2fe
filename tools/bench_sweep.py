"""Design sweeps on Dask, 1 and 2 local workers against the in-process loop (issue 16):
``python tools/bench_sweep.py --json``.

The benchmark ships in the package (:mod:`pkm.bench.sweep`, also ``pkm bench sweep``); this script runs it."""

from pkm.bench import main

if __name__ == "__main__":
    raise SystemExit(main("sweep"))
