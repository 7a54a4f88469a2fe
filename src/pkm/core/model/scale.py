"""A mechanism's size: its characteristic length, the Jacobians' homogenisation by it, a copy scaled in size.

Jacobians mix units: a closure's translation rows are in m and its rotation rows (a 6-D loop) in rad; a revolute
column moves 1 rad, a prismatic one 1 m; task coordinates are lengths or angles. A ratio of their singular values
then depends on the mechanism's size (a translation row's entries grow with the arm lengths, a rotation row's do
not), so that a fixed threshold on it judges a robot of 5 cm as it would not judge the same robot of 50 cm. Each
Jacobian is made homogeneous first, every entry a length [m]:

* rows that are angles (a closure's or a task's rotation) are multiplied by the characteristic length ``L``;
* columns that are lengths (a prismatic joint, a floating base's translation) are multiplied by ``L``
  (their rate taken per ``L``, as a revolute's per radian).

A mechanism made only of revolute (and ball) joints closed by point closures, whose task is a position, is left
exactly as it is. Scaling every length of a mechanism by ``s`` then scales every homogenised entry by ``s``: every
ratio of singular values (a distance to a singularity, a condition index) is unchanged.

``L`` (:attr:`Mechanism.characteristic_length <pkm.core.model.mechanism.Mechanism.characteristic_length>`) is the
root-mean-square distance of the joints' origins from their centroid at the reference configuration
(``mech.q_reference``), in [m]: a length of the mechanism itself, which scales exactly with it. Where every joint
origin coincides, the frames' origins are used instead, and 1 m where they coincide too (nothing in the mechanism has
a length). It is a spread, not an extent: the plausibility rules bound masses and inertias by the extent ``E``, the
largest width along x, y or z of every joint origin, frame origin and centre of mass
(:func:`pkm.core.model.plausibility.size`: a bound must enclose the whole mechanism, a scale need only grow with it;
both from :func:`~pkm.core.model.mechanism.reference_points`; ``E`` is 1.8 to 2.5 ``L`` on the shipped mechanisms).
:meth:`JacobianScales.of(mech) <JacobianScales.of>` holds the factors (made once per mechanism and reference).

:func:`~pkm.core.model.builder.scaled_mechanism` builds the copy of a mechanism with every length multiplied by a
factor (:func:`scale_urdf`: the URDF's origins, prismatic limits and speed limits, geometry, the inertias' centres of
mass and tensors, times ``s^2``, the masses unchanged; the spec's reference values of prismatic joints and of a
floating base's position); :func:`scale_configuration` maps a configuration onto it.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pkm._derived import derived
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism
from pkm.validation import as_scalar


@dataclass(frozen=True)
class JacobianScales:
    """The factors that homogenise a mechanism's Jacobians (module doc): ``rows[:, None] * J * columns``.

    Attributes:
        length: The characteristic length ``L`` [m].
        constraint_rows: Per closure equation (n_constraints,): ``L`` for a rotation row, 1 for a translation row.
        task_rows: Per task coordinate (n_task,): ``L`` for an angle, 1 for a length.
        columns: Per joint velocity (nv,): ``L`` for a length (prismatic, a floating base's translation), 1 for an
            angle.
        actuated: ``columns`` on the actuated joints (na,).
    """

    length: float
    constraint_rows: np.ndarray
    task_rows: np.ndarray
    columns: np.ndarray
    actuated: np.ndarray

    @functools.cached_property
    def trivial(self) -> bool:
        """Every factor is 1 (the Jacobians are already homogeneous: nothing to scale)."""
        return bool(np.all(self.constraint_rows == 1.0) and np.all(self.task_rows == 1.0)
                    and np.all(self.columns == 1.0))

    @functools.cached_property
    def closure_residual(self) -> np.ndarray:
        """Per closure equation (n_constraints,), the factor that counts its residual in ``L``: ``1 / L`` for a
        translation row, 1 for a rotation row (:func:`pkm.core.kinematics.solve.close_loops`' tolerance, the
        exported C's and the twin's Newton kernels' residual: scale-free)."""
        return self.constraint_rows / self.length

    @functools.cached_property
    def task_residual(self) -> np.ndarray:
        """Per task coordinate (n_task,), the factor that counts its error in ``L``: ``1 / L`` for a length, 1 for
        an angle (as :attr:`closure_residual`)."""
        return self.task_rows / self.length

    def constraint(self, Jc: np.ndarray) -> np.ndarray:
        """The constraint Jacobian (n_constraints x nv) homogenised."""
        return Jc if self.trivial else self.constraint_rows[:, None] * Jc * self.columns

    def task(self, Jt: np.ndarray) -> np.ndarray:
        """The task Jacobian (n_task x nv) homogenised."""
        return Jt if self.trivial else self.task_rows[:, None] * Jt * self.columns

    def joint_motions(self, basis: np.ndarray) -> np.ndarray:
        """A basis of motions found on the homogenised columns (nv x k), back in joint rates and orthonormal; a joint
        the basis does not move stays exactly unmoved (a floating base's rows stay 0, not QR's round-off)."""
        if self.trivial or not basis.shape[1]:
            return basis
        out = np.zeros(basis.shape)
        rows = np.flatnonzero(np.any(basis != 0.0, axis=1))
        out[rows] = np.linalg.qr(self.columns[rows, None] * basis[rows])[0]
        return out

    def forward(self, J: np.ndarray) -> np.ndarray:
        """A forward Jacobian (task rates from actuated rates, ``(..., n_task, na)``) homogenised."""
        return J if self.trivial else self.task_rows[:, None] * J * self.actuated

    @staticmethod
    def of(mech: Mechanism) -> JacobianScales:
        """The factors that homogenise ``mech``'s Jacobians by its
        :attr:`~pkm.core.model.mechanism.Mechanism.characteristic_length`, made once per mechanism (again where its
        ``q_reference`` changes)."""
        return derived(mech, _jacobian_scales)

    @staticmethod
    def at(mech: Mechanism, length: float) -> JacobianScales:
        """The factors that homogenise ``mech``'s Jacobians by the length ``length`` [m] (> 0) instead of its
        characteristic length: the assembly's, before there is a reference (:func:`pkm.core.kinematics.solve.assemble`)."""
        return _jacobian_scales(mech, length)


def _jacobian_scales(mech: Mechanism, length: float | None = None) -> JacobianScales:
    L = mech.characteristic_length if length is None else length
    rows = []
    for c in mech.spec.closures:
        rows += [1.0] * 3 + ([L] * 3 if c.type == "frame" else [])
    task_map = TaskMap.of(mech)
    task = [L if task_map.kinds[k] == "angle" else 1.0 for k in task_map.keys]
    columns = np.ones(mech.nv)
    for j in mech.joints.values():  # a translation's rate (prismatic, a free-flyer's first three) is a length
        columns[j.idx_v:j.idx_v + min(length_entries(j.kind), j.nv)] = L
    return JacobianScales(L, np.array(rows, dtype=float), np.array(task, dtype=float), columns, columns[mech.act_v])


# ---------------------------------------------------------------------- a mechanism scaled in size
_GEOMETRY = {"box": ("size",), "cylinder": ("radius", "length"), "sphere": ("radius",), "capsule": ("radius", "length"),
             "ellipsoid": ("radii",)}


def _times(text: str | None, s: float) -> str | None:
    if text is None:
        return None
    return " ".join(repr(float(x) * s) for x in text.split())


def scale_urdf(urdf: str, factor: float) -> str:
    """The URDF text with every length times ``factor`` (module doc); angles, masses and efforts unchanged."""
    from lxml import etree

    from pkm.core.model.urdf import check_urdf

    s = as_scalar(factor, "factor", low=0.0, strict_low=True)
    root = check_urdf(urdf)
    prismatic = {el.get("name") for el in root.findall("joint") if el.get("type") == "prismatic"}
    for el in root.iter("origin"):
        if el.get("xyz") is not None:
            el.set("xyz", _times(el.get("xyz"), s))
    for el in root.iter("inertia"):
        for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
            if el.get(key) is not None:
                el.set(key, repr(float(el.get(key)) * s * s))
    for tag, keys in _GEOMETRY.items():
        for el in root.iter(tag):
            for key in keys:
                if el.get(key) is not None:
                    el.set(key, _times(el.get(key), s))
    for el in root.iter("mesh"):
        el.set("scale", _times(el.get("scale") or "1 1 1", s))
    for joint in root.findall("joint"):
        if joint.get("name") in prismatic:
            for el in joint.findall("limit"):
                for key in ("lower", "upper", "velocity"):
                    if el.get(key) is not None:
                        el.set(key, repr(float(el.get(key)) * s))
        for el in joint.findall("mimic"):  # q = multiplier q_other + offset, in the units of each joint
            this, other = joint.get("name") in prismatic, el.get("joint") in prismatic
            if el.get("multiplier") is not None and this != other:
                el.set("multiplier", repr(float(el.get("multiplier")) * (s if this else 1.0 / s)))
            if el.get("offset") is not None and this:
                el.set("offset", repr(float(el.get("offset")) * s))
    return etree.tostring(root, encoding="unicode")


def scale_configuration(mech: Mechanism, q: ArrayLike, factor: float) -> np.ndarray:
    """The configuration ``q`` of ``mech`` on its copy scaled by ``factor``
    (:func:`~pkm.core.model.builder.scaled_mechanism`): prismatic joints' values and a floating base's position times
    ``factor``, angles unchanged (nq,).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> prs3 = pkm.load("prs3")
        >>> big = pkm.scaled_mechanism(prs3, 10.0)
        >>> q = pkm.scale_configuration(prs3, prs3.q_reference, 10.0)
        >>> np.allclose(q, big.q_reference)
        True
        >>> np.round(prs3.actuated_q(prs3.q_reference), 4), np.round(big.actuated_q(q), 4)
        (array([0.134, 0.134, 0.134]), array([1.3397, 1.3397, 1.3397]))
    """
    q = mech.check_q(q)
    s = as_scalar(factor, "factor", low=0.0, strict_low=True)
    out = q.copy()
    for j in mech.joints.values():
        k = min(length_entries(j.kind), j.nq)
        out[j.idx_q:j.idx_q + k] *= s
    return out


def length_entries(kind: str) -> int:
    """How many leading configuration entries (and velocity entries) of a joint of Pinocchio kind ``kind`` are
    lengths: a prismatic joint's one, a free flyer's or a translation's three, a planar joint's two."""
    if kind in ("JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismaticUnaligned"):
        return 1
    return {"JointModelFreeFlyer": 3, "JointModelTranslation": 3, "JointModelPlanar": 2}.get(kind, 0)


__all__ = ["JacobianScales", "length_entries", "scale_configuration", "scale_urdf"]
