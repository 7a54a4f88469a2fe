"""A model file in any format pkm reads, turned into its one representation: URDF text plus what a
closure spec adds (loops, joint types, actuators)."""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from pkm.core.model.spec import Closure, ClosureSpec, TaskSpec, read_text_file
from pkm.core.model.urdf import check_urdf, limit_notes
from pkm.errors import SpecError

if TYPE_CHECKING:
    from pkm.core.model.mechanism import Mechanism

#: File suffixes and the format they are read as.
SUFFIXES = {".urdf": "urdf", ".xml": "mjcf", ".mjcf": "mjcf", ".sdf": "sdf"}


@dataclass(frozen=True)
class Imported:
    """A model file read into pkm's one representation.

    Attributes:
        urdf: The tree as URDF text (frames for the closures' anchors included).
        closures: The loops the file closes (none for a URDF).
        joint_types: Joints URDF cannot state (``spherical``, ``universal``), for ``[joint_types]``.
        actuated: The actuated joints the file names (empty when it names none).
        name: The model's name.
        format: ``"urdf"``, ``"mjcf"`` or ``"sdf"``.
        floating_base: The free-flyer joint that carries the whole tree (an MJCF root ``<freejoint>``), or None.
        reference: Joint values the file states (an MJCF free body's pose), for ``[reference]``.
        notes: What the reader interpreted or ignored, one sentence each (a tendon actuator read as its joint, a
            velocity limit read as none...): :attr:`pkm.core.Mechanism.notes` after loading.
    """

    urdf: str
    closures: tuple[Closure, ...]
    joint_types: dict[str, str]
    actuated: tuple[str, ...]
    name: str
    format: str
    floating_base: str | None = None
    reference: dict[str, tuple[float, ...]] = dataclasses.field(default_factory=dict)
    notes: tuple[str, ...] = ()


def _root_tag(text: str) -> str | None:
    """The name of the document's first element (after the declaration and comments), or None."""
    body = re.sub(r"<\?.*?\?>|<!--.*?-->", "", text[:65536], flags=re.DOTALL)
    m = re.search(r"<\s*([A-Za-z_][\w.-]*)", body)
    return m.group(1) if m else None


def import_model(path: Path) -> Imported:
    """Read the model file at ``path``, by its root element (``robot``, ``mujoco``, ``sdf``), else by its suffix
    (:data:`SUFFIXES`; another suffix is read as URDF).

    Raises:
        SpecError: the file is missing, too large, malformed, or uses what its reader refuses.
    """
    kind = SUFFIXES.get(path.suffix.lower(), "urdf")
    text = read_text_file(path, kind.upper())
    kind = {"robot": "urdf", "mujoco": "mjcf", "sdf": "sdf"}.get(_root_tag(text) or "", kind)  # (a URDF named .xml)
    if kind == "mjcf":
        from pkm.core.formats.mjcf import read_mjcf

        return read_mjcf(text, str(path))
    if kind == "sdf":
        from pkm.core.formats.sdf import read_sdf

        return read_sdf(text, str(path))
    root = check_urdf(text, str(path))
    return Imported(text, (), {}, (), str(root.get("name") or path.stem), "urdf", notes=limit_notes(root))


def with_file(spec: ClosureSpec, imp: Imported, source: str) -> ClosureSpec:
    """``spec`` with the loops, joint types and floating base of the model file it names added (the spec's win).

    Raises:
        SpecError: a closure named both in the spec and in the file.
    """
    if not imp.closures and not imp.joint_types and imp.floating_base is None and not imp.reference:
        return spec
    clash = sorted({c.name for c in spec.closures} & {c.name for c in imp.closures})
    if clash:
        raise SpecError(source, f"closure {clash[0]!r} is both in the spec and in {spec.urdf!r}; rename the spec's")
    return dataclasses.replace(spec, closures=imp.closures + spec.closures,
                               joint_types={**imp.joint_types, **spec.joint_types},
                               floating_base=spec.floating_base or imp.floating_base,
                               reference={**imp.reference, **spec.reference})


