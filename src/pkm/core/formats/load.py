"""Loading a mechanism from files: every reader's result put through the builder
(:mod:`pkm.core.model.builder`). :func:`load_path` (behind :func:`pkm.load`) tries :data:`READERS` in order on a
file or folder, by content; :func:`load_model_file` reads an MJCF or SDF file alone; :func:`load_gepetto` a
Gepetto URDF + YAML pair; :func:`load_hyrodyn` a URDF with HyRoDyn's submechanisms file; :func:`load_package_model` a model an installed package ships, by name;
:func:`load_texts` the same kinds of files given as texts (an upload: no file name reaches the file system).

The readers themselves (:mod:`~pkm.core.formats.imported`, :mod:`~pkm.core.formats.gepetto`,
:mod:`~pkm.core.formats.packages`) only read files; this module, above the builder, makes mechanisms of them.
"""

from __future__ import annotations

import dataclasses
import re
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pkm.core.formats.base import FORMATS, Imported, by_root, suffixes
from pkm.core.formats.gepetto import find_gepetto, parse_yaml, read_gepetto, unmimic_motors
from pkm.core.formats.hyrodyn import MARKER as HYRODYN_MARKER
from pkm.core.formats.hyrodyn import PartialLoop, find_hyrodyn, read_hyrodyn
from pkm.core.formats.imported import format_of, import_model, root_tag, with_file
from pkm.core.formats.packages import model_file
from pkm.core.model.builder import from_files, from_imported, from_strings
from pkm.core.model.mechanism import Mechanism
from pkm.core.model.spec import FORMAT, ClosureSpec, TaskSpec, parse_toml, read_text_file
from pkm.core.model.urdf import check_urdf
from pkm.errors import InvalidInputError, PkmWarning, SpecError, SpecNameError

#: What ``task=`` takes (:func:`given_task`): a frame name, ``"FRAME:KIND"``, ``(frame, kind)`` or the spec's dict.
TaskGiven = str | Sequence[Any] | Mapping[str, Any] | None


@dataclass(frozen=True)
class Given:
    """What the caller states in code over what the files state (``pkm.load(path, actuated=..., task=...)``).

    Attributes:
        actuated: The driven joints (one coordinate each), or None: the file's.
        end_effector: The task's frame, or None (the task is then joint outputs).
        task: The task, or None: the file's (or, when ``actuated`` is given and the file's task is its actuated
            joints, the new actuated joints).
    """

    actuated: tuple[str, ...] | None = None
    end_effector: str | None = None
    task: TaskSpec | None = None

    @property
    def empty(self) -> bool:
        """Whether nothing is given (the file's own actuators and task are used)."""
        return self.actuated is None and self.task is None


def given(actuated: Sequence[str] | str | None = None, task: TaskGiven = None) -> Given:
    """``actuated=`` and ``task=`` of :func:`pkm.load` checked and read (see :func:`given_task` for ``task``).

    ``actuated``: joint names (a list, or one string of names separated by commas).

    Raises:
        InvalidInputError: ``actuated`` empty, not names, or a name twice; ``task`` in none of the forms, or with
            unknown components.
    """
    names: tuple[str, ...] | None = None
    if actuated is not None:
        listed = [n.strip() for n in actuated.split(",")] if isinstance(actuated, str) else actuated
        if (isinstance(listed, Mapping) or not isinstance(listed, Sequence)
                or not all(isinstance(n, str) and n for n in listed)):
            raise InvalidInputError("actuated", "expected joint names (a list of strings, or 'j1,j2')", actuated)
        names = tuple(listed)
        if not names or len(set(names)) != len(names):
            raise InvalidInputError("actuated", "name at least one joint, each once", actuated)
    if task is None:
        return Given(names)
    frame, spec_task = given_task(task, names or ("_",))
    return Given(names, frame, spec_task)


