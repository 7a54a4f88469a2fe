"""``pkm serve`` under load, on the loopback only, bounded in count and time.

A service is started as its own process (``python -m pkm serve`` on a free port of 127.0.0.1); then:

* **load**: ``--clients`` concurrent clients (asyncio, one ``httpx.AsyncClient`` each) send, for ``--duration``
  seconds, single-sample requests in turn: the Delta's FK, IK and inverse dynamics (JSON). Reported: requests,
  throughput, p50 and p99 latency, errors (any answer but 200), and the service's resident memory at the start and
  the end (``/proc/<pid>/status``);
* **batch**: one FK request of ``--batch`` samples against the same samples solved in this process by
  :func:`pkm.close_loops` (each from the previous solution, as the service does): samples per second both ways;
* **stream**: ``--stream`` samples through the WebSocket (FK, task rates and efforts per sample): samples per second
  (the issue's goal: at least 1,000 for the Delta).

Usage: ``python -m pkm.bench.serve [--json] [--quick] [--clients 32] [--duration 60] [--batch 2000] [--stream 2000]``.
"""

from __future__ import annotations

import asyncio
import time
from typing import Any

import numpy as np

QUICK = {"clients": 2, "duration": 0.2, "batch": 50, "stream": 50}
MECHANISM = "delta"


def add_arguments(ap) -> None:
    ap.add_argument("--clients", type=int, default=32, help="concurrent clients (default 32)")
    ap.add_argument("--duration", type=float, default=60.0, help="seconds of load (default 60)")
    ap.add_argument("--batch", type=int, default=2000, help="samples of the batch request (default 2000)")
    ap.add_argument("--stream", type=int, default=2000, help="samples through the WebSocket (default 2000)")


async def _load(url: str, clients: int, duration: float, bodies: list[tuple[str, dict]]) -> dict[str, Any]:
    import httpx

    latencies: list[float] = []
    errors = 0
    stop = time.monotonic() + duration

    async def client(k: int) -> None:
        nonlocal errors
        async with httpx.AsyncClient(base_url=url, timeout=60) as c:
            i = k
            while True:  # (at least one request a client: a busy machine can spend the duration connecting)
                path, body = bodies[i % len(bodies)]
                t0 = time.perf_counter()
                r = await c.post(path, json=body)
                latencies.append(time.perf_counter() - t0)
                errors += r.status_code != 200
                i += 1
                if time.monotonic() >= stop:
                    break

    t0 = time.perf_counter()
    await asyncio.gather(*(client(k) for k in range(clients)))
    wall = time.perf_counter() - t0
    lat = np.array(latencies) * 1e3
    return {"requests": len(lat), "throughput_per_s": len(lat) / wall, "p50_ms": float(np.percentile(lat, 50)),
            "p99_ms": float(np.percentile(lat, 99)), "errors": errors, "wall_s": wall}


def run(args) -> dict[str, Any]:
    from pkm._optional import missing

    if missing("serve"):
        return {"skipped": f"pip install \"pkm-robotics[serve]\" (missing: {', '.join(missing('serve'))})"}
    import pkm
    from pkm.client import Client
    from pkm.serve.process import rss_mb, start

    mech = pkm.load(MECHANISM)
    qa0 = mech.actuated_q(mech.q_reference)
    q = pkm.close_loops(mech, qa0 + 0.05, mech.q_reference).q
    y = pkm.TaskMap.of(mech).value(q).tolist()
    bodies = [(f"/models/{MECHANISM}/fk", {"qa": (qa0 + 0.05).tolist()}),
              (f"/models/{MECHANISM}/ik", {"y": y}),
              (f"/models/{MECHANISM}/dynamics", {"q": q.tolist(), "qd": [0.1, 0.0, 0.0], "qdd": [1.0, 0.0, 0.0]})]
    proc, url = start("--queue", "1024")
    try:
        with Client(url) as c:  # (warm: the model built, the stream's kernels compiled)
            for path, body in bodies:
                c._answer(c._http.post(path, json=body))
            with c.stream(MECHANISM) as s:
                s.send(qa=qa0)
        rss0 = rss_mb(proc.pid)
        load = asyncio.run(_load(url, args.clients, args.duration, bodies))
        rss1 = rss_mb(proc.pid)
        n = max(1, args.batch)
        path_qa = qa0 + 0.1 * np.sin(np.linspace(0.0, 6.0, n))[:, None] * np.array([1.0, -0.5, 0.3])
        with Client(url) as c:
            t0 = time.perf_counter()
            served = c.fk(MECHANISM, path_qa)
            batch_s = time.perf_counter() - t0
            m = max(1, args.stream)
            with c.stream(MECHANISM) as s:
                t0 = time.perf_counter()
                for k in range(m):
                    s.send(qa=path_qa[k % n], qd=[0.1, 0.0, 0.0], qdd=[1.0, 0.0, 0.0])
                stream_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        previous, local = mech.q_reference, []
        for a in path_qa:
            previous = pkm.close_loops(mech, a, previous).q
            local.append(previous)
        library_s = time.perf_counter() - t0
        agree = float(np.abs(np.array(local) - served["q"]).max())
    finally:
        proc.terminate()
        code = proc.wait(timeout=60)
    return {"mechanism": MECHANISM, "clients": args.clients, "duration_s": args.duration, **load,
            "rss_start_mb": rss0, "rss_end_mb": rss1, "batch_samples": n,
            "batch_samples_per_s": n / batch_s, "library_samples_per_s": n / library_s,
            "batch_over_library": library_s / batch_s, "batch_max_difference": agree,
            "stream_samples": m, "stream_samples_per_s": m / stream_s, "exit_code": code}


def table(r: dict[str, Any]) -> str:
    if "skipped" in r:
        return f"pkm serve under load: skipped ({r['skipped']})"
    return "\n".join([
        f"pkm serve under load ({r['mechanism']}, loopback; the service on its own process):",
        f"  {r['clients']} clients for {r['duration_s']:g} s of FK / IK / inverse dynamics: {r['requests']} requests, "
        f"{r['throughput_per_s']:.0f}/s, p50 {r['p50_ms']:.2f} ms, p99 {r['p99_ms']:.2f} ms, {r['errors']} errors",
        f"  memory {r['rss_start_mb']:.0f} MB at the start, {r['rss_end_mb']:.0f} MB at the end",
        f"  a batch of {r['batch_samples']} FK samples: {r['batch_samples_per_s']:.0f} samples/s through the service, "
        f"{r['library_samples_per_s']:.0f} in process ({r['batch_over_library']:.2f}x); largest difference "
        f"{r['batch_max_difference']:.1e}",
        f"  the WebSocket stream (FK, rates, efforts): {r['stream_samples_per_s']:.0f} samples/s",
        f"  stopped by SIGTERM: exit status {r['exit_code']}"])


if __name__ == "__main__":
    from pkm.bench import main

    raise SystemExit(main("serve"))
