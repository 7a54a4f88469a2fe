"""Task (output) coordinates of a mechanism: values, differences, Jacobian, bias.

The task of a mechanism (see :mod:`pkm.core.model.spec`) is either a list of
end-effector components among ``x y z roll pitch yaw`` (position of the
end-effector origin in the world, Z-Y-X Euler angles of its orientation), or the
full placement ``pose``; optionally followed by joint coordinates.

Values are flat vectors: the components in order; for ``pose``, the position
then the quaternion ``x y z w`` (7 numbers). Velocities are time derivatives of
the components; for ``pose``, the twist ``[v; w]`` of the end-effector origin in
world axes (``LOCAL_WORLD_ALIGNED``). Joint outputs follow in both.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm._derived import derived
from pkm.core.model.mechanism import Mechanism
from pkm.errors import InvalidInputError, SingularityError
from pkm.units import quantities, quantity
from pkm.validation import as_array, as_vector, bounded, wrap_angle

_ANGLES = ("roll", "pitch", "yaw")
_POS = {"x": 0, "y": 1, "z": 2}


def zyx_angles(R: ArrayLike) -> np.ndarray:
    r"""``(roll, pitch, yaw)`` [rad] with :math:`R = R_z(\psi)\, R_y(\theta)\, R_x(\phi)` (roll :math:`\phi`,
    pitch :math:`\theta`, yaw :math:`\psi`; the pitch in :math:`[-\pi/2, \pi/2]`): the inverse of :func:`zyx_matrix`.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> np.round(pkm.zyx_angles(pkm.zyx_matrix(0.1, 0.2, 0.3)), 12)
        array([0.1, 0.2, 0.3])
    """
    R = np.asarray(R, dtype=float)
    pitch = np.arctan2(-R[2, 0], np.hypot(R[0, 0], R[1, 0]))
    return np.array([np.arctan2(R[2, 1], R[2, 2]), pitch, np.arctan2(R[1, 0], R[0, 0])])


def zyx_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    r"""The rotation (3 x 3) :math:`R = R_z(\psi)\, R_y(\theta)\, R_x(\phi)` of the Z-Y-X Euler angles roll
    :math:`\phi`, pitch :math:`\theta` and yaw :math:`\psi` [rad] (rotations about the fixed x, y and z axes, in that
    order): the convention of a pose task's ``roll pitch yaw`` (:func:`pkm.task_values`).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> R = pkm.zyx_matrix(0.1, 0.2, 0.3)
        >>> np.round(R, 3)
        array([[ 0.936, -0.275,  0.218],
               [ 0.29 ,  0.956, -0.037],
               [-0.199,  0.098,  0.975]])
        >>> np.allclose(R.T @ R, np.eye(3))
        True
    """
    r, p, y = (as_array(a, n, "an angle [rad]") for a, n in ((roll, "roll"), (pitch, "pitch"), (yaw, "yaw")))
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def _rate_map(rpy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Columns of ``B`` with ``w = B [roll_dot, pitch_dot, yaw_dot]`` (world axes)."""
    _roll, pitch, yaw = rpy
    e_yaw = np.array([0.0, 0.0, 1.0])
    e_pitch = np.array([-np.sin(yaw), np.cos(yaw), 0.0])
    e_roll = np.array([np.cos(yaw) * np.cos(pitch), np.sin(yaw) * np.cos(pitch), -np.sin(pitch)])
    return e_roll, e_pitch, e_yaw


