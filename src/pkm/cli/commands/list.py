"""``pkm list [MECH|PATH ...] [--json]``: the mechanisms (every shipped one, or those named: any MECH), what each is
read from (its format and files), their joints, task and parameters (units, defaults), and the names of the other
models ``pkm.load`` takes by name. A folder that is no model itself is searched (:data:`DEPTH` levels down) for
what ``pkm.load`` reads there: each closure spec, Gepetto URDF + YAML, MJCF or SDF file is listed and described, each
that fails to load is named with its error; a folder with nothing loadable is one pkm error naming what it holds."""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pkm
from pkm.cli.command import Command
from pkm.cli.mechanism import add_mechanism_help
from pkm.cli.parsing import param_info
from pkm.errors import PkmError
from pkm.report import jsonable
from pkm.units import SI_UNITS, joint_unit

DEPTH = 3
"""How many folder levels below a folder ``pkm list PATH`` searches (``urdf/gepetto/robot_delta`` from ``urdf``)."""


def add_arguments(p: argparse.ArgumentParser) -> None:
    add_mechanism_help(p.add_argument("mechanisms", metavar="MECH", nargs="*"),
                       "the mechanisms to describe (default: every shipped one, then the names of the third-party "
                       "robots pkm ships and of the models of installed packages), or a folder to search for what "
                       "pkm loads: ")
    p.add_argument("--json", action="store_true", help="print JSON")


def _model_format(path: Path) -> str:
    """The registered format of a model file: its root element's, else its suffix's (as the readers decide)."""
    from pkm.core.formats.imported import format_of

    try:
        text = path.read_text(errors="replace")[:65536]
    except OSError:
        text = ""
    return format_of(path, text).name.upper()


def _reader(path: Path) -> tuple[str, Callable[[], pkm.Mechanism]] | None:
    """The reader of :func:`pkm.core.formats.load.load_path` that takes ``path`` (its name) and its loader, or None
    when none takes it. Raises :class:`~pkm.errors.SpecError` as a reader that takes it but cannot pair its files."""
    from pkm.core.formats.load import READERS

    for reader in READERS:
        claim = reader.claim(path)
        if not isinstance(claim, str):
            return reader.name, claim
    return None


def source(arg: str, mech: pkm.Mechanism) -> dict[str, Any]:
    """What ``mech`` (loaded from ``arg``, a name or a path) is read from: its format and its files."""
    from pkm.core.formats.catalogue import CATALOGUE, catalogue_path
    from pkm.core.formats.packages import PACKAGE_MODELS, model_file

    if arg in pkm.MECHANISMS:
        return {"format": "shipped mechanism (pkm closure spec + URDF)" if pkm.MECHANISMS[arg].reference else
                "shipped mechanism (built from its parameters)", "files": []}
    if arg in PACKAGE_MODELS:
        spec, model = model_file(arg)
        return {"format": f"model of the installed package {PACKAGE_MODELS[arg].package} ({_model_format(model)} + "
                          "the closure spec pkm ships)", "files": [str(spec), str(model)]}
    path = catalogue_path(arg) if arg in CATALOGUE else Path(arg)
    try:
        reader = _reader(path)
    except PkmError:
        reader = None
    if reader is None:
        return {"format": "?", "files": [str(path)]}
    name = reader[0]
    if name.startswith("Gepetto"):
        from pkm.core.formats.gepetto import gepetto_files

        files = gepetto_files(path) or ()
        return {"format": "Gepetto URDF + YAML", "files": [str(f) for f in reversed(files)]}
    if name.startswith("pkm closure spec"):
        model = path.parent / mech.spec.urdf
        return {"format": f"pkm closure spec + {_model_format(model)}", "files": [str(path), str(model)]}
    return {"format": f"{_model_format(path)} file", "files": [str(path)]}


