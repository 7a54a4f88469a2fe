"""Malformed requests against a running service: every endpoint with wrong types, shapes and units, huge arrays,
unknown models and queries, broken uploads (bad XML, binary, traversal names, entity bombs), truncated and garbage
bodies (JSON and msgpack), bad and missing tokens, coordinates beyond :data:`pkm.validation.ABSURD`. None may be
answered 500, every answer but a success must be JSON with a message, a query whose positions hold a coordinate beyond
the bound must not succeed (it is refused, never wrapped), the service must still answer afterwards, and its memory
must stay bounded.

``python -m pkm.serve.fuzz [--requests 10000] [--seed 0]`` starts a service of its own on a free port of 127.0.0.1
(loopback only), sends the requests, stops it with SIGTERM and prints the counts; exit status 1 on any failure.
:func:`fuzz` sends them to a service already running (the test suite's).
"""

from __future__ import annotations

import json
import random
import string
import time
from collections import Counter
from typing import Any

MODELS = ("delta", "rrr3", "prs3", "nope", "", "..", "%2e%2e", "a" * 300, "delta%00", "../../etc/passwd")
QUERIES = ("fk", "ik", "jacobians", "diagnose", "velocities", "dynamics", "capability", "scene", "stiffness",
           "clearance", "teleport", "",
           "jobs/map", "jobs/assembly_modes", "jobs/working_modes", "jobs/teleport", "variants")
#: The queries (not the jobs, whose answer is 202 before their input is read).
QUERY_NAMES = ("fk", "ik", "jacobians", "diagnose", "velocities", "dynamics", "capability", "scene", "stiffness",
               "clearance")
#: The fields of a query that hold coordinates (m, rad): a number beyond pkm.validation.ABSURD in one is refused.
POSITIONS = ("qa", "q", "y", "seed")
#: The typed operations' field names (pkm.serve.schemas), an unknown one and an empty one.
KEYS = ("qa", "q", "y", "qd", "qdd", "seed", "kind", "branch", "axes", "fixed", "index", "length", "params", "springs",
        "drives", "wrench", "x", "foo", "")


def _value(rng: random.Random, depth: int = 0) -> Any:
    """A random JSON-able value: numbers of every kind, strings, nested lists and maps, wrong shapes."""
    pick = rng.randrange(13)
    if pick == 0:
        return rng.choice([0, 1, -1, 10**30, -(10**30), 1e308, -1e308, 1e-308, 0.1])
    if pick == 1:
        return "".join(rng.choice(string.printable) for _ in range(rng.randrange(20)))
    if pick == 2:
        return rng.choice(["NaN", "Infinity", "-Infinity", "1e999", "3 deg", "5cm", None, True, False, "wrench",
                           "power", "10deg", "1e999deg", "5 kg"])
    if pick == 11 and depth < 2:  # (one sample or a batch with unit strings, of every kind and none)
        units = ["10deg", "-5mm", "0.3rad", "2cm", "1m", "3kg", "7", "deg", "1e400mm", "-0.1"]
        row = [rng.choice(units) if rng.random() < 0.5 else rng.uniform(-1, 1) for _ in range(rng.choice([2, 3, 12]))]
        return row if rng.random() < 0.5 else [row] * rng.choice([1, 2, 5])
    if pick in (3, 4, 5):
        row = [rng.uniform(-3, 3) for _ in range(rng.choice([0, 1, 2, 3, 4, 15, 16, 100]))]
        if row and pick == 5:  # (a coordinate beyond the bound: 1e308 rad was once wrapped and answered 200)
            row[rng.randrange(len(row))] = rng.choice([1e308, -1e308, 1e7, -2e6])
        return row
    if pick in (6, 7):
        n = rng.choice([1, 2, 3, 5])
        return [[rng.uniform(-3, 3) for _ in range(rng.choice([2, 3, 15]))] for _ in range(n)]
    if pick == 8 and depth < 3:
        return [_value(rng, depth + 1) for _ in range(rng.randrange(4))]
    if pick == 9 and depth < 3:
        return {rng.choice(KEYS): _value(rng, depth + 1) for _ in range(rng.randrange(4))}
    if pick == 10:
        return [[[rng.random()]]] * rng.randrange(1, 4)
    return [rng.random()] * rng.choice([3, 50_000])


