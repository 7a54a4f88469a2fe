r"""Geometric paths for timing: a curve :math:`y(s)`, :math:`s \in [0, 1]`, with its first two derivatives.

A path is given in **task space** (waypoints as :meth:`pkm.core.TaskMap.value` lays them out, or a ``pkm.motion``
case) or in **actuator space** (waypoints of the actuated coordinates). Waypoints are interpolated by a **C² cubic
spline** (:class:`scipy.interpolate.CubicSpline`, not-a-knot ends) over the **cumulative chord length**, the chords
measured in homogenised units (a length divided by the mechanism's characteristic length ``L``, an angle in rad:
the same parameter for the mechanism scaled in size), then normalised to ``s ∈ [0, 1]``. The parametrisation does not
change the time-optimal law (only the grid it is computed on): any regular parametrisation times the same motion.

A pose's orientation (a quaternion among the values) must be constant along a task path: the path moves the
position only (its angular rates are zero). Orientations that change are not interpolated here (a spline of
quaternions leaves the unit sphere); give the path in actuator space, or in a task of angles (the 3-PRS's).

A ``pkm.motion`` case becomes the path :math:`y(s) = Y(s T)` (``T`` its duration), its derivatives the laws' exact
ones: :math:`y' = T \dot Y`, :math:`y'' = T^2 \ddot Y`.

Refused (:class:`~pkm.errors.PathError`, naming the waypoint): two consecutive waypoints that coincide, and a
**corner**, where the chords turn by more than ``max_turn`` (default 60°) at a waypoint: a spline through a corner
swings wide of it; round the corner with more waypoints. A ``pkm.motion`` case whose motion stops inside
(:math:`y' = 0` away from its ends: a cusp or a reversal) is refused likewise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import InvalidInputError, PathError
from pkm.validation import as_array, as_choice, bounded

SPACES = ("task", "actuated")
#: The largest turn of the chords at a waypoint [rad] before a path is refused as a corner.
MAX_TURN = math.radians(60.0)
_QUATERNION = ("qx", "qy", "qz", "qw")


@dataclass(frozen=True)
class GeometricPath:
    """A path :math:`y(s)` on ``s ∈ [0, 1]`` (see the module doc).

    Attributes:
        space: ``"task"`` or ``"actuated"``.
        value_size: Columns of :meth:`values` (the task's value size, or ``na``).
        rate_size: Columns of the derivatives (the task's size, or ``na``).
        how: The interpolation, in words.
    """

    space: str
    value_size: int
    rate_size: int
    how: str
    _spline: object
    _rate_columns: tuple[int, ...]
    _constant: np.ndarray | None

    def evaluate(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(y, y', y'')`` at path parameters ``s`` (n,): values (n x value_size) and derivatives (n x rate_size)."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        if s.ndim != 1 or not np.all(np.isfinite(s)) or s.min() < -1e-12 or s.max() > 1.0 + 1e-12:
            raise InvalidInputError("s", "expected path parameters in [0, 1]", s)
        return self._raw(np.clip(s, 0.0, 1.0))

    def _raw(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`evaluate` unchecked, continued past [0, 1] by the interpolant's own polynomial (or law)."""
        y, d1, d2 = self._spline(s)  # type: ignore[operator]
        if self._constant is None:
            return y, d1, d2
        values = np.tile(self._constant, (len(s), 1))
        cols = list(self._rate_columns)
        values[:, cols] = y
        r1, r2 = np.zeros((len(s), self.rate_size)), np.zeros((len(s), self.rate_size))
        r1[:, : len(cols)], r2[:, : len(cols)] = d1, d2
        return values, r1, r2


class _Spline:
    def __init__(self, u: np.ndarray, Y: np.ndarray):
        from scipy.interpolate import CubicSpline

        self.cs = CubicSpline(u, Y, axis=0) if len(u) > 2 else None
        self.u, self.Y = u, Y

    def __call__(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if self.cs is None:  # (two waypoints: the straight line)
            d = self.Y[1] - self.Y[0]
            return self.Y[0] + np.outer(s, d), np.tile(d, (len(s), 1)), np.zeros((len(s), len(d)))
        return self.cs(s), self.cs(s, 1), self.cs(s, 2)


class _MotionLaw:
    def __init__(self, motion: object, order: list[int]):
        self.motion, self.order = motion, order

    def __call__(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        T = self.motion.duration  # type: ignore[attr-defined]
        _, Y, Yd, Ydd = self.motion.sample(s * T)  # type: ignore[attr-defined]
        o = self.order
        return Y[:, o], T * Yd[:, o], T * T * Ydd[:, o]


def _homogenised(mech: Mechanism, space: str, columns: list[int]) -> np.ndarray:
    """Per column, the factor that makes it dimensionless: 1/L for a length, 1 for an angle."""
    L = mech.characteristic_length
    if space == "actuated":
        return np.array([1.0 if mech.actuated[i].revolute else 1.0 / L for i in columns])
    kinds = TaskMap.of(mech).kinds
    names = TaskMap.of(mech).value_names
    return np.array([1.0 / L if kinds.get(names[i]) == "length" else 1.0 for i in columns])


def waypoint_path(mech: Mechanism, waypoints: ArrayLike, *, space: str = "task",
                  max_turn: float = MAX_TURN) -> GeometricPath:
    """The C² cubic spline through ``waypoints`` over their cumulative chord length (module doc).

    Args:
        mech: The mechanism.
        waypoints: (n x value size) task values (:meth:`pkm.core.TaskMap.value`) or (n x na) actuated coordinates
            [m, rad], n >= 2.
        space: ``"task"`` or ``"actuated"``.
        max_turn: The largest turn of the chords at a waypoint [rad].

    Raises:
        InvalidInputError: waypoints of the wrong shape, not finite, or a pose whose orientation changes.
        PathError: coinciding waypoints or a corner (``limit="smoothness"``, ``index`` the waypoint).
    """
    mech = check_mechanism(mech)
    space = as_choice(space, SPACES, "space")
    task = TaskMap.of(mech)
    size = task.value_size if space == "task" else mech.na
    W = as_array(waypoints, "waypoints", f"n x {size} waypoints")
    if W.ndim != 2 or W.shape[1] != size or len(W) < 2:
        raise InvalidInputError("waypoints", f"expected n >= 2 waypoints of {size} values, got shape {W.shape}",
                                waypoints)
    if not np.all(np.isfinite(W)):
        raise InvalidInputError("waypoints", "holds non-finite values", waypoints)
    bounded(W, "waypoints", waypoints)
    constant = None
    cols = list(range(size))
    if space == "task" and task.value_size != task.size:
        quat = [i for i, n in enumerate(task.value_names) if n in _QUATERNION]
        moved = np.flatnonzero(np.abs(W[:, quat] - W[0, quat]).max(axis=1) > 1e-12)
        if moved.size:
            raise InvalidInputError("waypoints", f"the orientation changes at waypoint {int(moved[0])}: a task path "
                                                 "moves the position only (give the path in actuator space)",
                                    W[int(moved[0])])
        cols = [i for i in range(size) if i not in quat]
        constant = W[0].copy()
        if [task.value_names[i] for i in cols] != list(task.keys[: len(cols)]):
            raise InvalidInputError("waypoints", f"this task's rates {list(task.keys)} do not start with its values "
                                                 f"{[task.value_names[i] for i in cols]} (a pose and joint outputs): "
                                                 "give the path in actuator space (space='actuated'; on the command "
                                                 f"line a CSV headed {','.join(mech.actuated_names)})",
                                    task.value_names)
    chords = np.diff(W[:, cols], axis=0) * _homogenised(mech, space, cols)
    length = np.linalg.norm(chords, axis=1)
    u = np.concatenate([[0.0], np.cumsum(length)])
    if length.min() <= 1e-12 * max(float(u[-1]), 1e-300):
        k = int(np.argmin(length))
        raise PathError(k + 1, float(u[k] / u[-1]) if u[-1] > 0 else 0.0, "smoothness",
                        f"waypoint {k + 1} coincides with waypoint {k}", "waypoint")
    u = u / u[-1]
    if len(chords) > 1:
        c = np.einsum("ij,ij->i", chords[:-1], chords[1:]) / (length[:-1] * length[1:])
        turn = np.arccos(np.clip(c, -1.0, 1.0))
        if turn.max() > max_turn:
            k = int(np.argmax(turn))
            raise PathError(k + 1, float(u[k + 1]), "smoothness",
                            f"the path turns by {math.degrees(turn[k]):.4g} deg at this waypoint, more than "
                            f"max_turn = {math.degrees(max_turn):.4g} deg: a corner (round it with more waypoints)",
                            "waypoint")
    how = ("the straight line between the two waypoints" if len(W) == 2 else
           f"C2 cubic spline (not-a-knot) through {len(W)} waypoints over their homogenised chord length")
    rate = task.size if space == "task" else mech.na
    return GeometricPath(space, size, rate, how, _Spline(u, W[:, cols]), tuple(cols), constant)


def motion_path(mech: Mechanism, motion: object, coordinates: tuple[str, ...] | None = None) -> GeometricPath:
    """The path of a ``pkm.motion`` case (:class:`pkm.motion.Motion`): :math:`y(s) = Y(s T)` with the laws' exact
    derivatives; its coordinates (or ``coordinates``, the names they take, in the file's order: the 3-PRS's
    ``("z", "pitch", "roll")`` for its paper's ``z, beta, phi``) must be the task's keys (a task without a quaternion)
    or, for ``space = "actuated"``, the actuated joints' names.

    Raises:
        InvalidInputError: coordinates that are not the task's (or the actuated joints').
        PathError: the motion stops inside (``limit="smoothness"``).
    """
    from pkm.motion import Motion

    mech = check_mechanism(mech)
    if not isinstance(motion, Motion):
        raise InvalidInputError("motion", "expected a pkm.motion.Motion", motion)
    names = tuple(mech.actuated_names if motion.space == "actuated" else TaskMap.of(mech).value_names)
    given = tuple(motion.coordinates if coordinates is None else coordinates)
    if sorted(given) != sorted(names) or len(given) != len(motion.coordinates) or (
            motion.space == "task" and TaskMap.of(mech).value_size != TaskMap.of(mech).size):
        raise InvalidInputError("motion", f"the motion's coordinates {given} must be {names} (rename them: "
                                          "coordinates=...)", given)
    order = [given.index(n) for n in names]
    law = _MotionLaw(motion, order)
    path = GeometricPath(motion.space, len(names), len(names), f"pkm.motion case {motion.name!r} (exact laws)",
                         law, tuple(range(len(names))), None)
    s = np.linspace(0.0, 1.0, 201)
    _, d1, _ = path.evaluate(s)
    scale = _homogenised(mech, motion.space, list(range(len(names))))
    speed = np.linalg.norm(d1 * scale, axis=1)
    inner = np.flatnonzero(speed[1:-1] <= 1e-9 * speed.max()) + 1
    if speed.max() == 0.0 or inner.size:
        k = int(inner[0]) if inner.size else 0
        raise PathError(k, float(s[k]), "smoothness", "the motion stops here (a cusp or a reversal): its geometric "
                                                      "path has no tangent; split the motion there")
    return path


__all__ = ["MAX_TURN", "SPACES", "GeometricPath", "adept_waypoints", "motion_path", "waypoint_path"]


def adept_waypoints(start: ArrayLike, *, across: float = 0.305, up: float = 0.025, points: int = 200,
                    direction: ArrayLike = (1.0, 0.0, 0.0)) -> np.ndarray:
    """Points (n x 3) [m] of the standard pick-and-place cycle ("Adept cycle": ``up`` 25 mm, ``across`` 305 mm,
    down 25 mm) from ``start`` along ``direction`` (horizontal), its corners rounded with the radius ``up`` (a
    quarter circle up, a straight line, a quarter circle down): geometry C¹, curvature 1/up on the arcs, sampled at
    ``points`` points for :func:`waypoint_path`'s spline."""
    p0 = as_array(start, "start", "x y z [m]")
    e = as_array(direction, "direction", "a horizontal direction")
    if p0.shape != (3,) or e.shape != (3,) or abs(e[2]) > 0.0 or not np.linalg.norm(e) > 0.0:
        raise InvalidInputError("start", "expected a point (x, y, z) and a horizontal direction", (start, direction))
    e = e / np.linalg.norm(e)
    r = float(up)
    if not (0.0 < 2.0 * r < across):
        raise InvalidInputError("across", f"needs across > 2 up, got {across} and {up}", across)
    lengths = np.array([0.5 * np.pi * r, across - 2.0 * r, 0.5 * np.pi * r])
    u = np.linspace(0.0, lengths.sum(), points)
    out = np.empty((points, 3))
    for k, arc in enumerate(u):
        if arc <= lengths[0]:
            th = arc / r
            h, z = r * (1.0 - np.cos(th)), r * np.sin(th)
        elif arc <= lengths[:2].sum():
            h, z = r + arc - lengths[0], r
        else:
            th = (arc - lengths[:2].sum()) / r
            h, z = across - r + r * np.sin(th), r * np.cos(th)
        out[k] = p0 + h * e + np.array([0.0, 0.0, z])
    return out
