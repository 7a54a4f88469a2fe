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
    floating_base = "pelvis"         # optional: a free-flyer joint on the world carrying everything;
                                     # its pose is an input the solvers hold

    [task]                           # the output coordinates
    components = ["x", "y", "z"]     # subset of x y z roll pitch yaw, or ["pose"]
    joints = []                      # joints whose coordinates are also outputs

    [task.frames]                    # optional: other frames' coordinates (several feet)
    right_toe = ["x", "z"]           # named right_toe.x, right_toe.z

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

    [joint_types]                    # joints the URDF writes as revolutes that are not
    ball_1 = "spherical"             # a ball joint (a unit quaternion, 3 velocities)
    cardan_1 = "universal_zy"        # a universal joint: about the joint frame's z, then its (turned) y
    lock_1 = "fixed"                 # welded at its neutral value

    [actuators.motor_1]              # optional: the drive of an actuated joint (pkm.core.model.actuators)
    rotor_inertia = 3.3e-5           # kg m^2; also gear_ratio, armature, viscous, coulomb,
    gear_ratio = 50.0                # effort_limit, peak_effort, velocity_limit (inf: none),
    stiffness = "2000 N m/rad"       # the servo stiffness (a number in SI, or a string with its unit)

    [springs.knee_spring]            # optional: a joint's spring and damper (pkm.core.model.springs),
    stiffness = 1500.0               # N m/rad; rest = its rest angle (rad), damping (N m s/rad);
    rest = 0.0                       # applied by the dynamics (the damping as the joint's friction)

    [transmission.left_ankle]        # optional: a closed sub-mechanism's name and output joints
    outputs = ["ankle_pitch", "ankle_roll"]   # (pkm.transmissions; pkm.core.transmissions.decompose)

    [links.proximal_1]               # optional: a link's compliance (pkm.stiffness; pkm.core.compliance.links):
    compliance = [[1e-8, 0, 0, 0, 0, 0], ...]  # 6 x 6, (dp, dtheta) per (f, m) at each thing it carries, the
                                     # link frame's axes, SI (m/N, m/(N m); rad/N, rad/(N m)), symmetric positive
                                     # definite

    [collision]                      # optional: the pairs of bodies pkm.clearance checks, over its rule
    exclude = [["rod_1", "rod_2"]]   # (pkm.core.collision.geometry): pairs not checked; include: pairs
    include = []                     # the rule leaves out (neighbours, closures, contact) checked

    [motors.waist_left]              # optional: a motor driving several actuated joints through a constant
    waist_yaw = 1.0                  # linear map (a differential: MuJoCo's fixed tendon, ros2_control's
    waist_roll = 1.0                 # DifferentialTransmission): its coordinate is sum(coef * q_joint)
                                     # (pkm.core.model.motors)