def given_task(task: TaskGiven, actuated: tuple[str, ...] = ("_",)) -> tuple[str | None, TaskSpec]:
    """The end effector and task that ``task=`` states, in the closure spec's terms (``end_effector`` and
    ``[task]``, :mod:`pkm.core.model.spec`), checked by the spec's own parser:

    * ``"FRAME"``: the frame's origin, components ``x, y, z`` [m] in the world frame;
    * ``"FRAME:KIND"``: KIND ``pose`` (the full placement) or components separated by commas (``"tip:x,z"``,
      of ``x y z roll pitch yaw``);
    * ``(frame, kind)``: kind as above, or a list of components;
    * the spec's dict: ``{"end_effector": frame, "components": [...], "joints": [...], "frames": {...}}``
      (``end_effector`` left out: joint outputs only).

    Raises:
        InvalidInputError: none of these forms; what the spec's parser refuses (unknown components...).
    """
    def kind_of(kind: object) -> list[str]:
        if isinstance(kind, str):
            return [c.strip() for c in kind.split(",")]
        if isinstance(kind, Sequence) and all(isinstance(c, str) for c in kind):
            return list(kind)
        raise InvalidInputError("task", f"a task's kind is 'pose' or components ('x,z', ['x', 'z']), got {kind!r}",
                                task)

    if isinstance(task, str):
        frame, sep, kind = task.partition(":")
        raw: dict[str, Any] = {"end_effector": frame, "task": {"components": kind_of(kind) if sep else
                                                                ["x", "y", "z"]}}
    elif isinstance(task, Mapping):
        table = dict(task)
        raw = {"task": table}
        if "end_effector" in table:
            raw["end_effector"] = table.pop("end_effector")
    elif isinstance(task, Sequence) and len(task) == 2 and isinstance(task[0], str):
        raw = {"end_effector": task[0], "task": {"components": kind_of(task[1])}}
    else:
        raise InvalidInputError("task", "expected 'FRAME', 'FRAME:KIND', (frame, kind) or the spec's dict "
                                        "{'end_effector': ..., 'components': [...], 'joints': [...]}", task)
    try:
        spec = ClosureSpec.from_dict({"format": FORMAT, "mechanism": "_", "urdf": "_", "actuated": list(actuated),
                                      **raw}, "task=")
    except SpecError as exc:
        raise InvalidInputError("task", str(exc).removeprefix("task=: "), task) from None
    return spec.end_effector, spec.task


def with_given(spec: ClosureSpec, g: Given, source: str) -> tuple[ClosureSpec, tuple[str, ...]]:
    """``spec`` with what the caller gave in code (:class:`Given`) in place of what its files state, and the notes
    for :attr:`~pkm.core.Mechanism.notes`: the actuated joints (a :class:`~pkm.errors.PkmWarning`, and its
    sentence as a note, when the files named others: the code wins), their drives' values kept for those still
    actuated; the task (when none is given and the files' task was their actuated joints, the new actuated
    joints)."""
    if g.empty:
        return spec, ()
    actuated, end_effector, task = spec.actuated, spec.end_effector, spec.task
    notes: tuple[str, ...] = ()
    if g.actuated is not None:
        if spec.actuated and set(spec.actuated) != set(g.actuated):
            notes = (f"actuated={list(g.actuated)} given in code replaces the actuated joints the files name, "
                     f"{list(spec.actuated)}",)
            warnings.warn(f"{source}: {notes[0]}", PkmWarning, stacklevel=4)
        actuated = g.actuated
        if g.task is None and not task.components and not task.frames and task.joints == spec.actuated:
            task = TaskSpec((), actuated)
    if g.task is not None:
        end_effector, task = g.end_effector, g.task
    return dataclasses.replace(spec, actuated=actuated, end_effector=end_effector, task=task,
                               actuators={j: v for j, v in spec.actuators.items() if j in actuated},
                               motors={m: c for m, c in spec.motors.items() if set(c) <= set(actuated)}), notes


def load_model_file(path: Path, given: Given = Given()) -> Mechanism:
    """The :class:`~pkm.core.Mechanism` of an MJCF or SDF file alone (or a URDF alone, an open tree): its loops,
    its actuators, the actuated joints as the task, no end effector, assembled (:func:`pkm.assemble`); ``given``:
    the actuated joints and task stated in code instead (:func:`with_given`).

    Raises:
        SpecError: as :func:`import_model`, or a file that names no actuated joint (SDF never does) when
            ``given`` names none: then ``actuated=`` in code, or a closure spec, must say which joints are driven.
    """
    imp = import_model(path)
    if not imp.actuated and given.actuated is None:
        raise SpecError(str(path), f"the {imp.format.upper()} file names no actuated joint: no actuators named: give "
                                   f"actuated=[...] to pkm.load (--actuated j1,j2 on the command line), or write a "
                                   f"closure spec with urdf = {path.name!r} and actuated = [...] beside it "
                                   f"(`pkm spec init {path}` writes one to fill in), and load the spec")
    spec = ClosureSpec(mechanism=imp.name, urdf=path.name, end_effector=None, actuated=imp.actuated,
                       closures=imp.closures, task=TaskSpec((), imp.actuated), reference=dict(imp.reference),
                       description=f"read from {path.name} ({imp.format.upper()})", joint_types=imp.joint_types,
                       floating_base=imp.floating_base, actuators=imp.actuators, springs=imp.springs,
                       motors=imp.motors)
    spec, read = with_given(spec, given, str(path))
    return from_strings(imp.urdf, spec, source=str(path), notes=imp.notes + read, seed=imp.seed, hold=imp.hold)