def load_model_file(path: Path):
    """The :class:`~pkm.core.Mechanism` of an MJCF or SDF file alone: its loops, its actuators, the actuated
    joints as the task, no end effector, assembled (:func:`pkm.assemble`).

    Raises:
        SpecError: as :func:`import_model`, or a file that names no actuated joint (SDF never does):
            then a closure spec must say which joints are driven.
    """
    from pkm.core.model.mechanism import Mechanism

    imp = import_model(path)
    if not imp.actuated:
        raise SpecError(str(path), f"the {imp.format.upper()} file names no actuated joint; write a closure spec with "
                                   f"urdf = {path.name!r} and actuated = [...] beside it (`pkm spec init {path}` "
                                   "writes one to fill in), and load the spec")
    spec = ClosureSpec(mechanism=imp.name, urdf=path.name, end_effector=None, actuated=imp.actuated,
                       closures=imp.closures, task=TaskSpec((), imp.actuated), reference=dict(imp.reference),
                       description=f"read from {path.name} ({imp.format.upper()})", joint_types=imp.joint_types,
                       floating_base=imp.floating_base)
    return Mechanism.from_strings(imp.urdf, spec, source=str(path), notes=imp.notes)


@dataclass(frozen=True)
class Reader:
    """One way :func:`load_path` may read a path.

    Attributes:
        name: What it reads, for the messages.
        claim: ``claim(path)``: a function that loads the mechanism when the reader takes ``path``, else why it
            does not (one line). It raises :class:`~pkm.errors.SpecError` when it takes ``path`` but cannot
            tell which files go together.
    """

    name: str
    claim: Callable[[Path], Callable[[], Mechanism] | str]


def _gepetto(path: Path) -> Callable[[], Mechanism] | str:
    from pkm.core.formats.gepetto import find_gepetto, load_gepetto

    found = find_gepetto(path)
    return found if isinstance(found, str) else (lambda: load_gepetto(*found))


def _head(path: Path) -> str | None:
    """The file's text, or None when it cannot be read as text (the readers that take it say why)."""
    try:
        return read_text_file(path, "file")
    except SpecError:
        return None


def _closure_spec(path: Path) -> Callable[[], Mechanism] | str:
    import tomllib

    from pkm.core.model.mechanism import Mechanism

    if path.is_dir():
        specs = sorted(p.name for p in path.glob("*.toml"))
        return "a folder: give the spec file (" + (f"it holds {', '.join(specs[:4])}" if specs else "NAME.closures.toml") + ")"
    if path.suffix.lower() == ".toml":
        return lambda: Mechanism.from_files(path)
    if path.suffix.lower() in (".yaml", ".yml"):
        return "a YAML file: a pkm closure spec is TOML (NAME.closures.toml)"
    if path.suffix.lower() in SUFFIXES:
        return f"a {path.suffix} file: a pkm closure spec is TOML (NAME.closures.toml)"
    text = _head(path)
    if text is None:
        return "not a readable text file"
    try:
        raw = tomllib.loads(text)
    except (tomllib.TOMLDecodeError, RecursionError) as exc:
        return f"not TOML ({' '.join(str(exc).split())})"
    if "format" not in raw:
        return "TOML without the key format = \"pkm.closures/1\""
    return lambda: Mechanism.from_files(path)


def _model_file(path: Path) -> Callable[[], Mechanism] | str:
    if path.is_dir():
        return "a folder (give the model file)"
    kind = SUFFIXES.get(path.suffix.lower())
    text = _head(path)
    root = _root_tag(text) if text is not None else None
    if kind is None and root not in ("robot", "mujoco", "sdf"):
        return ("not XML with a <robot>, <mujoco> or <sdf> root element" if root is None
                else f"XML whose root element is <{root}>, not <robot>, <mujoco> or <sdf>")
    return lambda: load_model_file(path)


#: The readers :func:`load_path` tries, in this order; the first that takes a path reads it.
READERS = (Reader("Gepetto URDF + YAML", _gepetto), Reader("pkm closure spec", _closure_spec),
           Reader("model file (URDF, MJCF, SDF)", _model_file))