``[joint_types]`` values (:mod:`pkm.core.model.joints`): ``"spherical"``; ``"universal_ab"`` with ``a``, ``b`` two
distinct axes of ``x``, ``y``, ``z`` (``R = exp(q1 [a]) exp(q2 [b])``, Gepetto's ``UJOINT_AB``), ``"universal"``
being ``"universal_xy"``; ``"fixed"``.

Task components: ``x, y, z`` are the end-effector origin in the world frame;
``roll, pitch, yaw`` are the Z-Y-X Euler angles of its orientation,
``R = Rz(yaw) Ry(pitch) Rx(roll)``. ``pose`` stands for the full placement; its
velocity is the twist ``[v; w]`` of the end-effector origin in world axes.

A branch fixes the sign of joint coordinates that vanish at a singularity that
separates working modes (for example the relative elbow angle of a leg).

What the loaders refuse
-----------------------

:meth:`ClosureSpec.load`, :meth:`ClosureSpec.from_toml` and :func:`pkm.load` (:func:`~pkm.core.model.builder.from_files`) raise :class:`~pkm.errors.SpecError` for:

* a path that is not a regular file: FIFOs, devices (``/dev/zero``) and directories are refused
  from ``fstat`` before anything is read, so a load never blocks; a file larger than 16 MiB
  (refused from its size) or not UTF-8; a path that is not a ``str``/``PathLike`` is an
  :class:`~pkm.errors.InvalidInputError`;
* TOML that does not parse (truncated files included) or nests too deeply;
* another ``format`` than ``pkm.closures/1``, unknown top-level keys, missing keys, a value of
  the wrong TOML type (a string or a boolean where a number is expected, a number where a
  name is expected...), empty names, a name listed twice, unknown task components or closure
  types, a closure that ties a frame to itself, branch signs other than the integers +1/-1;
* ``[reference]`` values that are not lists of finite numbers of magnitude <= 1e6 (SI);
  ``[parameters]`` values that are not finite numbers or strings;
* a ``urdf`` path that is absolute, contains ``..`` or would leave the spec's folder once
  symbolic links are resolved (:func:`~pkm.core.model.builder.from_files` opens the
  spec and that URDF, nothing else);
* once the URDF is loaded (see :mod:`pkm.core.model.urdf` for what it refuses): a frame or joint
  named by the spec that the URDF lacks (:class:`~pkm.errors.SpecNameError`, also an
  :class:`~pkm.errors.UnknownNameError` listing the valid names), an actuated, task or branch
  joint with more than one coordinate, a ``[reference]`` that misses a joint, gives it the
  wrong number of coordinates or a non-unit quaternion.
"""

from __future__ import annotations

import json
import math
import os
import re
import stat
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Any

import numpy as np

from pkm.core.model.actuators import parse_table
from pkm.core.model.springs import parse_springs
from pkm.errors import InvalidInputError, SpecError
from pkm.validation import ABSURD, symmetric_positive_definite

FORMAT = "pkm.closures/1"
MAX_FILE_BYTES = 16 * 1024 * 1024  # URDF, spec and motion files larger than this are refused
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
        frames: Other frames and their components (``[task.frames]``), after the end effector's.
    """

    components: tuple[str, ...]
    joints: tuple[str, ...] = ()
    #: Other frames whose coordinates are outputs too, ``{frame: components}`` (several feet of a leg).
    frames: Mapping[str, tuple[str, ...]] = field(default_factory=dict)

    @property
    def is_pose(self) -> bool:
        return self.components == ("pose",)

    @property
    def size(self) -> int:
        def n(components: tuple[str, ...]) -> int:
            return 6 if components == ("pose",) else len(components)
        return n(self.components) + sum(n(c) for c in self.frames.values()) + len(self.joints)


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
    end_effector: str | None  # None: no end effector (the task is joint outputs only)
    actuated: tuple[str, ...]
    closures: tuple[Closure, ...]
    task: TaskSpec
    reference: Mapping[str, tuple[float, ...]]
    branches: Mapping[str, Branch] = field(default_factory=dict)
    default_branch: str | None = None
    parameters: Mapping[str, float | str] = field(default_factory=dict)
    description: str = ""
    #: Joints the URDF writes as revolutes that are ``"spherical"``, ``"universal"`` / ``"universal_ab"`` (``ab``
    #: two distinct of ``x``, ``y``, ``z``) or ``"fixed"`` (:mod:`pkm.core.model.joints`).
    joint_types: Mapping[str, str] = field(default_factory=dict)
    #: A free-flyer joint on the world that carries the whole mechanism (a legged robot's pelvis): its pose is an
    #: input, held by the solvers where ``q`` puts it (see :class:`pkm.core.Mechanism`).
    floating_base: str | None = None
    #: ``{actuated joint: {field: value}}``: the drives' values the spec states (``[actuators.<joint>]``, see
    #: :mod:`pkm.core.model.actuators`), over those of the model file.
    actuators: Mapping[str, Mapping[str, float | str]] = field(default_factory=dict)
    #: ``{joint: {"stiffness", "rest", "damping": value}}``: the joints' springs and dampers (``[springs.<joint>]``,
    #: :mod:`pkm.core.model.springs`), over those of the model file; read, written and applied by the dynamics.
    springs: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    #: ``{transmission name: output joints}``: the ``[transmission.<name>]`` tables, the outputs
    #: :func:`pkm.transmissions` gives the closed sub-mechanism that holds them.
    transmissions: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    #: ``{motor: {actuated joint: coefficient}}``: the ``[motors.<name>]`` tables, motors that drive several
    #: actuated joints through a constant linear map (:mod:`pkm.core.model.motors`).
    motors: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    #: ``{link: 6 x 6 compliance}``: the ``[links.<link>] compliance`` tables, the links :func:`pkm.stiffness` takes
    #: compliant by default (:mod:`pkm.core.compliance.links`), rows of SI numbers.
    links: Mapping[str, tuple[tuple[float, ...], ...]] = field(default_factory=dict)
    #: ``[collision] exclude``: pairs of bodies (links with collision geometry) :func:`pkm.clearance` does not check.
    collision_exclude: tuple[tuple[str, str], ...] = ()
    #: ``[collision] include``: pairs it checks though its rule leaves them out (:mod:`pkm.core.collision.geometry`).
    collision_include: tuple[tuple[str, str], ...] = ()

    # ------------------------------------------------------------------ reading
    @property
    def task_is_actuated(self) -> bool:
        """Whether the task is the actuated joints' values (no end effector, components or frames): the task a format
        that cannot state one gives back on reading."""
        return (self.end_effector is None and not self.task.components and not self.task.frames
                and tuple(self.task.joints) == tuple(self.actuated))

    @classmethod
    def from_toml(cls, text: str, source: str = "<string>") -> ClosureSpec:
        """Parse a spec from TOML text. Raises :class:`SpecError` on any problem."""
        if not isinstance(text, str):
            raise InvalidInputError("text", f"expected the spec's TOML text as a str, got {type(text).__name__}", text)
        if len(text) > MAX_FILE_BYTES:
            raise SpecError(source, f"closure spec longer than {MAX_FILE_BYTES} characters")
        try:
            text.encode("utf-8")  # names end up in Pinocchio (C++), which takes UTF-8 only
        except UnicodeEncodeError as exc:
            raise SpecError(source, f"closure spec text cannot be encoded as UTF-8 (character {exc.start})") from None
        return cls.from_dict(parse_toml(text, source), source)

    @classmethod
    def load(cls, path: str | Path) -> ClosureSpec:
        """Read a spec file. Raises :class:`SpecError` if it is missing or malformed."""
        path = as_path(path, "path")
        return cls.from_toml(read_text_file(path, "closure spec"), str(path))

    @classmethod
    def from_dict(cls, raw: Mapping, source: str = "<dict>") -> ClosureSpec:
        def need(table: Mapping, key: str, typ: type | tuple[type, ...], where: str = "") -> Any:
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
                 "closure", "branch", "reference", "parameters", "description", "joint_types", "floating_base",
                 "actuators", "springs", "transmission", "motors", "collision", "links"}
        unknown = sorted(set(raw) - known)
        if unknown:
            raise SpecError(source, f"unknown keys {unknown}; known keys: {sorted(known)}")

        actuated = names(raw, "actuated")
        if not actuated:
            raise SpecError(source, "'actuated' must name at least one joint")

        end_effector = raw.get("end_effector")
        if end_effector is not None and (not isinstance(end_effector, str) or not end_effector):
            raise SpecError(source, "key 'end_effector' must be a non-empty string (or left out: no end effector)")
        if "task" not in raw and end_effector is not None:
            raise SpecError(source, "missing key 'task': with an end_effector, [task] says which of its coordinates "
                                    "are outputs (components = ['x', 'y', 'z'], or ['pose'])")
        task_raw = need(raw, "task", dict) if "task" in raw else {"components": [], "joints": list(actuated)}
        components = names(task_raw, "components", "task.") if "components" in task_raw else ()
        joints = names(task_raw, "joints", "task.") if "joints" in task_raw else ()
        if components and end_effector is None:
            raise SpecError(source, f"task.components {list(components)} need an end_effector frame; without one "
                                    "the task is joint outputs only (task.joints)")
        def checked(components: tuple[str, ...], where: str) -> tuple[str, ...]:
            if not components and where != "task.components":
                raise SpecError(source, f"{where} is empty: give its components (x y z roll pitch yaw, or pose)")
            if components != ("pose",):
                bad = [c for c in components if c not in TASK_COMPONENTS]
                if bad:
                    raise SpecError(source, f"{where} {bad} unknown; use {list(TASK_COMPONENTS)} or ['pose']")
            return components

        checked(components, "task.components")
        frames_raw = need(task_raw, "frames", dict, "task.") if "frames" in task_raw else {}
        frames = {str(f): checked(names(frames_raw, f, "task.frames."), f"task.frames.{f}") for f in frames_raw}
        if end_effector in frames:
            raise SpecError(source, f"task.frames names the end effector {end_effector!r}: give its components in "
                                    "task.components")
        unknown_task = sorted(set(task_raw) - {"components", "joints", "frames"})
        if unknown_task:
            raise SpecError(source, f"unknown keys {unknown_task} in [task]; known: components, joints, frames")
        task = TaskSpec(components, joints, frames)
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
            closure = Closure(need(c, "name", str, where), typ, need(c, "frame_a", str, where),
                              need(c, "frame_b", str, where))
            if closure.frame_a == closure.frame_b:
                raise SpecError(source, f"{where}frame_a and frame_b are both {closure.frame_a!r}: a closure ties "
                                        "two different frames")
            closures.append(closure)
        if len({c.name for c in closures}) != len(closures):
            raise SpecError(source, "two closures share a name")

        branches = {}
        for bname, b in need(raw, "branch", dict).items() if "branch" in raw else []:
            if not isinstance(b, dict):
                raise SpecError(source, f"branch.{bname} must be a table")
            signs = need(b, "signs", dict, f"branch.{bname}.")
            if not all(isinstance(v, int) and not isinstance(v, bool) and v in (-1, 1) for v in signs.values()):
                raise SpecError(source, f"branch.{bname}.signs values must be +1 or -1")
            branches[bname] = Branch(bname, dict(signs), str(b.get("description", "")))
        default_branch = raw.get("default_branch")
        if default_branch is not None and not isinstance(default_branch, str):
            raise SpecError(source, f"default_branch must be a string, got {type(default_branch).__name__}")
        if default_branch is not None and default_branch not in branches:
            raise SpecError(source, f"default_branch {default_branch!r} is not among the branches {sorted(branches)}")

        reference = {}
        if not isinstance(raw.get("reference", {}), dict):
            raise SpecError(source, f"key 'reference' must be a table, got {type(raw['reference']).__name__}")
        for jname, vals in raw.get("reference", {}).items():
            if not isinstance(vals, list) or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                     for v in vals):
                raise SpecError(source, f"reference.{jname} must be a list of numbers")
            if not all(math.isfinite(v) for v in vals):
                raise SpecError(source, f"reference.{jname} holds a non-finite number")
            if not all(abs(v) <= ABSURD for v in vals):
                raise SpecError(source, f"reference.{jname} holds a number beyond {ABSURD:g} (SI units: m, rad)")
            reference[jname] = tuple(float(v) for v in vals)

        joint_types = raw.get("joint_types", {})
        if not isinstance(joint_types, dict) or not all(isinstance(v, str) for v in joint_types.values()):
            raise SpecError(source, "joint_types must be a table of joint name = \"spherical\" | \"universal_ab\" | "
                                    "\"fixed\" (see pkm.core.model.joints)")

        floating_base = raw.get("floating_base")
        if floating_base is not None and (not isinstance(floating_base, str) or not floating_base):
            raise SpecError(source, "key 'floating_base' must name the free-flyer joint of the base")

        params = raw.get("parameters", {})
        if not isinstance(params, dict) or not all(
                isinstance(v, str) or (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v))
                for v in params.values()):
            raise SpecError(source, "parameters must be a table of finite numbers or strings")
        for key in ("mechanism", "urdf"):
            if not need(raw, key, str):
                raise SpecError(source, f"key {key!r} must not be empty")
        if not isinstance(raw.get("description", ""), str):
            raise SpecError(source, "description must be a string")
        urdf = PurePosixPath(raw["urdf"])
        if urdf.is_absolute() or ".." in urdf.parts or "\0" in raw["urdf"] or "\\" in raw["urdf"]:
            raise SpecError(source, f"urdf = {raw['urdf']!r}: the URDF path must be relative to the spec's folder "
                                    "and stay inside it (no absolute path, no '..'); copy the URDF next to the spec")

        actuators = parse_table(raw.get("actuators", {}), source)
        stray = [j for j in actuators if j not in actuated]
        if stray:
            raise SpecError(source, f"[actuators.{stray[0]}]: {stray[0]!r} is not an actuated joint; actuated: "
                                    f"{list(actuated)}")

        springs = parse_springs(raw.get("springs", {}), source)

        transmissions = {}
        for tname, table in need(raw, "transmission", dict).items() if "transmission" in raw else ():
            where = f"[transmission.{tname}] "
            if not isinstance(table, dict) or set(table) != {"outputs"}:
                raise SpecError(source, f"{where}must hold one key, outputs = [joint, ...]")
            transmissions[str(tname)] = names(table, "outputs", where)

        motors: dict[str, dict[str, float]] = {}
        for mname, table in need(raw, "motors", dict).items() if "motors" in raw else ():
            where = f"[motors.{mname}]"
            if not isinstance(table, dict) or not table or not all(
                    isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and abs(v) <= ABSURD
                    for v in table.values()):
                raise SpecError(source, f"{where} must be a table of actuated joint = finite coefficient (at least "
                                        "one)")
            stray = [j for j in table if j not in actuated]
            if stray:
                raise SpecError(source, f"{where}: {stray[0]!r} is not an actuated joint; actuated: {list(actuated)}")
            motors[str(mname)] = {str(j): float(v) for j, v in table.items()}

        links = {str(n): _compliance(t, f"[links.{n}]", source)
                 for n, t in (need(raw, "links", dict).items() if "links" in raw else ())}

        collision = need(raw, "collision", dict) if "collision" in raw else {}
        stray = sorted(set(collision) - {"exclude", "include"})
        if stray:
            raise SpecError(source, f"unknown keys {stray} in [collision]; known: exclude, include")
        pairs: dict[str, tuple[tuple[str, str], ...]] = {}
        for key in ("exclude", "include"):
            val = collision.get(key, [])
            if not isinstance(val, list) or not all(
                    isinstance(p, list) and len(p) == 2 and all(isinstance(n, str) and n for n in p) for p in val):
                raise SpecError(source, f"[collision] {key} must be a list of pairs of body names, "
                                        f'[["body_a", "body_b"], ...]')
            pairs[key] = tuple((str(a), str(b)) for a, b in val)

        return cls(
            mechanism=need(raw, "mechanism", str),
            urdf=need(raw, "urdf", str),
            end_effector=end_effector,
            actuated=actuated,
            closures=tuple(closures),
            task=task,
            reference=reference,
            branches=branches,
            default_branch=default_branch,
            parameters=dict(params),
            description=str(raw.get("description", "")),
            joint_types=dict(joint_types),
            floating_base=floating_base,
            actuators=actuators,
            springs=springs,
            transmissions=transmissions,
            motors=motors,
            links=links,
            collision_exclude=pairs["exclude"],
            collision_include=pairs["include"],
        )

    # ------------------------------------------------------------------ writing
    def to_toml(self) -> str:
        """Serialise deterministically: keys in a fixed order, every float as its shortest round-trip
        ``repr`` (the exact double; the checked-in files are compared as models, see
        :mod:`pkm.core.model.compare`, so another CPU's last bits do not matter)."""
        out = [
            "# pkm loop-closure spec (see pkm.core.model.spec). Units: SI (m, rad).",
            f"format = {_tv(FORMAT)}",
            f"mechanism = {_tv(self.mechanism)}",
        ]
        if self.description:
            out.append(f"description = {_tv(self.description)}")
        out += [
            f"urdf = {_tv(self.urdf)}",
        ]
        if self.end_effector is not None:
            out.append(f"end_effector = {_tv(self.end_effector)}")
        out.append(f"actuated = {_tv(list(self.actuated))}")
        if self.floating_base is not None:
            out.append(f"floating_base = {_tv(self.floating_base)}")
        if self.default_branch is not None:
            out.append(f"default_branch = {_tv(self.default_branch)}")
        out += ["", "[task]", f"components = {_tv(list(self.task.components))}",
                f"joints = {_tv(list(self.task.joints))}"]
        if self.task.frames:
            out += ["", "[task.frames]"] + [f"{_key(k)} = {_tv(list(v))}" for k, v in self.task.frames.items()]
        for c in self.closures:
            out += ["", "[[closure]]", f"name = {_tv(c.name)}", f"type = {_tv(c.type)}",
                    f"frame_a = {_tv(c.frame_a)}", f"frame_b = {_tv(c.frame_b)}"]
        for b in self.branches.values():
            out += ["", f"[branch.{_key(b.name)}]"]
            if b.description:
                out.append(f"description = {_tv(b.description)}")
            out.append("signs = { " + ", ".join(f"{_key(k)} = {v:d}" for k, v in b.signs.items()) + " }")
        if self.joint_types:
            out += ["", "[joint_types]"] + [f"{_key(k)} = {_tv(v)}" for k, v in self.joint_types.items()]
        for section, tables in (("actuators", self.actuators), ("springs", self.springs)):
            for joint, values in tables.items():
                if values:
                    out += ["", f"[{section}.{_key(joint)}]"] + [  # (a value with its unit as written)
                        f"{_key(k)} = {_tv(v if isinstance(v, str) else float(v))}" for k, v in values.items()]
        for tname, outputs in self.transmissions.items():
            out += ["", f"[transmission.{_key(tname)}]", f"outputs = {_tv(list(outputs))}"]
        for mname, coefs in self.motors.items():
            out += ["", f"[motors.{_key(mname)}]"] + [f"{_key(j)} = {_tv(float(c))}" for j, c in coefs.items()]
        for link, C in self.links.items():
            out += ["", f"[links.{_key(link)}]", "compliance = [" + ", ".join(_tv([float(v) for v in row]) for row in C)
                    + "]"]
        if self.collision_exclude or self.collision_include:
            out += ["", "[collision]"] + [f"{key} = {_tv([list(p) for p in pairs])}" for key, pairs in
                                          (("exclude", self.collision_exclude), ("include", self.collision_include))
                                          if pairs]
        out += ["", "[reference]"]
        out += [f"{_key(k)} = {_tv(list(v))}" for k, v in self.reference.items()]
        if self.parameters:
            out += ["", "[parameters]"]
            out += [f"{_key(k)} = {_tv(v)}" for k, v in self.parameters.items()]
        return "\n".join(out) + "\n"

    def dump(self, path: str | Path) -> None:
        Path(path).write_text(self.to_toml(), encoding="utf-8")


