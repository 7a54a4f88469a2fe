"""Calibration parameters: the geometric numbers a kinematic calibration estimates, by name.

* ``JOINT.x``, ``JOINT.y``, ``JOINT.z`` [m], ``JOINT.roll``, ``JOINT.pitch``, ``JOINT.yaw`` [rad]: a URDF joint's
  origin in its parent link (:mod:`pkm.core.twin.design`'s names, taken as the twin's design inputs). By default
  every joint that moves the kinematics: each moving joint but a free-flyer (its origin is absorbed by its six
  coordinates), and each fixed joint that carries a closure frame or the end effector. A prismatic actuator's
  direction is its origin's ``roll`` and ``pitch`` (``origins="position"`` with ``directions=True`` keeps just
  those angles).
* ``ACT.offset`` [rad or m] and ``ACT.gain`` [1] of each actuated joint ``ACT``: the joint coordinate is
  ``gain * reading + offset`` (nominal 1 and 0).
* The measurement frames: ``tracker.*`` (the instrument's frame in the base: the measured pose is the target's in
  it) and ``target.*`` (the target's frame on the end effector): six components for a full pose, the tracker's six
  and the target's ``x, y, z`` for a position (the target's orientation is invisible), ``x, y, yaw`` and
  ``x, y`` for a planar pose; none for self-calibration.
* ``SENSOR.offset`` [rad or m] of each passive joint ``SENSOR`` read by an encoder (self-calibration: its reading is
  ``q + offset``).

Names that a mechanism cannot honour (a frame named ``tracker``) raise; the values are SI.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.origins import ORIGIN
from pkm.errors import InvalidInputError, UnknownNameError
from pkm.validation import as_choice

#: The measurement models: what the instrument reads per pose.
KINDS = ("pose", "position", "planar", "passive")
#: The frame components each model takes as unknowns: (tracker, target).
FRAMES = {"pose": (tuple(ORIGIN), tuple(ORIGIN)), "position": (tuple(ORIGIN), ("x", "y", "z")),
          "planar": (("x", "y", "yaw"), ("x", "y")), "passive": ((), ())}


@dataclass(frozen=True)
class CalibrationParameters:
    """The parameters of a calibration (module doc).

    Attributes:
        names: The parameters, in the estimate's order.
        nominal: Their values in the mechanism's files (SI; gains 1, offsets and frames 0 unless given).
        units: Each one's unit (``"m"``, ``"rad"``, ``"1"``).
        origins: The indices of the joint-origin parameters (the twin's design inputs).
    """

    names: tuple[str, ...]
    nominal: np.ndarray
    units: tuple[str, ...]
    origins: tuple[int, ...]

    def __len__(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        """The position of parameter ``name``.

        Raises:
            UnknownNameError: not a parameter (the error lists them).
        """
        if name not in self.names:
            raise UnknownNameError("calibration parameter", name, self.names)
        return self.names.index(name)

    def subset(self, keep: Sequence[int]) -> CalibrationParameters:
        """These parameters restricted to the indices ``keep`` (in that order)."""
        keep = [int(k) for k in keep]
        return CalibrationParameters(tuple(self.names[k] for k in keep), self.nominal[keep].copy(),
                                     tuple(self.units[k] for k in keep),
                                     tuple(i for i, k in enumerate(keep) if k in self.origins))


def check_kind(kind: object) -> str:
    """``kind`` if it is a measurement model's name (:data:`KINDS`), else :class:`UnknownNameError` (a name it does
    not know: the close ones told) or :class:`InvalidInputError` (not a name: a configuration array in its place)."""
    if not isinstance(kind, str):
        raise InvalidInputError("kind", f"expected a measurement model's name, one of {list(KINDS)}, got "
                                        f"{type(kind).__name__}", kind)
    if kind not in KINDS:
        raise UnknownNameError("measurement model", kind, KINDS)
    return kind


def kinematic_joints(mech: Mechanism) -> tuple[str, ...]:
    """The URDF joints whose origins move the kinematics (module doc), in file order."""
    from pkm.core.twin.design import _urdf_joints

    model = mech.model
    used: set[str] = set()
    for fid in [f for pair in mech.closure_frames for f in pair] + ([mech.ee_frame] if mech.ee_frame else []):
        while fid and model.frames[fid].type != pin.FrameType.JOINT:
            if model.frames[fid].type == pin.FrameType.FIXED_JOINT:
                used.add(model.frames[fid].name)
            fid = model.frames[fid].parentFrame
    out = []
    for name in _urdf_joints(mech):
        if model.existJointName(name):
            if model.joints[model.getJointId(name)].nv < 6:  # (a free-flyer's origin: absorbed by its coordinates)
                out.append(name)
        elif name in used:
            out.append(name)
    return tuple(out)


def calibration_parameters(mech: Mechanism, kind: str = "pose", *, joints: Sequence[str] | None = None,
                           origins: str = "all", directions: bool = False, offsets: bool = True,
                           gains: bool = True, sensors: Sequence[str] = (), planar: bool | None = None) \
        -> CalibrationParameters:
    """The calibration parameters of ``mech`` for measurement model ``kind`` (:data:`KINDS`; module doc).

    Args:
        mech: The mechanism (built from URDF text).
        kind: ``pose``, ``position``, ``planar`` or ``passive``: which frame unknowns are added.
        joints: The URDF joints whose origins are unknowns (default :func:`kinematic_joints`).
        origins: ``"all"`` (position and orientation) or ``"position"`` (``x, y, z`` only).
        directions: With ``origins="position"``, add each prismatic actuator's ``roll`` and ``pitch`` (its axis).
        offsets: Each actuator's offset [rad or m].
        gains: Each actuator's gain [1].
        sensors: Passive joints read by encoders (``passive``): their offsets.
        planar: Keep only the in-plane components (``x, y, yaw``) of every origin: a planar mechanism whose loops
            an out-of-plane error would open (default: ``kind == "planar"``).

    Raises:
        InvalidInputError: an unknown ``kind`` or ``origins``, or a name clash with the frames' names.
        UnknownNameError: a joint or sensor the mechanism does not have.

    Examples:
        >>> import pkm
        >>> P = pkm.calibration_parameters(pkm.load("prs3"), "position")
        >>> len(P), P.names[:3], P.names[-3:]
        (87, ('slider_1.x', 'slider_1.y', 'slider_1.z'), ('target.x', 'target.y', 'target.z'))
    """
    from pkm.core.twin.design import _urdf_joints

    mech, kind = check_mechanism(mech), check_kind(kind)
    origins = as_choice(origins, ("all", "position"), "origins")
    urdf = _urdf_joints(mech)
    chosen = kinematic_joints(mech) if joints is None else tuple(joints)
    for j in chosen:
        if j not in urdf:
            raise UnknownNameError("URDF joint", j, list(urdf), mech.name)
    flat = kind == "planar" if planar is None else planar
    comps = ("x", "y", "yaw") if flat else ("x", "y", "z") if origins == "position" else tuple(ORIGIN)
    names: list[str] = []
    values: list[float] = []
    units: list[str] = []

    def add(name: str, value: float, unit: str) -> None:
        names.append(name)
        values.append(value)
        units.append(unit)

    for j in chosen:
        extra = ("roll", "pitch") if (directions and j in mech.actuated_names and not mech.joints[j].revolute
                                      and not flat and origins == "position") else ()
        for c in comps + extra:
            attr, i = ORIGIN[c]
            add(f"{j}.{c}", float(urdf[j][0 if attr == "xyz" else 1][i]), "m" if attr == "xyz" else "rad")
    origin_idx = tuple(range(len(names)))
    for a in mech.actuated_names:
        unit = "rad" if mech.joints[a].revolute else "m"
        if offsets:
            add(f"{a}.offset", 0.0, unit)
        if gains:
            add(f"{a}.gain", 1.0, "1")
    for s in sensors:
        if s not in mech.joints or mech.joints[s].nv != 1:
            raise UnknownNameError("passive joint with one coordinate", s,
                                   [n for n, j in mech.joints.items() if j.nv == 1 and n not in mech.actuated_names])
        add(f"{s}.offset", 0.0, "rad" if mech.joints[s].revolute else "m")
    tracker, target = FRAMES[kind]
    for frame, comps_f in (("tracker", tracker), ("target", target)):
        if frame in urdf:
            raise InvalidInputError("mechanism", f"a URDF joint is named {frame!r}: the measurement frames' names "
                                                 f"would clash", frame)
        for c in comps_f:
            add(f"{frame}.{c}", 0.0, "m" if c in ("x", "y", "z") else "rad")
    if len(set(names)) != len(names):
        raise InvalidInputError("parameters", "a parameter is named twice (a joint listed twice?)", names)
    return CalibrationParameters(tuple(names), np.array(values, dtype=float), tuple(units), origin_idx)


__all__ = ["FRAMES", "KINDS", "CalibrationParameters", "calibration_parameters", "check_kind", "kinematic_joints"]
