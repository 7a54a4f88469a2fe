r"""The serial-equivalent model: the tree with only the output joints, every other body welded where the reference puts it.

Rule: every joint of a sub-mechanism that is not an output (the motors, the rods' joints) is locked at the
reference and its body welded to its parent there (Pinocchio's ``buildReducedModel``): its mass, centre of mass and
rotational inertia are carried by the nearest output above it, or by the transmission's root (a motor's crank and
its rod by the shank, a rod hung from the foot by the foot), so that the whole robot's mass and centre of mass at the
reference are the closed robot's; the motors' rotors' reflected inertia (an armature) is dropped. The outputs keep
their own armature, if the file gives one, in both models.

``ΔM`` and ``Δh`` (:class:`~pkm.core.transmissions.transmission.Transmission`) are what the sub-mechanism's serial
model **with those bodies welded** (:func:`~pkm.core.transmissions.coordinates.serial_tree`) lacks: the welded
bodies' motion relative to their anchor (a rod swinging as the foot turns, a crank turning), the rotors, and the
welded mass's own share taken back: ``M_s + ΔM = M_o`` and ``h_s + Δh = h_o`` exactly.

For a whole robot, :func:`serial_equivalent` locks every transmission's motors and passive joints at the reference:
the serial tree keeps the robot's serial joints and the outputs. Each output gets a **constant armature**, ``ΔM``'s
diagonal entry at the robot's reference (what a constant-armature model uses: exact at that pose for a diagonal
``ΔM``, neither its off-diagonal coupling nor its change with the pose nor ``Δh``), and **box limits** from its
transmission's feasible region (:mod:`pkm.core.transmissions.limits`: the largest box that holds the reference, or
the point ``around`` gives). :meth:`SerialEquivalent.urdf` and :meth:`SerialEquivalent.mjcf` write it;
:func:`write_serial_equivalent` writes both and a JSON data file describing each transmission for the kernels.
The joint springs (``[springs]``) of the joints the serial model keeps are in its MJCF and its URDF (Gazebo's
extension); those of the locked motors
and passive joints act through their loops, in the kernels' ``Δh``: the serial model's files lack them (a warning
names them).

Each transmission's ``ΔM`` and ``Δh`` are exact for its sub-mechanism with its root held. On a whole robot whose
root moves (a knee carrying an ankle, a floating base), the rods' coupling with the joints above the root is not in
them.
"""

from __future__ import annotations

import dataclasses
import json
import os
import re
import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
from lxml import etree

from pkm.core.analysis.region import SINGULARITY
from pkm.core.formats.to_mjcf import MIN_INERTIA, MIN_MASS, TIMESTEP, _joints, _num, _pose, qpos_of, write_spring
from pkm.core.formats.to_urdfplus import damping_of
from pkm.core.model.joints import reduced_model
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.spec import as_path
from pkm.core.model.urdf import urdf_from_model, write_gazebo_springs
from pkm.core.transmissions.decompose import transmissions as find
from pkm.core.transmissions.limits import OutputLimits, output_limits
from pkm.core.transmissions.transmission import Transmission
from pkm.errors import InvalidInputError, PkmWarning
from pkm.validation import instance_of


