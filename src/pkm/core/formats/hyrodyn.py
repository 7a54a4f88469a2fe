"""HyRoDyn's ``submechanisms.yml`` (DFKI's Hybrid Robot Dynamics; Phobos writes the same list in a SMURF model's
submechanisms file): a robot URDF, the spanning tree of the whole robot, and a YAML file that splits it into
submechanisms and states the loop closures of the numerical ones.

What pkm reads (the keys HyRoDyn's parser reads, ``RobotModel_HyRoDyn::load_robotmodel`` in dfki-ric/hyrodyn's
``src/robot_model_hyrodyn.cpp``, and the geometry of its ``NumericalLoopConstraints`` constructor,
``src/NumericalLoopConstraints.cpp``; an example: ``robot/rh5v2/submechanisms/submechanisms_reduced_numerical.yml``):

* ``submechanisms``: a list; of each entry ``name``, ``type``, ``contextual_name``, ``jointnames_spanningtree``,
  ``jointnames_active`` (the drives: pkm's actuated joints, in file order), ``jointnames_independent`` (the
  submechanism's output joints: pkm's task is these joints' values), and, for ``type: NUMERICAL``,
  ``loop_constraints``: per loop ``cut_joint`` (Phobos's SMURF writes ``joint``), ``predecessor_body``,
  ``successor_body`` and ``constraint_axes``, each ``{name, axis}``, ``axis`` a spatial vector
  ``[wx, wy, wz, vx, vy, vz]`` (RBDL's order: rotation first) in the predecessor body's frame.
* HyRoDyn places each loop's cut frame at the predecessor body's origin, oriented as that body, in the spanning
  tree's zero configuration, and ties a copy of it fixed to the successor body (``X_s``) along the constraint axes.
  pkm does the same: a frame ``<cut_joint>_cut`` on the successor body, placed where the predecessor body's frame is
  at zero, and a ``point`` closure (the axes span the three translations) or a ``frame`` closure (all six) between
  the predecessor body and it. The zero configuration is thus assembled, as HyRoDyn's is.
* Axes that span only some translations (a planar loop: HyRoDyn's ``rrPr`` example states y and z) are read as a
  point closure when the translations the file leaves out are implied by the others at the zero configuration (the
  closures' Jacobian has the same rank with and without them, so they remove no motion), said in a note; otherwise,
  or with rotation axes other than all three, the loop is refused, naming it.
* A submechanism of a serial type (``R``, ``RR``, ``3R``, ``P``...: its spanning tree, independent and active joints
  alike) adds its active joints and no loop. Another type without ``loop_constraints`` (HyRoDyn's analytic
  submechanisms, ``rrPr``, ``2SPRR+1U``, ``2SPU+1U``, ``3UPS``...: their loop geometry lives in HyRoDyn's C++ code,
  not in the files) is refused, naming the type and what to add (``type: NUMERICAL`` and its ``loop_constraints``).
* Not read (said in the notes): ``file_path`` (the submechanism's own URDF: pkm reads the robot URDF, whose zero
  configuration places the same bodies), ``jointnames`` (with fixed joints), the constraint axes'
  ``baumgarte_stabilization_parameter``, ``exoskeletons``; a first submechanism with no active joint (HyRoDyn's
  floating base) is read as none: the base is fixed.

The file is recognised by content: a YAML mapping with a ``submechanisms`` list. Its URDF is the one of its stem
(``leg.yml``: ``leg.urdf``), else the folder's only URDF that no submechanism names as its ``file_path``. A Phobos
SMURF file (``<model>.smurf``, a YAML whose ``files`` list names the URDF and the submechanisms file, relative to it:
hyrodyn's ``robot/leg/smurf/leg.smurf``) is read as the pair it lists.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pkm.core.formats.gepetto import parse_yaml
from pkm.core.model.spec import Closure, ClosureSpec, TaskSpec, read_text_file
from pkm.errors import SpecError, SpecNameError

MARKER = "submechanisms"
_YAML_SUFFIXES = (".yml", ".yaml")
#: A serial submechanism's type: revolutes and prismatics in a chain (``R``, ``RR``, ``3R``, ``RRR``, ``P``).
_SERIAL = re.compile(r"^(\d*[RP])+$")
_KEYS = ("name", "type", "contextual_name", "jointnames", "jointnames_spanningtree", "jointnames_active",
         "jointnames_independent", "file_path", "loop_constraints")


@dataclass(frozen=True)
class PartialLoop:
    """A loop whose constraint axes span only some translations: read as a point closure when the others are implied
    (the module doc). ``stated``: the stated translation directions (k x 3) in the predecessor body's frame."""

    closure: str
    predecessor: str
    stated: np.ndarray


