"""``pkm serve``: its help lists the service's routes, read from the application; Ctrl-C (SIGINT) stops it within a
second, the request in flight answered first and an idle keep-alive connection not waited for."""

from __future__ import annotations

import os
import signal
import threading
import time

import pytest

from pkm import cli
from tests import http
from tests.bounded import tree_cpu

pytest.importorskip("fastapi")
pytest.importorskip("uvicorn")


def test_the_help_lists_the_routes_of_the_application(capsys):
    """``pkm serve --help`` ends with one line per route of :func:`pkm.serve.app.create_app`, in its order: its
    methods (WS for a WebSocket), its path and its summary where it has one."""
    from pkm.serve.app import create_app

    assert cli.main(["serve", "--help"]) == 0
    rows = [line.split(None, 2) for line in capsys.readouterr().out.split("\nRoutes (")[1].splitlines()[1:]]
    from starlette.routing import Mount

    app = create_app()
    listed = [route for route in app.routes if not route.name.startswith("unknown_")]
    assert len(listed) < len(app.routes)  # (the 404 catch-alls of an unknown query or job kind: not listed)
    assert [r[1] for r in rows] == [route.path + ("/..." if isinstance(route, Mount) else "") for route in listed]
    for row, route in zip(rows, listed):
        methods = {"GET"} if isinstance(route, Mount) else set(getattr(route, "methods", None) or {"WS"})
        assert row[0] == ",".join(sorted(methods - {"HEAD"})), row
        if getattr(route, "summary", None):
            assert row[2] == route.summary
    paths = [r[:2] for r in rows]
    assert ["GET", "/health"] in paths and ["WS", "/models/{model}/stream"] in paths and ["POST", "/models/{model}/fk"] \
        in paths and ["GET", "/docs"] in paths


def test_ctrl_c_stops_the_service_promptly_once_the_request_in_flight_is_answered():
    """SIGINT while a query of about half a second runs (FK of 4,000 samples, its kernels compiled by a first
    query; signalled once the service has computed 0.1 s on it), another client's keep-alive connection open and idle: the query is answered 200, then the process exits
    0 having used under 0.5 s of processor time after the answer (before: 0.7-1.2 s of wall time on a quiet
    machine, 3-5 s on a busy one, the interpreter's last garbage collections at exit walking everything the
    service's imports made). Processor time, not a clock: a busy machine slows the exit, not its work."""
    import httpx
    import numpy as np

    from pkm.serve.process import start

    proc, url = start()
    try:
        idle = httpx.Client()
        assert idle.post(url + "/models/delta/fk", json={"qa": [0.0, 0.0, 0.0]}, timeout=60).status_code == 200
        qa = (0.1 * np.sin(np.linspace(0, 6, 4000))[:, None] + np.zeros(3)).tolist()
        answer: dict = {}

        def query() -> None:
            r = http.post(url + "/models/delta/fk", json={"qa": qa}, timeout=120)
            answer["status"], answer["at"] = r.status_code, time.monotonic()
            try:
                answer["cpu"] = tree_cpu(proc.pid)
            except ProcessLookupError:  # (already gone: it used none after)
                answer["cpu"] = None

        before = tree_cpu(proc.pid)
        t = threading.Thread(target=query)
        t.start()
        deadline = time.monotonic() + 120  # (a hang's bound)
        while tree_cpu(proc.pid) < before + 0.1 and time.monotonic() < deadline:  # (the service is at it)
            time.sleep(0.01)
        signalled = time.monotonic()
        proc.send_signal(signal.SIGINT)
        _, status, usage = os.wait4(proc.pid, 0)  # (its processor time at exit, with the exit status)
        proc.returncode = os.waitstatus_to_exitcode(status)
        t.join(timeout=120)
        idle.close()
        assert proc.returncode == 0
        assert answer["status"] == 200 and answer["at"] > signalled  # (in flight when signalled, then answered)
        after = usage.ru_utime + usage.ru_stime - answer["cpu"] if answer["cpu"] is not None else 0.0
        assert after < 0.5, f"{after:.2f} s of processor time spent exiting after the answer"
    finally:
        proc.kill()