@dataclass(frozen=True)
class SerialEquivalent:
    """A whole robot's serial-equivalent model (module doc), what :func:`serial_equivalent` returns.

    Attributes:
        robot: The whole robot.
        transmissions: Its transmissions.
        model: The serial tree (Pinocchio): the robot's model with every transmission's motors and passive joints
            locked at the reference and their bodies welded to their parents there (mass kept); each output's
            ``armature`` is its own plus the constant armature.
        armature: ``{output: ΔM's diagonal entry at the reference}`` [kg m^2 or kg]: the constant armature a
            serial model uses in place of ``ΔM`` (today's practice; :func:`pkm.core.transmissions.fidelity` measures
            what it misses).
        limits: ``{joint: (lower, upper)}`` [rad or m]: each output's box limits
            (:func:`~pkm.core.transmissions.limits.output_limits`), the serial joints' stated limits.
        regions: ``{transmission: OutputLimits}``: the feasible regions the boxes come from, each box's point
            and its area against its region's.
        q_reference: The serial model's reference configuration (the robot's).
    """

    robot: Mechanism
    transmissions: tuple[Transmission, ...]
    model: pin.Model
    armature: dict[str, float]
    limits: dict[str, tuple[float, float]]
    regions: dict[str, OutputLimits]
    q_reference: np.ndarray

    @property
    def outputs(self) -> tuple[str, ...]:
        """Every transmission's outputs, in transmission order."""
        return tuple(o for t in self.transmissions for o in t.outputs)

    def urdf(self) -> str:
        """The serial model as URDF (Pinocchio loads it): the outputs' box limits; the kept joints' springs
        (``[springs]``) with Gazebo's URDF extension (:func:`~pkm.core.model.urdf.write_gazebo_springs`), their
        damping as ``<dynamics damping>``; URDF has no armature (the data file and the MJCF carry it)."""
        text, types = urdf_from_model(self.model, name=f"{self.robot.name}_serial", limits=self.limits,
                                      source=self.robot.source)
        springs = {n: t for n, t in self.robot.spec.springs.items() if self.model.existJointName(n)}
        if springs:
            root = etree.fromstring(text.encode())
            write_gazebo_springs(root, springs, damping_of(self.robot))
            etree.indent(root, space="  ")
            text = etree.tostring(root, encoding="unicode") + "\n"
        if types:
            text = text.replace("<robot ", f"<!-- joint types URDF cannot state: {types} -->\n<robot ", 1)
        return text

    def mjcf(self, *, timestep: float = TIMESTEP) -> str:
        """The serial model as MJCF (MuJoCo loads it): one body per joint, the outputs' box limits as ``range``
        (``limited``), their constant armature, the kept joints' springs (``[springs]``: ``stiffness``,
        ``springref``, ``damping``), a ``<motor>`` on every output and on every serial joint the robot actuates, the
        reference as ``<keyframe><key name="reference">``; contacts disabled, the robot's gravity."""
        return _mjcf(self, timestep)

    def data(self) -> dict[str, Any]:
        """The data file's content (JSON-ready): per transmission its names, motors, outputs, passive joints,
        closures, root, constant armature, box limits and feasible region, for the kernels."""
        out = []
        none = OutputLimits((), None, None, None, (), 0)
        for t in self.transmissions:
            reg = self.regions.get(t.name, none)
            out.append({
                "name": t.name, "root": t.root, "motors": list(t.motors), "outputs": list(t.outputs),
                "passive": list(t.passive), "closures": [] if t.constant else [c.name for c in t.mechanism.spec.closures],
                "drives": list(t.drives), "motor_map": t.motor_matrix.tolist(),
                "armature": [self.armature[o] for o in t.outputs],
                "lower": None if reg.lower is None else reg.lower.tolist(),
                "upper": None if reg.upper is None else reg.upper.tolist(),
                "around": None if reg.around is None else reg.around.tolist(),
                "area_fraction": reg.area_fraction,
                "region": None if reg.polygon is None else reg.polygon.tolist(), "binding": list(reg.binding),
                "q_reference": t.q_reference.tolist()})
        return {"format": "pkm.transmissions/1", "robot": self.robot.name, "source": str(self.robot.source),
                "outputs": {t.name: list(t.outputs) for t in self.transmissions}, "transmissions": out}


