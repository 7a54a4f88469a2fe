"""``pkm spec init MODEL [--out FILE] [--force]``: a commented closure spec to fill in, for a URDF, MJCF or SDF
file."""

from __future__ import annotations

import argparse

from pkm.cli.command import Command
from pkm.cli.usage import UsageError, debug_option


def add_arguments(p: argparse.ArgumentParser) -> None:
    actions = p.add_subparsers(dest="spec_command", metavar="ACTION", required=True)
    p = actions.add_parser("init", parents=[debug_option()],
                           help="write a commented closure spec for a URDF, MJCF or SDF file")
    p.add_argument("model", metavar="MODEL", help="the model file (.urdf, .xml MJCF, .sdf)")
    p.add_argument("--out", metavar="FILE", help="where to write it (default: MODEL's folder, <stem>.closures.toml)")
    p.add_argument("--force", action="store_true", help="overwrite an existing file")


def run(args: argparse.Namespace) -> int:
    """The action named (``init``, the only one)."""
    return {"init": init}[args.spec_command](args)


def init(args: argparse.Namespace) -> int:
    from pathlib import Path

    from pkm.core.formats.imported import spec_skeleton

    model = Path(args.model)
    out = Path(args.out) if args.out else model.with_name(f"{model.stem}.closures.toml")
    if out.exists() and not args.force:
        raise UsageError(f"{out} exists; pass --force to overwrite it")
    if out.resolve().parent != model.resolve().parent:
        raise UsageError(f"write the spec beside the model ({model.resolve().parent}): its urdf path is relative")
    text, complete = spec_skeleton(model)
    out.write_text(text, encoding="utf-8")
    print(f"wrote {out}" + ("" if complete else ": fill in the lines marked TODO"))
    return 0


COMMAND = Command("closure specs: 'pkm spec init MODEL' writes one to fill in", add_arguments, run)
