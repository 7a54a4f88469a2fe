"""The formats pkm writes a mechanism in, chosen by the path's suffix or by name (:func:`write`, behind
:func:`pkm.save` and ``pkm convert``):

* ``"pkm"`` (``.closures.toml``, ``.toml``): pkm's closure spec and its URDF beside it (``<stem>.urdf``): the whole
  mechanism, reference configuration included;
* ``"mjcf"`` (``.xml``, ``.mjcf``): MuJoCo's MJCF (:mod:`pkm.core.formats.to_mjcf`; loops as stiff ``<connect>`` /
  ``<weld>`` equalities, drives as armature, damping, friction and force ranges);
* ``"gepetto"`` (``.yaml``, ``.yml``): URDF + YAML in the convention of Gepetto's toolbox-parallel-robots
  (:mod:`pkm.core.formats.to_gepetto`), the URDF beside the YAML (``<stem>.urdf``);
* ``"urdfplus"`` (``.urdf``): MIT's URDF+, loops as ``<loop>`` elements in the URDF
  (:mod:`pkm.core.formats.to_urdfplus`);
* ``"sdf"`` (``.sdf``): SDFormat 1.11, loops as cut joints, posed at the reference configuration
  (:mod:`pkm.core.formats.to_sdf`), with a closure spec beside it (``<stem>.closures.toml``: the actuated joints,
  the task, the drives, which SDFormat does not say): the spec is the main file, the one :func:`pkm.load` takes;
* ``"usd"`` (``.usda`` text, ``.usd``, ``.usdc`` binary): USD, a UsdPhysics articulation, loops as joints excluded
  from it, drives as ``PhysicsDriveAPI`` (:mod:`pkm.core.formats.to_usd`; the ``usd`` extra: ``usd-core``).

A path without a suffix, with ``to`` given, is a folder: the files go in it (``<mechanism>.closures.toml``,
``<mechanism>.xml``, ``robot.yaml``).

Errors follow one rule: what is wrong with the arguments (a path or ``to`` naming no format, not a
:class:`~pkm.core.Mechanism`) is an :class:`~pkm.errors.InvalidInputError` (an :class:`~pkm.errors.UnknownNameError`
for ``to``); what the mechanism cannot be written as (a joint or a floating base the format has no element for, no URDF
text for a format that carries the URDF: pkm's spec, Gepetto's and URDF+) is a :class:`~pkm.errors.SpecError` naming
the file it was to go in, whatever the writer; so is a file that cannot be written. Each writer returns what it wrote
and what its format cannot hold (:class:`Written`); the latter is also written as comments where the format has them
(YAML) and is never silent: :func:`pkm.save` warns with it, ``pkm convert`` prints it.
"""

from __future__ import annotations

import dataclasses as dc
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.spec import as_path
from pkm.errors import InvalidInputError, SpecError, UnknownNameError


@dataclass(frozen=True)
class Written:
    """What a writer did.

    Attributes:
        files: The files written, the main one first (the one :func:`pkm.load` takes).
        dropped: What the format cannot hold, one line each (empty when nothing was lost).
        format: The writer's name (a key of :data:`WRITERS`).
    """

    files: tuple[Path, ...]
    dropped: tuple[str, ...]
    format: str


@dataclass(frozen=True)
class Writer:
    """One output format: its name, its suffixes (the first for a folder's file), what it is, how it writes (to
    :func:`destination`'s files), and the URDF it writes beside its main file, if any."""

    name: str
    suffixes: tuple[str, ...]
    description: str
    write: Callable[[Mechanism, tuple[Path, ...]], Written]
    urdf_beside: Callable[[Path], Path] | None = None


def _urdf_text(mech: Mechanism, what: str) -> str:
    if mech.urdf is None:  # (what the mechanism lacks for this format: a SpecError, as every writer's, module doc)
        raise SpecError(mech.source, f"built from a Pinocchio model, not URDF text: no URDF to write ({what}); "
                                     "SDF and MJCF are written from the model")
    return mech.urdf


def _write_pkm(mech: Mechanism, files: tuple[Path, ...]) -> Written:
    path, urdf_path = files
    urdf = _urdf_text(mech, "pkm's spec + URDF")
    reference = {k: tuple(float(x) for x in np.atleast_1d(v)) for k, v in mech.q_to_dict(mech.q_reference).items()}
    spec = dc.replace(mech.spec, urdf=urdf_path.name, reference=reference)
    text = spec.to_toml()
    path.parent.mkdir(parents=True, exist_ok=True)
    urdf_path.write_text(urdf, encoding="utf-8")
    path.write_text(text, encoding="utf-8")
    return Written((path, urdf_path), (), "pkm")


def _write_mjcf(mech: Mechanism, files: tuple[Path, ...]) -> Written:
    from pkm.core.formats.to_mjcf import mjcf_from_mechanism, mjcf_omissions

    (path,) = files
    text = mjcf_from_mechanism(mech)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return Written((path,), mjcf_omissions(mech), "mjcf")


def _write_gepetto(mech: Mechanism, files: tuple[Path, ...]) -> Written:
    from pkm.core.formats.to_gepetto import gepetto_from_mechanism

    path, urdf_path = files
    text, dropped = gepetto_from_mechanism(mech)
    path.parent.mkdir(parents=True, exist_ok=True)
    urdf_path.write_text(_urdf_text(mech, "Gepetto's URDF + YAML"), encoding="utf-8")
    path.write_text(text, encoding="utf-8")
    return Written((path, urdf_path), dropped, "gepetto")