#: A reader's loader: the mechanism, given what the caller states in code (:class:`Given`, default nothing).
Loader = Callable[..., Mechanism]


@dataclass(frozen=True)
class Reader:
    """One way :func:`load_path` may read a path.

    Attributes:
        name: What it reads, for the messages.
        claim: ``claim(path)``: a function that loads the mechanism when the reader takes ``path`` (called with
            no argument, or with a :class:`Given`: what the caller states in code), else why it does not (one
            line). It raises :class:`~pkm.errors.SpecError` when it takes ``path`` but cannot
            tell which files go together.
    """

    name: str
    claim: Callable[[Path], Loader | str]


def _gepetto(path: Path) -> Loader | str:
    found = find_gepetto(path)
    return found if isinstance(found, str) else (lambda given=Given(): load_gepetto(*found, given=given))


def _hyrodyn(path: Path) -> Loader | str:
    found = find_hyrodyn(path)
    return found if isinstance(found, str) else (lambda given=Given(): load_hyrodyn(*found, given=given))


def _head(path: Path) -> str | None:
    """The file's text, or None when it cannot be read as text (the readers that take it say why)."""
    try:
        return read_text_file(path, "file")
    except SpecError:
        return None


def _closure_spec(path: Path) -> Loader | str:
    import tomllib


    if path.is_dir():
        specs = sorted(p.name for p in path.glob("*.toml"))
        return "a folder: give the spec file (" + (f"it holds {', '.join(specs[:4])}" if specs else "NAME.closures.toml") + ")"
    if path.suffix.lower() == ".toml":
        text = _head(path)
        fmt = by_root(root_tag(text)) if text is not None and text.lstrip().startswith("<") else None
        if fmt is not None:  # a model file named as a spec: said before TOML's parser says "line 1"
            def refuse(given: Given = Given()) -> Mechanism:
                raise SpecError(str(path), f"XML with the root element <{fmt.root}>, a {fmt.name.upper()} file, not a "
                                           f"pkm closure spec (TOML): name it {fmt.suffixes[0]}, and write the spec "
                                           f"beside it (`pkm spec init {path.with_suffix(fmt.suffixes[0])}`)")
            return refuse
        return lambda given=Given(): load_spec_file(path, given)
    if path.suffix.lower() in (".yaml", ".yml"):
        return "a YAML file: a pkm closure spec is TOML (NAME.closures.toml)"
    if path.suffix.lower() in suffixes():
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
    return lambda given=Given(): load_spec_file(path, given)


def _model_file(path: Path) -> Loader | str:
    if path.is_dir():
        return "a folder (give the model file)"
    kind = suffixes().get(path.suffix.lower())
    text = _head(path)
    root = root_tag(text) if text is not None else None
    roots = [f.root for f in FORMATS.values() if f.root]
    if kind is None and root not in roots:
        known = ", ".join(f"<{r}>" for r in roots)
        return (f"not XML with a root element {known}" if root is None
                else f"XML whose root element is <{root}>, not one of {known}")
    return lambda given=Given(): load_model_file(path, given)


#: The readers :func:`load_path` tries, in this order; the first that takes a path reads it.
READERS = (Reader("Gepetto URDF + YAML", _gepetto), Reader("HyRoDyn URDF + submechanisms.yml", _hyrodyn),
           Reader("pkm closure spec", _closure_spec),
           Reader("model file (URDF, MJCF, SDF)", _model_file))


