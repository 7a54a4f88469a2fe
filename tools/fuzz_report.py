#!/usr/bin/env python3
"""Fuzz report: every public entry point of pkm fed random and adversarial inputs, within time bounds.

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
* ``other``: it raised anything else, or its worker process died in it (``WorkerDied``): a bug. The type,
  message, entry point and a repro (the call with its arguments) are kept for the first few;
* ``hang``: it ran past ``--timeout`` seconds: interrupted there (``SIGALRM``) when the call gives control back,
  else its worker process is killed ``--grace`` seconds later and replaced (a deadlock, a C loop), and the rest
  of its chunk goes on in the new worker. Never waited on longer: a bug, with its repro.

A PkmError whose numeric attributes (residual, excess, sigma_min, deficit) are NaN is counted
in ``error_nan``.

What the libraries print on a worker's stdout and stderr (urdfdom's parser messages through Pinocchio's C++,
LAPACK's, loggers') goes to a temporary file, not to the run's stderr: each entry point reports how many of its
calls printed (``output_calls``), how many lines (``output_lines``) and the start of the first (``output_example``).

Time bounds: the whole run may take ``--total-seconds`` (default 2700: 45 minutes; counted from when its workers
are started, so that a slow fork of a large process on a busy machine spends none of it) plus at most one call's
bound.
Every entry point may spend (its calls' wall time, summed over its chunks) ``--entry-seconds`` if given, else its
share of the total, re-divided whenever a chunk is handed out: the time left (``x --jobs``) plus what the entry
points not finished have spent, divided equally among them. So the time a cheap entry point leaves unused goes to
those still running, and a slow one waits (its chunks stay queued) until the share grows past what it spent.
An entry point stopped before its ``--n`` calls is reported with the calls it got (``tried``) and why (``cut``:
``entry``, its ``--entry-seconds`` spent, or ``total``, the run's); the table marks it ``*``. The full default run
(109 entry points x 10,000 inputs on 2 cores) is sized to give every entry point its 10,000 within the 45 minutes:
its calls need about 2,500 of the 5,400 worker-seconds (issue 47: the slowest entry points, 5 to 25 ms a call).

Usage::

    python tools/fuzz_report.py                 # 10,000 inputs per entry point, table, within 45 minutes
    python tools/fuzz_report.py --n 30 --json   # quick, machine output
    python tools/fuzz_report.py --only solve_ik --n 2000 --seed 3 --entry-seconds 600

``--jobs`` worker processes (default: the CPU count, each forked from this one) share the work in chunks of
:data:`CHUNK` calls; every chunk has its own seed derived from ``--seed``, the entry's name and the chunk index,
so a run is reproducible whatever the number of workers (the calls an entry gets within a time bound excepted).
Exit status 1 when any ``other``, ``nonfinite`` or ``hang`` was found.
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing
import os
import signal
import sys
import tempfile
import time
import traceback
import warnings
import zlib
from collections import Counter, deque
from multiprocessing.connection import wait
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the checkout: the entries live in tests/fuzzing.py
from tests.fuzzing import ENTRIES, Entry, Gen, ctx, finite  # noqa: F401 (Entry: to plant entries in tests)

CHUNK = 250  # calls per task handed to a worker
EXAMPLES = 5  # "other" / "nonfinite" / "hang" examples kept per entry point
OUTCOMES = ("ok", "pkm_error", "other", "nonfinite", "hang")
TOTAL_SECONDS = 2700.0  # default bound of the whole run (45 minutes)
BETWEEN_CALLS = 300.0  # a worker silent this long outside a call (making inputs, starting) is killed as hung


# ---------------------------------------------------------------------- classification (in a worker process)
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


def run_chunk(task: tuple, send) -> None:
    """Run the calls ``start..count-1`` of one chunk of an entry point, telling ``send`` about each: ``("start",
    k)`` before call ``k``, ``("done", k, outcome)`` after it, and ``("end", stopped)`` at the end (``stopped``:
    the chunk's ``budget`` of seconds ran out first). The calls before ``start`` are generated again (the inputs
    are one stream a chunk) but not run; ``hung`` (a call that hung in an earlier worker) gets its repro sent,
    ``("hung", k, repro)``."""
    name, seed, chunk_index, count, timeout, start, hung, budget = task
    warnings.simplefilter("ignore")
    signal.signal(signal.SIGALRM, _alarm)
    c = ctx()
    e = next(e for e in ENTRIES if e.name == name)
    rng = np.random.default_rng([seed, zlib.crc32(name.encode()), chunk_index])
    g = Gen(rng)
    PkmError = c.pkm.PkmError
    spent = 0.0
    for k in range(count):
        if k >= start and budget is not None and spent >= budget:
            send(("end", True))
            return
        t0 = time.perf_counter()
        adversarial = (chunk_index * CHUNK + k) % 2 == 1
        try:
            fn, args, kwargs = e.make(g, adversarial)
        except Exception as exc:  # a bug of this harness, not of pkm
            send(("fail", f"generator of {name} failed: {exc!r}"))
            return
        if k < start:
            if k == hung:
                send(("hung", k, _repro(name, fn, args, kwargs)))
            continue
        send(("start", k))
        out = {"verdict": "", "error": None, "documented": False, "error_nan": False, "example": None}
        mark = _capture_mark()
        signal.setitimer(signal.ITIMER_REAL, timeout)
        try:
            try:
                res = fn(*args, **kwargs)
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0)
            if finite(res):
                out["verdict"] = "ok"
            elif e.sentinel is not None and _safe(e.sentinel, res):
                out.update(verdict="ok", documented=True)
            else:
                out.update(verdict="nonfinite", example={"result": repr(res)[:500],
                                                         "repro": _repro(name, fn, args, kwargs)})
        except PkmError as exc:
            out.update(verdict="pkm_error", error=type(exc).__name__)
            out["error_nan"] = any(isinstance(getattr(exc, a, None), float) and math.isnan(getattr(exc, a))
                                   for a in ("residual", "excess", "sigma_min", "deficit"))
        except CallTimeout:
            out.update(verdict="hang", example={"type": "Timeout", "message": f"ran past {timeout} s",
                                                "repro": _repro(name, fn, args, kwargs), "traceback": ""})
        except Exception as exc:
            out.update(verdict="other", error=type(exc).__name__,
                       example={"type": type(exc).__name__, "message": str(exc)[:500],
                                "repro": _repro(name, fn, args, kwargs),
                                "traceback": "".join(traceback.format_exception(exc)[-3:])[-1500:]})
        out["output"] = _captured_since(mark)
        seconds = time.perf_counter() - t0
        spent += seconds
        send(("done", k, out, seconds))
    send(("end", False))


def _safe(check, res) -> bool:
    try:
        return bool(check(res))
    except Exception:
        return False


_CAPTURE: int | None = None  # (in a worker: the descriptor of the file its stdout and stderr go to)
CAPTURE_BYTES = 1 << 20  # the capture file is emptied past this size


def _capture() -> None:
    """This process's stdout and stderr (the descriptors 1 and 2, which C and C++ libraries write to: urdfdom's
    parser messages through Pinocchio, LAPACK's, loggers') to an unlinked temporary file, read after each call."""
    global _CAPTURE
    f = tempfile.TemporaryFile()
    _CAPTURE = os.dup(f.fileno())
    f.close()
    sys.stdout.flush()
    sys.stderr.flush()
    os.dup2(_CAPTURE, 1)
    os.dup2(_CAPTURE, 2)


def _captured_since(mark: int) -> tuple[int, str]:
    """(lines, their text's start) written to the capture since offset ``mark`` (nothing where none is made)."""
    if _CAPTURE is None:
        return 0, ""
    sys.stdout.flush()
    sys.stderr.flush()
    end = os.lseek(_CAPTURE, 0, os.SEEK_END)
    if end <= mark:
        return 0, ""
    text = os.pread(_CAPTURE, min(end - mark, 1 << 16), mark)
    lines = text.count(b"\n") + (not text.endswith(b"\n"))
    if end > CAPTURE_BYTES:
        os.ftruncate(_CAPTURE, 0)
        os.lseek(_CAPTURE, 0, os.SEEK_SET)
    return lines, text[:300].decode("utf-8", "replace")


def _capture_mark() -> int:
    return 0 if _CAPTURE is None else os.lseek(_CAPTURE, 0, os.SEEK_END)


def _serve(conn) -> None:
    """A worker process (its output captured: :func:`_capture`): runs the chunks it is sent until it is sent
    None."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # (Ctrl-C is the parent's to handle)
    _capture()
    while True:
        task = conn.recv()
        if task is None:
            return
        run_chunk(task, conn.send)


# ---------------------------------------------------------------------- the tallies (in this process)
def _tally() -> dict:
    return {"tried": 0, **dict.fromkeys(OUTCOMES, 0), "documented": 0, "error_nan": 0, "seconds": 0.0,
            "by_kind": {"random": Counter(), "adversarial": Counter()}, "errors": Counter(),
            "examples_other": [], "examples_nonfinite": [], "examples_hang": [], "cut": None,
            "output_calls": 0, "output_lines": 0, "output_example": None}


def _count(t: dict, chunk_index: int, k: int, verdict: str, seconds: float, *, error: str | None = None,
           example: dict | None = None, documented: bool = False, error_nan: bool = False,
           output: tuple[int, str] = (0, "")) -> None:
    kind = "adversarial" if (chunk_index * CHUNK + k) % 2 == 1 else "random"
    if output[0]:
        t["output_calls"] += 1
        t["output_lines"] += output[0]
        t["output_example"] = t["output_example"] or output[1]
    t["tried"] += 1
    t[verdict] += 1
    t["by_kind"][kind][verdict] += 1
    t["seconds"] += seconds
    t["documented"] += documented
    t["error_nan"] += error_nan
    if error is not None:
        t["errors"][error] += 1 if verdict == "pkm_error" else 0  # (an other's type: its key, not a PkmError)
    if example is not None:
        key = {"other": "examples_other", "nonfinite": "examples_nonfinite", "hang": "examples_hang"}[verdict]
        if len(t[key]) < EXAMPLES:
            t[key].append(example)


class _Worker:
    """One worker process and the chunk it runs: ``task``, the call in progress (``call``, since ``since``)."""

    def __init__(self, mp):
        self.conn, child = mp.Pipe()
        self.proc = mp.Process(target=_serve, args=(child,), daemon=True)
        self.proc.start()
        child.close()
        self.task: tuple | None = None
        self.call: int | None = None
        self.last = 0.0  # the chunk's last call done (or -1)
        self.since = time.monotonic()

    def give(self, task: tuple) -> None:
        self.task, self.call, self.last, self.since = task, None, task[5] - 1, time.monotonic()
        self.conn.send(task)

    def kill(self) -> None:
        self.proc.kill()
        self.proc.join()
        self.conn.close()

    def stop(self) -> None:
        try:
            self.conn.send(None)
        except OSError:
            pass
        self.proc.join(timeout=5)
        if self.proc.is_alive():
            self.kill()
        self.conn.close()


def run(names: list[str], n: int, *, seed: int = 0, jobs: int = 1, timeout: float = 30.0, grace: float = 5.0,
        entry_seconds: float | None = None, total_seconds: float | None = None, progress: bool = False) -> dict:
    """Fuzz the entry points ``names`` with ``n`` inputs each; the report as a dict (see ``--json``).

    ``timeout``: seconds a call may run before it counts as a hang (its worker killed ``grace`` seconds later
    when it does not give control back); ``entry_seconds`` and ``total_seconds``: the time bounds (see the module
    doc; None: none). ``jobs`` worker processes, forked from this one.
    """
    tasks = deque((nm, seed, k, min(CHUNK, n - k * CHUNK), timeout, 0, -1)
                  for k in range(math.ceil(n / CHUNK)) for nm in names)  # chunk-major: slow entries spread out
    totals = {nm: _tally() for nm in names}
    t0 = time.perf_counter()
    sys.stdout.flush()
    saved_stdout = os.dup(1)
    os.dup2(2, 1)  # what C libraries print (LAPACK's "On entry to DLASCL...") must not mix with --json
    try:
        _run_tasks(tasks, totals, max(1, jobs), progress, len(names) * n, timeout + grace, entry_seconds,
                   total_seconds)
    finally:
        sys.stdout.flush()
        os.dup2(saved_stdout, 1)
        os.close(saved_stdout)
    report = {"n": n, "seed": seed, "jobs": jobs, "timeout": timeout, "entry_seconds": entry_seconds,
              "total_seconds": total_seconds, "wall_seconds": round(time.perf_counter() - t0, 1), "entries": {}}
    return _report_entries(report, names, totals)


def _run_tasks(tasks: deque, totals: dict, jobs: int, progress: bool, calls: int, kill_after: float,
               entry_seconds: float | None, total_seconds: float | None) -> None:
    """Hand the chunks to ``jobs`` workers; count every call; kill a worker whose call outlives ``kill_after``
    and go on with the rest of its chunk in a new one; stop giving an entry (or anything) chunks past its bound
    (the run's: ``total_seconds`` after the workers are started)."""
    bar = None
    if progress:
        try:
            from tqdm import tqdm
            bar = tqdm(total=calls, unit="call", file=sys.stderr, smoothing=0.05)
        except ImportError:  # pragma: no cover
            bar = None
    mp = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else None)
    workers = [_Worker(mp) for _ in range(min(jobs, len(tasks)) or 1)]
    deadline = None if total_seconds is None else time.monotonic() + total_seconds
    open_chunks = Counter(t[0] for t in tasks)  # an entry's chunks not finished (queued, waiting or running)

    def bounds(now: float) -> dict[str, tuple[float, str]]:
        """For each entry not finished, (seconds it may still spend, the bound that says so): its
        ``entry_seconds``, or (none given) its share of the time left: ``(deadline - now) x jobs`` plus what the
        entries not finished have spent, divided equally among them, less what it has spent. The time the cheap
        entries leave unused goes to those still running."""
        unfinished = [nm for nm, k in open_chunks.items() if k]
        if entry_seconds is not None:
            return {nm: (entry_seconds - totals[nm]["seconds"], "entry") for nm in unfinished}
        if deadline is None:
            return dict.fromkeys(unfinished, (math.inf, ""))
        share = (max(0.0, deadline - now) * jobs + sum(totals[nm]["seconds"] for nm in unfinished)) / len(unfinished)
        return {nm: (share - totals[nm]["seconds"], "total") for nm in unfinished}

    def take(left: dict, now: float) -> tuple | None:
        """The first queued chunk whose entry has time left (its budget: that time, within the deadline); the
        chunks of an entry out of time are dropped (cut) when no more time can come to it (its ``entry_seconds``
        spent, or the deadline past), else left queued."""
        over = deadline is not None and now >= deadline
        i = 0
        while i < len(tasks):
            nm, seed, chunk_index, count, timeout, start, hung = tasks[i]
            room, why = (0.0, "total") if over else left[nm]
            if deadline is not None:
                room = min(room, deadline - now)
            if room > 0 or hung >= 0:  # (a hung call's repro is sent even by an entry out of time)
                del tasks[i]
                return nm, seed, chunk_index, count, timeout, start, hung, max(0.0, room) if why else None
            if over or why == "entry":
                del tasks[i]
                totals[nm]["cut"] = totals[nm]["cut"] or why
                open_chunks[nm] -= 1
            else:
                i += 1
        return None

    def replace(w: _Worker, verdict: str, example: dict) -> None:
        """``w``'s call in progress ended as ``verdict``: counted, ``w`` replaced, the rest of its chunk queued."""
        nm, seed, chunk_index, count, timeout = w.task[:5]
        k = w.call if w.call is not None else w.last + 1
        spent = time.monotonic() - w.since
        w.kill()
        if k < count:
            _count(totals[nm], chunk_index, k, verdict, spent, error=example["type"], example=example)
            if bar:
                bar.update(1)
        tasks.appendleft((nm, seed, chunk_index, count, timeout, k + 1, k))  # (k: its repro, from the new one)
        workers[workers.index(w)] = _Worker(mp)

    try:
        while True:
            now = time.monotonic()
            if any(w.task is None for w in workers) and tasks:
                left = bounds(now)
                for w in workers:  # hand out chunks
                    if w.task is None:
                        task = take(left, now)
                        if task is not None:
                            w.give(task)
            busy = [w for w in workers if w.task is not None]
            if not busy:
                if tasks:  # (none could be given: only past the deadline, where take dropped them)
                    for nm in {t[0] for t in tasks}:
                        totals[nm]["cut"] = totals[nm]["cut"] or "total"
                break
            for conn in wait([w.conn for w in busy], timeout=0.25):
                w = next(w for w in busy if w.conn is conn)
                try:
                    msg = conn.recv()
                except (EOFError, OSError):  # the process died (a segfault, the OOM killer)
                    w.proc.join(1)
                    k = w.call if w.call is not None else w.last + 1
                    replace(w, "other", {"type": "WorkerDied", "message": f"the worker process ended in the call "
                                         f"(exit code {w.proc.exitcode})", "repro": "", "traceback": "",
                                         "k": (w.task[2], k)})
                    continue
                nm, chunk_index = w.task[0], w.task[2]
                if msg[0] == "start":
                    w.call, w.since = msg[1], time.monotonic()
                elif msg[0] == "done":
                    _, k, out, seconds = msg
                    _count(totals[nm], chunk_index, k, out["verdict"], seconds, error=out["error"],
                           example=out["example"], documented=out["documented"], error_nan=out["error_nan"],
                           output=out["output"])
                    w.call, w.last, w.since = None, k, time.monotonic()
                    if bar:
                        bar.update(1)
                elif msg[0] == "hung":
                    _, k, repro = msg
                    for ex in totals[nm]["examples_hang"] + totals[nm]["examples_other"]:
                        if ex.get("k") == (chunk_index, k):
                            ex["repro"] = repro
                elif msg[0] == "end":
                    if msg[1]:  # (its budget spent: the rest waits for time to be given, or is cut)
                        tasks.appendleft((nm, w.task[1], chunk_index, w.task[3], w.task[4], w.last + 1, -1))
                    else:
                        open_chunks[nm] -= 1
                    w.task, w.call = None, None
                elif msg[0] == "fail":
                    raise RuntimeError(msg[1])
            now = time.monotonic()
            for w in list(workers):
                if w.task is None:
                    continue
                if w.call is not None and now - w.since > kill_after:
                    replace(w, "hang", {"type": "Hang", "message": f"no answer after {kill_after:g} s: killed",
                                        "repro": "", "traceback": "", "k": (w.task[2], w.call)})
                elif w.call is None and now - w.since > BETWEEN_CALLS:
                    replace(w, "hang", {"type": "Hang", "message": f"silent {BETWEEN_CALLS:g} s between calls: "
                                        "killed", "repro": "", "traceback": "", "k": (w.task[2], w.last + 1)})
    finally:
        for w in workers:
            if w.task is None:
                w.stop()
            else:
                w.kill()
        if bar:
            bar.close()


def _report_entries(report: dict, names: list[str], totals: dict) -> dict:
    for nm in names:
        t = totals[nm]
        report["entries"][nm] = {
            "tried": t["tried"], **{k: t[k] for k in OUTCOMES}, "documented": t["documented"],
            "error_nan": t["error_nan"], "seconds": round(t["seconds"], 2), "cut": t["cut"],
            "output_calls": t["output_calls"], "output_lines": t["output_lines"],
            "output_example": t["output_example"],
            "random": dict(t["by_kind"]["random"]), "adversarial": dict(t["by_kind"]["adversarial"]),
            "errors": dict(t["errors"].most_common()),
            "examples_other": [_public(ex) for ex in t["examples_other"]],
            "examples_nonfinite": t["examples_nonfinite"],
            "examples_hang": [_public(ex) for ex in t["examples_hang"]]}
    report["total"] = {k: sum(e[k] for e in report["entries"].values())
                       for k in ("tried", *OUTCOMES, "documented", "error_nan", "output_calls", "output_lines")}
    report["total"]["cut"] = sum(1 for e in report["entries"].values() if e["cut"])
    return report


def _public(example: dict) -> dict:
    return {k: v for k, v in example.items() if k != "k"}  # (k: which call, to put its repro in)


def table(report: dict) -> str:
    """The human table of a report (``*``: the entry point was stopped by a time bound before its ``n`` calls),
    then the examples of "other", "nonfinite" and "hang"."""
    names = list(report["entries"])
    w = max(len(nm) for nm in names)
    lines = [f"{'entry point':{w}}  {'tried':>8} {'ok':>7} {'PkmError':>8} {'other':>6} {'nonfin':>6} {'hang':>5} "
             f"{'s':>7}"]
    for nm, e in report["entries"].items():
        cut = "*" if e["cut"] else " "
        lines.append(f"{nm:{w}}  {e['tried']:7d}{cut} {e['ok']:7d} {e['pkm_error']:8d} {e['other']:6d} "
                     f"{e['nonfinite']:6d} {e['hang']:5d} {e['seconds']:7.1f}")
    tot = report["total"]
    lines.append(f"{'total':{w}}  {tot['tried']:7d}  {tot['ok']:7d} {tot['pkm_error']:8d} {tot['other']:6d} "
                 f"{tot['nonfinite']:6d} {tot['hang']:5d}   wall {report['wall_seconds']:.0f} s on "
                 f"{report['jobs']} worker(s)")
    if tot["output_lines"]:
        noisy = sorted(((e["output_lines"], nm) for nm, e in report["entries"].items() if e["output_lines"]),
                       reverse=True)
        lines.append(f"{tot['output_lines']} line(s) printed by libraries in {tot['output_calls']} call(s), captured "
                     f"(not shown; --json: output_example): " + ", ".join(f"{nm} {k}" for k, nm in noisy[:8]))
    if tot["cut"]:
        lines.append(f"* {tot['cut']} entry point(s) stopped by a time bound before their {report['n']} calls "
                     f"(--entry-seconds {report['entry_seconds']}, --total-seconds {report['total_seconds']})")
    for nm, e in report["entries"].items():
        for ex in e["examples_other"] + e["examples_nonfinite"] + e["examples_hang"]:
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
    ap.add_argument("--timeout", type=float, default=30.0, help="seconds a call may run before it counts as a hang "
                                                               "(default 30)")
    ap.add_argument("--grace", type=float, default=5.0, help="seconds more before the worker of a call that does "
                                                             "not give control back is killed (default 5)")
    ap.add_argument("--entry-seconds", type=float, help="seconds of calls each entry point may spend (default: "
                                                        "its share of the total, re-divided as entries finish)")
    ap.add_argument("--total-seconds", type=float, default=TOTAL_SECONDS,
                    help=f"seconds the whole run may take (default {TOTAL_SECONDS:g}; 0: no bound)")
    ap.add_argument("--list", action="store_true", help="list the entry points and exit")
    ap.add_argument("--no-progress", action="store_true")
    args = ap.parse_args(argv)
    names = [e.name for e in ENTRIES if not args.only or any(s in e.name for s in args.only)]
    if args.list:
        print("\n".join(names))
        return 0
    if not names or args.n < 1 or args.jobs < 1 or min(args.timeout, args.grace) <= 0:
        print(f"nothing to run (--only {args.only}, --n {args.n}, --jobs {args.jobs}, --timeout {args.timeout}, "
              f"--grace {args.grace})", file=sys.stderr)
        return 2
    report = run(names, args.n, seed=args.seed, jobs=args.jobs, timeout=args.timeout, grace=args.grace,
                 entry_seconds=args.entry_seconds, total_seconds=args.total_seconds or None,
                 progress=not args.no_progress)
    if args.json:
        json.dump(report, sys.stdout, indent=1)
        print()
    else:
        print(table(report))
    return 1 if report["total"]["other"] or report["total"]["nonfinite"] or report["total"]["hang"] else 0


if __name__ == "__main__":
    sys.exit(main())
