"""``pkm preview MECH [--pose ... | --joints ...] [--html FILE] [--no-wait] [--no-collisions]``: a configuration in
the live meshcat viewer (until Ctrl-C, SIGTERM or SIGHUP, which stop its server too) or as a self-contained HTML page;
a mechanism with collision geometry is shown with the bodies that interpenetrate in red and the witness points marked
(:mod:`pkm.viz.interference`; ``--no-collisions``: not)."""

from __future__ import annotations

import argparse
import signal
import sys
import time

from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, configuration, load_mechanism


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, "optional", "optional")
    p.add_argument("--html", metavar="FILE", help="write a self-contained HTML scene instead of opening the viewer")
    p.add_argument("--no-wait", action="store_true", help="return once the viewer is up instead of waiting for Ctrl-C")
    p.add_argument("--no-collisions", action="store_true",
                   help="leave out the interference marks of a mechanism with collision geometry")


def run(args: argparse.Namespace) -> int:
    mech = load_mechanism(args)
    q = configuration(mech, args)
    from pkm import viz

    if args.html:
        path = viz.write_html(args.html, mech, q, collisions=not args.no_collisions)
        print(f"wrote {path}")
        return 0
    vis = viz.show(mech, q, collisions=not args.no_collisions)
    if args.no_wait:
        print(f"viewer: {vis.url()}", flush=True)
        return 0  # the server stops with this process (meshcat's atexit hook)

    def stop(signum, frame):
        raise KeyboardInterrupt

    previous = {s: signal.signal(s, stop) for s in (signal.SIGTERM, signal.SIGHUP)}
    try:
        print(f"viewer: {vis.url()}", flush=True)
        print("press Ctrl-C to quit", file=sys.stderr, flush=True)
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        return 0
    finally:  # SIGTERM, SIGHUP or Ctrl-C: the meshcat server goes too, and frees its ports
        viz.close(vis)
        for s, handler in previous.items():
            signal.signal(s, handler)


COMMAND = Command("show a configuration in the meshcat viewer or as HTML", add_arguments, run)