def load_spec_file(path: Path, given: Given = Given()) -> Mechanism:
    """A closure spec file and the model file it names (:func:`~pkm.core.model.builder.from_files`), with what the
    caller states in code (:class:`Given`) in place of the spec's actuated joints and task: then the spec may
    leave ``actuated`` empty (a URDF and its closures, no drives named).

    Raises:
        SpecError: as :func:`~pkm.core.model.builder.from_files`.
    """
    try:
        if given.empty:
            return from_files(path)
        raw = parse_toml(read_text_file(path, "closure spec"), str(path))
        if isinstance(raw, dict) and given.actuated is not None and not raw.get("actuated"):
            raw["actuated"] = list(given.actuated)  # (the spec's parser asks for one; the code gives them)
        spec, read = with_given(ClosureSpec.from_dict(raw, str(path)), given, str(path))
        mech = from_files(path, spec)
    except SpecNameError as exc:
        if exc.source != str(path):
            raise
        raise located(exc, read_text_file(path, "closure spec"), "toml") from None
    mech.notes += read
    return mech


def located(exc: SpecNameError, text: str, kind: str) -> SpecNameError:
    """``exc`` (a name a closure spec or Gepetto YAML gives that the model lacks) with the line of ``text`` where that
    name is written, when it is written on one line only (else ``exc`` itself): for YAML (``kind="yaml"``) the lines
    PyYAML's composer gives its scalars; for TOML (``"toml"``), whose parser gives no positions, the lines where
    the name stands quoted."""
    if kind == "yaml":
        import yaml

        lines: set[int] = set()
        try:
            stack = [yaml.compose(text, Loader=yaml.SafeLoader)]
        except yaml.YAMLError:
            return exc
        while stack:
            node = stack.pop()
            if isinstance(node, yaml.ScalarNode):
                if node.value == exc.name:
                    lines.add(node.start_mark.line + 1)
            elif isinstance(node, yaml.SequenceNode):
                stack.extend(node.value)
            elif isinstance(node, yaml.MappingNode):
                stack.extend(n for pair in node.value for n in pair)
    else:
        quoted = (f'"{exc.name}"', f"'{exc.name}'")
        lines = {k for k, line in enumerate(text.splitlines(), 1) if any(q in line for q in quoted)}
    if len(lines) != 1:
        return exc
    what = re.search(rf" in {re.escape(exc.source)} \((.*?)\);", str(exc))
    where = f"{what.group(1)}, line {lines.pop()}" if what else f"line {lines.pop()}"
    return SpecNameError(exc.source, exc.kind, exc.name, exc.valid, where)


def load_path(path: Path, given: Given = Given()) -> Mechanism:
    """The mechanism of a file or folder, read by the first of :data:`READERS` that takes it, by content: a folder
    or YAML in Gepetto's convention (:mod:`pkm.core.formats.gepetto`), a URDF with HyRoDyn's submechanisms file
    (:mod:`pkm.core.formats.hyrodyn`), a closure spec (``.toml``, or TOML text
    with a ``format`` key), an MJCF or SDF file (or a URDF alone, which then asks for a spec); ``given``: the
    actuated joints and task stated in code, over the files' (:func:`with_given`).

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
            return claim(given)
        reasons.append(f"  {reader.name}: {claim}")
    raise SpecError(str(path), "no reader takes it:\n" + "\n".join(reasons))


def _read_text(name: str, text: str) -> Imported:
    """A model file given as text: read by the format of its root element, else of its name's suffix."""
    return format_of(name, text).read(text, name)


#: The file name of a Gepetto robot's URDF: its folder names the robot (``urdf/gepetto/battobot_6d/robot.urdf``).
GEPETTO_URDF = "robot.urdf"


def gepetto_name(urdf: str, folder: str | None) -> str:
    """The name of a Gepetto pair's mechanism: its URDF's stem, or, for :data:`GEPETTO_URDF`, its folder's name
    (``"robot"`` without one); :func:`pkm.load` and an upload (:func:`load_texts`' ``folder``) name it alike."""
    stem = Path(urdf).stem
    return (folder or "robot") if stem == "robot" else stem


