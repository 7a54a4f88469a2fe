"""Motors that drive several actuated joints through a constant linear map: a differential.

A spec's ``[motors.<name>]`` table (:attr:`~pkm.core.model.spec.ClosureSpec.motors`) gives a motor's coordinate as
a constant linear combination of actuated joint coordinates, ``u = sum_j c_j q_j`` (MuJoCo's ``<tendon><fixed>``
under a ``<motor>``, its ``gear`` folded into the coefficients; ros2_control's ``DifferentialTransmission``); every
actuated joint no motor names is driven by a motor of its own, ``u = q_joint``. Together they make the square map
:attr:`MotorMap.matrix` ``C`` (``na x na``, rows the motors, columns the actuated joints in spec order):

* positions and velocities: ``u = C q_a`` (up to a constant), ``du = C dq_a``;
* efforts, by virtual work: the motors' forces ``f`` act on the joints as ``tau_a = C^T f``, so the motor efforts
  of actuated-joint efforts ``tau_a`` (:func:`pkm.inverse_dynamics`) are ``f = C^-T tau_a``
  (:func:`pkm.core.dynamics.motors.motor_efforts`; :func:`~pkm.core.dynamics.motors.joint_efforts` is the
  converse).

The motors that name a set of joints must be as many as those joints, their map invertible (a differential of two
motors on two joints; a joint named by a motor is driven by the motors only): else a :class:`~pkm.errors.SpecError`.
The rows are ordered by the first actuated joint each names (the motors of one differential in spec order).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from pkm.errors import SpecError

#: The smallest ratio of the smallest to the largest singular value of a differential's map: below it the motors
#: do not determine the joints.
RCOND = 1e-9


@dataclass(frozen=True)
class MotorMap:
    """The motors of a mechanism and their map onto its actuated joints (module doc).

    Attributes:
        names: One per motor (row): its ``[motors]`` name, or the actuated joint's that a motor of its own drives.
        matrix: ``C`` (``na x na``): the motors' velocities are ``C dq_a``, the joints' efforts ``C^T f``.
    """

    names: tuple[str, ...]
    matrix: np.ndarray

    @property
    def identity(self) -> bool:
        """Whether every actuated joint has a motor of its own (no ``[motors]``)."""
        return bool(np.array_equal(self.matrix, np.eye(len(self.names))))

    def equations(self, actuated: Sequence[str]) -> tuple[str, ...]:
        """Each motor's coordinate as text, ``"m = 1 a + 1 b"``, the columns named ``actuated`` (the mechanism's
        actuated joints): what the C and the command line show of a motor (a differential's map, not a joint)."""
        return tuple(f"{n} = " + linear_text((j, float(c)) for j, c in zip(actuated, row) if c != 0.0)
                     for n, row in zip(self.names, self.matrix))


def linear_text(terms: Iterable[tuple[str, float]]) -> str:
    """``c1 j1 + c2 j2 - c3 j3``: a linear combination of joints, for notes and listings."""
    out = ""
    for j, c in terms:
        out += (f"{c:.6g} {j}" if not out else f" - {-c:.6g} {j}" if c < 0 else f" + {c:.6g} {j}")
    return out


def motor_map(actuated: Sequence[str], motors: Mapping[str, Mapping[str, float]], source: str = "<spec>") -> MotorMap:
    """The :class:`MotorMap` of the actuated joints ``actuated`` and the ``[motors]`` tables ``motors``.

    Raises:
        SpecError: a motor naming a joint that is not actuated; motors that name a set of joints but are not as many
            as they, or whose map is singular.
    """
    col = {j: k for k, j in enumerate(actuated)}
    rows: list[tuple[int, str, np.ndarray]] = []
    named: set[str] = set()
    for name, coefs in motors.items():
        stray = [j for j in coefs if j not in col]
        if stray:
            raise SpecError(source, f"[motors.{name}]: {stray[0]!r} is not an actuated joint; actuated: "
                                    f"{list(actuated)}")
        row = np.zeros(len(actuated))
        for j, c in coefs.items():
            row[col[j]] = float(c)
        rows.append((min(col[j] for j in coefs), name, row))
        named |= set(coefs)
    clash = sorted(set(motors) & (set(actuated) - named))
    if clash:
        raise SpecError(source, f"[motors.{clash[0]}] has the name of the actuated joint its own motor drives: rename "
                                "the motor")
    _check_groups(motors, source)
    for j in actuated:
        if j not in named:
            row = np.zeros(len(actuated))
            row[col[j]] = 1.0
            rows.append((col[j], j, row))
    rows.sort(key=lambda r: r[0])  # (stable: the motors of one differential in spec order)
    return MotorMap(tuple(r[1] for r in rows), np.array([r[2] for r in rows]).reshape(len(rows), len(actuated)))


def _check_groups(motors: Mapping[str, Mapping[str, float]], source: str) -> None:
    """Each set of motors that share joints (transitively) is as many as its joints, its map invertible."""
    groups: list[tuple[list[str], set[str]]] = []
    for name, coefs in motors.items():
        joints = {j for j, c in coefs.items() if c != 0.0} or set(coefs)
        touching = [g for g in groups if g[1] & joints]
        merged = ([name], set(joints))
        for g in touching:
            merged[0][:0] = g[0]
            merged[1].update(g[1])
            groups.remove(g)
        groups.append(merged)
    for names, joints in groups:
        order = sorted(joints)
        C = np.array([[motors[m].get(j, 0.0) for j in order] for m in names])
        if len(names) != len(order):
            raise SpecError(source, f"motors {names} drive the joints {order}: pkm reads a differential of as many "
                                    "motors as joints (a square map)")
        s = np.linalg.svd(C, compute_uv=False)
        if s[-1] <= RCOND * s[0]:
            raise SpecError(source, f"motors {names} do not determine the joints {order}: their map "
                                    f"{C.tolist()} is singular (singular values {s[0]:.3g} and {s[-1]:.3g})")


__all__ = ["RCOND", "MotorMap", "linear_text", "motor_map"]