def _absurd(value: Any) -> bool:
    """Whether ``value`` (a field of a body) holds a finite number beyond :data:`pkm.validation.ABSURD`."""
    from pkm.validation import ABSURD

    if isinstance(value, (list, tuple)):
        return any(_absurd(v) for v in value)
    return isinstance(value, (int, float)) and not isinstance(value, bool) and ABSURD < abs(value) < float("inf")


def _body(rng: random.Random) -> tuple[bytes, dict[str, str]]:
    """A request body and its headers: JSON (sometimes truncated or not an object), msgpack (sometimes garbage or a
    malformed array extension), or raw bytes; :data:`_SENT` keeps the last one's payload."""
    import msgpack  # type: ignore[import-untyped]

    kind = rng.randrange(10)
    payload = {rng.choice(KEYS): _value(rng) for _ in range(rng.randrange(1, 4))}
    _SENT[0] = payload if kind < 7 and kind != 4 else None  # (as sent whole: JSON or msgpack)
    if kind < 5:
        text = json.dumps(payload).encode()
        if kind == 4:
            text = text[: rng.randrange(max(1, len(text)))]
        return text, {"content-type": "application/json"}
    if kind < 7:
        try:
            return msgpack.packb(payload), {"content-type": "application/msgpack"}
        except OverflowError:  # (an integer msgpack cannot hold: sent as JSON)
            return json.dumps(payload).encode(), {"content-type": "application/json"}
    if kind == 7:
        bad = msgpack.ExtType(1, msgpack.packb(["<f8", [rng.randrange(-3, 10**6), 3], b"\x00" * rng.randrange(64)]))
        return msgpack.packb({"qa": bad}), {"content-type": "application/msgpack"}
    if kind == 8:
        return bytes(rng.randrange(256) for _ in range(rng.randrange(64))), {"content-type": "application/msgpack"}
    return json.dumps(rng.choice([[1, 2, 3], "qa", 3, None])).encode(), {"content-type": "application/json"}


_SENT: list[dict[str, Any] | None] = [None]

_BOMB = (b"<?xml version='1.0'?><!DOCTYPE l [<!ENTITY a 'aaaaaaaaaa'><!ENTITY b '&a;&a;&a;&a;&a;&a;&a;&a;'>"
         b"<!ENTITY c '&b;&b;&b;&b;&b;&b;&b;&b;'><!ENTITY d '&c;&c;&c;&c;&c;&c;&c;&c;'>]><robot name='&d;'/>")


def _upload(rng: random.Random) -> list[tuple[str, tuple[str, bytes]]]:
    names = ["robot.urdf", "x.closures.toml", "m.xml", "r.yaml", "../up.urdf", "a/b.urdf", "", ".", "z" * 300,
             "model.sdf"]
    contents = [_BOMB, b"<robot name='r'><link name='a'/></robot>", b'format = "pkm.closures/1"\nurdf = "robot.urdf"\n',
                b"\xff\xfe\x00\x01", b"<mujoco><worldbody><body><joint/></body></worldbody></mujoco>", b"",
                b"not: [yaml", b"<sdf version='1.7'><model name='m'/></sdf>", b"<" * 1000]
    return [("files", (rng.choice(names), rng.choice(contents))) for _ in range(rng.randrange(0, 4))]


def _lying_length(url: str, path: str, headers: dict[str, str]) -> int:
    """The status answered to a request whose body is shorter than its Content-Length (0: none)."""
    import socket
    from urllib.parse import urlsplit

    parts = urlsplit(url)
    lines = [f"POST {path} HTTP/1.1", f"Host: {parts.hostname}", "Content-Type: application/json",
             "Content-Length: 999999999", "Connection: close", *(f"{k}: {v}" for k, v in headers.items())]
    with socket.create_connection((parts.hostname, parts.port), timeout=30) as s:
        s.sendall(("\r\n".join(lines) + "\r\n\r\n").encode() + b'{"qa": [1, 2')
        s.shutdown(socket.SHUT_WR)
        answer = b""
        while chunk := s.recv(65536):
            answer += chunk
    head = answer.split(b"\r\n", 1)[0].split()
    return int(head[1]) if len(head) > 1 and head[1].isdigit() else 0


