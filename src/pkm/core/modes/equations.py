"""The reduced forward-kinematics equations of :mod:`pkm.core.modes.reduce` as polynomials, and the platform
displacements they encode.

The unknown is the platform's displacement ``G`` from its reference pose, acting in world axes: a platform point
at ``b`` (world, at the reference) goes to ``R b + t``. Each leg, with the actuators held, contributes (``A`` its
centre, ``r = B - A`` its end at the passive reference, ``n`` a circle's axis):

* sphere: ``|R b + t - A|^2 = |r|^2``;  circle: also ``n . (R b + t - A) = n . r``.

In ``SE3`` the unknowns are Study parameters ``(e, g)`` (homogeneous, P^7): ``R = R~(e) / D``,
``t = 2 vec(g e*) / D`` with ``D = e . e``, on the Study quadric ``e . g = 0``. Multiplied by ``D^2``, a sphere is
a quartic; on the quadric it is ``D`` times the quadric (Husty 1996)::

    D (|b|^2 + |A|^2 - |r|^2) + 4 |g|^2 - 2 A . R~b + 4 Re(e b^ g*) - 4 A . vec(g e*) = 0

and a circle's plane ``n . (R~b + 2 vec(g e*) - D A) - (n . r) D = 0``: seven quadrics in P^7 (128 paths). Points with
``e = 0`` solve every such system (the exceptional generator of the Study quadric) and are not poses.
``SE2``: ``(x, y, c, s)`` with ``c^2 + s^2 = 1``, distances in the plane (16 paths); ``T3``: the translation
(8 paths).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin

from pkm.core.modes.polynomial import Poly, dot, fix, variables
from pkm.core.modes.reduce import Reduction


# ---------------------------------------------------------------------- quaternions (w, x, y, z) of polynomials
def qmul(p: Sequence[Any], q: Sequence[Any]) -> list[Any]:  # entries: numbers or Polys
    a0, a1, a2, a3 = p
    b0, b1, b2, b3 = q
    return [a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
            a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
            a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0]


def qconj(p: Sequence[Any]) -> list[Any]:
    return [p[0], -p[1], -p[2], -p[3]]


def study_from_pose(R: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Study parameters ``(e0..e3, g0..g3)`` of ``x -> R x + t`` with ``|e| = 1``: ``g = t^ e / 2``."""
    qc = pin.Quaternion(np.asarray(R, dtype=float)).coeffs()  # x y z w
    e = [qc[3], qc[0], qc[1], qc[2]]
    g = [0.5 * c for c in qmul([0.0, *np.asarray(t, dtype=float)], e)]
    return np.array(e + g)