def load_texts(files: Mapping[str, str], source: str = "<upload>", *, actuated: Sequence[str] | str | None = None,
               task: TaskGiven = None, folder: str | None = None) -> Mechanism:
    """The mechanism of files given as ``{name: text}`` (an upload), read as :func:`load_path` reads them from a
    folder, without touching the file system (the names are labels: a spec's ``urdf`` must name one of them):

    * a closure spec (``.toml``) and the model file it names (URDF, MJCF or SDF);
    * a Gepetto pair: a YAML and the URDF beside it (the only ``.urdf``);
    * a HyRoDyn pair: a YAML with a ``submechanisms`` list and the robot URDF (the one of its stem, else the only
      ``.urdf``);
    * an MJCF or SDF file alone (its loops and actuators from the file), or a URDF with URDF+ ``<loop>`` or urdfdom
      ``<constraint>`` elements.

    ``actuated``, ``task``: as :func:`pkm.load`'s (:func:`given`), over what the files state (:func:`with_given`): a
    file that names no actuated joint (SDF never does), or a spec or YAML that leaves them empty, loads with them.
    ``folder``: the name of the folder the files came from, naming a Gepetto pair's mechanism as :func:`pkm.load`
    names it from its folder (:func:`gepetto_name`: ``battobot_6d`` for ``battobot_6d/robot.urdf``).

    Raises:
        SpecError: none of these, or several; a spec naming a file that is not there; no actuated joint named by
            the files nor given; what the readers refuse.
        InvalidInputError: ``actuated`` or ``task`` in none of their forms (:func:`given`).
    """
    g = given(actuated, task)
    try:
        return _load_texts(files, source, g, folder)
    except SpecNameError as exc:
        label = exc.source.removeprefix(f"{source}:")
        if label not in files or Path(label).suffix.lower() not in (".toml", ".yaml", ".yml"):
            raise
        raise located(exc, files[label], "toml" if label.lower().endswith(".toml") else "yaml") from None


def _load_texts(files: Mapping[str, str], source: str, g: Given, folder: str | None = None) -> Mechanism:
    names = sorted(files)
    kind = {n: Path(n).suffix.lower() for n in names}
    specs = [n for n in names if kind[n] == ".toml"]
    yamls = [n for n in names if kind[n] in (".yaml", ".yml")]
    if len(specs) > 1 or len(yamls) > 1 or (specs and yamls):
        raise SpecError(source, f"give one closure spec (.toml) or one Gepetto YAML, not {specs + yamls}")
    if specs:
        where = f"{source}:{specs[0]}"
        raw = parse_toml(files[specs[0]], where)
        if isinstance(raw, dict) and g.actuated is not None and not raw.get("actuated"):
            raw["actuated"] = list(g.actuated)  # (the spec's parser asks for one; the code gives them)
        spec, read = with_given(ClosureSpec.from_dict(raw, where), g, where)
        if spec.urdf not in files:
            raise SpecError(where, f"urdf = {spec.urdf!r}: not among the files given ({names})")
        mech = from_imported(spec, _read_text(spec.urdf, files[spec.urdf]), where)
        mech.notes += read
        return mech
    if yamls and _is_hyrodyn(files[yamls[0]]):
        where = f"{source}:{yamls[0]}"
        stem = [n for n in names if n == str(Path(yamls[0]).with_suffix(".urdf"))]
        urdfs = stem or [n for n in names if kind[n] == ".urdf"]
        if len(urdfs) != 1:
            raise SpecError(source, f"a HyRoDyn submechanisms file goes with one robot URDF (or one named "
                                    f"{Path(yamls[0]).stem}.urdf); given {urdfs or 'none'}")
        imported = _read_text(urdfs[0], files[urdfs[0]])
        return _hyrodyn_mechanism(imported, urdfs[0], files[yamls[0]], Path(urdfs[0]).stem, where, g, ())
    if yamls:
        urdfs = [n for n in names if kind[n] == ".urdf"]
        if len(urdfs) != 1:
            raise SpecError(source, f"a Gepetto YAML goes with one URDF; given {urdfs or 'none'}")
        where = f"{source}:{yamls[0]}"
        imported = _read_text(urdfs[0], files[urdfs[0]])
        joints = [str(j.get("name")) for j in check_urdf(imported.urdf, urdfs[0]).findall("joint")]
        spec, read = read_gepetto(files[yamls[0]], urdfs[0], joints, gepetto_name(urdfs[0], folder), where)
        spec, replaced = with_given(spec, g, where)
        return _gepetto_mechanism(imported.urdf, spec, where, imported.notes + read + replaced)
    if len(names) != 1:
        raise SpecError(source, f"give a closure spec with its model file, a Gepetto YAML with its URDF, or one model "
                                f"file alone (MJCF, SDF, or a URDF with URDF+ <loop> or urdfdom <constraint> "
                                f"elements); given {names}")
    where = f"{source}:{names[0]}"
    imported = _read_text(names[0], files[names[0]])
    if imported.format == "urdf":
        raise SpecError(where, "the file names no loop (a plain URDF cannot hold one): send a closure spec with it")
    if not imported.actuated and g.actuated is None:
        raise SpecError(where, f"the {imported.format.upper()} file names no actuated joint: give actuated=[...], or "
                               "send a closure spec with it")
    spec = ClosureSpec(mechanism=imported.name, urdf=names[0], end_effector=None,
                       actuated=imported.actuated or g.actuated or (), closures=(),
                       task=TaskSpec((), imported.actuated or g.actuated or ()), reference={},
                       description=f"read from {names[0]} ({imported.format.upper()})")
    spec, read = with_given(spec, g, where)
    mech = from_imported(spec, imported, where)
    mech.notes += read
    return mech