def load_path(path: Path) -> Mechanism:
    """The mechanism of a file or folder, read by the first of :data:`READERS` that takes it, by content: a folder
    or YAML in Gepetto's convention (:mod:`pkm.core.formats.gepetto`), a closure spec (``.toml``, or TOML text
    with a ``format`` key), an MJCF or SDF file (or a URDF alone, which then asks for a spec).

    Raises:
        SpecError: nothing at ``path``; no reader takes it (the message says, one line each, why each declined);
            what the reader that takes it refuses.
    """
    path = Path(path)
    if not path.exists():
        raise SpecError(str(path), "no such file or folder")
    reasons = []
    for reader in READERS:
        claim = reader.claim(path)
        if not isinstance(claim, str):
            return claim()
        reasons.append(f"  {reader.name}: {claim}")
    raise SpecError(str(path), "no reader takes it:\n" + "\n".join(reasons))


def spec_skeleton(path: Path) -> tuple[str, bool]:
    """A commented closure spec for the model file at ``path`` (URDF, MJCF or SDF), to fill in: what the file
    states is written out (its loops as comments, its actuators), the rest is commented with the names the model
    offers. Returns ``(text, complete)``: complete when it loads as it is (the file states loops and actuators).
    ``pkm spec init FILE`` writes it.

    Raises:
        SpecError: as :func:`import_model`.
    """
    import json

    import pinocchio as pin

    from pkm.core.model.joints import retype_joints
    from pkm.core.model.urdf import load_model

    imp = import_model(path)
    model = retype_joints(load_model(imp.urdf, str(path)), imp.joint_types, str(path))
    scalar = [model.names[j] for j in range(1, model.njoints) if model.joints[j].nq == 1]
    frames = [f.name for f in model.frames[1:] if f.type in (pin.FrameType.BODY, pin.FrameType.OP_FRAME)]

    def listing(names: list[str], limit: int = 40) -> str:
        shown = ", ".join(names[:limit])
        return shown + (f", ... ({len(names)} in all)" if len(names) > limit else "")

    q = json.dumps
    lines = [f"# pkm closure spec for {path.name}, written by `pkm spec init`: fill in the lines marked TODO, then",
             f"#   pkm fk {path.stem}.closures.toml --joints NAME=VALUE ...",
             "# Values SI (m, rad). Format: the docstring of pkm.core.model.spec.",
             'format = "pkm.closures/1"',
             f"mechanism = {q(imp.name)}",
             f"urdf = {q(path.name)}"
             + ("" if imp.format == "urdf" else f"  # an {imp.format.upper()} file: its loops and joint types count"),
             f"# end_effector = {q(frames[-1] if frames else 'FRAME')}  # optional: a frame whose placement is the "
             "task; frames: " + listing(frames)]
    if imp.actuated:
        lines.append(f"actuated = {q(list(imp.actuated))}  # from the file's actuators")
    else:
        lines += ["actuated = []  # TODO: the driven joints (one coordinate each); the model's: " + listing(scalar)]
    lines += ["",
              "# [task]  # optional; without it the task is the actuated joints",
              '# components = ["x", "y", "z"]  # of end_effector: x y z roll pitch yaw, or ["pose"]',
              "# joints = []  # joints whose coordinates are outputs too", ""]
    if imp.closures:
        lines.append("# The loops the file closes (nothing to add):")
        lines += [f"#   {c.name}: {c.type} closure between {c.frame_a} and {c.frame_b}" for c in imp.closures]
    else:
        lines += ["# TODO: one [[closure]] per loop, between two frames of the tree that the loop ties",
                  "[[closure]]",
                  'name = "loop1"',
                  'type = "point"  # "point": the frames\' origins meet (a ball joint); "frame": the frames coincide',
                  f"frame_a = {q(frames[0] if frames else 'FRAME_A')}  # TODO",
                  f"frame_b = {q(frames[-1] if frames else 'FRAME_B')}  # TODO"]
    lines += ["",
              "# [joint_types]  # joints the file writes as revolutes that are \"spherical\", \"universal_ab\" "
              "(about axis a then b: \"universal_zy\"...) or \"fixed\""]
    lines += [f"# {k} = {q(v)}  # (from the file)" for k, v in imp.joint_types.items()]
    lines += ["",
              "# [reference]  # optional: pkm assembles the mechanism (pkm.assemble); the joints stated here are held",
              f"# {scalar[0] if scalar else 'joint'} = [0.0]", ""]
    return "\n".join(lines), bool(imp.actuated and imp.closures)


__all__ = ["READERS", "SUFFIXES", "Imported", "Reader", "import_model", "load_model_file", "load_path", "spec_skeleton",
           "with_file"]