def pose_from_study(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(R, t)`` of real Study parameters (any scale)."""
    x = np.real(np.asarray(x))
    e, g = list(x[:4]), list(x[4:])
    D = float(np.dot(e, e))
    w, a, b, c = (v / np.sqrt(D) for v in e)
    R = pin.Quaternion(w, a, b, c).toRotationMatrix()
    t = 2.0 * np.array(qmul(g, qconj(e))[1:]) / D
    return R, t


# ---------------------------------------------------------------------- the systems
def leg_parameters(red: Reduction, d: pin.Data) -> list[np.ndarray]:
    """Each leg's parameters for the actuators in ``d``: ``(b, A, |r|^2[, n, n . r])`` (``SE3``, ``T3``: 7 or 11
    numbers) or ``(b_u, b_v, A_u, A_v, |r|^2 in the plane)`` (``SE2``, in the plane's axes)."""
    out = []
    for leg in red.legs:
        A, r, n = leg.geometry(d)
        b = leg.platform_point
        if red.group == "SE2":
            nrm = _normal(red)
            u, v = plane_axes(nrm)
            out.append(np.array([b @ u, b @ v, A @ u, A @ v, r @ r - (nrm @ r) ** 2]))
        else:
            out.append(np.r_[b, A, r @ r] if n is None else np.r_[b, A, r @ r, n, n @ r])
    return out


def _normal(red: Reduction) -> np.ndarray:
    if red.normal is None:
        raise ValueError(f"a platform in {red.group} has no plane")
    return red.normal


def plane_axes(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two axes ``(u, v)`` of the plane normal to ``normal`` (``u, v, normal`` right-handed)."""
    u = np.cross(normal, [1.0, 0.0, 0.0])
    if np.linalg.norm(u) < 0.5:
        u = np.cross(normal, [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    return u, np.cross(normal, u)


def equations(group: str, params: Sequence[np.ndarray | Sequence[Any]], x: Sequence[Poly]) -> list[Poly]:
    """The reduced equations in the unknowns ``x`` (polynomials) for leg parameters ``params`` (numbers, or
    polynomials in the same variables: a parameter homotopy's path)."""
    if group == "SE3":
        e, g = x[:4], x[4:8]
        D = dot(e, e)
        polys = [dot(e, g)]
        ge = qmul(g, qconj(e))[1:]
        for P in params:
            b, A, rr = P[0:3], P[3:6], P[6]
            Rb = qmul(qmul(e, [0.0, *b]), qconj(e))[1:]
            ebg = qmul(qmul(e, [0.0, *b]), qconj(g))[0]
            polys.append(D * (dot(b, b) + dot(A, A) - rr) + 4.0 * dot(g, g) - 2.0 * dot(A, Rb) + 4.0 * ebg
                         - 4.0 * dot(A, ge))
            if len(P) > 7:
                n, nr = P[7:10], P[10]
                polys.append(dot(n, [Rb[i] + 2.0 * ge[i] - D * A[i] for i in range(3)]) - D * nr)
        return polys
    if group == "SE2":
        px, py, c, s = x[:4]
        polys = [c * c + s * s - 1.0]
        for b1, b2, au, av, rr in params:
            pu = c * b1 - s * b2 + px - au
            pv = s * b1 + c * b2 + py - av
            polys.append(pu * pu + pv * pv - rr)
        return polys
    polys = []
    for P in params:
        p = [x[i] + P[i] - P[3 + i] for i in range(3)]
        polys.append(dot(p, p) - P[6])
        if len(P) > 7:
            polys.append(dot(P[7:10], p) - P[10])
    return polys


#: Unknowns per group.
N_UNKNOWNS = {"SE3": 8, "SE2": 4, "T3": 3}


class FKSystem:
    """The reduced equations for one set of actuator values: ``polys``, Bertini's variable ``groups``, whether
    they are ``projective``, and :meth:`displacement` from a solution to ``(R, t)``."""

    def __init__(self, red: Reduction, d: pin.Data):
        self.red = red
        self.params = leg_parameters(red, d)
        n = N_UNKNOWNS[red.group]
        self.polys = equations(red.group, self.params, variables(n))
        self.groups = [list(range(n))]
        self.projective = red.group == "SE3"
        if red.group == "SE2":
            self._plane = plane_axes(_normal(red))

    @property
    def signature(self) -> str:
        """The family this system belongs to: its group and its legs' kinds (``"SE3:ssssss"``)."""
        return f"{self.red.group}:" + "".join(leg.kind[0] for leg in self.red.legs)

    def is_pose(self, x: np.ndarray) -> bool:
        """Whether a solution is a pose, real or complex (in ``SE3``: not on the exceptional set ``e = 0``)."""
        if self.red.group == "SE3":
            return bool(np.linalg.norm(x[:4]) > 1e-6 * np.linalg.norm(x))
        return True

    def displacement(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(R, t)``: the world displacement of the platform from its reference pose."""
        x = np.real(np.asarray(x))
        if self.red.group == "SE3":
            return pose_from_study(x)
        if self.red.group == "T3":
            return np.eye(3), x.copy()
        u, v = self._plane
        nrm = _normal(self.red)
        c, s = x[2], x[3]
        h = np.hypot(c, s)
        P = np.column_stack([u, v, nrm])
        R = P @ np.array([[c / h, -s / h, 0.0], [s / h, c / h, 0.0], [0.0, 0.0, 1.0]]) @ P.T
        return R, x[0] * u + x[1] * v

    def encode(self, R: np.ndarray, t: np.ndarray) -> np.ndarray:
        """The unknowns of a displacement (the inverse of :meth:`displacement`)."""
        if self.red.group == "SE3":
            return study_from_pose(R, t)
        if self.red.group == "T3":
            return np.asarray(t, dtype=float).copy()
        u, v = self._plane
        Ru = R @ u
        return np.array([t @ u, t @ v, Ru @ u, Ru @ v])

    def affine(self, x: np.ndarray) -> tuple[list[Poly], np.ndarray, int | None]:
        """A square affine system and the point on it: a projective system on the chart of ``x``'s largest
        coordinate (set to 1, removed), an affine one as it is. Returns ``(polys, point, fixed index)``."""
        if not self.projective:
            return self.polys, np.asarray(x, dtype=complex), None
        k = int(np.argmax(np.abs(x)))
        x = np.asarray(x, dtype=complex) / x[k]
        return [fix(p, k, 1.0) for p in self.polys], np.delete(x, k), k