def serial_equivalent(robot: Mechanism, transmissions: Sequence[Transmission] | None = None, *,
                      limits: bool = True, around: Mapping[str, float] | None = None, directions: int = 24,
                      singularity: float = SINGULARITY) -> SerialEquivalent:
    """The serial-equivalent model of ``robot`` (module doc); ``transmissions`` default ``pkm.transmissions(robot)``;
    ``around``: ``{output: value}`` [rad or m], the point each transmission's box holds (its other outputs at the
    reference; default every output's reference); ``directions`` and ``singularity``: the feasible regions'
    (:func:`~pkm.core.transmissions.limits.output_limits`); ``limits=False``: no limits at all (no region traced, the
    robot's stated limits left out: a model for a free motion, as :mod:`pkm.core.transmissions.fidelity` runs it).

    Raises:
        InvalidInputError: ``transmissions`` not :class:`Transmission` objects, ``around`` no mapping; a closure no
            transmission covers; ``around`` naming no output, or a point outside its transmission's feasible region.

    Examples:
        >>> import pinocchio as pin
        >>> import pkm
        >>> bot = pkm.load("gepetto:battobot_6d")  # (two legs: a knee four-bar and a two-motor ankle each)
        >>> se = pkm.serial_equivalent(bot, limits=False)  # (limits=True traces each region: seconds)
        >>> se.outputs
        ('knee_left', 'knee_right', 'ankley_right', 'anklex_right', 'ankley_left', 'anklex_left')
        >>> round(pin.computeTotalMass(se.model), 6), round(pin.computeTotalMass(bot.model), 6)  # (rods welded)
        (17.513222, 17.513222)
        >>> round(se.armature["ankley_left"], 7)  # (ΔM's diagonal at the reference [kg m^2])
        0.0002152
    """
    robot = check_mechanism(robot)
    named = dict(instance_of({} if around is None else around, Mapping, "around",
                             "a mapping {output: value} [rad or m]"))
    if transmissions is None:
        found = tuple(find(robot))
    elif isinstance(transmissions, (str, bytes)) or not isinstance(transmissions, Iterable):
        raise InvalidInputError("transmissions", "expected a sequence of pkm.Transmission (pkm.transmissions(robot)), "
                                                 f"got {type(transmissions).__name__}", transmissions)
    else:
        found = tuple(instance_of(t, Transmission, f"transmissions[{k}]", "a pkm.Transmission "
                                  "(one of pkm.transmissions(robot))") for k, t in enumerate(transmissions))
    covered = {c.name for t in found for c in t.mechanism.spec.closures}
    open_loops = [c.name for c in robot.spec.closures if c.name not in covered]
    if open_loops:
        raise InvalidInputError("transmissions", f"closures {open_loops} belong to no transmission given: the serial "
                                "model would keep their joints with the loops open", open_loops)
    unknown = sorted(set(named) - {o for t in found for o in t.outputs})
    if unknown:
        raise InvalidInputError("around", f"{unknown} are no outputs; the outputs are "
                                f"{[o for t in found for o in t.outputs]}", unknown)
    gone = [robot.joints[n].id for t in found for n in t.welded]
    serial = reduced_model(robot.model, sorted(gone), robot.q_reference)  # (their bodies welded: mass kept)
    serial.name = f"{robot.name}_serial"
    armature = np.array(serial.armature, dtype=float)
    constant: dict[str, float] = {}
    bounds = {n: lim for n, lim in robot.limits.items() if serial.existJointName(n)} if limits else {}
    regions = {}
    for t in found:
        dM = t.delta_mass(t.q_reference)
        for i, o in enumerate(t.outputs):
            constant[o] = float(dM[i, i])
            armature[serial.joints[serial.getJointId(o)].idx_v] += dM[i, i]
        if not limits:
            continue
        point = [float(named.get(o, t.q_reference[t.out_q[i]])) for i, o in enumerate(t.outputs)]
        reg = output_limits(t, around=point, directions=directions, singularity=singularity)
        regions[t.name] = reg
        if reg.lower is not None and reg.upper is not None:
            ref = t.q_reference[t.out_q]
            if set(named) & set(t.outputs) and not ((reg.lower <= ref) & (ref <= reg.upper)).all():
                warnings.warn(PkmWarning(f"transmission {t.name!r}: its box about {dict(zip(t.outputs, point))} "
                                         f"leaves out the reference {dict(zip(t.outputs, ref.tolist()))}: the "
                                         "serial model's keyframe 'reference' lies outside its limits"), stacklevel=2)
            bounds.update({o: (float(lo), float(hi)) for o, lo, hi in zip(t.outputs, reg.lower, reg.upper)})
    serial.armature = armature
    locked = [n for t in found for n in t.welded if robot.spec.springs.get(n, {}).get("stiffness")]
    if locked:
        warnings.warn(PkmWarning(f"the springs of {locked} (locked in the serial model) act through their loops: "
                                 "the transmissions' kernels have them (in Δh), the serial model's files do not"),
                      stacklevel=2)
    keep = [j for j in range(1, robot.model.njoints) if robot.model.names[j] not in
            {robot.model.names[g] for g in gone}]
    q_ref = np.concatenate([robot.q_reference[robot.model.joints[j].idx_q:
                                              robot.model.joints[j].idx_q + robot.model.joints[j].nq] for j in keep]) \
        if keep else np.zeros(0)
    return SerialEquivalent(robot, found, serial, constant, bounds, regions, q_ref)


