"""Closed-loop model formats other than pkm's closure spec, read into one.

**URDF + YAML in the convention of Gepetto's toolbox-parallel-robots** (the format of
example-parallel-robots; models exported with onshape-to-robot). A folder holds ``robot.urdf`` and
``robot.yaml`` with the keys:

* ``closed_loop``: pairs of frame names ``[[frame_a, frame_b], ...]``, one per loop;
* ``type``: per loop ``"3d"`` (the two frames' origins meet: a ball joint, pkm's ``point`` closure) or
  ``"6d"`` (the frames coincide: pkm's ``frame`` closure);
* ``name_mot``: the actuated joints: exact joint names, or, as the toolbox reads them, patterns
  searched in the joint names (``"mot"`` matches ``mot1`` and ``motor_knee``), in model order;
* optional ``joint_name`` / ``joint_type``: joints the URDF writes as revolutes that are ``SPHERICAL``,
  ``CARDAN`` (a universal joint) or ``FIXED`` (see :mod:`pkm.core.joints`).

The spec made from it has no end effector (the task is the actuated joints) and no reference (the
mechanism is assembled, :func:`pkm.core.solve.assemble`). :func:`pkm.save` writes it as a pkm spec.
"""

from __future__ import annotations

import re
from pathlib import Path

from pkm.core.spec import MAX_FILE_BYTES, Closure, ClosureSpec, TaskSpec, read_text_file
from pkm.errors import InvalidInputError, SpecError

_YAML_TYPES = {"3d": "point", "6d": "frame"}
_JOINT_TYPES = {"SPHERICAL": "spherical", "CARDAN": "universal", "FIXED": "fixed"}


def gepetto_files(path: Path) -> tuple[Path, Path] | None:
    """``(urdf, yaml)`` when ``path`` is a Gepetto-convention model: a folder holding ``robot.urdf`` and
    ``robot.yaml``, or a ``.yaml`` file beside a URDF of the same stem (or ``robot.urdf``); else None."""
    if path.is_dir():
        urdf, yml = path / "robot.urdf", path / "robot.yaml"
        return (urdf, yml) if urdf.is_file() and yml.is_file() else None
    if path.suffix.lower() in (".yaml", ".yml") and path.is_file():
        for urdf in (path.with_suffix(".urdf"), path.parent / "robot.urdf"):
            if urdf.is_file():
                return urdf, path
    return None


def spec_from_gepetto(yaml_text: str, urdf_name: str, joint_names: list[str], mechanism: str,
                      source: str = "<yaml>") -> ClosureSpec:
    """The closure spec a Gepetto ``robot.yaml`` states (see the module doc).

    Args:
        yaml_text: The YAML text.
        urdf_name: The URDF's file name, relative to the spec's folder.
        joint_names: The URDF's joint names, in model order (for the ``name_mot`` patterns).
        mechanism: The mechanism's name.

    Raises:
        SpecError: not YAML, keys missing or of the wrong type, a ``type`` or ``joint_type`` unknown, a
            ``name_mot`` that matches no joint.
    """
    import yaml

    if not isinstance(yaml_text, str):
        raise InvalidInputError("yaml_text", f"expected the YAML text as a str, got {type(yaml_text).__name__}",
                                yaml_text)
    if len(yaml_text) > MAX_FILE_BYTES:
        raise SpecError(source, f"YAML file longer than {MAX_FILE_BYTES} characters")
    try:
        raw = yaml.safe_load(yaml_text)
    except yaml.YAMLError as exc:
        raise SpecError(source, f"not valid YAML: {' '.join(str(exc).split())}") from None
    if not isinstance(raw, dict):
        raise SpecError(source, "a robot.yaml is a mapping with keys closed_loop, type, name_mot")

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
            raise SpecError(source, f"name_mot {pattern!r} matches no joint of the URDF; joints: {joint_names}")
        actuated += [n for n in found if n not in actuated]
    actuated.sort(key=joint_names.index)
    names, kinds = strings("joint_name", False), strings("joint_type", False)
    if len(names) != len(kinds):
        raise SpecError(source, f"{len(names)} joint_name entries but {len(kinds)} joint_type entries")
    joint_types = {}
    for name, kind in zip(names, kinds):
        if not isinstance(kind, str) or kind.upper() not in _JOINT_TYPES:
            raise SpecError(source, f"joint_type {kind!r} of {name!r}: use one of {list(_JOINT_TYPES)}")
        joint_types[str(name)] = _JOINT_TYPES[kind.upper()]
    return ClosureSpec(mechanism=mechanism, urdf=urdf_name, end_effector=None, actuated=tuple(actuated),
                       closures=tuple(closures), task=TaskSpec((), tuple(actuated)), reference={},
                       description=f"read from {source} (Gepetto toolbox-parallel-robots convention)",
                       joint_types=joint_types)


def load_gepetto(urdf_path: Path, yaml_path: Path):
    """The :class:`~pkm.core.Mechanism` of a Gepetto-convention URDF + YAML pair (see the module doc)."""
    from pkm.core.mechanism import Mechanism
    from pkm.core.urdf import check_urdf

    urdf = read_text_file(urdf_path, "URDF")
    joints = [str(j.get("name")) for j in check_urdf(urdf, str(urdf_path)).findall("joint")]
    name = urdf_path.parent.name if urdf_path.stem == "robot" else urdf_path.stem
    spec = spec_from_gepetto(read_text_file(yaml_path, "YAML"), urdf_path.name, joints, name or "robot",
                             str(yaml_path))
    return Mechanism.from_strings(urdf, spec, source=str(yaml_path))


__all__ = ["gepetto_files", "load_gepetto", "spec_from_gepetto"]
