"""Closed-loop model formats other than pkm's closure spec, read into one.

**URDF + YAML in the convention of Gepetto's toolbox-parallel-robots** (the format of
example-parallel-robots; models exported with onshape-to-robot). A folder holds a URDF and a YAML file
(``robot.urdf`` and ``robot.yaml`` in the toolbox's examples) with the keys:

* ``closed_loop``: pairs of frame names ``[[frame_a, frame_b], ...]``, one per loop;
* ``type``: per loop ``"3d"`` (the two frames' origins meet: a ball joint, pkm's ``point`` closure) or
  ``"6d"`` (the frames coincide: pkm's ``frame`` closure);
* ``name_mot``: the actuated joints: exact joint names, or, as the toolbox reads them, patterns
  searched in the joint names (``"mot"`` matches ``mot1`` and ``motor_knee``), in model order;
* optional ``joint_name`` / ``joint_type``: joints the URDF writes as revolutes that are ``SPHERICAL``,
  ``CARDAN`` (a universal joint about x then y), ``UJOINT_AB`` (a universal joint about the joint frame's
  axis ``A`` then ``B``, two distinct of ``X``, ``Y``, ``Z``: pkm's ``universal_ab``) or ``FIXED`` (see
  :mod:`pkm.core.model.joints`). The toolbox splits a universal joint into two revolutes ``<name>_A``, ``<name>_B``;
  pkm keeps one joint ``<name>`` of two coordinates.

A URDF ``<mimic>`` joint named among the motors (Gepetto's ``true_talos_2_legs`` names its grippers' followers in
``name_mot``) is read as the toolbox reads it: the toolbox builds its model with Pinocchio's URDF parser, whose
default ignores ``<mimic>`` (``buildModel(..., mimic=False)``), so each follower is a joint of its own, driven by
its own motor. pkm drops the ``<mimic>`` of each follower named as a motor (:func:`unmimic_motors`) and says so
(a :class:`~pkm.errors.PkmWarning` naming each coupling dropped, and a note); the followers no motor names keep
their coupling.

The convention is recognised by content, whatever the files are named (:func:`find_gepetto`): a YAML mapping
with a ``closed_loop`` or ``name_mot`` key. Its URDF is the one of the YAML's stem (``leg.yaml``: ``leg.urdf``),
else ``robot.urdf``, else the folder's only URDF; a URDF given by its path is paired with the YAML of its stem,
or the folder's only Gepetto YAML. What the reader chose or interpreted is in the mechanism's
:attr:`~pkm.core.Mechanism.notes`.

The spec made from it has no end effector (the task is the actuated joints) and no reference (the
mechanism is assembled, :func:`pkm.core.kinematics.solve.assemble`). :func:`pkm.save` writes it as a pkm spec.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING

from pkm.core.formats.base import suffixes
from pkm.core.model.spec import MAX_FILE_BYTES, Closure, ClosureSpec, TaskSpec, read_text_file
from pkm.errors import InvalidInputError, SpecError, SpecNameError, closest, did_you_mean

if TYPE_CHECKING:
    pass

_YAML_TYPES = {"3d": "point", "6d": "frame"}
#: The toolbox's ``joint_type`` values and pkm's ``[joint_types]`` for them.
JOINT_TYPES = {"SPHERICAL": "spherical", "CARDAN": "universal", "FIXED": "fixed",
               **{f"UJOINT_{a}{b}": f"universal_{a.lower()}{b.lower()}" for a in "XYZ" for b in "XYZ" if a != b}}
#: The keys pkm reads; a YAML mapping with one of :data:`MARKERS` is taken for the convention.
KEYS = ("closed_loop", "type", "name_mot", "joint_name", "joint_type")
MARKERS = ("closed_loop", "name_mot")
_YAML_SUFFIXES = (".yaml", ".yml")


def parse_yaml(text: str, source: str = "<yaml>") -> object:
    """The document of YAML text (``yaml.safe_load``: no Python objects are built).

    Raises:
        SpecError: longer than 16 MiB, or not YAML (the parser's message on one line).
    """
    import yaml

    if not isinstance(text, str):
        raise InvalidInputError("yaml_text", f"expected the YAML text as a str, got {type(text).__name__}", text)
    if len(text) > MAX_FILE_BYTES:
        raise SpecError(source, f"YAML file longer than {MAX_FILE_BYTES} characters")
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise SpecError(source, f"not valid YAML: {' '.join(str(exc).split())}") from None


def gepetto_yaml(path: Path) -> str | None:
    """None when the file at ``path`` is a YAML mapping in Gepetto's convention (a ``closed_loop`` or ``name_mot``
    key), else why it is not (one line)."""
    try:
        raw = parse_yaml(read_text_file(path, "YAML"), str(path))
    except SpecError as exc:
        return str(exc).removeprefix(f"{path}: ")
    if not isinstance(raw, dict):
        return f"YAML, but a {type(raw).__name__}, not a mapping with keys {', '.join(KEYS[:3])}"
    if not any(k in raw for k in MARKERS):
        keys = ", ".join(map(str, list(raw)[:6])) or "none"
        return f"a YAML mapping without the keys {' or '.join(MARKERS)} (its keys: {keys})"
    return None


def _only(files: list[Path], what: str, folder: Path, ask: str) -> Path:
    """The one file of ``files``; else a SpecError naming them (``what``: their plural) and asking ``ask``."""
    if len(files) == 1:
        return files[0]
    raise SpecError(str(folder), f"{len(files)} {what} in the folder ({', '.join(f.name for f in files)}): {ask}")


def _urdf_for(yml: Path) -> tuple[Path, str | None]:
    """The URDF of a Gepetto YAML, and a note when it was found by elimination (see the module doc)."""
    for urdf in (yml.with_suffix(".urdf"), yml.parent / "robot.urdf"):
        if urdf.is_file():
            return urdf, None
    urdfs = sorted(p for p in yml.parent.glob("*.urdf") if p.is_file())
    if not urdfs:
        raise SpecError(str(yml), f"a YAML in Gepetto's convention with no URDF beside it ({yml.stem}.urdf, "
                                  "robot.urdf or any other)")
    urdf = _only(urdfs, "URDFs", yml.parent, f"none is named {yml.stem}.urdf or robot.urdf; load the one that goes "
                                            f"with {yml.name} by its path (pkm.load('{yml.parent / urdfs[0].name}'))")
    return urdf, f"{yml.name} read with {urdf.name}, the folder's only URDF"


def _yamls(folder: Path) -> tuple[list[Path], list[str]]:
    """The Gepetto YAML files of a folder, and why each other YAML file is not one."""
    found, others = [], []
    for p in sorted(folder.iterdir()):
        if p.suffix.lower() in _YAML_SUFFIXES and p.is_file():
            why = gepetto_yaml(p)
            if why is None:
                found.append(p)
            else:
                others.append(f"{p.name}: {why}")
    return found, others


def find_gepetto(path: Path) -> tuple[Path, Path, tuple[str, ...]] | str:
    """``(urdf, yaml, notes)`` when ``path`` is a Gepetto-convention model, else why it is not (one line).

    ``path`` is a folder holding a YAML in the convention (by content: a mapping with a ``closed_loop`` or
    ``name_mot`` key) and its URDF, or such a YAML file (whatever its suffix, but ``.toml``, ``.xml``, ``.mjcf``,
    ``.sdf``), or a URDF beside such a YAML (see the module doc).

    Raises:
        SpecError: it is one, but which file goes with which cannot be told (several URDFs and none of the
            YAML's name, several YAMLs in the convention): the message names them and says how to choose.
    """
    path = Path(path)
    if path.is_dir():
        found, others = _yamls(path)
        if not found:
            why = f" ({'; '.join(others)})" if others else ""
            return f"a folder with no YAML file in Gepetto's convention{why}"
        if len(found) > 1:
            paired = [y for y in found if y.with_suffix(".urdf").is_file()]
            standard = [y for y in found if y.name == "robot.yaml" and y in paired]
            found = standard or paired or found
        yml = _only(found, "YAML files in Gepetto's convention", path,
                    "load the one you mean by its path (pkm.load('" + str(path / found[0].name) + "'))")
        urdf, note = _urdf_for(yml)
        return urdf, yml, (note,) if note else ()
    suffix = path.suffix.lower()
    if suffix in _YAML_SUFFIXES or (path.is_file() and suffix not in (".toml", *suffixes())):
        reason = gepetto_yaml(path)  # (a YAML of another suffix is taken by content too)
        if reason is not None:
            return reason
        urdf, note = _urdf_for(path)
        return urdf, path, (note,) if note else ()
    if suffix == ".urdf" and path.is_file():
        for yml in (path.with_suffix(s) for s in _YAML_SUFFIXES):
            if yml.is_file() and gepetto_yaml(yml) is None:
                return path, yml, ()
        found, _ = _yamls(path.parent)
        if len(found) == 1:
            return path, found[0], (f"{path.name} read with {found[0].name}, the folder's only YAML in Gepetto's "
                                    "convention",)
        if found:
            return f"a URDF beside {len(found)} YAML files in Gepetto's convention, none named {path.stem}.yaml"
        return f"a URDF with no YAML file in Gepetto's convention beside it ({path.stem}.yaml)"
    return "neither a folder, nor YAML, nor a URDF"


def gepetto_files(path: Path) -> tuple[Path, Path] | None:
    """``(urdf, yaml)`` when ``path`` is a Gepetto-convention model (:func:`find_gepetto`); else None."""
    found = find_gepetto(path)
    return None if isinstance(found, str) else found[:2]


def read_gepetto(yaml_text: str, urdf_name: str, joint_names: list[str], mechanism: str,
                 source: str = "<yaml>") -> tuple[ClosureSpec, tuple[str, ...]]:
    """The closure spec a Gepetto ``robot.yaml`` states (see the module doc), and the notes on what was
    interpreted or ignored (patterns in ``name_mot``, keys pkm does not read, universal joints kept whole).

    Args:
        yaml_text: The YAML text.
        urdf_name: The URDF's file name, relative to the spec's folder.
        joint_names: The URDF's joint names, in model order (for the ``name_mot`` patterns).
        mechanism: The mechanism's name.
        source: Where the text came from, for the messages.

    Raises:
        SpecError: not YAML, keys missing or of the wrong type, a ``type`` or ``joint_type`` unknown.
        SpecNameError: a ``name_mot`` that matches no joint, a ``joint_name`` that is not a joint of the URDF
            (naming the closest ones).
    """
    raw = parse_yaml(yaml_text, source)
    if not isinstance(raw, dict):
        raise SpecError(source, f"a Gepetto robot.yaml is a mapping with keys {', '.join(KEYS[:3])}")
    notes: list[str] = []
    ignored = [str(k) for k in raw if k not in KEYS]
    if ignored:
        notes.append(f"{Path(source).name}: key{'s' if len(ignored) > 1 else ''} {', '.join(ignored)} ignored "
                     f"(pkm reads {', '.join(KEYS)})")

    def strings(key: str, required: bool = True) -> list:
        value = raw.get(key, None if required else [])
        if value is None:
            raise SpecError(source, f"missing key {key!r}")
        if not isinstance(value, list):
            raise SpecError(source, f"{key} must be a list, got {type(value).__name__}")
        return value

    loops, types, motors = strings("closed_loop"), strings("type"), strings("name_mot")
    if len(types) != len(loops):
        raise SpecError(source, f"{len(loops)} closed_loop pairs but {len(types)} types")
    closures = []
    for k, (pair, kind) in enumerate(zip(loops, types)):
        if not (isinstance(pair, list) and len(pair) == 2 and all(isinstance(n, str) and n for n in pair)):
            raise SpecError(source, f"closed_loop[{k}] must be a pair of frame names, got {pair!r}")
        if not isinstance(kind, str) or kind.lower() not in _YAML_TYPES:
            raise SpecError(source, f"type[{k}] = {kind!r}: use '3d' (point) or '6d' (frame)")
        closures.append(Closure(f"loop{k + 1}", _YAML_TYPES[kind.lower()], pair[0], pair[1]))
    actuated: list[str] = []
    for pattern in motors:
        if not isinstance(pattern, str) or not pattern:
            raise SpecError(source, f"name_mot entries are joint names or patterns, got {pattern!r}")
        found = [pattern] if pattern in joint_names else [n for n in joint_names if re.search(re.escape(pattern), n)]
        if not found:
            raise SpecNameError(source, "joint", pattern, joint_names, "name_mot: neither a joint name nor a part "
                                                                       "of one")
        if found != [pattern]:
            notes.append(f"name_mot {pattern!r} read as a pattern, as the toolbox reads it: "
                         + ", ".join(repr(n) for n in found))
        actuated += [n for n in found if n not in actuated]
    actuated.sort(key=joint_names.index)
    names, kinds = strings("joint_name", False), strings("joint_type", False)
    if len(names) != len(kinds):
        raise SpecError(source, f"{len(names)} joint_name entries but {len(kinds)} joint_type entries")
    joint_types: dict[str, str] = {}
    for name, kind in zip(names, kinds):
        if not isinstance(name, str) or name not in joint_names:
            raise SpecNameError(source, "joint", str(name), joint_names, "joint_name")
        if name in joint_types:
            raise SpecError(source, f"joint_name lists {name!r} twice")
        if not isinstance(kind, str) or kind.upper() not in JOINT_TYPES:
            hint = closest(kind, JOINT_TYPES) if isinstance(kind, str) else ()
            raise SpecError(source, f"joint_type {kind!r} of {name!r}: " + (did_you_mean(hint) + " " if hint else "")
                                    + f"use one of {list(JOINT_TYPES)}")
        joint_types[name] = JOINT_TYPES[kind.upper()]
    split = [n for n, k in joint_types.items() if k.startswith("universal")]
    if split:
        notes.append("universal joints kept whole, two coordinates each (the toolbox splits each into two revolutes "
                     "<name>_A, <name>_B): " + ", ".join(split))
    spec = ClosureSpec(mechanism=mechanism, urdf=urdf_name, end_effector=None, actuated=tuple(actuated),
                       closures=tuple(closures), task=TaskSpec((), tuple(actuated)), reference={},
                       description=f"read from {Path(source).name} (Gepetto toolbox-parallel-robots convention)",
                       joint_types=joint_types)
    return spec, tuple(notes)


def unmimic_motors(urdf_text: str, actuated: tuple[str, ...] | list[str], source: str = "<urdf>") \
        -> tuple[str, tuple[str, ...]]:
    """``urdf_text`` without the ``<mimic>`` of the joints ``actuated`` names (see the module doc: Gepetto's toolbox
    loads every follower as a joint of its own), and the note naming each coupling dropped (none: the text as given).
    """
    from lxml import etree

    from pkm.core.model.urdf import check_urdf

    root = check_urdf(urdf_text, source)
    dropped = []
    for el in root.findall("joint"):
        mim = el.find("mimic")
        if el.get("name") in actuated and mim is not None and el.get("type") != "fixed":
            dropped.append(f"{el.get('name')!r} = {float(mim.get('multiplier', 1.0)):g} {mim.get('joint')!r} "
                           f"+ {float(mim.get('offset', 0.0)):g}")
            for m in el.findall("mimic"):
                el.remove(m)
    if not dropped:
        return urdf_text, ()
    note = (f"mimic coupling{'s' if len(dropped) > 1 else ''} dropped: {', '.join(dropped)}: name_mot names "
            f"{'these followers' if len(dropped) > 1 else 'this follower'} among the motors, and Gepetto's toolbox "
            "loads the URDF without its mimic tags (Pinocchio's parser by default), each follower a joint driven by "
            "its own motor")
    return etree.tostring(root, encoding="unicode"), (note,)


def spec_from_gepetto(yaml_text: str, urdf_name: str, joint_names: list[str], mechanism: str,
                      source: str = "<yaml>") -> ClosureSpec:
    """The closure spec a Gepetto ``robot.yaml`` states: :func:`read_gepetto` without its notes."""
    return read_gepetto(yaml_text, urdf_name, joint_names, mechanism, source)[0]


__all__ = ["JOINT_TYPES", "KEYS", "MARKERS", "find_gepetto", "gepetto_files", "gepetto_yaml",
           "parse_yaml", "read_gepetto", "spec_from_gepetto", "unmimic_motors"]
