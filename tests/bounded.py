"""Subprocesses the tests start, ended when they hang, never because the machine is busy.

A fixed wall-clock timeout fails a correct test on a loaded machine (two example scripts did, at 300 s, with both
cores taken by another suite). :func:`run` bounds the CPU time of the child and of every process it starts (read
from ``/proc``: a child that computes is making progress however slow the machine is), and ends it past ``cpu``
seconds of CPU; a child that uses no CPU at all (a deadlock, a wait on a closed pipe) is ended past ``idle``
seconds without gaining any. Where ``/proc`` cannot be read (not Linux), the bound falls back to a wall-clock
timeout of ``4 * cpu``.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path
from typing import Any

#: How often the child's CPU time is read [s].
POLL = 0.5
#: The clock ticks a second of /proc's utime and stime.
_TICKS = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100


def processes() -> dict[int, tuple[int, float]]:
    """``{pid: (parent pid, CPU seconds of the process and its waited-for children)}`` of every process (/proc)."""
    out = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        # fields[0] is the state (stat's third field): utime, stime, cutime, cstime are stat's 14th to 17th
        out[int(stat.parent.name)] = (int(fields[1]), sum(int(f) for f in fields[11:15]) / _TICKS)
    return out


def children(pid: int) -> list[int]:
    """Processes whose parent is ``pid``."""
    return [c for c, (parent, _) in processes().items() if parent == pid]


def tree_cpu(pid: int) -> float:
    """CPU seconds used by ``pid`` and all its live descendants (and the children they have waited for).

    Raises:
        ProcessLookupError: ``pid`` is gone (reaped).
    """
    stats = processes()
    if pid not in stats:
        raise ProcessLookupError(pid)
    total, frontier = 0.0, [pid]
    while frontier:
        p = frontier.pop()
        if p in stats:
            total += stats[p][1]
        frontier.extend(c for c, (parent, _) in stats.items() if parent == p)
    return total


def run(args: list[str], *, cpu: float, idle: float = 120.0, **kwargs: Any) -> subprocess.CompletedProcess:
    """``subprocess.run(args, capture_output=True, text=True, **kwargs)``, ended (``subprocess.TimeoutExpired``)
    past ``cpu`` seconds of CPU time of its process tree, or past ``idle`` seconds in which the tree used none."""
    if not Path("/proc/self/stat").exists():
        return subprocess.run(args, capture_output=True, text=True, timeout=4 * cpu, check=False, **kwargs)
    kwargs.setdefault("start_new_session", True)  # (its own process group: ended whole, grandchildren too)
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kwargs)
    used, last_change = 0.0, time.monotonic()
    while True:
        try:
            out, err = proc.communicate(timeout=POLL)
            return subprocess.CompletedProcess(args, proc.returncode, out, err)
        except subprocess.TimeoutExpired:
            now_used = tree_cpu(proc.pid)
            if now_used > used:
                used, last_change = now_used, time.monotonic()
            if used > cpu or time.monotonic() - last_change > idle:
                try:
                    os.killpg(proc.pid, signal.SIGKILL) if kwargs["start_new_session"] else proc.kill()
                except ProcessLookupError:
                    pass
                out, err = proc.communicate()
                why = f"{used:.0f} s of CPU (bound {cpu:g} s)" if used > cpu else f"no CPU used in {idle:g} s"
                raise subprocess.TimeoutExpired(args, cpu, output=out, stderr=f"{err}\n[ended: {why}]") from None
