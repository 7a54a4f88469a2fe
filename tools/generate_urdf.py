#!/usr/bin/env python3
"""Regenerate the checked-in reference designs: ``urdf/<name>.urdf`` and ``urdf/<name>.closures.toml``.

Usage: ``python tools/generate_urdf.py [--check] [NAME ...]`` (all mechanisms by default).

A file is rewritten only when the generator's output differs from it *as a model* (see
:mod:`pkm.core.model.compare`): regenerating on a CPU whose arithmetic rounds the last bits differently
leaves the files as they are. ``--check`` writes nothing and lists the differences (exit status 1
when there are any), as ``tests/test_reference_files.py`` does.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from pkm.core.model.compare import document_differences
from pkm.mechanisms import module, names

ROOT = Path(__file__).resolve().parents[1] / "urdf"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="write nothing; list the differences")
    ap.add_argument("names", nargs="*", default=list(names(with_files=True)))
    args = ap.parse_args()
    status = 0
    for name in args.names:
        mod = module(name)
        params = mod.Params()
        for path, kind, text in ((ROOT / f"{name}.urdf", "urdf", mod.urdf_xml(params)),
                                 (ROOT / f"{name}.closures.toml", "toml", mod.closure_spec(params).to_toml())):
            diffs = document_differences(path.read_text(encoding="utf-8"), text, kind) if path.exists() else ["new"]
            if not diffs:
                continue
            status = 1
            print(f"{path.relative_to(ROOT.parent)}: {len(diffs)} difference(s)", *diffs[:10], sep="\n  ")
            if not args.check:
                path.write_text(text, encoding="utf-8")
                print("  rewritten")
    return status if args.check else 0


if __name__ == "__main__":
    raise SystemExit(main())