def load_gepetto(urdf_path: Path, yaml_path: Path, notes: tuple[str, ...] = (), given: Given = Given()) -> Mechanism:
    """The :class:`~pkm.core.Mechanism` of a Gepetto-convention URDF + YAML pair (see the module doc); its
    :attr:`~pkm.core.Mechanism.notes` say what was interpreted (``notes`` first: how the files were paired);
    ``given``: the actuated joints and task stated in code (:func:`with_given`), over ``name_mot``."""

    urdf_path, yaml_path = Path(urdf_path), Path(yaml_path)
    imported = import_model(urdf_path)
    if imported.format != "urdf":
        raise SpecError(str(urdf_path), f"the model beside {yaml_path.name} is {imported.format.upper()}, not URDF: "
                                        "Gepetto's convention pairs a YAML with a URDF")
    joints = [str(j.get("name")) for j in check_urdf(imported.urdf, str(urdf_path)).findall("joint")]
    name = gepetto_name(urdf_path.name, urdf_path.parent.name)
    text = read_text_file(yaml_path, "YAML")
    try:
        spec, read = read_gepetto(text, urdf_path.name, joints, name, str(yaml_path))
        spec, replaced = with_given(spec, given, str(yaml_path))
        return _gepetto_mechanism(imported.urdf, spec, str(yaml_path), tuple(notes) + imported.notes + read + replaced)
    except SpecNameError as exc:
        if exc.source != str(yaml_path):
            raise
        raise located(exc, text, "yaml") from None


def _gepetto_mechanism(urdf: str, spec: ClosureSpec, source: str, notes: tuple[str, ...]) -> Mechanism:
    """The mechanism of a Gepetto pair read: the ``<mimic>`` of the followers named as motors dropped, as the
    toolbox loads them (:func:`~pkm.core.formats.gepetto.unmimic_motors`: a :class:`~pkm.errors.PkmWarning` and a
    note naming each coupling dropped)."""
    urdf, dropped = unmimic_motors(urdf, spec.actuated, source)
    if dropped:
        warnings.warn(f"{source}: {dropped[0]}", PkmWarning, stacklevel=4)
    return from_strings(urdf, spec, source=source, notes=notes + dropped)


def _is_hyrodyn(text: str) -> bool:
    try:
        raw = parse_yaml(text)
    except SpecError:
        return False
    return isinstance(raw, dict) and isinstance(raw.get(HYRODYN_MARKER), list)


def load_hyrodyn(urdf_path: Path, yaml_path: Path, notes: tuple[str, ...] = (), given: Given = Given()) -> Mechanism:
    """The :class:`~pkm.core.Mechanism` of a robot URDF and HyRoDyn's ``submechanisms.yml``
    (:mod:`pkm.core.formats.hyrodyn`); ``notes`` first (how the files were paired); ``given``: the actuated joints
    and task stated in code (:func:`with_given`), over the file's."""
    urdf_path, yaml_path = Path(urdf_path), Path(yaml_path)
    imported = import_model(urdf_path)
    if imported.format != "urdf":
        raise SpecError(str(urdf_path), f"the model beside {yaml_path.name} is {imported.format.upper()}, not URDF: "
                                        "HyRoDyn pairs its submechanisms file with a URDF")
    name = urdf_path.stem
    text = read_text_file(yaml_path, "YAML")
    try:
        return _hyrodyn_mechanism(imported, urdf_path.name, text, name, str(yaml_path), given, tuple(notes))
    except SpecNameError as exc:
        if exc.source != str(yaml_path):
            raise
        raise located(exc, text, "yaml") from None