def as_path(path: object, name: str = "path") -> Path:
    """``path`` (str or path-like) as a :class:`~pathlib.Path`, or :class:`InvalidInputError`."""
    if isinstance(path, (str, os.PathLike)) and not isinstance(path, bytes):
        text = os.fspath(path)
        if isinstance(text, str) and text and "\0" not in text:
            return Path(text)
    raise InvalidInputError(name, f"expected a file path (str or pathlib.Path), got {type(path).__name__} {path!r}",
                            path)


def parse_toml(text: str, source: str) -> dict:
    """The TOML document ``text``; :class:`SpecError` naming ``source`` when it does not parse."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(source, f"not valid TOML: {exc}") from None
    except RecursionError:
        raise SpecError(source, "not valid TOML for pkm: arrays or tables nested too deeply") from None


def read_text_file(path: str | Path, what: str, max_bytes: int = MAX_FILE_BYTES) -> str:
    """The UTF-8 text of a regular file of at most ``max_bytes``.

    Never blocks and never reads without bound: a FIFO, a device (``/dev/zero``), a directory or
    a file larger than ``max_bytes`` is refused before reading.

    Raises:
        SpecError: The file is missing, unreadable, not a regular file, too large, or not UTF-8.
    """
    path = as_path(path)
    src = str(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as exc:
        raise SpecError(src, f"cannot read {what}: {exc.strerror}") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise SpecError(src, f"cannot read {what}: not a regular file")
        if st.st_size > max_bytes:
            raise SpecError(src, f"{what} is {st.st_size} bytes, more than the {max_bytes} accepted")
        chunks, size = [], 0
        while size <= max_bytes:
            chunk = os.read(fd, min(1 << 20, max_bytes + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as exc:
        raise SpecError(src, f"cannot read {what}: {exc.strerror}") from None
    finally:
        os.close(fd)
    if size > max_bytes:
        raise SpecError(src, f"{what} grew beyond the {max_bytes} bytes accepted while being read")
    try:
        return b"".join(chunks).decode("utf-8")
    except UnicodeDecodeError as exc:
        raise SpecError(src, f"{what} is not UTF-8 text (byte {exc.start})") from None


def _typename(typ: type | tuple[type, ...]) -> str:
    names = {str: "a string", list: "a list", dict: "a table", int: "an integer", float: "a number"}
    if isinstance(typ, tuple):
        return " or ".join(names.get(t, t.__name__) for t in typ)
    return names.get(typ, typ.__name__)


_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def _key(name: str) -> str:
    """A TOML key: bare when TOML allows it, else a quoted string (a joint named ``a/b`` or ``knee 1``)."""
    return name if _BARE_KEY.fullmatch(name) else _tv(name)


def _compliance(table: object, where: str, source: str) -> tuple[tuple[float, ...], ...]:
    """A ``[links.<link>]`` table's ``compliance``: 6 x 6 finite numbers, symmetric (1e-9 relative) and positive
    definite."""
    if not isinstance(table, dict) or set(table) != {"compliance"}:
        raise SpecError(source, f"{where} must hold one key, compliance = [[6 numbers] x 6] (SI)")
    rows = table["compliance"]
    if not (isinstance(rows, list) and len(rows) == 6 and all(
            isinstance(r, list) and len(r) == 6 and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                        and math.isfinite(v) for v in r) for r in rows)):
        raise SpecError(source, f"{where} compliance must be 6 rows of 6 finite numbers (SI: m/N, m/(N m); rad/N, "
                                "rad/(N m))")
    C = np.array(rows, dtype=float)
    if not symmetric_positive_definite(C):
        raise SpecError(source, f"{where} compliance must be symmetric positive definite")
    return tuple(tuple(float(v) for v in r) for r in rows)


def _tv(value: object) -> str:
    """A TOML literal for the few value types the spec uses (strings with every control character escaped)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(float(value))
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_tv(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} to TOML")
