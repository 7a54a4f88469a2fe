"""``pkm export c MECH --out DIR [--name NAME] [--check] [--json]``: the mechanism's kinematics and dynamics as a
self-contained C99 library (:func:`pkm.export_c`): ``<name>.h``, ``<name>.c``, a ``Makefile``, a
``CMakeLists.txt``, an example ``main.c`` and a ``README.md`` (how to get a first solution). ``--check`` builds it
with ``cc -std=c99 -Wall -Wextra -Werror -pedantic``, checks that it references no allocation or I/O, compares every function with pkm at four closed
configurations and proves each named mode id of the header on a configuration in its mode
(:mod:`pkm.core.export.harness`)."""

from __future__ import annotations

import argparse
import json
from typing import Any

from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_arguments, load_mechanism


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("language", choices=("c",), help="the language (C99)")
    add_mechanism_arguments(p, None, None)
    p.add_argument("--out", metavar="DIR", required=True, help="the folder to write (created)")
    p.add_argument("--name", help="the C prefix (default: the mechanism's name)")
    p.add_argument("--check", action="store_true",
                   help="build it strictly with cc, compare every function with pkm, prove the named mode ids")
    p.add_argument("--json", action="store_true", help="print JSON")


def run(args: argparse.Namespace) -> int:
    from pkm.core.export import export_c
    from pkm.report import jsonable

    mech = load_mechanism(args)
    lib = export_c(mech, args.out, name=args.name)
    out: dict[str, Any] = {"mechanism": mech.name, "name": lib.name, "files": [str(f) for f in lib.files],
                           "sizes": lib.sizes, "operations": lib.operations, "modes": lib.blocks,
                           "limits": list(lib.limits), "idle": list(lib.idle), "mode_ids": lib.modes}
    if args.check:
        from pkm.core.export.harness import build, check_modes, compare

        h = build(lib, "cc")
        errors = compare(mech, h)
        out["check"] = {"undefined_symbols": sorted(h.symbols), "largest_difference": errors,
                        "mode_ids": check_modes(mech, h)}
    if args.json:
        print(json.dumps(jsonable(out), indent=2))
        return 0
    print(f"{mech.name}: C library {lib.name} in {lib.directory} ({', '.join(f.name for f in lib.files)})")
    for k, (mul, add, other) in lib.operations.items():
        print(f"  {k:18s} {mul:6d} mul {add:6d} add {other:5d} functions")
    print("  named mode ids: " + ", ".join(f"{lib.name.upper()}_{kind.upper()}_MODE_{key} = {ident}"
                                          for kind, named in lib.modes.items() for key, ident in named.items()))
    if args.check:
        worst = {k: v for k, v in out["check"]["largest_difference"].items() if k != "status"}
        print(f"  built with {' '.join(('cc', '-std=c99', '-Wall', '-Wextra', '-Werror', '-pedantic'))}: uses "
              f"{', '.join(out['check']['undefined_symbols']) or 'nothing'}; largest difference to pkm "
              f"{max(worst.values()):.2e} ({max(worst, key=lambda k: worst[k])}), "
              f"{int(out['check']['largest_difference']['status'])} calls not OK; named mode ids "
              + ("each the id the C returns in its mode" if not out["check"]["mode_ids"] else
                 "WRONG: " + "; ".join(out["check"]["mode_ids"])))
    return 0


COMMAND = Command("a mechanism's kinematics and dynamics as a C99 library a controller can link", add_arguments, run)