def hyrodyn_yaml(path: Path) -> str | None:
    """None when the file at ``path`` is a YAML mapping with a ``submechanisms`` list, else why it is not."""
    try:
        raw = parse_yaml(read_text_file(path, "YAML"), str(path))
    except SpecError as exc:
        return str(exc).removeprefix(f"{path}: ")
    if not isinstance(raw, dict) or not isinstance(raw.get(MARKER), list):
        return "not a YAML mapping with a submechanisms list"
    return None


def _file_paths(path: Path) -> set[str]:
    raw = parse_yaml(read_text_file(path, "YAML"), str(path))
    subs = raw.get(MARKER, []) if isinstance(raw, dict) else []
    return {Path(str(s["file_path"])).name for s in subs if isinstance(s, dict) and s.get("file_path")}


def _urdf_for(yml: Path) -> tuple[Path, tuple[str, ...]]:
    own = yml.with_suffix(".urdf")
    if own.is_file():
        return own, ()
    sub = _file_paths(yml)
    urdfs = sorted(p for p in yml.parent.glob("*.urdf") if p.is_file() and p.name not in sub)
    if len(urdfs) != 1:
        raise SpecError(str(yml), f"a HyRoDyn submechanisms file with {len(urdfs)} robot URDFs beside it "
                                  f"({', '.join(p.name for p in urdfs) or 'none'}; the submechanisms' file_path "
                                  f"URDFs left out): name the robot's URDF {yml.stem}.urdf, or load the URDF by its "
                                  "path")
    return urdfs[0], (f"{yml.name} read with {urdfs[0].name}, the folder's only robot URDF",)


def find_hyrodyn(path: Path) -> tuple[Path, Path, tuple[str, ...]] | str:
    """``(urdf, yaml, notes)`` when ``path`` is a HyRoDyn model (a folder holding a submechanisms YAML and its URDF,
    such a YAML, or a URDF beside one: the module doc), else why it is not (one line).

    Raises:
        SpecError: it is one, but which URDF goes with it cannot be told.
    """
    path = Path(path)
    if path.is_dir():
        found = sorted(p for p in path.iterdir() if p.suffix.lower() in _YAML_SUFFIXES and p.is_file()
                       and hyrodyn_yaml(p) is None)
        if not found:
            return "a folder with no YAML file holding a submechanisms list"
        if len(found) > 1:
            raise SpecError(str(path), f"{len(found)} HyRoDyn submechanisms files in the folder "
                                       f"({', '.join(p.name for p in found)}): load the one you mean by its path")
        urdf, notes = _urdf_for(found[0])
        return urdf, found[0], notes
    if path.suffix.lower() == ".smurf" and path.is_file():
        return _smurf(path)
    if path.suffix.lower() in _YAML_SUFFIXES:
        why = hyrodyn_yaml(path)
        if why is not None:
            return why
        urdf, notes = _urdf_for(path)
        return urdf, path, notes
    if path.suffix.lower() == ".urdf" and path.is_file():
        beside = sorted(p for p in path.parent.iterdir() if p.suffix.lower() in _YAML_SUFFIXES and p.is_file()
                        and hyrodyn_yaml(p) is None and path.name not in _file_paths(p))
        if len(beside) == 1:
            return path, beside[0], (f"{path.name} read with {beside[0].name}",)
        return "a URDF with no (or several) HyRoDyn submechanisms files beside it"
    return "neither a folder, nor YAML, nor a URDF, nor a SMURF file"


def _smurf(path: Path) -> tuple[Path, Path, tuple[str, ...]] | str:
    """The URDF and the submechanisms file a SMURF file lists (Phobos's ``<model>.smurf``: ``files``, paths relative to
    it), or why it names no such pair."""
    try:
        raw = parse_yaml(read_text_file(path, "SMURF"), str(path))
    except SpecError as exc:
        return str(exc).removeprefix(f"{path}: ")
    files = raw.get("files") if isinstance(raw, dict) else None
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        return "a SMURF file without a files list"
    listed = [path.parent / f for f in files]
    urdfs = [p for p in listed if p.suffix.lower() == ".urdf" and p.is_file()]
    subs = [p for p in listed if p.suffix.lower() in _YAML_SUFFIXES and p.is_file() and hyrodyn_yaml(p) is None]
    if len(urdfs) != 1 or len(subs) != 1:
        return (f"a SMURF file listing {len(urdfs)} URDF and {len(subs)} submechanisms files found (pkm reads a SMURF "
                "model's loops from its one HyRoDyn submechanisms file, with its one URDF)")
    return urdfs[0], subs[0], (f"{path.name}: read as its files {urdfs[0].name} and {subs[0].name}",)