def _write_sdf(mech: Mechanism, files: tuple[Path, ...]) -> Written:
    from pkm.core.formats.to_sdf import sdf_from_mechanism, sdf_spec

    path, spec_path = files
    text, dropped = sdf_from_mechanism(mech)
    spec = sdf_spec(mech, path.name).to_toml()
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    spec_path.write_text(spec, encoding="utf-8")
    return Written((spec_path, path), dropped, "sdf")


def _write_urdfplus(mech: Mechanism, files: tuple[Path, ...]) -> Written:
    from pkm.core.formats.to_urdfplus import urdfplus_from_mechanism

    (path,) = files
    text, dropped = urdfplus_from_mechanism(mech)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return Written((path,), dropped, "urdfplus")


def _write_usd(mech: Mechanism, files: tuple[Path, ...]) -> Written:
    from pkm.core.formats.to_usd import pxr, usd_from_mechanism

    (path,) = files
    pxr("writing USD")  # (the missing extra said before any folder is made)
    path.parent.mkdir(parents=True, exist_ok=True)
    _, dropped = usd_from_mechanism(mech, path)
    return Written((path,), dropped, "usd")


#: The writers by name (see the module doc).
WRITERS: dict[str, Writer] = {w.name: w for w in (
    Writer("pkm", (".closures.toml", ".toml"), "pkm's closure spec + URDF", _write_pkm,
           lambda p: p.with_name(f"{p.name.removesuffix('.toml').removesuffix('.closures')}.urdf")),
    Writer("mjcf", (".xml", ".mjcf"), "MuJoCo's MJCF", _write_mjcf),
    Writer("gepetto", (".yaml", ".yml"), "Gepetto's URDF + YAML (toolbox-parallel-robots)", _write_gepetto,
           lambda p: p.with_suffix(".urdf")),
    Writer("urdfplus", (".urdf",), "MIT's URDF+ (loops as <loop> elements)", _write_urdfplus),
    Writer("sdf", (".sdf",), "SDFormat (loops as cut joints) + pkm's closure spec", _write_sdf,
           lambda p: p.with_name(f"{p.name.removesuffix(p.suffix)}.closures.toml")),
    Writer("usd", (".usda", ".usd", ".usdc"), "USD (UsdPhysics; loops as joints excluded from the articulation)",
           _write_usd),
)}


def _known() -> str:
    return "; ".join(f"{w.name} ({', '.join(w.suffixes)})" for w in WRITERS.values())


def target(path: str | os.PathLike[str], to: str | None = None) -> tuple[Writer, Path | None]:
    """The writer for ``path`` (by its suffix, or ``to``) and, when ``path`` is a folder (no suffix, ``to`` given),
    None for the file (the caller names it); else ``path`` itself.

    Raises:
        UnknownNameError: ``to`` is not a format pkm writes.
        InvalidInputError: a suffix no writer takes, a suffix of another format than ``to``, or a folder without
            ``to``; each message lists the formats and their suffixes.
    """
    path = as_path(path)
    if to is not None:
        if not isinstance(to, str) or to not in WRITERS:
            raise UnknownNameError("format", str(to), WRITERS, "the formats pkm writes")
    name = path.name.lower()
    by_suffix = next((w for w in WRITERS.values() if name.endswith(w.suffixes)), None)
    if by_suffix is None:
        if to is not None and path.suffix == "":
            return WRITERS[to], None
        why = "a folder (no suffix) needs to= (--to) to say which format" if path.suffix == "" else \
            f"the suffix {path.suffix!r} names no format pkm writes"
        raise InvalidInputError("path", f"{path}: {why}; known: {_known()}", str(path))
    if to is not None and by_suffix.name != to:
        raise InvalidInputError("path", f"{path}: the suffix {path.suffix!r} is {by_suffix.name}'s, not {to}'s "
                                        f"(use one of {', '.join(WRITERS[to].suffixes)}); known: {_known()}", str(path))
    return by_suffix, path


def destination(mech: Mechanism, path: str | os.PathLike[str], to: str | None = None) -> tuple[Writer, tuple[Path, ...]]:
    """The writer for ``path`` (:func:`target`) and the files it will write, the main one first (a folder's named
    after the mechanism, or ``robot.yaml``; the URDF beside a spec or a Gepetto YAML).

    Raises:
        UnknownNameError, InvalidInputError: see :func:`target`.
    """
    writer, file = target(path, to)
    if file is None:
        file = Path(path) / ("robot.yaml" if writer.name == "gepetto" else
                             f"{_safe(mech.spec.mechanism)}{writer.suffixes[0]}")
    return writer, (file,) if writer.urdf_beside is None else (file, writer.urdf_beside(file))


def write(mech: Mechanism, path: str | os.PathLike[str], to: str | None = None) -> Written:
    """Write ``mech`` at ``path`` in the format its suffix names, or ``to`` (see the module doc); the files are
    :func:`destination`'s.

    Raises:
        UnknownNameError, InvalidInputError: see :func:`target`; not a Mechanism.
        SpecError: the format cannot hold something the mechanism needs (a joint MJCF has no kind for, a floating
            base in Gepetto's format, no URDF text for pkm's spec, Gepetto's or URDF+): the message names the file
            and what; a file that cannot be written (module doc).
    """
    mech = check_mechanism(mech)
    writer, files = destination(mech, path, to)
    try:
        return writer.write(mech, files)
    except OSError as exc:
        raise SpecError(str(files[0]), f"cannot write: {exc.strerror or exc}") from None
    except SpecError as exc:  # what the format cannot hold: said with the file it was to go in
        if exc.source == str(files[0]):
            raise
        raise SpecError(str(files[0]), f"{writer.description} cannot hold mechanism {mech.spec.mechanism!r}, nothing "
                                       f"written: {exc}") from None


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "mechanism"


__all__ = ["WRITERS", "Writer", "Written", "destination", "target", "write"]
