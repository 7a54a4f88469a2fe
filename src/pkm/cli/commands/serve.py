"""``pkm serve [--host 127.0.0.1] [--port 8000] [--store DIR] [--workers N] [--queue N] [--compute-limit S]
[--token T]``: pkm as a model and dynamics
service (:mod:`pkm.serve`): its OpenAPI docs at ``/docs``; ``pkm serve --help`` lists its routes (:func:`routes`,
read from the application itself). Binds to this machine only unless ``--host`` says otherwise; stops on Ctrl-C or
SIGTERM once in-flight requests are answered (within a second of the last answer)."""

from __future__ import annotations

import argparse
import gc
import os

from pkm.cli.command import Command
from pkm.cli.usage import late_epilog


def routes() -> list[tuple[str, str, str]]:
    """``(methods, path, summary)`` of every route of the service's application (:func:`pkm.serve.app.create_app`),
    in its order: read from the application, so that the help cannot drift from the service. ``methods`` is ``"WS"``
    for a WebSocket; a mounted folder of static files is one line; the catch-alls that answer an unknown query or
    job kind (404 naming the valid ones) are left out; the summary is the route's own, else its description's first line, else its name.

    Raises:
        MissingDependencyError: pkm-robotics[serve] is not installed.
    """
    from starlette.routing import Mount, WebSocketRoute

    from pkm.serve.app import create_app

    out = []
    for route in create_app().routes:  # (no thread started: the job manager's start with a job)
        if isinstance(route, Mount):  # (static files under a folder: the docs pages' scripts)
            out.append(("GET", f"{route.path}/...", f"{route.name}: static files"))
            continue
        if route.name.startswith("unknown_"):  # (the catch-alls answering an unknown query or job kind with 404)
            continue
        methods = sorted(getattr(route, "methods", None) or ())
        if "GET" in methods and "HEAD" in methods:
            methods.remove("HEAD")  # (starlette answers HEAD for every GET)
        description = (getattr(route, "description", "") or "").strip().splitlines()
        summary = getattr(route, "summary", None) or (description[0] if description else "") \
            or route.name.replace("_", " ")
        out.append(("WS" if isinstance(route, WebSocketRoute) else ",".join(methods), route.path, summary))
    return out


def routes_help() -> str:
    """The end of ``pkm serve --help``: the routes, or how to see them."""
    from pkm.errors import MissingDependencyError

    try:
        rows = routes()
    except MissingDependencyError as exc:
        return f"Routes: {exc}"
    width = max(len(m) for m, _, _ in rows), max(len(p) for _, p, _ in rows)
    return "Routes (method, path, summary; their bodies in the OpenAPI schema):\n" + "\n".join(
        f"  {m.ljust(width[0])}  {p.ljust(width[1])}  {s}" for m, p, s in rows)


def add_arguments(p: argparse.ArgumentParser) -> None:
    late_epilog(p, routes_help)
    p.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1: this machine only)")
    p.add_argument("--port", type=int, default=8000, help="port (default 8000)")
    p.add_argument("--store", metavar="DIR", help="keep uploaded models here across restarts")
    p.add_argument("--workers", type=int, default=2, help="queries computed at once (default 2)")
    p.add_argument("--queue", type=int, default=64, help="queries waiting at most; more get 429 (default 64)")
    p.add_argument("--compute-limit", type=float, default=60.0, metavar="S",
                   help="a query computing longer is answered 503 (default 60 s; jobs have none)")
    p.add_argument("--token", help="require 'Authorization: Bearer TOKEN' (default: $PKM_SERVE_TOKEN, else none)")


def run(args: argparse.Namespace) -> int:
    from pkm.errors import InvalidInputError
    from pkm.serve.app import serve

    if not 1 <= args.workers <= 64 or not 0 <= args.queue <= 10_000 or not 0 < args.port < 65536 \
            or not args.compute_limit > 0:
        raise InvalidInputError("--workers", "workers 1..64, queue 0..10000, port 1..65535, compute limit > 0",
                                (args.workers, args.queue, args.port, args.compute_limit))
    try:  # (Ctrl-C from the first line on: a stop like any other)
        print(f"pkm serve on http://{args.host}:{args.port} (docs: /docs; Ctrl-C stops it)", flush=True)
        serve(args.host, args.port, store=args.store, workers=args.workers, queue=args.queue,
              token=args.token or os.environ.get("PKM_SERVE_TOKEN"), compute_limit=args.compute_limit)
    except KeyboardInterrupt:
        pass
    # Drained and stopped: the process ends now. The interpreter's garbage collections at exit would walk every object
    # the service's imports and models made (measured: 0.44 s of a 0.7-1 s stop on a quiet machine, seconds on a busy
    # one; 0.04 s frozen): frozen, they are left to the exit.
    gc.freeze()
    return 0


COMMAND = Command("the model and dynamics service over HTTP and WebSocket (OpenAPI docs at /docs)", add_arguments, run)
