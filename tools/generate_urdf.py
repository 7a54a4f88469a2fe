#!/usr/bin/env python3
"""Regenerate the checked-in reference designs: ``urdf/<name>.urdf`` and ``urdf/<name>.closures.toml``.

Usage: ``python tools/generate_urdf.py [NAME ...]`` (all mechanisms by default).
``tests/test_reference_files.py`` fails when the files and the generators disagree.
"""

from __future__ import annotations

import sys
from pathlib import Path

from pkm.mechanisms import NAMES, module

ROOT = Path(__file__).resolve().parents[1] / "urdf"


def main(names: list[str]) -> None:
    for name in names or NAMES:
        mod = module(name)
        params = mod.Params()
        (ROOT / f"{name}.urdf").write_text(mod.urdf_xml(params), encoding="utf-8")
        (ROOT / f"{name}.closures.toml").write_text(mod.closure_spec(params).to_toml(), encoding="utf-8")
        print(f"wrote urdf/{name}.urdf and urdf/{name}.closures.toml")


if __name__ == "__main__":
    main(sys.argv[1:])