def fuzz(url: str, n: int, *, token: str | None = None, seed: int = 0) -> dict[str, Any]:
    """Send ``n`` malformed requests to the service at ``url``; returns the counts by status, the failures (a 500, an
    answer that is not JSON with a message, a dropped connection) and whether the service still answers."""
    from pkm._optional import require

    require("serve", "the service's fuzz")
    import httpx

    rng = random.Random(seed)
    good = {"authorization": f"Bearer {token}"} if token else {}
    statuses: Counter = Counter()
    failures: list[str] = []
    with httpx.Client(base_url=url, timeout=60) as c:
        for k in range(n):
            auth = good if rng.random() < 0.9 else rng.choice([{}, {"authorization": "Bearer wrong"},
                                                              {"authorization": "Basic abc"}])
            model, query = rng.choice(MODELS), rng.choice(QUERIES)
            what = rng.randrange(10)
            try:
                if what < 6 and rng.random() < 0.1:  # (a shipped model's well-formed fk or ik, one coordinate
                    row = [rng.uniform(-0.5, 0.5) for _ in range(3)]  # beyond the bound: refused, never wrapped)
                    row[rng.randrange(3)] = rng.choice([1e308, -1e308, 1e7, -2e6])
                    model, query = rng.choice(("delta", "rrr3", "prs3")), rng.choice(("fk", "ik"))
                    _SENT[0] = {"qa" if query == "fk" else "y": row}
                    body, headers = json.dumps(_SENT[0]).encode(), {"content-type": "application/json"}
                    r = c.post(f"/models/{model}/{query}", content=body, headers={**auth, **headers})
                elif what < 6:
                    body, headers = _body(rng)
                    r = c.post(f"/models/{model}/{query}", content=body, headers={**auth, **headers})
                elif what == 6:
                    r = c.post("/models", files=_upload(rng) or None, headers=auth)
                elif what == 7:
                    r = c.request(rng.choice(["GET", "DELETE", "PUT", "PATCH"]),
                                  rng.choice([f"/models/{model}", f"/models/{model}/files", f"/models/{model}/preview",
                                              f"/models/{model}/{query}", "/nothing", "/models"]), headers=auth)
                elif what == 8:
                    r = c.post(f"/models/{model}/{query}", content=b"x" * rng.choice([10, 2**21]),
                               headers={**auth, "content-type": "application/json"})
                else:  # (a body shorter than its Content-Length says, then the connection half-closed: raw)
                    status = _lying_length(url, f"/models/{model}/{query}", auth)
                    statuses[status] += 1
                    if status >= 500 or status == 0:
                        failures.append(f"request {k}: a truncated body got {status or 'no answer'}")
                    continue
            except httpx.HTTPError as e:
                failures.append(f"request {k}: {type(e).__name__}: {e}")
                continue
            statuses[r.status_code] += 1
            sent = _SENT[0] if what < 6 else None
            _SENT[0] = None
            if r.status_code < 300 and sent is not None and query in QUERY_NAMES and \
                    any(_absurd(sent.get(key)) for key in POSITIONS):
                failures.append(f"request {k}: {query} answered {r.status_code} to a coordinate beyond the bound: "
                                f"{json.dumps(sent)[:200]}")
            if r.status_code >= 500:
                failures.append(f"request {k}: {r.status_code} {r.text[:200]}")
            elif r.status_code >= 400:
                try:
                    ok = bool(r.json().get("message"))
                except ValueError:
                    ok = False
                if not ok:
                    failures.append(f"request {k}: {r.status_code} without a JSON message: {r.text[:120]}")
        alive = c.get("/health").status_code == 200
    return {"requests": n, "statuses": dict(sorted(statuses.items())), "failures": failures, "alive": alive}


def main(argv: list[str] | None = None) -> int:
    import argparse

    from pkm.serve.process import rss_mb, start

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--requests", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    token = "fuzz-token"
    proc, url = start("--token", token)
    try:
        rss0 = rss_mb(proc.pid)
        t0 = time.perf_counter()
        out = fuzz(url, args.requests, token=token, seed=args.seed)
        wall = time.perf_counter() - t0
        rss1 = rss_mb(proc.pid)
    finally:
        proc.terminate()
        code = proc.wait(timeout=60)
    print(f"fuzz: {out['requests']} malformed requests in {wall:.0f} s, answers {out['statuses']}; memory "
          f"{rss0:.0f} -> {rss1:.0f} MB; still answering: {out['alive']}; stopped with status {code}")
    for line in out["failures"][:20]:
        print("  FAILED", line)
    bounded = rss1 < rss0 + 300
    return 0 if not out["failures"] and out["alive"] and bounded and code == 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
