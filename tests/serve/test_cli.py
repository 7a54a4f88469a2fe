"""``pkm serve`` as a process: it binds to 127.0.0.1, answers, and on SIGTERM finishes the request in flight before
it exits (status 0)."""

from __future__ import annotations

import signal
import threading
import time

import numpy as np

import pkm
from pkm.serve.process import start
from tests import http
from tests.bounded import tree_cpu


def test_sigterm_drains_the_request_in_flight():
    proc, url = start()
    try:
        assert url in proc.stdout.readline()
        delta = pkm.load("delta")
        qa = delta.actuated_q(delta.q_reference) + 0.1 * np.sin(np.linspace(0, 6, 4000))[:, None]
        answer = {}

        def slow() -> None:  # (4,000 samples: about a second of work)
            answer["r"] = http.post(url + "/models/delta/fk", json={"qa": qa.tolist()}, timeout=120)

        before = tree_cpu(proc.pid)
        t = threading.Thread(target=slow)
        t.start()
        deadline = time.monotonic() + 120  # (a hang's bound: the wait is on the service's CPU time, not a clock)
        while tree_cpu(proc.pid) < before + 0.1 and time.monotonic() < deadline:  # (the request is in flight)
            time.sleep(0.01)
        proc.send_signal(signal.SIGTERM)
        t.join(timeout=120)
        assert answer["r"].status_code == 200 and answer["r"].json()["status"] == ["ok"] * 4000
        assert proc.wait(timeout=60) == 0
    finally:
        proc.kill()
