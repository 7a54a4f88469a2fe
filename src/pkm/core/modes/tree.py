"""A mechanism's forward kinematics as polynomials in some of its joints: a revolute as ``(cos, sin)`` (with the unit
circle ``c^2 + s^2 = 1`` it adds), a prismatic joint as its coordinate, every other joint a number taken from a
Pinocchio data (the actuators where the caller put them). Shared by the legs' systems of
:mod:`~pkm.core.modes.working` and the whole-mechanism systems of :mod:`~pkm.core.modes.generic`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
import pinocchio as pin

from pkm.core.model.mechanism import Mechanism
from pkm.core.modes.polynomial import Poly, matvec, variables
from pkm.errors import StructureError

#: Revolute joints (one angle; the unbounded ones store it as ``(cos, sin)``).
REVOLUTE = {"RX", "RY", "RZ", "RevoluteUnaligned", "RUBX", "RUBY", "RUBZ"}
#: Prismatic joints.
PRISMATIC = {"PX", "PY", "PZ", "PrismaticUnaligned"}


def joint_axis(model: pin.Model, jid: int) -> tuple[str, np.ndarray]:
    """``("R", unit axis)`` or ``("P", unit direction)`` of a one-degree-of-freedom joint, in its own frame;
    another kind is a :class:`~pkm.errors.StructureError`."""
    jm = model.joints[jid]
    kind = jm.shortname().removeprefix("JointModel")
    if kind not in REVOLUTE | PRISMATIC:
        raise StructureError(f"joint {model.names[jid]!r}", f"a {kind} joint: the polynomial kinematics write "
                                                             "revolute and prismatic joints only")
    jd = jm.createData()
    jm.calc(jd, pin.neutral(model)[jm.idx_q:jm.idx_q + jm.nq])
    S = np.asarray(jd.S, dtype=float).reshape(6, -1)[:, 0]
    return ("R", S[3:] / np.linalg.norm(S[3:])) if kind in REVOLUTE else ("P", S[:3] / np.linalg.norm(S[:3]))


class PolyTree:
    """Points and directions of the tree as polynomials in the joints ``unknown`` (ids), the others read from ``d``
    (``d.liMi``, a forward kinematics done by the caller).

    Attributes:
        x: The variables (Polys), ``n`` of them.
        slots: Each unknown joint's variable indices (two for a revolute, one for a prismatic joint).
        kinds: Each unknown joint's ``(kind, axis)`` (:func:`joint_axis`).
        circles: ``c^2 + s^2 - 1`` per unknown revolute.
    """

    def __init__(self, mech: Mechanism, d: pin.Data, unknown: Sequence[int]):
        m = mech.model
        self.mech, self.d, self.unknown = mech, d, list(unknown)
        self.kinds = [joint_axis(m, j) for j in self.unknown]
        self.n = sum(2 if k == "R" else 1 for k, _ in self.kinds)
        self.x = variables(self.n)
        self.slots: dict[int, tuple[int, ...]] = {}
        self.circles: list[Poly] = []
        k = 0
        for j, (kind, _) in zip(self.unknown, self.kinds):
            self.slots[j] = (k, k + 1) if kind == "R" else (k,)
            if kind == "R":
                self.circles.append(self.x[k] * self.x[k] + self.x[k + 1] * self.x[k + 1] - 1.0)
            k += len(self.slots[j])

    @property
    def groups(self) -> list[list[int]]:
        """Each unknown joint's variables: the multihomogeneous groups that fit the equations."""
        return [list(self.slots[j]) for j in self.unknown]

    def _motion(self, j: int, p: Sequence[Any], point: bool) -> list[Any]:  # entries: numbers or Polys
        m = self.mech.model
        kind, w = self.kinds[self.unknown.index(j)]
        sl = self.slots[j]
        if kind == "R":
            c, s = self.x[sl[0]], self.x[sl[1]]
            W = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
            ww = np.outer(w, w)
            R = [[c * (float(i == k) - ww[i, k]) + s * W[i, k] + ww[i, k] for k in range(3)] for i in range(3)]
            p = matvec(R, p)
        elif point:
            p = [p[i] + self.x[sl[0]] * float(w[i]) for i in range(3)]
        M = m.jointPlacements[j]
        out = matvec(M.rotation, p)
        return [out[i] + float(M.translation[i]) for i in range(3)] if point else out

    def up(self, j: int, p: Iterable[float], stop: int = 0, *, point: bool = True) -> list[Any]:
        """A point (or direction) fixed in joint ``j``'s frame, in the frame of its ancestor ``stop`` (0: world)."""
        m, d = self.mech.model, self.d
        out: list[Any] = [float(v) for v in p]
        while j != stop:
            if j in self.slots:
                out = self._motion(j, out, point)
            else:
                M = d.liMi[j]
                r = matvec(M.rotation, out)
                out = [r[i] + float(M.translation[i]) for i in range(3)] if point else r
            j = int(m.parents[j])
        return out

    def frame_point(self, fid: int) -> list[Any]:
        """The origin of frame ``fid`` in world."""
        f = self.mech.model.frames[fid]
        return self.up(f.parentJoint, f.placement.translation)

    def frame_axis(self, fid: int, axis: int) -> list[Any]:
        """Column ``axis`` of frame ``fid``'s rotation, in world."""
        f = self.mech.model.frames[fid]
        return self.up(f.parentJoint, f.placement.rotation[:, axis], point=False)

    def values(self, x: np.ndarray) -> dict[int, float]:
        """Each unknown joint's coordinate at the solution ``x`` (an angle by ``atan2``) [rad or m]."""
        out = {}
        for j, (kind, _) in zip(self.unknown, self.kinds):
            sl = self.slots[j]
            out[j] = float(math.atan2(x[sl[1]], x[sl[0]])) if kind == "R" else float(x[sl[0]])
        return out

    def configuration(self, q: np.ndarray, x: np.ndarray, near: np.ndarray) -> np.ndarray:
        """``q`` with the unknown joints set from the solution ``x``, an angle on the turn nearest ``near``'s."""
        q = q.copy()
        m = self.mech.model
        for j, v in self.values(x).items():
            jm = m.joints[j]
            if jm.nq == 2:  # an unbounded revolute stores (cos, sin)
                q[jm.idx_q:jm.idx_q + 2] = (math.cos(v), math.sin(v))
            elif self.kinds[self.unknown.index(j)][0] == "R":
                q[jm.idx_q] = near[jm.idx_q] + (v - near[jm.idx_q] + math.pi) % (2.0 * math.pi) - math.pi
            else:
                q[jm.idx_q] = v
        return q