def _hyrodyn_mechanism(imported: Imported, urdf_name: str, yaml_text: str, name: str, source: str, given: Given,
                       notes: tuple[str, ...]) -> Mechanism:
    urdf, spec, read, partial = read_hyrodyn(yaml_text, imported.urdf, urdf_name, name or "robot", source)
    spec, replaced = with_given(spec, given, source)
    mech = from_strings(urdf, spec, source=source, notes=notes + imported.notes + read + replaced)
    implied = [_implied(mech, loop, source) for loop in partial]
    mech.notes += tuple(implied)
    return mech


def _implied(mech: Mechanism, loop: PartialLoop, source: str) -> str:
    """The note saying that the translations ``loop`` leaves out are implied by the closures at the reference (the
    closures' Jacobian keeps its rank without them); else a SpecError: read as a point closure they would remove
    a motion the file leaves free."""
    import numpy as np
    import pinocchio as pin

    from pkm.core.differential.velocity import RTOL
    from pkm.core.kinematics import constraints

    q = mech.q_reference
    J = constraints.jacobian(mech, q)
    start = sum(3 if c.type == "point" else 6 for c in mech.spec.closures[:[c.name for c in mech.spec.closures]
                                                                        .index(loop.closure)])
    R = mech.data.oMf[mech.model.getFrameId(loop.predecessor, pin.FrameType.BODY)].rotation
    stated = loop.stated @ R.T @ J[start:start + 3]  # (the stated rows, in the predecessor's frame)
    rest = np.vstack([J[:start], stated, J[start + 3:]])

    def rank(A: np.ndarray) -> int:
        s = np.linalg.svd(A, compute_uv=False)
        return int(np.sum(s > RTOL * s[0])) if s.size and s[0] > 0 else 0

    full, partial = rank(J), rank(rest)
    if full != partial:
        raise SpecError(source, f"closure {loop.closure!r} (predecessor {loop.predecessor!r}) states "
                                f"{len(loop.stated)} translation axes of 3: the others are not implied by the loops "
                                f"at the zero configuration (the closures' rank {partial} becomes {full} with them), so "
                                "a point closure would remove a motion the file leaves free; pkm closes a point "
                                "(three translations) or a frame (six)")
    return (f"closure {loop.closure!r}: its file states {len(loop.stated)} translation axes of 3; read as a point "
            f"closure, the others implied by the loops at the zero configuration (the closures' Jacobian has rank "
            f"{full} with them and without)")


_PACKAGE_FILES: dict[tuple[str, int, int], Imported] = {}  # (path, mtime [ns], size): the file read


def _package_file(path: Path) -> Imported:
    """:func:`import_model` of an installed package's file, read once per process while the file is unchanged
    (Cassie's SDF: half the time of a load); a file that cannot be read raises each time."""
    try:
        st = path.stat()
    except OSError:
        return import_model(path)  # (its SpecError)
    key = (str(path), st.st_mtime_ns, st.st_size)
    if key not in _PACKAGE_FILES:
        if len(_PACKAGE_FILES) >= 8:
            _PACKAGE_FILES.pop(next(iter(_PACKAGE_FILES)))
        _PACKAGE_FILES[key] = import_model(path)
    return _PACKAGE_FILES[key]


def load_package_model(name: str, given: Given = Given()) -> Mechanism:
    """The :class:`~pkm.core.Mechanism` of model ``name`` (``<package>:<model>``): the package's file, read where
    it is installed, with the loops and joint types it states and the spec pkm ships (actuated joints, more joint
    types); assembled (:func:`pkm.assemble`).

    Raises:
        UnknownNameError: no such model (the valid names listed).
        SpecError: the package is not installed, or its file is missing or refused by its reader.
    """

    spec_path, path = model_file(name)
    imported = _package_file(path)
    spec, read = with_given(with_file(ClosureSpec.load(spec_path), imported, str(spec_path)), given, name)
    return from_strings(imported.urdf, spec, source=f"{name} ({path})", notes=imported.notes + read)


__all__ = ["GEPETTO_URDF", "READERS", "Given", "Loader", "Reader", "gepetto_name", "given", "given_task",
           "load_gepetto", "load_hyrodyn", "load_model_file", "load_package_model", "load_path", "load_spec_file",
           "with_given"]