def _names(sub: dict, key: str, where: str, source: str, required: bool = True) -> list[str]:
    value = sub.get(key, None if required else [])
    if value is None:
        raise SpecError(source, f"{where}: missing key {key!r}")
    if not isinstance(value, list) or not all(isinstance(n, str) and n for n in value):
        raise SpecError(source, f"{where}: {key} must be a list of joint names, got {value!r}")
    return list(value)


def _axes(loop: dict, where: str, source: str) -> np.ndarray:
    raw = loop.get("constraint_axes")
    if not isinstance(raw, list) or not raw:
        raise SpecError(source, f"{where}: constraint_axes must be a list of {{name, axis}}, got {raw!r}")
    rows = []
    for k, ax in enumerate(raw):
        vec = ax.get("axis") if isinstance(ax, dict) else None
        try:
            row = np.array(vec, dtype=float)
        except (TypeError, ValueError):
            row = np.zeros(0)
        if row.shape != (6,) or not np.all(np.isfinite(row)) or not np.any(row):
            raise SpecError(source, f"{where}: constraint_axes[{k}].axis must be 6 finite numbers, not all zero "
                                    f"([wx, wy, wz, vx, vy, vz]), got {vec!r}")
        rows.append(row)
    return np.array(rows)


def read_hyrodyn(yaml_text: str, urdf_text: str, urdf_name: str, mechanism: str, source: str = "<yaml>") \
        -> tuple[str, ClosureSpec, tuple[str, ...], tuple[PartialLoop, ...]]:
    """The URDF text with the loops' successor frames added, the closure spec the submechanisms file states (see the
    module doc), the notes on what was interpreted or not read, and the loops whose axes span only some translations
    (:class:`PartialLoop`: the loader checks that the others are implied).

    Raises:
        SpecError: not YAML, keys missing or of the wrong type, an analytic submechanism without loop constraints,
            constraint axes pkm cannot close (rotations without all six).
        SpecNameError: a joint or body the URDF lacks.
    """
    import pinocchio as pin
    from lxml import etree

    from pkm.core.model.urdf import check_urdf, load_model

    raw = parse_yaml(yaml_text, source)
    if not isinstance(raw, dict) or not isinstance(raw.get(MARKER), list) or not raw[MARKER]:
        raise SpecError(source, "a HyRoDyn submechanisms file is a mapping with a non-empty submechanisms list")
    root = check_urdf(urdf_text, urdf_name)
    joints = [str(j.get("name")) for j in root.findall("joint")]
    links = [str(lk.get("name")) for lk in root.findall("link")]
    notes: list[str] = []
    ignored = sorted({k for s in raw[MARKER] if isinstance(s, dict) for k in s if k not in _KEYS})
    other = [str(k) for k in raw if k != MARKER]
    if other or ignored:
        notes.append(f"{Path(source).name}: not read: " + ", ".join([*other, *ignored]))
    unread = sorted({k for s in raw[MARKER] if isinstance(s, dict) for k in ("file_path", "jointnames") if k in s})
    if unread:
        notes.append(f"{Path(source).name}: {' and '.join(unread)} not read (pkm reads the robot URDF {urdf_name}, "
                     "whose zero configuration places the same bodies)")
    model = load_model(urdf_text, urdf_name)
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))

    def placement(link: str, what: str) -> pin.SE3:
        if link not in links:
            raise SpecNameError(source, "link", link, links, what)
        return data.oMf[model.getFrameId(link, pin.FrameType.BODY)]

    actuated: list[str] = []
    outputs: list[str] = []
    closures: list[Closure] = []
    partial: list[PartialLoop] = []
    added: list[str] = []
    for i, sub in enumerate(raw[MARKER]):
        if not isinstance(sub, dict):
            raise SpecError(source, f"submechanisms[{i}] must be a mapping, got {sub!r}")
        kind = str(sub.get("type", ""))
        where = f"submechanisms[{i}] ({sub.get('contextual_name') or sub.get('name') or kind})"
        tree, active = _names(sub, "jointnames_spanningtree", where, source), _names(sub, "jointnames_active",
                                                                                      where, source)
        independent = _names(sub, "jointnames_independent", where, source)
        for key, names in (("jointnames_spanningtree", tree), ("jointnames_active", active),
                           ("jointnames_independent", independent)):
            for n in names:
                if n not in joints:
                    raise SpecNameError(source, "joint", n, joints, f"{where} {key}")
        if not active:
            if i == 0:
                notes.append(f"{where}: no active joint, HyRoDyn's floating base: read as none (the base fixed)")
                continue
            raise SpecError(source, f"{where}: no active joint (HyRoDyn takes that for a floating base, first only)")
        loops = sub.get("loop_constraints")
        if loops is None:
            if not (_SERIAL.match(kind) or kind == "NUMERICAL") or set(tree) != set(independent):
                raise SpecError(source, f"{where}: type {kind!r} without loop_constraints: its loop geometry lives "
                                        "in HyRoDyn's code (an analytic submechanism), not in the files; add to it "
                                        "type: NUMERICAL and loop_constraints (per loop cut_joint, predecessor_body, "
                                        "successor_body, constraint_axes), as HyRoDyn's numerical submechanisms "
                                        "state them")
        elif not isinstance(loops, list) or not loops:
            raise SpecError(source, f"{where}: loop_constraints must be a non-empty list, got {loops!r}")
        for k, loop in enumerate(loops or []):
            lw = f"{where} loop_constraints[{k}]"
            if not isinstance(loop, dict):
                raise SpecError(source, f"{lw} must be a mapping, got {loop!r}")
            cut = loop.get("cut_joint", loop.get("joint"))
            if not isinstance(cut, str) or not cut:
                raise SpecError(source, f"{lw}: cut_joint must be a joint name, got {cut!r}")
            if cut not in joints:
                raise SpecNameError(source, "joint", cut, joints, f"{lw} cut_joint")
            pred, succ = (loop.get(key) for key in ("predecessor_body", "successor_body"))
            for key, body in (("predecessor_body", pred), ("successor_body", succ)):
                if not isinstance(body, str) or not body:
                    raise SpecError(source, f"{lw}: {key} must be a link name, got {body!r}")
            T0p = placement(str(pred), f"{lw} predecessor_body")
            T0s = placement(str(succ), f"{lw} successor_body")
            axes = _axes(loop, lw, source)
            rot, trans = axes[:, :3], axes[:, 3:]
            rank_rot = np.linalg.matrix_rank(rot) if np.any(rot) else 0
            name = f"{cut}_loop"
            while name in {c.name for c in closures}:
                name += "_"
            if rank_rot == 3 and np.linalg.matrix_rank(axes) == 6:
                ctype = "frame"
            elif rank_rot == 0:
                ctype = "point"
                if np.linalg.matrix_rank(trans) < 3:
                    partial.append(PartialLoop(name, str(pred), trans / np.linalg.norm(trans, axis=1)[:, None]))
            else:
                raise SpecError(source, f"{lw}: constraint axes {axes.tolist()} constrain some rotations but not "
                                        "all six directions: pkm closes a point (the three translations, vx vy vz) "
                                        "or a frame (all six); state those")
            frame_b = f"{cut}_cut"
            while frame_b in links or frame_b in added:
                frame_b += "_"
            added.append(frame_b)
            X = T0s.actInv(T0p)  # the predecessor's frame at zero, in the successor's (HyRoDyn's X_s)
            rpy = pin.rpy.matrixToRpy(X.rotation)
            etree.SubElement(root, "link", name=frame_b)
            joint = etree.SubElement(root, "joint", name=f"{frame_b}_fixed", type="fixed")
            etree.SubElement(joint, "parent", link=str(succ))
            etree.SubElement(joint, "child", link=frame_b)
            etree.SubElement(joint, "origin", xyz=" ".join(repr(float(x)) for x in X.translation),
                             rpy=" ".join(repr(float(x)) for x in rpy))
            closures.append(Closure(name, ctype, str(pred), frame_b))
        actuated += [n for n in active if n not in actuated]
        outputs += [n for n in independent if n not in outputs]
    if added:
        notes.append(f"{Path(source).name}: each loop's cut frame placed at its predecessor body's origin in the zero "
                     f"configuration and fixed to its successor body, as HyRoDyn places it: frames {', '.join(added)}")
    spec = ClosureSpec(mechanism=mechanism, urdf=urdf_name, end_effector=None, actuated=tuple(actuated),
                       closures=tuple(closures), task=TaskSpec((), tuple(outputs)), reference={},
                       description=f"read from {Path(source).name} (HyRoDyn submechanisms)")
    return etree.tostring(root, encoding="unicode"), spec, tuple(notes), tuple(partial)


__all__ = ["MARKER", "PartialLoop", "find_hyrodyn", "hyrodyn_yaml", "read_hyrodyn"]
