"""A ``pkm serve`` of its own, as a process on a free port of 127.0.0.1 (loopback only): for benchmarks, the fuzz and
tests that need the real command (its signals, its memory)."""

from __future__ import annotations

import socket
import subprocess
import sys
import time


def free_port() -> int:
    """A port of 127.0.0.1 free now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def start(*options: str, timeout: float = 60.0) -> tuple[subprocess.Popen, str]:
    """``python -m pkm serve --port P OPTIONS...`` started and answering ``/health``; returns the process and its URL.
    Its standard output is piped (the first line says where it listens), its errors are discarded.

    Raises:
        MissingDependencyError: pkm-robotics[serve] is not installed.
        RuntimeError: it did not answer within ``timeout`` seconds (it is killed).
    """
    from pkm._optional import require

    require("serve", "pkm serve")
    import httpx

    port = free_port()
    proc = subprocess.Popen([sys.executable, "-m", "pkm", "serve", "--port", str(port), *options],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + timeout
    with httpx.Client() as http:  # (one client: each of its own loads the CA certificates, 0.1 s of CPU a poll)
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                if http.get(url + "/health").status_code == 200:
                    return proc, url
            except httpx.TransportError:
                time.sleep(0.05)
    proc.kill()
    raise RuntimeError(f"pkm serve did not answer on {url} within {timeout} s")


def rss_mb(pid: int) -> float:
    """The resident memory of process ``pid`` [MB] (Linux's ``/proc/<pid>/status``; NaN elsewhere)."""
    try:
        with open(f"/proc/{pid}/status") as fh:
            for line in fh:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return float("nan")


__all__ = ["free_port", "rss_mb", "start"]
