"""Where the shipped data lives: ``urdf/`` (trees and closure specs) and ``dynamics/``.

In a wheel they are inside the package (``pkm/_data/...``); in a source checkout
(editable install) they are the top-level folders of the repository.
"""

from __future__ import annotations

from pathlib import Path

from pkm.errors import PkmError

_PKG = Path(__file__).resolve().parent


def data_dir(kind: str) -> Path:
    """The folder ``urdf`` or ``dynamics``."""
    if kind not in ("urdf", "dynamics"):
        from pkm.errors import InvalidInputError

        raise InvalidInputError("kind", f"unknown data kind {kind!r}: pkm ships 'urdf' and 'dynamics'", kind)
    for cand in (_PKG / "_data" / kind, _PKG.parents[1] / kind):
        if cand.is_dir():
            return cand
    raise PkmError(f"pkm's {kind}/ data folder is missing from this installation ({_PKG})")


def urdf_path(name: str) -> Path:
    return data_dir("urdf") / f"{name}.urdf"


def spec_path(name: str) -> Path:
    return data_dir("urdf") / f"{name}.closures.toml"


def dynamics_path(filename: str) -> Path:
    return data_dir("dynamics") / filename
