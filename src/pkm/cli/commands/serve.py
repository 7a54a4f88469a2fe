"""``pkm serve [--host 127.0.0.1] [--port 8000] [--store DIR] [--workers N] [--queue N] [--compute-limit S]
[--token T]``: pkm as a model and dynamics
service (:mod:`pkm.serve`): its OpenAPI docs at ``/docs``. Binds to this machine only unless ``--host`` says
otherwise; stops on Ctrl-C or SIGTERM once in-flight requests are answered."""

from __future__ import annotations

import argparse
import os

from pkm.cli.command import Command


def add_arguments(p: argparse.ArgumentParser) -> None:
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
    return 0


COMMAND = Command("the model and dynamics service over HTTP and WebSocket (OpenAPI docs at /docs)", add_arguments, run)