class _FrameTask:
    """The coordinates of one frame in the task: components among x y z roll pitch yaw, or its pose."""

    def __init__(self, mech: Mechanism, fid: int, components: tuple[str, ...], prefix: str):
        self.mech, self.fid = mech, fid
        self.pose = components == ("pose",)
        self.comp = () if self.pose else components
        self.value_size, self.size = (7, 6) if self.pose else (len(components), len(components))
        self.keys = tuple(prefix + k for k in (("x", "y", "z", "roll", "pitch", "yaw") if self.pose else self.comp))
        self.names = tuple(prefix + k for k in (("x", "y", "z", "wx", "wy", "wz") if self.pose else self.comp))
        self.value_names = tuple(prefix + k for k in (("x", "y", "z", "qx", "qy", "qz", "qw") if self.pose
                                                      else self.comp))
        self.kinds = {prefix + k: ("length" if k in _POS else "angle")
                      for k in (("x", "y", "z", "roll", "pitch", "yaw") if self.pose else self.comp)}
        self.has_angles = any(c in _ANGLES for c in self.comp)

    def value(self, d: pin.Data) -> np.ndarray:
        M = d.oMf[self.fid]
        if self.pose:
            return np.concatenate([M.translation, pin.Quaternion(M.rotation).coeffs()])
        rpy = zyx_angles(M.rotation) if self.has_angles else np.zeros(3)
        return np.array([M.translation[_POS[c]] if c in _POS else rpy[_ANGLES.index(c)] for c in self.comp])

    def named(self, y: np.ndarray) -> list[float]:
        if not self.pose:
            return [float(v) for v in y]
        return [float(v) for v in list(y[:3]) + list(zyx_angles(pin.Quaternion(*_wxyz(y[3:7])).toRotationMatrix()))]

    def from_named(self, values: Mapping[str, float]) -> list[float]:
        v = [values[k] for k in self.keys]
        if not self.pose:
            return v
        return v[:3] + list(pin.Quaternion(zyx_matrix(*v[3:6])).coeffs())

    def error(self, y_target: np.ndarray, y: np.ndarray) -> np.ndarray:
        if self.pose:
            R_t = pin.Quaternion(*_wxyz(y_target[3:7])).toRotationMatrix()
            R = pin.Quaternion(*_wxyz(y[3:7])).toRotationMatrix()
            return np.concatenate([y_target[:3] - y[:3], pin.log3(R_t @ R.T)])
        out = y_target - y
        for i, c in enumerate(self.comp):
            if c in _ANGLES:
                out[i] = wrap_angle(out[i])
        return out

    def retract(self, y: np.ndarray, dy: np.ndarray) -> np.ndarray:
        if not self.pose:
            return y + dy
        R = pin.exp3(dy[3:6]) @ pin.Quaternion(*_wxyz(y[3:7])).toRotationMatrix()
        return np.concatenate([y[:3] + dy[:3], pin.Quaternion(R).coeffs()])

    def jacobian(self, d: pin.Data) -> np.ndarray:
        J6 = pin.getFrameJacobian(self.mech.model, d, self.fid, pin.LOCAL_WORLD_ALIGNED)
        if self.pose:
            return J6
        Jw = _euler_rows(d.oMf[self.fid].rotation) @ J6[3:] if self.has_angles else J6[3:]
        return np.vstack([J6[_POS[c]][None] if c in _POS else Jw[_ANGLES.index(c)][None] for c in self.comp])

    def bias(self, d: pin.Data) -> np.ndarray:
        """``dJ/dt v`` of these coordinates, from the kinematics (with velocity, zero acceleration) in ``d``."""
        m, f = self.mech.model, self.fid
        acc = pin.getFrameClassicalAcceleration(m, d, f, pin.LOCAL_WORLD_ALIGNED)
        if self.pose:
            return np.concatenate([acc.linear, acc.angular])
        ang = acc.angular  # replaced by the Euler-angle accelerations when the task has angles
        if self.has_angles:
            R = d.oMf[f].rotation
            rpy = zyx_angles(R)
            w = pin.getFrameVelocity(m, d, f, pin.LOCAL_WORLD_ALIGNED).angular
            Binv = _euler_rows(R)
            rates = Binv @ w
            e_roll, e_pitch, e_yaw = _rate_map(rpy)
            w_py = rates[2] * e_yaw + rates[1] * e_pitch  # angular velocity of the yaw-pitch frame
            Bdot_rates = rates[0] * np.cross(w_py, e_roll) + rates[1] * np.cross(rates[2] * e_yaw, e_pitch)
            ang = Binv @ (acc.angular - Bdot_rates)
        return np.array([acc.linear[_POS[c]] if c in _POS else ang[_ANGLES.index(c)] for c in self.comp])