def describe(name: str, mech: pkm.Mechanism | None = None) -> dict[str, Any]:
    """What ``pkm list`` says of the mechanism ``name`` (any MECH; ``mech``: it loaded already): what it is read
    from, its actuated joints and task coordinates with their units, a reachable pose, its working modes; a shipped
    mechanism's title and parameters too."""
    mech = pkm.load(name) if mech is None else mech
    entry = pkm.MECHANISMS.get(name)
    frame = f"the frame {mech.spec.end_effector!r} in the world frame" if mech.spec.end_effector else "joint outputs"
    out: dict[str, Any] = {"name": mech.name,
                           "title": entry.title if entry else mech.spec.description,
                           **source(name, mech),
                           "actuated": {j: joint_unit(mech.joints[j].revolute) for j in mech.actuated_names},
                           "task": {k: SI_UNITS[kind] for k, kind in pkm.TaskMap.of(mech).kinds.items()},
                           "task_origin": entry.origin if entry else frame,
                           "reference_pose": pkm.TaskMap.of(mech).named(mech.q_reference),
                           "branches": list(mech.spec.branches),
                           "default_branch": mech.spec.default_branch,
                           "joints": len(mech.joints), "loops": len(mech.spec.closures)}
    if entry:
        out["parameters"] = {p.name: {"default": p.default, "unit": p.unit, "type": p.type,
                                      "description": p.description} for p in param_info(name).values()}
    return out


def _candidates(folder: Path, depth: int) -> list[Path]:
    """The files and folders under ``folder`` (``depth`` levels at most) that a reader of
    :func:`pkm.core.formats.load.load_path` may take, by their names: closure specs, YAML and model files, and the
    folders a reader takes whole (a Gepetto folder: not searched further). Hidden entries are skipped."""
    from pkm.core.formats.base import suffixes

    wanted = {".toml", ".yaml", ".yml", *suffixes()}
    out: list[Path] = []
    try:
        children = sorted(folder.iterdir())
    except OSError:  # (a folder one may not read: nothing found there)
        return out
    for child in children:
        if child.name.startswith((".", "__")):
            continue
        if child.is_dir():
            try:
                taken = _reader(child) is not None
            except PkmError:
                taken = True  # (a reader takes it, and its load says why it cannot)
            if taken:
                out.append(child)
            elif depth > 1:
                out += _candidates(child, depth - 1)
        elif child.suffix.lower() in wanted:
            out.append(child)
    return out


def _is_spec(path: Path) -> bool:
    """False for a ``.toml`` file that is no closure spec (no ``format`` key: a ``pyproject.toml``), which
    :func:`pkm.load` would try as one (the reader takes any ``.toml``), but a folder's listing leaves out."""
    import tomllib

    if path.suffix.lower() != ".toml":
        return True
    try:
        return "format" in tomllib.loads(path.read_text(errors="replace"))
    except (OSError, tomllib.TOMLDecodeError, RecursionError):
        return True  # (pkm.load's error names the fault)


def search(folder: Path, depth: int = DEPTH) -> tuple[dict[str, dict[str, Any]], dict[str, str]]:
    """What :func:`pkm.load` reads in ``folder`` and below (``depth`` levels): ``({path: describe(path)},
    {path: why it did not load})``. A file no reader takes (a TOML without a ``format`` key, XML of another kind) is
    left out; so is a model file that a listed closure spec or Gepetto pair reads (it is among that entry's files).

    Raises:
        SpecError: nothing in ``folder`` loads (the message names what failed, and why, or that no file there is
            of a kind pkm reads).
    """
    found: dict[str, dict[str, Any]] = {}
    failed: dict[str, str] = {}
    declined: list[str] = []
    for path in _candidates(folder, depth):
        try:
            if _reader(path) is None or not _is_spec(path):
                declined.append(str(path))
                continue
            found[str(path)] = describe(str(path), pkm.load(path))
        except PkmError as exc:
            failed[str(path)] = " ".join(str(exc).split()).removeprefix(f"{path}: ")
    used = {str(Path(f).resolve()) for d in found.values() for f in d["files"]}
    failed = {p: why for p, why in failed.items() if str(Path(p).resolve()) not in used}
    if not found:
        from pkm.core.formats.base import FORMATS
        from pkm.errors import SpecError

        kinds = ", ".join(f"{f.name.upper()} ({' '.join(f.suffixes)})" for f in FORMATS.values())
        held = "; ".join(f"{p}: {why}" for p, why in failed.items()) or (
            f"no closure spec, Gepetto YAML or model file ({kinds}) within {depth} levels"
            + (f"; not pkm's: {', '.join(declined[:5])}" if declined else ""))
        raise SpecError(str(folder), f"pkm loads nothing here: {held}")
    return found, failed


