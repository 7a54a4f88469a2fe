"""A disk cache for results that cost seconds and depend only on their inputs (the report's homotopy rows).

An entry is a JSON document stored under the SHA-256 of its key: the inputs (mechanism files, actuator values,
row id...), the pkm version, and the source text of every module whose code computes the result, so that a change
of inputs or of code computes it anew. Entries are written atomically (a temporary file renamed), so that
parallel processes (``pytest -n 2``, several ``pkm report`` runs) share them safely; a damaged or unreadable entry
is computed again. Processes asking for one entry at once compute it once: the first holds a lock on the entry
(``fcntl.flock``), the others wait for it and read what it wrote.

Where: ``$PKM_CACHE_DIR``, else ``$XDG_CACHE_HOME/pkm``, else ``~/.cache/pkm``. ``PKM_CACHE=0`` turns the cache off
(every result computed); a folder that cannot be written is skipped silently (the result is computed and
returned).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import sys
import tempfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any


def cache_dir() -> Path:
    """The cache's folder (module doc)."""
    if os.environ.get("PKM_CACHE_DIR"):
        return Path(os.environ["PKM_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "pkm"


def code_digest(modules: Iterable[ModuleType | str]) -> str:
    """The SHA-256 of the source files of ``modules`` (modules or dotted names; a package counts with every
    ``.py`` file under it)."""
    h = hashlib.sha256()
    for mod in modules:
        mod = sys.modules[mod] if isinstance(mod, str) and mod in sys.modules else mod
        if isinstance(mod, str):
            import importlib

            mod = importlib.import_module(mod)
        path = Path(mod.__file__ or "")
        files = sorted(path.parent.rglob("*.py")) if path.name == "__init__.py" else [path]
        for f in files:
            h.update(str(f.name).encode())
            h.update(f.read_bytes())
    return h.hexdigest()


def file_digest(paths: Iterable[Path]) -> str:
    """The SHA-256 of the files under ``paths`` (folders walked, in name order): names and contents."""
    h = hashlib.sha256()
    for root in paths:
        root = Path(root)
        for f in sorted(root.rglob("*")) if root.is_dir() else [root]:
            if f.is_file():
                h.update(str(f.relative_to(root.parent)).encode())
                h.update(f.read_bytes())
    return h.hexdigest()


def cached(kind: str, key: Any, compute: Callable[[], Any], *, code: Iterable[ModuleType | str] = ()) -> Any:
    """``compute()``, or its JSON-able result stored earlier under the same ``kind``, ``key`` and ``code``.

    Args:
        kind: A folder name for the entries (``"rows"``).
        key: The inputs, JSON-able (numbers are written with ``repr``, so equal floats give equal keys).
        compute: Computes the result (JSON-able: dicts, lists, str, numbers, bool, None).
        code: The modules whose source computes the result (with pkm's version, part of the key).
    """
    import pkm

    if os.environ.get("PKM_CACHE", "1") == "0":
        return compute()
    text = json.dumps({"key": key, "version": pkm.__version__, "code": code_digest(code)}, sort_keys=True,
                      default=repr)
    path = cache_dir() / kind / f"{hashlib.sha256(text.encode()).hexdigest()}.json"
    found = _read(path)
    if found is not None:
        return found[0]
    with _entry_lock(path):  # (another process computing the same entry: wait for it, then read it)
        found = _read(path)
        if found is not None:
            return found[0]
        value = compute()
        try:
            with tempfile.NamedTemporaryFile("w", dir=path.parent, suffix=".tmp", delete=False) as fh:
                json.dump({"value": value}, fh)
            os.replace(fh.name, path)
        except OSError:
            pass
    return value


def _read(path: Path) -> tuple[Any] | None:
    """``(value,)`` of the entry at ``path``, None where it is missing or damaged."""
    try:
        return (json.loads(path.read_text())["value"],)
    except (OSError, ValueError, KeyError, TypeError):
        return None


@contextlib.contextmanager
def _entry_lock(path: Path) -> Iterator[None]:
    """An exclusive lock on ``path``'s entry across processes (``fcntl.flock`` on a ``.lock`` file beside it), so that
    parallel processes asking for one entry compute it once; none where the folder cannot be written or the platform
    has no ``flock`` (each process then computes it). Entries nest in one order (a paper's rows, then its modes'), so
    two processes never wait on each other."""
    try:
        import fcntl

        path.parent.mkdir(parents=True, exist_ok=True)
        fh = open(path.with_suffix(".lock"), "a")  # (held across the yield)
    except (ImportError, OSError):
        fh = None
    if fh is None:
        yield
        return
    try:
        fcntl.flock(fh, fcntl.LOCK_EX)
        yield
    finally:
        fh.close()  # (closing releases the lock)


__all__ = ["cache_dir", "cached", "code_digest", "file_digest"]
