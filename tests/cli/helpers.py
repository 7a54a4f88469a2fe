"""Running the ``pkm`` command line in a subprocess, and what the tests read of it."""

from __future__ import annotations

import signal
import socket
import subprocess
import sys
from pathlib import Path

from tests import bounded


def run(*args: str, cwd: Path | None = None, cpu: float = 120) -> subprocess.CompletedProcess:
    """``python -m pkm ARGS`` in a subprocess (text output, no check), ended past ``cpu`` seconds of CPU time (a
    hang; :mod:`tests.bounded`: never because the machine is busy)."""
    return bounded.run([sys.executable, "-m", "pkm", *args], cwd=cwd, cpu=cpu)


def one_error_line(proc: subprocess.CompletedProcess) -> str:
    """The single ``pkm: error: ...`` line a failing command prints (asserted: nothing else, no traceback)."""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("pkm: error: "), proc.stderr
    assert proc.stdout == ""
    return lines[0]


def port_is_free(port: int) -> bool:
    with socket.socket() as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


def default_sigint() -> None:
    """In the child: Ctrl-C as in a terminal's foreground (a suite run from a background job ignores SIGINT, and
    Python keeps an ignored SIGINT ignored)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def start_live_preview(*args: str) -> tuple[subprocess.Popen, str]:
    """``python -m pkm preview ARGS`` (live viewer, waiting) started; returns it once it printed its URL."""
    proc = subprocess.Popen([sys.executable, "-m", "pkm", "preview", *args], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, preexec_fn=default_sigint)
    line = proc.stdout.readline()
    assert line.startswith("viewer: http://"), (line, proc.stderr.read() if proc.poll() is not None else "")
    return proc, line.split()[1]