def _is_search(arg: str) -> bool:
    """Whether ``pkm list ARG`` searches ARG: a folder that is neither a name nor a model a reader takes whole."""
    path = Path(arg)
    if arg in pkm.MECHANISMS or not path.is_dir():
        return False
    try:
        return _reader(path) is None
    except PkmError:
        return False  # (a reader takes it but cannot pair its files: pkm.load says so)


def run(args: argparse.Namespace) -> int:
    from pkm.core.formats.catalogue import CATALOGUE
    from pkm.core.formats.packages import PACKAGE_MODELS

    data: dict[str, dict[str, Any]] = {}
    failed: dict[str, str] = {}
    for arg in args.mechanisms or pkm.MECHANISMS:
        if _is_search(arg):
            found, bad = search(Path(arg))
            data.update(found)
            failed.update(bad)
        else:
            data[arg] = describe(arg)
    others: dict[str, str] = {} if args.mechanisms else {**{n: e.description for n, e in CATALOGUE.items()},
                                                          **{n: e.description for n, e in PACKAGE_MODELS.items()}}
    if args.json:
        print(json.dumps(jsonable({"units": "SI (m, rad, kg) unless a parameter says otherwise",
                                   "mechanisms": data, **({"by_name": others} if others else {}),
                                   **({"not_loaded": failed} if failed else {})}), indent=2))
        return 0

    def named(m: dict[str, str]) -> str:
        return ", ".join(f"{k} [{u}]" for k, u in m.items())

    for name, d in data.items():
        branches = ", ".join(b + (" (default)" if b == d["default_branch"] else "") for b in d["branches"])
        print(f"{name}: {d['title']}" if d["title"] else f"{name}:")
        print(f"  read from: {d['format']}" + (f" ({', '.join(d['files'])})" if d["files"] else ""))
        print(f"  name: {d['name']}; joints: {d['joints']}, loops: {d['loops']}")
        print(f"  actuated (--joints): {named(d['actuated'])}")
        print(f"  task (--pose): {named(d['task'])}")
        print(f"  task origin: {d['task_origin']}")
        print("  reference pose (reachable): " + " ".join(f"{k}={_fmt_value(v, d['task'][k])}"
                                                       for k, v in d["reference_pose"].items()))
        if branches:
            print(f"  branches (--branch): {branches}")
        if "parameters" in d:
            print("  parameters (--param NAME=VALUE, SI unless a unit suffix is given):")
            rows = [(p.name, _fmt_default(p.default), p.unit, p.summary) for p in param_info(name).values()]
            w = [max(len(r[i]) for r in rows) for i in range(3)]
            for r in rows:
                print(f"    {r[0].ljust(w[0])}  {r[1].ljust(w[1])}  {r[2].ljust(w[2])}  {r[3]}")
        print()
    if failed:
        print("Not loaded (pkm.load's error):")
        for path, why in failed.items():
            print(f"  {path}: {why}")
    if others:
        print("Also loaded by name (pkm list NAME describes one):")
        width = max(len(name) for name in others)
        for name, what in others.items():
            print(f"  {name.ljust(width)}  {what}")
    return 0


def _fmt_value(v: float, unit: str) -> str:
    """A task value for the eye, in the unit a user would type: cm or deg (``pkm ik --pose`` takes them back)."""
    x, suffix = (v * 100.0, "cm") if unit == "m" else (math.degrees(v), "deg") if unit == "rad" else (v, "")
    return f"{round(x, 6) + 0.0:.4g}{suffix}"  # (rounded, + 0.0: no "-0" nor "1e-15")


def _fmt_default(v: Any) -> str:
    if v is None:
        return "found"
    if isinstance(v, tuple):
        return ",".join(_fmt_default(x) for x in v)
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


COMMAND = Command("the mechanisms (or MECH, or what a folder holds): format, joints, task, parameters (units, "
                  "defaults)", add_arguments, run)
