"""A model file in any format pkm reads, turned into its one representation (:class:`~pkm.core.formats.base.Imported`:
URDF text plus what a closure spec adds: loops, joint types, actuators): :func:`import_model` dispatches on the
file's root element and suffix; :func:`with_file` adds what the file states to a closure spec;
:func:`spec_skeleton` writes a spec to fill in. Making mechanisms of them is :mod:`pkm.core.formats.load`'s."""

from __future__ import annotations

import dataclasses
import re
import warnings
from pathlib import Path

from pkm.core.formats.base import FORMATS, Format, Imported, by_root, suffixes
from pkm.core.model.spec import ClosureSpec, read_text_file
from pkm.core.model.springs import spring_notes
from pkm.core.model.urdf import check_urdf, gazebo_springs, limit_notes
from pkm.errors import PkmWarning, SpecError


def root_tag(text: str) -> str | None:
    """The name of the document's first element (after the declaration and comments), or None."""
    body = re.sub(r"<\?.*?\?>|<!--.*?-->", "", text[:65536], flags=re.DOTALL)
    m = re.search(r"<\s*([A-Za-z_][\w.-]*)", body)
    return m.group(1) if m else None


def format_of(name: str | Path, text: str) -> Format:
    """The format a model file is read as: its root element's (``text``), else its name's suffix's, else URDF's."""
    return by_root(root_tag(text)) or FORMATS.get(suffixes().get(Path(name).suffix.lower(), ""), FORMATS["urdf"])


def import_model(path: Path) -> Imported:
    """Read the model file at ``path`` with the registered format (:data:`~pkm.core.formats.base.FORMATS`) whose
    root element it has (a URDF named ``.xml`` is a URDF), else the one of its suffix; another is read as URDF.
    A suffix that names another format than the root element (``.urdf``, ``.sdf``, ``.mjcf``; ``.xml`` names any XML)
    is said: a note (:attr:`Imported.notes`) and a :class:`~pkm.errors.PkmWarning` naming the file, the root element
    and its line.

    Raises:
        SpecError: the file is missing, too large, malformed, or uses what its reader refuses.
    """
    named = FORMATS.get(suffixes().get(path.suffix.lower(), ""))
    if named is not None and named.opens:  # (USD: binary crate files, layers that name others)
        if not path.is_file():
            raise SpecError(str(path), f"cannot read {named.name.upper()}: not a regular file")
        return named.read("", str(path))
    fmt = named or FORMATS["urdf"]
    text = read_text_file(path, fmt.name.upper())
    fmt = format_of(path, text)
    imp = fmt.read(text, str(path))
    if named is not None and named is not fmt and path.suffix.lower() != ".xml":  # (.xml: any XML, URDF too)
        line = _root_line(text)
        said = (f"read as {fmt.name.upper()} by its root element <{fmt.root}>" + (f" (line {line})" if line else "")
                + f", though its suffix {path.suffix!r} names {named.name.upper()}")
        warnings.warn(f"{path}: {said}", PkmWarning, stacklevel=2)
        imp = dataclasses.replace(imp, notes=(*imp.notes, said))
    return imp


def _root_line(text: str) -> int | None:
    """The line of the document's first element (as :func:`root_tag` finds it), or None."""
    body = re.sub(r"<\?.*?\?>|<!--.*?-->", lambda m: "\n" * m.group(0).count("\n"), text[:65536], flags=re.DOTALL)
    m = re.search(r"<\s*[A-Za-z_]", body)
    return body[:m.start()].count("\n") + 1 if m else None


def read_urdf(text: str, source: str = "<urdf>") -> Imported:
    """A URDF file (its loops come from a closure spec); exporters' "unlimited" limits noted; the joint springs of
    Gazebo's URDF extension read (:func:`~pkm.core.model.urdf.gazebo_springs`) and noted."""
    root = check_urdf(text, source)
    springs = gazebo_springs(root, source)
    return Imported(text, (), {}, (), str(root.get("name") or Path(source).stem), "urdf",
                    notes=limit_notes(root) + spring_notes(springs), springs=springs)


def with_file(spec: ClosureSpec, imp: Imported, source: str) -> ClosureSpec:
    """``spec`` with the loops, joint types, floating base, springs, the spec's actuated joints' drive values and the
    motors of its differentials (those on the spec's actuated joints) of the model file it names added (the spec's win, a drive's or a spring's field by field; a joint the spec's
    ``[joint_types]`` makes ``"fixed"`` keeps no spring: held rigid).

    Raises:
        SpecError: a closure named both in the spec and in the file.
    """
    if not imp.closures and not imp.joint_types and imp.floating_base is None and not imp.reference \
            and not imp.actuators and not imp.springs and not imp.motors:
        return spec
    clash = sorted({c.name for c in spec.closures} & {c.name for c in imp.closures})
    if clash:
        raise SpecError(source, f"closure {clash[0]!r} is both in the spec and in {spec.urdf!r}; rename the spec's")
    joint_types = {**imp.joint_types, **spec.joint_types}
    return dataclasses.replace(spec, closures=imp.closures + spec.closures, joint_types=joint_types,
                               floating_base=spec.floating_base or imp.floating_base,
                               reference={**imp.reference, **spec.reference},
                               actuators={j: {**imp.actuators.get(j, {}), **spec.actuators.get(j, {})}
                                          for j in spec.actuated if j in imp.actuators or j in spec.actuators},
                               springs={j: {**imp.springs.get(j, {}), **spec.springs.get(j, {})}
                                        for j in {**imp.springs, **spec.springs} if joint_types.get(j) != "fixed"},
                               motors={**{m: c for m, c in imp.motors.items() if set(c) <= set(spec.actuated)},
                                       **spec.motors})


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
    lines += ["", "# Drives (optional; pkm.core.model.actuators): per actuated joint, over what the file states:"]
    for joint in imp.actuated or scalar[:1]:
        stated = imp.actuators.get(joint, {})
        lines.append(f"# [actuators.{joint}]" + ("" if stated else "  # for example:"))
        lines += [f"# {k} = {v!r}  # (from the file)" for k, v in stated.items()] or \
            ["# rotor_inertia = 3.3e-5  # kg m^2 (kg: a linear motor's moving mass)", "# gear_ratio = 50.0",
             "# viscous = 0.02  # N m s/rad", "# coulomb = 0.1  # N m",
             "# effort_limit = 20.0  # N m, continuous", "# peak_effort = 60.0  # N m",
             "# velocity_limit = 6.0  # rad/s"]
    lines += ["",
              "# [reference]  # optional: pkm assembles the mechanism (pkm.assemble); the joints stated here are held",
              f"# {scalar[0] if scalar else 'joint'} = [0.0]", ""]
    return "\n".join(lines), bool(imp.actuated and imp.closures)


__all__ = ["format_of", "import_model", "read_urdf", "root_tag", "spec_skeleton",
           "with_file"]
