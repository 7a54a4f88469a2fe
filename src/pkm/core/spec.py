"""The loop-closure spec: what a URDF tree cannot say about a parallel mechanism.

A URDF describes a tree. A parallel mechanism is a tree whose leaves are tied
back together. The closure spec, a small TOML file stored next to the URDF
(``urdf/<name>.closures.toml``), says which frames are tied, which joints are
driven, which frame is the end effector, which coordinates describe its task,
which working modes exist, and an assembled reference configuration.

Format ``pkm.closures/1`` (all values SI: m, rad)::

    format = "pkm.closures/1"
    mechanism = "delta"              # a name
    urdf = "delta.urdf"              # the tree, relative to this file
    end_effector = "platform"        # a frame of the URDF
    actuated = ["motor_1", ...]      # 1-DOF joints driven by motors
    default_branch = "knee_out"      # optional, a key of [branch]

    [task]                           # the output coordinates
    components = ["x", "y", "z"]     # subset of x y z roll pitch yaw, or ["pose"]
    joints = []                      # joints whose coordinates are also outputs

    [[closure]]                      # one table per loop
    name = "ball_1"
    type = "point"                   # "point": frame origins coincide (3 eq.)
    frame_a = "leg1_tip"             # "frame": the two frames coincide (6 eq.)
    frame_b = "platform_ball_1"

    [branch.knee_out]                # a working mode: signs of joint coordinates
    description = "..."
    signs = { knee_1 = -1, knee_2 = -1, knee_3 = -1 }

    [reference]                      # an assembled configuration of the tree
    motor_1 = [0.1]                  # joint name = its configuration vector
    platform = [0, 0, -0.3, 0, 0, 0, 1]   # free-flyer: x y z qx qy qz qw

    [parameters]                     # the design that generated the files (informative)
    R = 0.15

Task components: ``x, y, z`` are the end-effector origin in the world frame;
``roll, pitch, yaw`` are the Z-Y-X Euler angles of its orientation,
``R = Rz(yaw) Ry(pitch) Rx(roll)``. ``pose`` stands for the full placement; its
velocity is the twist ``[v; w]`` of the end-effector origin in world axes.

A branch fixes the sign of joint coordinates that vanish at a singularity that
separates working modes (for example the relative elbow angle of a leg).
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

from pkm.errors import SpecError

FORMAT = "pkm.closures/1"
CLOSURE_TYPES = ("point", "frame")
TASK_COMPONENTS = ("x", "y", "z", "roll", "pitch", "yaw")


@dataclass(frozen=True)
class Closure:
    """One loop closure: frame ``frame_a`` tied to frame ``frame_b``.

    Attributes:
        name: Name of the loop.
        type: ``"point"`` (origins coincide, 3 equations) or ``"frame"`` (placements coincide, 6).
        frame_a: First frame (usually the tip of a leg).
        frame_b: Second frame (usually on the platform).
    """

    name: str
    type: str
    frame_a: str
    frame_b: str


@dataclass(frozen=True)
class TaskSpec:
    """The output coordinates of the mechanism.

    Attributes:
        components: End-effector components (see module doc) or ``("pose",)``.
        joints: Joint names whose coordinates are outputs too (e.g. a reconfiguration angle).
    """

    components: tuple[str, ...]
    joints: tuple[str, ...] = ()

    @property
    def is_pose(self) -> bool:
        return self.components == ("pose",)

    @property
    def size(self) -> int:
        return (6 if self.is_pose else len(self.components)) + len(self.joints)


@dataclass(frozen=True)
class Branch:
    """A working mode: required signs of some joint coordinates."""

    name: str
    signs: Mapping[str, int]
    description: str = ""


@dataclass(frozen=True)
class ClosureSpec:
    """The parsed content of a closure-spec file (see module docstring)."""

    mechanism: str
    urdf: str
    end_effector: str
    actuated: tuple[str, ...]
    closures: tuple[Closure, ...]
    task: TaskSpec
    reference: Mapping[str, tuple[float, ...]]
    branches: Mapping[str, Branch] = field(default_factory=dict)
    default_branch: str | None = None
    parameters: Mapping[str, float | str] = field(default_factory=dict)
    description: str = ""

    # ------------------------------------------------------------------ reading
    @classmethod
    def from_toml(cls, text: str, source: str = "<string>") -> ClosureSpec:
        """Parse a spec from TOML text. Raises :class:`SpecError` on any problem."""
        try:
            raw = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise SpecError(source, f"not valid TOML: {exc}") from None
        return cls.from_dict(raw, source)

    @classmethod
    def load(cls, path: str | Path) -> ClosureSpec:
        """Read a spec file. Raises :class:`SpecError` if it is missing or malformed."""
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as exc:
            raise SpecError(str(path), f"cannot read closure spec: {exc.strerror}") from None
        return cls.from_toml(text, str(path))

    @classmethod
    def from_dict(cls, raw: Mapping, source: str = "<dict>") -> ClosureSpec:
        def need(table: Mapping, key: str, typ: type | tuple[type, ...], where: str = ""):
            if key not in table:
                raise SpecError(source, f"missing key {where}{key!r}")
            val = table[key]
            if not isinstance(val, typ):
                raise SpecError(source, f"key {where}{key!r} must be {_typename(typ)}, got {type(val).__name__}")
            return val

        def names(table: Mapping, key: str, where: str = "") -> tuple[str, ...]:
            val = need(table, key, list, where)
            if not all(isinstance(v, str) and v for v in val):
                raise SpecError(source, f"{where}{key!r} must be a list of non-empty strings")
            if len(set(val)) != len(val):
                raise SpecError(source, f"{where}{key!r} lists a name twice")
            return tuple(val)

        if not isinstance(raw, Mapping):
            raise SpecError(source, "a closure spec must be a table")
        fmt = need(raw, "format", str)
        if fmt != FORMAT:
            raise SpecError(source, f"unsupported format {fmt!r}; this pkm reads {FORMAT!r}")
        known = {"format", "mechanism", "urdf", "end_effector", "actuated", "default_branch", "task",
                 "closure", "branch", "reference", "parameters", "description"}
        unknown = sorted(set(raw) - known)
        if unknown:
            raise SpecError(source, f"unknown keys {unknown}; known keys: {sorted(known)}")

        actuated = names(raw, "actuated")
        if not actuated:
            raise SpecError(source, "'actuated' must name at least one joint")

        task_raw = need(raw, "task", dict)
        components = names(task_raw, "components", "task.")
        joints = names(task_raw, "joints", "task.") if "joints" in task_raw else ()
        if components != ("pose",):
            bad = [c for c in components if c not in TASK_COMPONENTS]
            if bad:
                raise SpecError(source, f"task.components {bad} unknown; use {list(TASK_COMPONENTS)} or ['pose']")
        task = TaskSpec(components, joints)
        if task.size == 0:
            raise SpecError(source, "the task has no coordinates")

        closures = []
        for k, c in enumerate(raw.get("closure", [])):
            where = f"closure[{k}]."
            if not isinstance(c, dict):
                raise SpecError(source, f"closure[{k}] must be a table")
            typ = need(c, "type", str, where)
            if typ not in CLOSURE_TYPES:
                raise SpecError(source, f"{where}type {typ!r} unknown; use one of {list(CLOSURE_TYPES)}")
            closures.append(Closure(need(c, "name", str, where), typ, need(c, "frame_a", str, where),
                                    need(c, "frame_b", str, where)))
        if len({c.name for c in closures}) != len(closures):
            raise SpecError(source, "two closures share a name")

        branches = {}
        for bname, b in need(raw, "branch", dict).items() if "branch" in raw else []:
            if not isinstance(b, dict):
                raise SpecError(source, f"branch.{bname} must be a table")
            signs = need(b, "signs", dict, f"branch.{bname}.")
            if not all(v in (-1, 1) and isinstance(v, int) for v in signs.values()):
                raise SpecError(source, f"branch.{bname}.signs values must be +1 or -1")
            branches[bname] = Branch(bname, dict(signs), str(b.get("description", "")))
        default_branch = raw.get("default_branch")
        if default_branch is not None and default_branch not in branches:
            raise SpecError(source, f"default_branch {default_branch!r} is not among the branches {sorted(branches)}")

        reference = {}
        for jname, vals in need(raw, "reference", dict).items():
            if not isinstance(vals, list) or not all(isinstance(v, (int, float)) for v in vals):
                raise SpecError(source, f"reference.{jname} must be a list of numbers")
            if not all(math.isfinite(v) for v in vals):
                raise SpecError(source, f"reference.{jname} holds a non-finite number")
            reference[jname] = tuple(float(v) for v in vals)

        params = raw.get("parameters", {})
        if not isinstance(params, dict) or not all(isinstance(v, (int, float, str)) for v in params.values()):
            raise SpecError(source, "parameters must be a table of numbers or strings")

        return cls(
            mechanism=need(raw, "mechanism", str),
            urdf=need(raw, "urdf", str),
            end_effector=need(raw, "end_effector", str),
            actuated=actuated,
            closures=tuple(closures),
            task=task,
            reference=reference,
            branches=branches,
            default_branch=default_branch,
            parameters=dict(params),
            description=str(raw.get("description", "")),
        )

    # ------------------------------------------------------------------ writing
    def to_toml(self) -> str:
        """Serialise deterministically (the checked-in files are compared byte for byte)."""
        out = [
            "# pkm loop-closure spec (see pkm.core.spec). Units: SI (m, rad).",
            f"format = {_tv(FORMAT)}",
            f"mechanism = {_tv(self.mechanism)}",
        ]
        if self.description:
            out.append(f"description = {_tv(self.description)}")
        out += [
            f"urdf = {_tv(self.urdf)}",
            f"end_effector = {_tv(self.end_effector)}",
            f"actuated = {_tv(list(self.actuated))}",
        ]
        if self.default_branch is not None:
            out.append(f"default_branch = {_tv(self.default_branch)}")
        out += ["", "[task]", f"components = {_tv(list(self.task.components))}",
                f"joints = {_tv(list(self.task.joints))}"]
        for c in self.closures:
            out += ["", "[[closure]]", f"name = {_tv(c.name)}", f"type = {_tv(c.type)}",
                    f"frame_a = {_tv(c.frame_a)}", f"frame_b = {_tv(c.frame_b)}"]
        for b in self.branches.values():
            out += ["", f"[branch.{b.name}]"]
            if b.description:
                out.append(f"description = {_tv(b.description)}")
            out.append("signs = { " + ", ".join(f"{k} = {v:d}" for k, v in b.signs.items()) + " }")
        out += ["", "[reference]"]
        out += [f"{k} = {_tv(list(v))}" for k, v in self.reference.items()]
        if self.parameters:
            out += ["", "[parameters]"]
            out += [f"{k} = {_tv(v)}" for k, v in self.parameters.items()]
        return "\n".join(out) + "\n"

    def dump(self, path: str | Path) -> None:
        Path(path).write_text(self.to_toml(), encoding="utf-8")


def _typename(typ: type | tuple[type, ...]) -> str:
    names = {str: "a string", list: "a list", dict: "a table", int: "an integer", float: "a number"}
    if isinstance(typ, tuple):
        return " or ".join(names.get(t, t.__name__) for t in typ)
    return names.get(typ, typ.__name__)


def _tv(value) -> str:
    """A TOML literal for the few value types the spec uses."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(float(value))
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_tv(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} to TOML")
