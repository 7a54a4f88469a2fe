"""Benchmarks: each measures pkm against a baseline timed in the same run, and reports ratios.

They ship inside the package, so ``pkm bench`` works from an installed wheel. One module a
benchmark, each with the same four names:

* ``add_arguments(parser)``: its options (sizes, repeats);
* ``QUICK``: the option values of a quick run (``pkm bench --quick``: seconds, not minutes; for
  checking that a benchmark runs, not for its numbers);
* ``run(args) -> dict``: the measurements (JSON-ready);
* ``table(result) -> str``: the same as a table.

``python -m pkm.bench.NAME [--json] [--quick] ...`` runs one; ``pkm bench`` runs several.
"""

from __future__ import annotations

import argparse
import importlib
import json
import math
import statistics
import time
from collections.abc import Callable, Sequence
from types import ModuleType
from typing import Any

from pkm.errors import UnknownNameError

NAMES = ("assembly", "batch", "clearance", "designs", "dynamics", "export", "hexapod", "identification", "kinematics", "opcount", "serve",
         "simulation", "simulation_speed", "stiffness", "sweep", "time_optimal", "transmissions", "twin", "workspace")


def module(name: str) -> ModuleType:
    """The module of benchmark ``name``; :class:`UnknownNameError` listing :data:`NAMES` otherwise."""
    if not isinstance(name, str) or name not in NAMES:
        raise UnknownNameError("benchmark", str(name), NAMES)
    return importlib.import_module(f"pkm.bench.{name}")


def best_time(fn: Callable[[], Any], repeat: int, clock: Callable[[], float] = time.perf_counter) -> tuple[float, Any]:
    """Best wall time of ``repeat`` calls of ``fn`` [s] (or the time of another ``clock``: ``time.process_time``, the
    process's CPU time, on a shared machine), and the last call's result."""
    best, out = math.inf, None
    for _ in range(max(1, repeat)):
        t0 = clock()
        out = fn()
        best = min(best, clock() - t0)
    return best, out


def median_us(fn: Callable[..., Any], args: Sequence[tuple] = ((),), repeat: int = 2000) -> float:
    """Median wall time of one call ``fn(*a)`` [us] over ``repeat`` calls cycling through ``args``, after up to 50
    warm-up calls."""
    for a in list(args[:50]) * max(1, 50 // max(len(args), 1)):
        fn(*a)
    times = []
    for k in range(repeat):
        a = args[k % len(args)]
        t0 = time.perf_counter()
        fn(*a)
        times.append(time.perf_counter() - t0)
    return statistics.median(times) * 1e6


#: XLA's options for the JAX compiles of a quick run (:func:`jax_batch`): its backend unoptimised (LLVM ``-O0``: the
#: compile of the 3-PRS's inverse dynamics 1.7 -> 1.1 s of CPU, the knee's fk_j_dm 0.8 -> 0.5 s; the kernel then runs
#: several times slower, which a quick run, a check that the route runs and agrees, does not measure).
QUICK_XLA: dict[str, str | bool] = {"xla_backend_optimization_level": "0"}


def jax_batch(fn: Callable[..., Any], args: Sequence[Any], quick: bool = False) -> Callable[..., Any]:
    """``jax.jit(jax.vmap(fn))``, compiled on its first call; ``quick``: compiled here for ``args``' shapes with
    :data:`QUICK_XLA` (call it with arrays of those shapes)."""
    from pkm._optional import module as optional

    jax = optional("jax", extra="jax", what="the benchmarks' JAX route")

    f = jax.jit(jax.vmap(fn))
    return f.lower(*args).compile(QUICK_XLA) if quick else f


def parser(mod: ModuleType, cls: type[argparse.ArgumentParser] = argparse.ArgumentParser) -> argparse.ArgumentParser:
    """The command-line options of benchmark module ``mod`` (an argparse parser of class ``cls``)."""
    doc = mod.__doc__ or ""
    ap = cls(prog=f"python -m {mod.__name__}", description=doc.strip().splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print JSON instead of a table")
    ap.add_argument("--quick", action="store_true", help="small sizes: checks that it runs, in seconds")
    mod.add_arguments(ap)
    return ap


def arguments(mod: ModuleType, argv: Sequence[str] = (), quick: bool = False,
              cls: type[argparse.ArgumentParser] = argparse.ArgumentParser) -> argparse.Namespace:
    """Parsed options of ``mod``; ``quick`` (or ``--quick`` in ``argv``) applies its ``QUICK`` sizes
    to the options that ``argv`` does not set."""
    ap = parser(mod, cls)
    args = ap.parse_args(list(argv))
    if quick or args.quick:
        defaults = ap.parse_args([])
        for key, value in mod.QUICK.items():
            if getattr(args, key) == getattr(defaults, key):
                setattr(args, key, value)
        args.quick = True
    return args


def main(name: str, argv: Sequence[str] | None = None) -> int:
    """``python -m pkm.bench.NAME``: run one benchmark and print its table (or JSON)."""
    import sys

    mod = module(name)
    args = arguments(mod, sys.argv[1:] if argv is None else argv)
    result = mod.run(args)
    print(json.dumps(result, indent=2) if args.json else mod.table(result))
    return 0


__all__ = ["NAMES", "QUICK_XLA", "arguments", "best_time", "jax_batch", "main", "median_us", "module", "parser"]