def _mjcf(se: SerialEquivalent, timestep: float) -> str:
    model = se.model
    root = etree.Element("mujoco", model=model.name)
    etree.SubElement(root, "compiler", angle="radian", boundmass=repr(MIN_MASS), boundinertia=repr(MIN_INERTIA))
    option = etree.SubElement(root, "option", timestep=repr(float(timestep)), gravity=_num(model.gravity.linear))
    etree.SubElement(option, "flag", contact="disable")
    bodies: list[etree._Element] = [etree.SubElement(root, "worldbody")]
    qpos: list[float] = []
    armature = np.array(model.armature, dtype=float)
    for j in range(1, model.njoints):
        jm, name = model.joints[j], model.names[j]
        body = etree.SubElement(bodies[int(model.parents[j])], "body", name=f"{name}_body")
        _pose(body, model.jointPlacements[j])
        inertia = model.inertias[j]
        I = inertia.inertia
        etree.SubElement(body, "inertial", pos=_num(inertia.lever), mass=repr(max(float(inertia.mass), MIN_MASS)),
                         fullinertia=_num([I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]))
        names = _joints(body, jm, name, se.robot.source)
        qpos += qpos_of(model, j, se.q_reference)
        if jm.nv == 1:
            el = body.find(f"joint[@name='{names[0]}']")
            if name in se.limits:
                el.set("range", _num(se.limits[name]))
                el.set("limited", "true")
            if armature[jm.idx_v] != 0.0:
                el.set("armature", repr(float(armature[jm.idx_v])))
            write_spring(el, se.robot.spec.springs.get(name, {}))  # (a kept joint's spring)
        bodies.append(body)
    keyframe = etree.SubElement(root, "keyframe")
    etree.SubElement(keyframe, "key", name="reference", qpos=_num(qpos))
    actuator = etree.SubElement(root, "actuator")
    driven = [*se.outputs, *(n for n in se.robot.actuated_names if model.existJointName(n))]
    for name in dict.fromkeys(driven):
        etree.SubElement(actuator, "motor", name=f"{name}_motor", joint=name, gear="1")
    return etree.tostring(root, pretty_print=True, encoding="unicode")


def write_serial_equivalent(se: SerialEquivalent, folder: str | os.PathLike[str]) -> tuple[Path, ...]:
    """Write ``se`` into ``folder`` (made if missing): ``<robot>_serial.urdf``, ``<robot>_serial.xml`` (MJCF),
    each transmission's sub-mechanism as ``<robot>_<transmission>.urdf`` and ``.closures.toml`` (``pkm.load`` reads
    it back) and ``<robot>_transmissions.json`` (:meth:`SerialEquivalent.data`, with the files' names); returns
    their paths, the data file last.

    Examples:
        >>> import tempfile
        >>> import pkm
        >>> se = pkm.serial_equivalent(pkm.load("gepetto:talos_like"), limits=False)
        >>> with tempfile.TemporaryDirectory() as folder:
        ...     [p.name for p in pkm.write_serial_equivalent(se, folder)]
        ['talos_like_serial.urdf', 'talos_like_serial.xml', 'talos_like_ankle.urdf', 'talos_like_ankle.closures.toml', 'talos_like_transmissions.json']
    """
    se, out = instance_of(se, SerialEquivalent, "se", "a pkm.SerialEquivalent (pkm.serial_equivalent(robot))"), \
        as_path(folder, "folder")
    out.mkdir(parents=True, exist_ok=True)
    stem = _safe(se.robot.name)
    urdf, mjcf, data = out / f"{stem}_serial.urdf", out / f"{stem}_serial.xml", out / f"{stem}_transmissions.json"
    urdf.write_text(se.urdf())
    mjcf.write_text(se.mjcf())
    written = [urdf, mjcf]
    content = se.data()
    content["files"] = {"urdf": urdf.name, "mjcf": mjcf.name}
    for t, entry in zip(se.transmissions, content["transmissions"]):
        sub = t.mechanism
        sub_urdf, sub_spec = out / f"{stem}_{_safe(t.name)}.urdf", out / f"{stem}_{_safe(t.name)}.closures.toml"
        sub_urdf.write_text(sub.urdf or "")
        sub_spec.write_text(dataclasses.replace(sub.spec, urdf=sub_urdf.name).to_toml())
        entry["files"] = {"urdf": sub_urdf.name, "spec": sub_spec.name}
        written += [sub_urdf, sub_spec]
    data.write_text(json.dumps(content, indent=1))
    return (*written, data)


def _safe(name: str) -> str:
    """``name`` as a file name: every character but letters, digits, ``_``, ``-`` and ``.`` written ``_``."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)


__all__ = ["SerialEquivalent", "serial_equivalent", "write_serial_equivalent"]
