"""``pkm convert IN OUT [--to FORMAT] [--force] [--json]``: a mechanism read from anything ``pkm.load`` takes,
written in the format OUT's suffix names (or ``--to``: one of :data:`~pkm.core.formats.writers.WRITERS`, each
listed with its suffixes in the help; OUT without a suffix is then a folder): :mod:`pkm.core.formats.writers`. It prints every file written, what the reader noted while reading IN, and
what the target format cannot hold (left out, or kept as comments); a mechanism the format cannot express is one
error line naming what."""

from __future__ import annotations

import argparse
import json
from typing import Any

from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, load_mechanism
from pkm.cli.usage import UsageError

#: The formats and their suffixes as the help says them: :data:`pkm.core.formats.writers.WRITERS` (not imported here:
#: ``pkm --help`` imports no model code; tests/cli/test_convert.py keeps the two the same).
FORMATS = {"pkm": ".closures.toml/.toml (pkm's closure spec + URDF)", "mjcf": ".xml/.mjcf (MuJoCo's MJCF)",
           "gepetto": ".yaml/.yml (Gepetto's URDF + YAML)", "urdfplus": ".urdf (MIT's URDF+)",
           "sdf": ".sdf (SDFormat + pkm's closure spec)",
           "usd": ".usda/.usd/.usdc (USD: UsdPhysics, loops as joints excluded from the articulation)"}


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_arguments(p, None, None)
    p.add_argument("out", metavar="OUT", help=f"the file to write: {'; '.join(FORMATS.values())}; with --to, a "
                                              "folder too")
    p.add_argument("--to", metavar="FORMAT", help=f"the format ({', '.join(FORMATS)}), when OUT's suffix does not say")
    p.add_argument("--force", action="store_true", help="overwrite existing files")
    p.add_argument("--json", action="store_true", help="print JSON")


def run(args: argparse.Namespace) -> int:
    from pkm.core.formats.writers import destination, write

    mech = load_mechanism(args)
    _, files = destination(mech, args.out, args.to)
    existing = [str(f) for f in files if f.exists()]
    if existing and not args.force:
        raise UsageError(f"{', '.join(existing)} exist{'s' if len(existing) == 1 else ''}; pass --force to overwrite")
    written = write(mech, args.out, args.to)
    out: dict[str, Any] = {"mechanism": mech.name, "format": written.format,
                           "files": [str(f) for f in written.files], "read_notes": list(mech.notes),
                           "dropped": list(written.dropped)}
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    print(f"{mech.name}: written as {written.format}")
    for f in written.files:
        print(f"  wrote {f}")
    for note in mech.notes:
        print(f"  read: {note}")
    for d in written.dropped:
        print(f"  not expressible in {written.format}, left out: {d}")
    return 0


COMMAND = Command("a mechanism written in another format: pkm's spec, MJCF, Gepetto's URDF + YAML", add_arguments,
                  run)