def _euler_rows(R: np.ndarray) -> np.ndarray:
    """``B^-1``: world angular velocity -> (roll, pitch, yaw) rates."""
    rpy = zyx_angles(R)
    if abs(np.cos(rpy[1])) < 1e-9:
        raise SingularityError("representation", abs(np.cos(rpy[1])),
                               "Z-Y-X Euler angles are singular at pitch = +-90 deg")
    return np.linalg.inv(np.column_stack(_rate_map(rpy)))


class TaskMap:
    """Evaluates the task coordinates of ``mech`` (see module doc): the end effector's components, those of
    the task's other frames (``[task.frames]``, keys ``frame.x``...), then the joint outputs.

    :meth:`of` gives a mechanism's own (made once; it holds no per-call state): the mechanism's module does not
    import this one, which is built on it."""

    @classmethod
    def of(cls, mech: Mechanism) -> TaskMap:
        """``mech``'s task map, made on the first call and kept with the mechanism."""
        return derived(mech, cls)

    def __init__(self, mech: Mechanism):
        self.mech = mech
        self.spec = mech.spec.task
        groups = [_FrameTask(mech, mech.ee_frame, self.spec.components, "")] if self.spec.components else []
        groups += [_FrameTask(mech, fid, comps, f"{name}.")
                   for (name, comps), fid in zip(self.spec.frames.items(), mech.task_frames)]
        self._groups = groups
        #: A task that is the end effector's pose (and joint outputs): targets may be a pin.SE3.
        self.pose = len(groups) == 1 and groups[0].pose and not self.spec.frames
        self.size = self.spec.size
        self.value_size = sum(g.value_size for g in groups) + len(self.spec.joints)
        self._jq = np.array([j.idx_q for j in mech.task_joints], dtype=int)
        self._jv = np.array([j.idx_v for j in mech.task_joints], dtype=int)
        self._value_at = np.cumsum([0] + [g.value_size for g in groups])
        self._tangent_at = np.cumsum([0] + [g.size for g in groups])
        self.names = tuple(n for g in groups for n in g.names) + self.spec.joints
        #: The entries of a task value (a pose's orientation as its quaternion ``qx qy qz qw``).
        self.value_names = tuple(n for g in groups for n in g.value_names) + self.spec.joints
        #: The task coordinates by name, as :meth:`named` gives them and targets may state them (a pose:
        #: ``x y z roll pitch yaw``; another frame's prefixed, ``foot.z``), then the joint outputs.
        self.keys = tuple(k for g in groups for k in g.keys) + self.spec.joints
        #: Each key's kind (``"length"`` or ``"angle"``), for units.
        self.kinds = {k: v for g in groups for k, v in g.kinds.items()}
        self.kinds.update({j: "angle" if mech.joints[j].revolute else "length" for j in self.spec.joints})

    def default_length(self, length: float | None) -> float | None:
        """``length``, or where it is None and the task mixes lengths and angles, the mechanism's characteristic
        length [m] (:attr:`Mechanism.characteristic_length <pkm.core.model.mechanism.Mechanism.characteristic_length>`):
        the default of the command line's and the service's maps (the library's functions ask for it)."""
        mixed = {"angle", "length"} <= set(self.kinds.values())
        return float(self.mech.characteristic_length) if length is None and mixed else length

    def rate_scale(self, length: float | None, keys: Sequence[str] | None = None) -> np.ndarray:
        """The scales of the task rates ``keys`` (default: all, in :attr:`keys` order): 1 for a length, ``1/length``
        for an angle, the homogenisation by a characteristic length ``L`` [m] that makes every rate a speed.

        Raises:
            InvalidInputError: the rates mix lengths and angles and no ``length`` is given.
        """
        kinds = [self.kinds[k] for k in (self.keys if keys is None else keys)]
        if "angle" in kinds and "length" in kinds and length is None:
            raise InvalidInputError("length", "the task mixes lengths and angles: give the characteristic length L "
                                              "[m] that homogenises the angular rates")
        return np.array([1.0 if k == "length" else 1.0 / (length or 1.0) for k in kinds])

    def _parts(self, y: np.ndarray, tangent: bool = False) -> tuple[list[np.ndarray], np.ndarray]:
        at = self._tangent_at if tangent else self._value_at
        return [y[at[i]:at[i + 1]] for i in range(len(self._groups))], y[at[-1]:]

    # values ---------------------------------------------------------------
    def value(self, q: np.ndarray) -> np.ndarray:
        """The task coordinates at ``q``."""
        pin.framesForwardKinematics(self.mech.model, self.mech.data, q)
        return self.value_from(self.mech.data, q)

    def value_from(self, d: pin.Data, q: np.ndarray) -> np.ndarray:
        """The task coordinates from the frame placements already in ``d`` (see :class:`pkm.core.Configuration`)."""
        return np.concatenate([g.value(d) for g in self._groups] + [np.asarray(q)[self._jq]])

    def named(self, q: np.ndarray) -> dict[str, float]:
        """The task coordinates at ``q`` by name (:attr:`keys`; a pose as x y z and Z-Y-X Euler angles) [m, rad]."""
        heads, tail = self._parts(self.value(q))
        values = [v for g, y in zip(self._groups, heads) for v in g.named(y)] + [float(v) for v in tail]
        return dict(zip(self.keys, values))

    def parse(self, target: Mapping[str, Any] | pin.SE3 | ArrayLike, base: np.ndarray | None = None) -> np.ndarray:
        """A target value from user input.

        Accepted: a flat vector of the task coordinates; a mapping ``{name: value}`` over some of
        :attr:`keys` (a pose by ``x y z roll pitch yaw``), the others taken from the configuration ``base``
        (default: the reference); a mapping with ``"pose"`` (a ``pin.SE3`` or a 4x4 matrix) and the
        joint outputs; for a pose task, a ``pin.SE3`` or 4x4 matrix alone. Values may be strings with
        units (``"20mm"``, ``"5deg"``; :mod:`pkm.units`).
        """
        nj = len(self.spec.joints)
        if self.pose and (isinstance(target, pin.SE3) or _shape(target) == (4, 4)):
            if nj:
                raise InvalidInputError("target", f"this task also needs the joints {list(self.spec.joints)}: "
                                                  "pass {'pose': T, joint: value, ...}")
            target = {"pose": target}
        if isinstance(target, Mapping) and "pose" in target and self.pose:
            unknown = [k for k in target if k != "pose" and k not in self.spec.joints]
            if unknown:
                raise InvalidInputError("target", f"with 'pose' give only the joint outputs {list(self.spec.joints)}, "
                                                  f"got {unknown}", target)
            M = _as_se3(target["pose"])
            rest = self.named(self.mech.q_reference if base is None else base)
            target = list(M.translation) + list(pin.Quaternion(M.rotation).coeffs()) + [
                quantity(target.get(j, rest[j]), self.kinds[j], j) for j in self.spec.joints]
        elif isinstance(target, Mapping):
            unknown = [k for k in target if k not in self.keys]
            if unknown:
                raise InvalidInputError("target", f"unknown task coordinates {unknown}; this task has {list(self.keys)}",
                                        target)
            values = self.named(self.mech.q_reference if base is None else base)
            values.update({k: quantity(v, self.kinds[k], k) for k, v in target.items()})
            target = [v for g in self._groups for v in g.from_named(values)] + [values[j] for j in self.spec.joints]
        elif not any(g.pose for g in self._groups):
            target = quantities(target, [self.kinds[k] for k in self.keys], "target")
        y = as_array(target, "target", f"{self.value_size} task coordinates {list(self.value_names)}")
        if y.shape != (self.value_size,):
            raise InvalidInputError("target", f"expected {self.value_size} task coordinates "
                                              f"{list(self.value_names)}, got shape {y.shape}", target)
        if not np.all(np.isfinite(y)):
            raise InvalidInputError("target", "holds non-finite values", target)
        bounded(y, "target", target)
        for g, part in zip(self._groups, self._parts(y)[0]):
            if g.pose and abs((qn := float(np.linalg.norm(part[3:7]))) - 1.0) > 1e-6:
                raise InvalidInputError("target", f"quaternion norm {qn:.6g}, expected 1", target)
        return y

    def error(self, y_target: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Tangent-space difference ``y_target - y`` (angles wrapped to (-pi, pi])."""
        (heads_t, tail_t), (heads, tail) = self._parts(np.asarray(y_target)), self._parts(np.asarray(y))
        return np.concatenate([g.error(a, b) for g, a, b in zip(self._groups, heads_t, heads)] + [tail_t - tail])

    def retract(self, y: np.ndarray, dy: np.ndarray) -> np.ndarray:
        """``y`` moved by the tangent vector ``dy`` (the inverse of :meth:`error`)."""
        y, dy = np.asarray(y, dtype=float), np.asarray(dy, dtype=float)
        (heads, tail), (dheads, dtail) = self._parts(y), self._parts(dy, tangent=True)
        return np.concatenate([g.retract(a, b) for g, a, b in zip(self._groups, heads, dheads)] + [tail + dtail])

    def interpolate(self, y0: np.ndarray, y1: np.ndarray, s: float) -> np.ndarray:
        """The point at fraction ``s`` of the way from ``y0`` to ``y1`` (geodesic for rotations)."""
        return self.retract(y0, s * self.error(y1, y0))

    # derivatives ------------------------------------------------------------
    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """``d(task)/dq`` on the tangent space (size x nv)."""
        pin.computeJointJacobians(self.mech.model, self.mech.data, q)
        pin.updateFramePlacements(self.mech.model, self.mech.data)
        return self.jacobian_from(self.mech.data)

    def jacobian_from(self, d: pin.Data) -> np.ndarray:
        """``d(task)/dq`` from the joint Jacobians and frame placements already in ``d``."""
        Jj = np.zeros((len(self._jv), self.mech.model.nv))
        Jj[np.arange(len(self._jv)), self._jv] = 1.0
        return np.vstack([g.jacobian(d) for g in self._groups] + [Jj])

    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``dJ/dt v``: task acceleration produced by ``v`` alone (a = 0)."""
        m, d = self.mech.model, self.mech.data
        pin.forwardKinematics(m, d, q, v, np.zeros(m.nv))
        pin.updateFramePlacements(m, d)
        return np.concatenate([g.bias(d) for g in self._groups] + [np.zeros(len(self._jv))])


def _shape(x: Any) -> tuple[int, ...] | None:
    """``np.shape(x)``, or None for what numpy cannot shape (ragged nestings)."""
    try:
        return np.shape(x)
    except (ValueError, TypeError):
        return None


def _wxyz(xyzw: np.ndarray) -> tuple[float, float, float, float]:
    return float(xyzw[3]), float(xyzw[0]), float(xyzw[1]), float(xyzw[2])


ROTATION_TOL = 2e-3  # max|R^T R - I| projected away: matrices printed to 4 digits, as in the papers


def as_rotation(R: ArrayLike, name: str = "R", tol: float = ROTATION_TOL) -> np.ndarray:
    """``R`` checked to be a rotation matrix and projected on SO(3) (SVD).

    Matrices printed with a few digits (the papers' poses carry 4) are accepted: the defect
    ``max|R^T R - I|`` may reach ``tol``; beyond it, or with ``det R <= 0``, ``R`` is refused.

    Raises:
        InvalidInputError: with the size of the defect and the determinant.
    """
    M = np.reshape(as_vector(np.ravel(as_array(R, name, "a 3x3 rotation matrix")), 9, name), (3, 3))
    defect, det = float(np.abs(M.T @ M - np.eye(3)).max()), float(np.linalg.det(M))
    if defect > tol or det <= 0.0:
        raise InvalidInputError(name, f"not a rotation matrix: max|R^T R - I| = {defect:.3g} (tolerance {tol:.0e}), "
                                      f"det R = {det:.6g}", R)
    if defect < 1e-15:
        return M
    U, _, Vt = np.linalg.svd(M)
    return U @ Vt


def _as_se3(T: pin.SE3 | ArrayLike) -> pin.SE3:
    if isinstance(T, pin.SE3):
        if not (np.all(np.isfinite(T.translation)) and np.all(np.isfinite(T.rotation))):
            raise InvalidInputError("pose", "the pin.SE3 holds non-finite values", T)
        return pin.SE3(as_rotation(T.rotation, "pose"), T.translation.copy())
    T = as_array(T, "pose", "a pin.SE3 or a 4x4 matrix")
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise InvalidInputError("pose", f"expected a pin.SE3 or a finite 4x4 matrix, got shape {T.shape}", T)
    return pin.SE3(as_rotation(T[:3, :3], "pose"), T[:3, 3].copy())
