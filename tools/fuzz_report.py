#!/usr/bin/env python3
"""Fuzz report: every public entry point of pkm fed random and adversarial inputs.

For each entry point of :data:`tests.fuzzing.ENTRIES`, ``--n`` inputs are generated (half *random*: valid-looking
or near-valid values around a reference configuration, pose or parameter set; half *adversarial*:
NaN, infinities, huge and tiny numbers, wrong shapes and types, strings, ``None``, negative lengths,
poses far outside the workspace, singular configurations, mutated and hostile files) and each call
is classified:

* ``ok``: it returned, and every number in the result is finite (numpy arrays, dataclasses,
  tuples, dicts... walked recursively). The few documented sentinels are accepted as ok and
  counted apart (``documented``): ``inf`` for condition numbers at singular or unreachable
  points, ``NaN`` in maps at unreachable nodes and baseline comparisons where the baseline is
  inadmissible, each flagged by a mask in the same result;
* ``nonfinite``: it returned a NaN or an infinity that is not a documented sentinel;
* ``pkm_error``: it raised a :class:`pkm.errors.PkmError` (the expected way to refuse);
* ``other``: it raised anything else (or ran past ``--timeout``): a bug. The type, message,
  entry point and a repro (the call with its arguments) are kept for the first few.

A PkmError whose numeric attributes (residual, excess, sigma_min, deficit) are NaN is counted
in ``error_nan``.

Usage::

    python tools/fuzz_report.py                 # 10,000 inputs per entry point, table
    python tools/fuzz_report.py --n 30 --json   # quick, machine output
    python tools/fuzz_report.py --only solve_ik --n 2000 --seed 3

``--jobs`` worker processes (default: the CPU count) share the work in chunks; every chunk has
its own seed derived from ``--seed``, the entry's name and the chunk index, so a run is
reproducible whatever the number of workers. Exit status 1 when any ``other`` or ``nonfinite``
was found.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import sys
import time
import traceback
import warnings
import zlib
from collections import Counter
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the checkout: the entries live in tests/fuzzing.py
from tests.fuzzing import ENTRIES, Entry, Gen, ctx, finite  # noqa: F401 (Entry: to plant entries in tests)

CHUNK = 250  # calls per task handed to a worker
EXAMPLES = 5  # "other" / "nonfinite" examples kept per entry point

# ---------------------------------------------------------------------- classification
class CallTimeout(BaseException):
    """A call ran past ``--timeout`` (a BaseException, so that no ``except Exception`` swallows it)."""


def _alarm(signum, frame):
    raise CallTimeout()


def _repro(entry_name: str, fn, args, kwargs) -> str:
    def short(v):
        r = repr(v)
        return r if len(r) <= 300 else r[:150] + f"...<{len(r)} chars>..." + r[-100:]
    name = f"{getattr(fn, '__module__', '?')}.{getattr(fn, '__qualname__', repr(fn))}"
    parts = [short(a) for a in args] + [f"{k}={short(v)}" for k, v in kwargs.items()]
    return f"[{entry_name}] {name}({', '.join(parts)})"


def run_chunk(task: tuple) -> dict:
    """Run ``count`` calls of one entry point; returns its tallies."""
    name, seed, chunk_index, count, timeout = task
    warnings.simplefilter("ignore")
    signal.signal(signal.SIGALRM, _alarm)
    c = ctx()
    e = next(e for e in ENTRIES if e.name == name)
    rng = np.random.default_rng([seed, zlib.crc32(name.encode()), chunk_index])
    g = Gen(rng)
    out = {"tried": 0, "ok": 0, "pkm_error": 0, "other": 0, "nonfinite": 0, "documented": 0, "error_nan": 0,
           "seconds": 0.0, "by_kind": {"random": Counter(), "adversarial": Counter()}, "errors": Counter(),
           "examples_other": [], "examples_nonfinite": []}
    PkmError = c.pkm.PkmError
    for k in range(count):
        adversarial = (chunk_index * CHUNK + k) % 2 == 1
        kind = "adversarial" if adversarial else "random"
        try:
            fn, args, kwargs = e.make(g, adversarial)
        except Exception as exc:  # a bug of this harness, not of pkm
            raise RuntimeError(f"generator of {name} failed: {exc!r}") from exc
        t0 = time.perf_counter()
        signal.setitimer(signal.ITIMER_REAL, timeout)
        try:
            try:
                res = fn(*args, **kwargs)
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0)
            if finite(res):
                verdict = "ok"
            elif e.sentinel is not None and _safe(e.sentinel, res):
                verdict = "ok"
                out["documented"] += 1
            else:
                verdict = "nonfinite"
                if len(out["examples_nonfinite"]) < EXAMPLES:
                    out["examples_nonfinite"].append({"result": repr(res)[:500],
                                                      "repro": _repro(name, fn, args, kwargs)})
        except PkmError as exc:
            verdict = "pkm_error"
            out["errors"][type(exc).__name__] += 1
            if any(isinstance(getattr(exc, a, None), float) and math.isnan(getattr(exc, a))
                   for a in ("residual", "excess", "sigma_min", "deficit")):
                out["error_nan"] += 1
        except CallTimeout:
            verdict = "other"
            _keep(out, name, "Timeout", f"ran past {timeout} s", fn, args, kwargs, "")
        except Exception as exc:
            verdict = "other"
            _keep(out, name, type(exc).__name__, str(exc)[:500], fn, args, kwargs,
                  "".join(traceback.format_exception(exc)[-3:])[-1500:])
        out["seconds"] += time.perf_counter() - t0
        out["tried"] += 1
        out[verdict] += 1
        out["by_kind"][kind][verdict] += 1
    return {"name": name, **out}


def _safe(check, res) -> bool:
    try:
        return bool(check(res))
    except Exception:
        return False


def _keep(out, name, typ, msg, fn, args, kwargs, tb) -> None:
    out["errors"][typ] += 0  # keep the key out of the PkmError tally
    if len(out["examples_other"]) < EXAMPLES:
        out["examples_other"].append({"type": typ, "message": msg, "repro": _repro(name, fn, args, kwargs),
                                      "traceback": tb})


def merge(total: dict, part: dict) -> None:
    for k in ("tried", "ok", "pkm_error", "other", "nonfinite", "documented", "error_nan", "seconds"):
        total[k] += part[k]
    for kind in ("random", "adversarial"):
        total["by_kind"][kind].update(part["by_kind"][kind])
    total["errors"].update(part["errors"])
    for key in ("examples_other", "examples_nonfinite"):
        total[key] += part[key][:max(0, EXAMPLES - len(total[key]))]


def run(names: list[str], n: int, *, seed: int = 0, jobs: int = 1, timeout: float = 30.0,
        progress: bool = False) -> dict:
    """Fuzz the entry points ``names`` with ``n`` inputs each; the report as a dict (see ``--json``)."""
    tasks = [(nm, seed, k, min(CHUNK, n - k * CHUNK), timeout)
             for k in range(math.ceil(n / CHUNK)) for nm in names]  # chunk-major: slow entries spread out
    totals = {nm: {"tried": 0, "ok": 0, "pkm_error": 0, "other": 0, "nonfinite": 0, "documented": 0,
                   "error_nan": 0, "seconds": 0.0, "by_kind": {"random": Counter(), "adversarial": Counter()},
                   "errors": Counter(), "examples_other": [], "examples_nonfinite": []} for nm in names}
    t0 = time.perf_counter()
    sys.stdout.flush()
    saved_stdout = os.dup(1)
    os.dup2(2, 1)  # what C libraries print (LAPACK's "On entry to DLASCL...") must not mix with --json
    try:
        _run_tasks(tasks, totals, jobs, progress, len(names) * n)
    finally:
        sys.stdout.flush()
        os.dup2(saved_stdout, 1)
        os.close(saved_stdout)
    report = {"n": n, "seed": seed, "jobs": jobs, "wall_seconds": round(time.perf_counter() - t0, 1), "entries": {}}
    return _report_entries(report, names, totals)


def _run_tasks(tasks: list, totals: dict, jobs: int, progress: bool, calls: int) -> None:
    bar = None
    if progress:
        try:
            from tqdm import tqdm
            bar = tqdm(total=calls, unit="call", file=sys.stderr, smoothing=0.05)
        except ImportError:  # pragma: no cover
            bar = None
    if jobs <= 1:
        for t in tasks:
            part = run_chunk(t)
            merge(totals[part["name"]], part)
            if bar:
                bar.update(part["tried"])
    else:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            futures = [pool.submit(run_chunk, t) for t in tasks]
            for f in as_completed(futures):
                part = f.result()
                merge(totals[part["name"]], part)
                if bar:
                    bar.update(part["tried"])
    if bar:
        bar.close()


def _report_entries(report: dict, names: list[str], totals: dict) -> dict:
    for nm in names:
        t = totals[nm]
        report["entries"][nm] = {
            "tried": t["tried"], "ok": t["ok"], "pkm_error": t["pkm_error"], "other": t["other"],
            "nonfinite": t["nonfinite"], "documented": t["documented"], "error_nan": t["error_nan"],
            "seconds": round(t["seconds"], 2),
            "random": dict(t["by_kind"]["random"]), "adversarial": dict(t["by_kind"]["adversarial"]),
            "errors": dict(t["errors"].most_common()),
            "examples_other": t["examples_other"], "examples_nonfinite": t["examples_nonfinite"]}
    report["total"] = {k: sum(e[k] for e in report["entries"].values())
                       for k in ("tried", "ok", "pkm_error", "other", "nonfinite", "documented", "error_nan")}
    return report


def table(report: dict) -> str:
    """The human table of a report, then the examples of "other" and "nonfinite"."""
    names = list(report["entries"])
    w = max(len(nm) for nm in names)
    lines = [f"{'entry point':{w}}  {'tried':>7} {'ok':>7} {'PkmError':>8} {'other':>6} {'nonfin':>6} {'s':>7}"]
    for nm, e in report["entries"].items():
        lines.append(f"{nm:{w}}  {e['tried']:7d} {e['ok']:7d} {e['pkm_error']:8d} {e['other']:6d} {e['nonfinite']:6d} "
                     f"{e['seconds']:7.1f}")
    tot = report["total"]
    lines.append(f"{'total':{w}}  {tot['tried']:7d} {tot['ok']:7d} {tot['pkm_error']:8d} {tot['other']:6d} "
                 f"{tot['nonfinite']:6d}   wall {report['wall_seconds']:.0f} s on {report['jobs']} worker(s)")
    for nm, e in report["entries"].items():
        for ex in e["examples_other"] + e["examples_nonfinite"]:
            lines.append(f"\n{nm}: {ex.get('type', 'nonfinite')}: {ex.get('message', ex.get('result'))}\n"
                         f"  {ex['repro']}")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=10_000, help="inputs per entry point (default 10000)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--only", action="append", default=[], help="entry points whose name contains this (repeatable)")
    ap.add_argument("--json", action="store_true", help="machine output on stdout")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--timeout", type=float, default=30.0, help="seconds allowed per call before it counts as other")
    ap.add_argument("--list", action="store_true", help="list the entry points and exit")
    ap.add_argument("--no-progress", action="store_true")
    args = ap.parse_args(argv)
    names = [e.name for e in ENTRIES if not args.only or any(s in e.name for s in args.only)]
    if args.list:
        print("\n".join(names))
        return 0
    if not names or args.n < 1:
        print(f"nothing to run (--only {args.only}, --n {args.n})", file=sys.stderr)
        return 2
    report = run(names, args.n, seed=args.seed, jobs=args.jobs, timeout=args.timeout,
                 progress=not args.no_progress)
    if args.json:
        json.dump(report, sys.stdout, indent=1)
        print()
    else:
        print(table(report))
    return 1 if report["total"]["other"] or report["total"]["nonfinite"] else 0


if __name__ == "__main__":
    sys.exit(main())
