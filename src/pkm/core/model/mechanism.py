"""A closed-loop mechanism: a Pinocchio tree, its loop closures, actuation and task.

:class:`Mechanism` holds no algorithm of its own beyond bookkeeping (names,
indices, validated configuration vectors); the algorithms live in
:mod:`pkm.core.kinematics.solve` and :mod:`pkm.core.differential.velocity` and take a mechanism.
It is made by :mod:`pkm.core.model.builder` (:func:`~pkm.core.model.builder.build`,
:func:`~pkm.core.model.builder.from_strings`, also :func:`pkm.from_strings`, and
:func:`~pkm.core.model.builder.from_files`, which :func:`pkm.load` reaches), which assembles and checks its reference
configuration; ``Mechanism(model, spec)`` alone takes the spec's ``[reference]`` over the neutral configuration as it
is. The model never imports its builder: the builder registers how a mechanism it made pickles (:data:`REDUCE`).
Nor does it import what is built on it: its task map is :meth:`TaskMap.of(mech) <pkm.core.kinematics.task.TaskMap.of>`,
the factors that homogenise its Jacobians :meth:`JacobianScales.of(mech) <pkm.core.model.scale.JacobianScales.of>`,
each made once and kept with the mechanism (:func:`pkm._derived.derived`).

Joint coordinates follow Pinocchio: ``q`` has ``model.nq`` entries (a free-flyer
takes 7: position and quaternion x y z w), velocities ``v`` have ``model.nv``.
Joints are indexed by name through ``idx_q``/``idx_v`` (Pinocchio orders them
by tree traversal, not by file order). Mimic joints take no coordinate.
"""

from __future__ import annotations

import functools
import math
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm._derived import SLOT
from pkm.core.model.actuators import Actuator, from_model, write_model
from pkm.core.model.motors import motor_map
from pkm.core.model.spec import Branch, ClosureSpec
from pkm.core.model.springs import JointSprings, joint_springs
from pkm.core.model.urdf import position_limits
from pkm.errors import InvalidInputError, SpecError, SpecNameError, StructureError, UnknownNameError
from pkm.units import joint_kind, quantities
from pkm.validation import as_array, as_vector, bounded, instance_of, wrap_angle


@dataclass(frozen=True)
class JointInfo:
    """Where a named joint sits in ``q`` and ``v``."""

    name: str
    id: int
    idx_q: int
    nq: int
    idx_v: int
    nv: int
    kind: str

    @property
    def revolute(self) -> bool:
        """A bounded revolute joint (its coordinate is an angle defined modulo 2 pi)."""
        return self.nq == 1 and self.kind.startswith("JointModelR")


#: How a mechanism that :mod:`pkm.core.model.builder` made pickles, ``mech -> (rebuild, (urdf, spec, ...))``: set by
#: the builder when it is imported (the model does not import its builder). None until then.
REDUCE: Callable[[Mechanism], tuple[Callable[..., Mechanism], tuple[Any, ...]]] | None = None


class LimitViolation(NamedTuple):
    """A joint outside the position limits its model states (:meth:`Mechanism.limit_violations`)."""

    joint: str
    value: float  # [rad, m]
    limit: tuple[float, float]  # (lower, upper) [rad, m]


def reference_points(model: pin.Model, q: np.ndarray, min_mass: float = 0.0) -> tuple[np.ndarray, np.ndarray,
                                                                                     np.ndarray]:
    """A model's points at ``q`` (each n x 3) [m]: its joints' origins, its frames' origins and its bodies' centres of
    mass (the bodies with mass, and at least ``min_mass`` [kg]). The one source of a mechanism's size: the characteristic length
    (:attr:`Mechanism.characteristic_length`) and the plausibility rules' extent
    (:func:`pkm.core.model.plausibility.size`)."""
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    joints = np.array([data.oMi[j].translation for j in range(1, model.njoints)]).reshape(-1, 3)
    frames = np.array([f.translation for f in data.oMf]).reshape(-1, 3)
    centres = np.array([data.oMi[j].act(model.inertias[j].lever) for j in range(1, model.njoints)
                        if model.inertias[j].mass > 0.0 and model.inertias[j].mass >= min_mass]).reshape(-1, 3)
    return joints, frames, centres


def spread(model: pin.Model, q: np.ndarray) -> float:
    """The root-mean-square distance [m] of ``model``'s joint origins from their centroid at ``q`` (its frames'
    origins where the joints' coincide, 1 m where those coincide too): :attr:`Mechanism.characteristic_length` at the
    reference, and the assembly's scale at the configuration it starts from, before there is a reference
    (:func:`pkm.core.kinematics.solve.assemble`). Scaling every length of the model and of ``q`` scales it alike."""
    joints, frames, _ = reference_points(model, q)
    for points in (joints, frames):
        if len(points):
            length = float(np.sqrt(np.mean(np.sum((points - points.mean(axis=0)) ** 2, axis=1))))
            if length > 0.0:
                return length
    return 1.0


class Mechanism:
    """A parallel mechanism on Pinocchio.

    The model, the spec and every index are fixed once built: pkm keeps what it derives from them with the mechanism
    (compiled kernels, 50-digit programs, scales, random states), so a model changed in place (its gravity, a mass)
    would be answered for partly as it was: build a new mechanism instead. The Pinocchio data the algorithms
    write into are per thread (:attr:`data`, :attr:`constraint_datas`), so that one mechanism can be
    used from several threads at once. A mechanism pickles (it is rebuilt from its URDF and spec),
    so it can travel to worker processes.

    Attributes:
        model: The Pinocchio model of the tree (loops open).
        data: This thread's Pinocchio data of the model (algorithms write into it).
        spec: The closure spec.
        params: The parameter object that generated it (None when loaded from files).
        urdf: The URDF text, when known.
        base: The floating base's joint (``spec.floating_base``: a free-flyer on the world carrying the whole
            tree), or None. Its pose is an input like the actuators' values: the solvers hold it where ``q``
            puts it and the rate maps give it no velocity; the dynamics lets it move free by default (no
            wrench on it, its own equations of motion), or holds it (``base="fixed"``):
            :mod:`pkm.core.dynamics.model`.
        constraint_models: One ``pin.RigidConstraintModel`` per closure, in spec order.
            Point closures are ``CONTACT_3D`` in ``LOCAL_WORLD_ALIGNED``: their Jacobian is
            exactly d(p_A - p_B)/dq. Frame closures are ``CONTACT_6D`` in ``LOCAL`` (frame A):
            their Jacobian maps v to the twist of B relative to A, expressed in A, with a sign
            such that it is the derivative of ``-log6(A^-1 B)`` at closure.

    Examples:
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> delta.na, delta.nq, delta.nv, delta.actuated_names
        (3, 12, 12, ('motor_1', 'motor_2', 'motor_3'))
        >>> pkm.TaskMap.of(delta).keys
        ('x', 'y', 'z')
        >>> {k: round(v, 4) for k, v in delta.q_to_dict(delta.q_reference).items() if k.startswith("motor")}
        {'motor_1': 0.0017, 'motor_2': 0.0017, 'motor_3': 0.0017}
    """

    def __init__(self, model: pin.Model, spec: ClosureSpec, params: Any = None, urdf: str | None = None,
                 source: str = "<model>", notes: tuple[str, ...] = ()):
        if not isinstance(model, pin.Model):
            raise InvalidInputError("model", f"expected a pinocchio.Model, got {type(model).__name__}", model)
        if not isinstance(spec, ClosureSpec):
            raise InvalidInputError("spec", f"expected a ClosureSpec, got {type(spec).__name__}", spec)
        self.model = model
        self._local = threading.local()
        self.spec = spec
        self.params = params
        self.urdf = urdf
        self.source = source
        #: What the file's reader interpreted or ignored (:attr:`pkm.core.formats.base.Imported.notes`), and
        #: actuators that do not fit the mobility (:func:`pkm.core.differential.velocity.actuation`).
        self.notes: tuple[str, ...] = tuple(notes)
        #: ``{joint: (lower, upper)}`` position limits stated by the URDF (none when built from a model).
        self.limits: dict[str, tuple[float, float]] = position_limits(urdf, source) if urdf is not None else {}
        self.joints: dict[str, JointInfo] = {}
        for jid in range(1, model.njoints):
            jm = model.joints[jid]
            self.joints[model.names[jid]] = JointInfo(model.names[jid], jid, jm.idx_q, jm.nq, jm.idx_v, jm.nv,
                                                      jm.shortname())
        frame_names = [f.name for f in model.frames]

        def frame(name: str, what: str) -> int:
            fid = _frame_id(model, name, source)
            if fid is None:
                raise SpecNameError(source, "frame", name, frame_names, what)
            return fid

        def scalar_joint(name: str, what: str) -> JointInfo:
            if name not in self.joints:
                raise SpecNameError(source, "joint", name, self.scalar_joint_names(), what)
            info = self.joints[name]
            if info.kind == "JointModelMimic":
                raise SpecError(source, f"{what}: joint {name!r} follows another joint (a URDF <mimic>) and has no "
                                        "coordinate of its own: name the joint it mimics, or drop its <mimic>")
            if info.nq != 1 or info.nv != 1:
                raise SpecError(source, f"{what}: joint {name!r} ({info.kind}) must have one coordinate")
            return info

        #: The end-effector frame's id; 0 (the world frame, fixed) for a mechanism without one.
        if not spec.closures:
            raise SpecError(source, "no loop closure: give [[closure]] tables (or a model file with loops); pkm "
                                    "models closed-loop mechanisms, a tree alone needs none of it")
        self.ee_frame = frame(spec.end_effector, "end_effector") if spec.end_effector is not None else 0
        #: The ids of the task's other frames (``[task.frames]``), in spec order.
        self.task_frames = [frame(f, "task.frames") for f in spec.task.frames]
        self.closure_frames = [(frame(c.frame_a, f"closure {c.name!r}"), frame(c.frame_b, f"closure {c.name!r}"))
                               for c in spec.closures]
        if not spec.actuated:
            raise SpecError(source, "no actuated joint: name the driven joints (actuated = [...] in a closure spec)")
        self.actuated = tuple(scalar_joint(n, "actuated") for n in spec.actuated)
        self.task_joints = tuple(scalar_joint(n, "task.joints") for n in spec.task.joints)
        if spec.task.size > len(self.actuated):
            raise SpecError(source, f"the task has {spec.task.size} coordinates but only {len(self.actuated)} joints are "
                                    "actuated: give as many task coordinates as degrees of freedom, or fewer")
        for b in spec.branches.values():
            for n in b.signs:
                scalar_joint(n, f"branch {b.name!r}")
        for n in spec.springs:
            scalar_joint(n, f"[springs.{n}]")
        #: The drive of each actuated joint, in ``actuated`` order: the model file's values, then the spec's
        #: ``[actuators.<joint>]`` tables (:mod:`pkm.core.model.actuators`); written into the model's fields.
        self.actuators: tuple[Actuator, ...] = ()
        try:
            self.actuators = tuple(from_model(model, j.name, j.idx_v, spec.actuators.get(j.name))
                                   for j in self.actuated)
        except InvalidInputError as exc:
            raise SpecError(source, f"the drives of the model file with the spec's [actuators] tables: {exc}") from None
        for a, j in zip(self.actuators, self.actuated):
            write_model(model, a, j.idx_v)
        driven = {j.name: a.viscous for j, a in zip(self.actuated, self.actuators)}
        damping = np.array(model.damping, dtype=float)
        for n, t in spec.springs.items():  # (a spring's damping is the joint's viscous friction; on a driven joint
            if "damping" in t:            # in parallel with its drive's)
                damping[self.joints[n].idx_v] = t["damping"] + driven.get(n, 0.0)
        model.damping = damping
        #: The joint springs' stiffnesses about their rest positions (``[springs]``, :mod:`pkm.core.model.springs`):
        #: the efforts every dynamics route applies; their damping is in the model's ``damping`` (friction).
        self.springs: JointSprings = joint_springs(model, spec.springs)
        #: The motors and their map onto the actuated joints (``[motors]``: a differential; else one per joint).
        self.motor_map = motor_map(spec.actuated, spec.motors, source)
        self.act_q = np.array([j.idx_q for j in self.actuated])
        self.act_v = np.array([j.idx_v for j in self.actuated])
        self._revolute_q = np.array([j.idx_q for j in self.joints.values() if j.revolute], dtype=int)
        self._revolute_v = np.array([j.idx_v for j in self.joints.values() if j.revolute], dtype=int)
        self.base: JointInfo | None = None
        if spec.floating_base is not None:
            if spec.floating_base not in self.joints:
                raise SpecNameError(source, "joint", spec.floating_base, list(self.joints), "floating_base")
            self.base = self.joints[spec.floating_base]
            if self.base.kind != "JointModelFreeFlyer" or model.parents[self.base.id] != 0:
                raise SpecError(source, f"floating_base {spec.floating_base!r} is a {self.base.kind} on "
                                        f"{model.names[model.parents[self.base.id]]!r}: it must be a free-flyer "
                                        "joint on the world")
        self.base_v = np.arange(self.base.idx_v, self.base.idx_v + 6) if self.base else np.zeros(0, dtype=int)
        inputs = set(self.act_v) | set(self.base_v)
        self.passive_v = np.array([i for i in range(model.nv) if i not in inputs], dtype=int)
        #: The velocity columns the solvers move (all but the floating base's); None: all of them.
        self.free_v = np.array([i for i in range(model.nv) if i not in set(self.base_v)]) if self.base else None

        self.constraint_models = []
        for c, (fa, fb) in zip(spec.closures, self.closure_frames):
            A, B = model.frames[fa], model.frames[fb]
            if c.type == "point":
                cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, A.parentJoint, A.placement,
                                              B.parentJoint, B.placement, pin.LOCAL_WORLD_ALIGNED)
            else:
                cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_6D, model, A.parentJoint, A.placement,
                                              B.parentJoint, B.placement, pin.LOCAL)
            cm.name = c.name
            self.constraint_models.append(cm)
        self.n_constraints = sum(cm.residualSize() for cm in self.constraint_models)

        unknown = [n for n in spec.reference if n not in self.joints]
        if unknown:
            raise SpecNameError(source, "joint", unknown[0], list(self.joints), "[reference]")
        degrees = [n for n, v in spec.reference.items()
                   if self.joints[n].revolute and len(v) == 1 and abs(v[0]) > 2.0 * np.pi]
        if degrees:
            raise SpecError(source, f"[reference] gives {degrees[0]} = {spec.reference[degrees[0]][0]:g}, beyond "
                                    "2 pi: angles are in rad (degrees?)")
        try:
            self.q_reference = self.check_q(self.q_from_dict(spec.reference, base=pin.neutral(model)), "[reference]")
        except InvalidInputError as exc:
            raise SpecError(source, f"{exc}; fix the [reference] table of the closure spec") from None
        #: Actuators whose values the others fix at the reference (redundant actuation), set by the builder.
        self.dependent_actuators: tuple[str, ...] = ()

    def outside_limits(self, q: ArrayLike, *, tol: float = 1e-9) -> tuple[str, ...]:
        """The joints whose coordinate in ``q`` lies outside their stated position limits by more than ``tol``
        (m or rad), in model order. pkm's solvers do not enforce limits; their results report these."""
        return tuple(n for n, _, _ in self.limit_violations(q, tol=tol))

    def limit_violations(self, q: ArrayLike, *, tol: float = 1e-9) -> tuple[LimitViolation, ...]:
        """:meth:`outside_limits` with the data: a :class:`LimitViolation` (joint, value, limit) per joint outside
        (``._asdict()``: what the command line and the service print)."""
        q = np.asarray(q, dtype=float)
        out = []
        for n, (lo, hi) in self.limits.items():  # (a loop: at one configuration, 10x faster than limits_along)
            x = float(q[self.joints[n].idx_q]) if n in self.joints else math.nan
            if not lo - tol <= x <= hi + tol and x == x:  # (NaN: not called outside, the caller's to refuse)
                out.append(LimitViolation(n, x, (lo, hi)))
        return tuple(out)

    def limits_along(self, Q: ArrayLike, *, tol: float = 1e-9) -> tuple[tuple[int, LimitViolation], ...]:
        """Along configurations ``Q`` (N x nq), per joint that leaves its stated position limits by more than
        ``tol``: the first sample outside and there its :class:`LimitViolation`, in the order of the samples (as
        :meth:`limit_violations` at each sample, vectorised: a path of 100,000 samples costs milliseconds)."""
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        named = [(n, self.joints[n].idx_q, lo, hi) for n, (lo, hi) in self.limits.items() if n in self.joints]
        if not named or not len(Q):
            return ()
        names, idx, lo, hi = zip(*named)
        X = Q[:, list(idx)]
        with np.errstate(invalid="ignore"):
            out = ~((np.array(lo) - tol <= X) & (X <= np.array(hi) + tol)) & ~np.isnan(X)
        first = [(int(np.argmax(out[:, j])), j) for j in range(len(names)) if out[:, j].any()]
        return tuple((k, LimitViolation(names[j], float(X[k, j]), (lo[j], hi[j]))) for k, j in sorted(first))

    # ------------------------------------------------------------------ per-thread data, pickling
    @property
    def data(self) -> pin.Data:
        """This thread's ``pin.Data`` (made on first use in each thread)."""
        try:
            return self._local.data
        except AttributeError:
            self._local.data = self.model.createData()
            return self._local.data

    @property
    def constraint_datas(self) -> list[pin.RigidConstraintData]:
        """This thread's data of :attr:`constraint_models`."""
        try:
            return self._local.constraint_datas
        except AttributeError:
            self._local.constraint_datas = [cm.createData() for cm in self.constraint_models]
            return self._local.constraint_datas

    @property
    def task_map(self) -> Any:
        """Moved: :meth:`pkm.TaskMap.of(mech) <pkm.core.kinematics.task.TaskMap.of>` (the task map is built on the
        mechanism, whose module does not import it)."""
        raise AttributeError("Mechanism.task_map moved to pkm.TaskMap.of(mech) (the same map, made once per "
                             "mechanism): the task map is built on the mechanism, above it")

    @property
    def q_reference(self) -> np.ndarray:
        """The reference configuration (nq,): the spec's ``[reference]``, assembled by the builder."""
        return self._q_reference

    @q_reference.setter
    def q_reference(self, q: np.ndarray) -> None:
        self._q_reference = q
        for cached in ("characteristic_length", SLOT):  # (measured at the reference; what was derived from it)
            self.__dict__.pop(cached, None)

    @functools.cached_property
    def characteristic_length(self) -> float:
        """The mechanism's characteristic length ``L`` [m]: the root-mean-square distance of its joints' origins from
        their centroid at :attr:`q_reference` (:mod:`pkm.core.model.scale`). The singularity measures homogenise
        their Jacobians by it (:meth:`JacobianScales.of(mech) <pkm.core.model.scale.JacobianScales.of>`), so that
        they judge a mechanism of 5 cm as the same one of 5 m. Where every joint origin coincides, the frames'
        origins are used instead, and 1 m where they coincide too (nothing in the mechanism has a length)."""
        return spread(self.model, self.q_reference)

    @property
    def jacobian_scales(self) -> Any:
        """Moved: :meth:`pkm.core.model.scale.JacobianScales.of(mech) <pkm.core.model.scale.JacobianScales.of>`."""
        raise AttributeError("Mechanism.jacobian_scales moved to pkm.core.model.scale.JacobianScales.of(mech): the "
                             "scales are built on the mechanism, above it")

    def __reduce__(self) -> tuple[Callable[..., Mechanism], tuple[Any, ...]]:
        if self.urdf is None or REDUCE is None:
            raise InvalidInputError("mech", "a Mechanism built from a pinocchio.Model (no URDF text, or not by pkm's "
                                            "builder) cannot be pickled; build it with pkm.from_strings or pkm.load",
                                    self)
        return REDUCE(self)

    # ------------------------------------------------------------------ construction (moved)
    @classmethod
    def from_strings(cls, *args: Any, **kwargs: Any) -> Mechanism:
        """Moved: :func:`pkm.from_strings` (construction lives in the builder, above the model)."""
        raise AttributeError("Mechanism.from_strings moved to pkm.from_strings (the same arguments): construction lives in the builder")

    @classmethod
    def from_files(cls, *args: Any, **kwargs: Any) -> Mechanism:
        """Moved: :func:`pkm.load` (any model file or closure spec by path)."""
        raise AttributeError("Mechanism.from_files moved to pkm.load: pkm.load(path) reads a closure spec "
                             "and the model file it names, or any other model file pkm reads")

    # ------------------------------------------------------------------ sizes and names
    @property
    def name(self) -> str:
        return self.spec.mechanism

    @property
    def nq(self) -> int:
        return self.model.nq

    @property
    def nv(self) -> int:
        return self.model.nv

    @property
    def na(self) -> int:
        """Number of actuated coordinates."""
        return len(self.actuated)

    @property
    def n_task(self) -> int:
        """Number of output (task) coordinates."""
        return self.spec.task.size

    @property
    def actuated_names(self) -> tuple[str, ...]:
        return self.spec.actuated

    def scalar_joint_names(self) -> list[str]:
        return [n for n, j in self.joints.items() if j.nq == 1 and j.nv == 1]

    def frame_id(self, name: str) -> int:
        """Frame index by name; raises :class:`UnknownNameError` listing the valid names."""
        fid = _frame_id(self.model, name, self.source)
        if fid is None:
            raise UnknownNameError("frame", name, [f.name for f in self.model.frames], self.name)
        return fid

    def joint(self, name: str) -> JointInfo:
        if not isinstance(name, str) or name not in self.joints:
            raise UnknownNameError("joint", name, list(self.joints), self.name)
        return self.joints[name]

    # ------------------------------------------------------------------ vectors
    def check_q(self, q: ArrayLike, name: str = "q") -> np.ndarray:
        """``q`` as a float array of shape (nq,), finite, within :data:`~pkm.validation.ABSURD` (a coordinate beyond
        is refused, never wrapped: :func:`~pkm.validation.bounded`), with unit quaternions; else raise."""
        q = bounded(as_vector(q, self.nq, name), name, q)
        for j in self.joints.values():
            if j.kind == "JointModelFreeFlyer":
                quat = q[j.idx_q + 3:j.idx_q + 7]
            elif j.kind == "JointModelSpherical":
                quat = q[j.idx_q:j.idx_q + 4]
            else:
                continue
            if abs(np.linalg.norm(quat) - 1.0) > 1e-6:
                raise InvalidInputError(name, f"quaternion of joint {j.name!r} has norm {np.linalg.norm(quat):.6g}, "
                                              "expected 1", quat)
        return q

    def check_v(self, v: ArrayLike, name: str = "v") -> np.ndarray:
        return as_vector(v, self.nv, name)

    def check_actuated(self, qa: ArrayLike, name: str = "q_actuated", *, positions: bool = False,
                       order: str | None = None) -> np.ndarray:
        """Actuated values as a vector (``na``, SI). With ``order`` (``"position"``, ``"rate"``, ``"effort"``:
        :data:`pkm.units.JOINT_KINDS`; ``positions``: ``"position"``), entries may be strings with a unit of that
        order (``"5deg"``, ``"20mm"``; ``"-30deg/s"``, ``"300rpm"``, ``"50mm/s"``; ``"2 N m"``, ``"5N"``); without,
        and for accelerations, numbers only (SI). Positions are bounded (:func:`~pkm.validation.bounded`: beyond 1e6
        m or rad refused, never wrapped)."""
        order = "position" if positions else order
        kinds = None if order is None else [joint_kind(j.revolute, order) for j in self.actuated]
        if kinds is not None and None not in kinds:
            qa = quantities(qa, kinds, name)
        if order == "position":
            return bounded(as_vector(qa, self.na, name), name, qa)
        return as_vector(qa, self.na, name)

    def actuated_q(self, q: ArrayLike) -> np.ndarray:
        """The actuated coordinates of a configuration, in spec order."""
        return np.asarray(q, dtype=float)[self.act_q].copy()

    def with_actuated(self, q: ArrayLike, qa: ArrayLike) -> np.ndarray:
        q = np.array(q, dtype=float)
        q[self.act_q] = qa
        return q

    def difference(self, q0: ArrayLike, q1: ArrayLike) -> np.ndarray:
        """The tangent step from ``q0`` to ``q1`` (``pin.difference``), revolute angles taken the short way round
        (a crank passing pi moves by a little, not by 2 pi)."""
        dq = pin.difference(self.model, np.asarray(q0, dtype=float), np.asarray(q1, dtype=float))
        dq[self._revolute_v] = wrap_angle(dq[self._revolute_v])
        return dq

    def wrap(self, q: ArrayLike) -> np.ndarray:
        """``q`` with every revolute coordinate brought into (-pi, pi]."""
        q = np.array(q, dtype=float)
        q[self._revolute_q] = wrap_angle(q[self._revolute_q])
        return q

    def q_from_dict(self, values: Mapping[str, Any], base: ArrayLike | None = None) -> np.ndarray:
        """A configuration from ``{joint name: value or vector}``; other joints from ``base``."""
        if not isinstance(values, Mapping):
            raise InvalidInputError("values", f"expected a mapping {{joint name: value}}, got {type(values).__name__}",
                                    values)
        q = np.array(self.q_reference if base is None else base, dtype=float)
        for name, val in values.items():
            j = self.joint(name)
            arr = np.atleast_1d(as_array(val, name, f"{j.nq} coordinate(s) of joint {name!r}"))
            if arr.shape != (j.nq,):
                raise InvalidInputError(name, f"joint {name!r} takes {j.nq} coordinate(s), got {arr.shape}", val)
            if not np.all(np.isfinite(arr)):
                raise InvalidInputError(name, "value is not finite", val)
            q[j.idx_q:j.idx_q + j.nq] = bounded(arr, name, val)
        return q

    def q_to_dict(self, q: ArrayLike) -> dict[str, np.ndarray | float]:
        """``{joint name: coordinate}`` (scalars for 1-DOF joints); mimic joints are left out."""
        q = np.asarray(q, dtype=float)
        out: dict[str, np.ndarray | float] = {}
        for name, j in self.joints.items():
            if j.nq == 1:
                out[name] = float(q[j.idx_q])
            elif j.nq > 1:
                out[name] = q[j.idx_q:j.idx_q + j.nq].copy()
        return out

    def branch_signs(self, q: ArrayLike, branch: str | None = None) -> dict[str, int]:
        """Signs of the joints that define ``branch`` (default branch when None).

        Angles are taken modulo 2 pi in (-pi, pi]: the sign of a revolute coordinate is that of its sine.
        """
        b = self.branch(branch)
        q = self.wrap(q)
        return {n: (1 if q[self.joints[n].idx_q] >= 0 else -1) for n in b.signs}

    def on_branch(self, q: ArrayLike, branch: str | None = None) -> bool:
        b = self.branch(branch)
        return self.branch_signs(q, b.name) == dict(b.signs)

    def branch(self, name: str | None = None) -> Branch:
        """The named branch (the spec's default when None)."""
        key = self.spec.default_branch if name is None else name
        if not isinstance(key, str) or key not in self.spec.branches:
            raise UnknownNameError("branch", str(name), list(self.spec.branches), self.name)
        return self.spec.branches[key]

    def __repr__(self) -> str:
        return (f"Mechanism({self.name!r}: nq={self.nq}, nv={self.nv}, actuated={list(self.actuated_names)}, "
                f"closures={len(self.spec.closures)} ({self.n_constraints} equations), "
                f"task={list(self.spec.task.components) + list(self.spec.task.joints)})")


#: The frame a name means when frames of several types share it (MJCF bodies, joints and sites may share names; a
#: URDF link and joint may): a body's, an operational frame's (a site, a closure's anchor), a fixed joint's, a
#: joint's, a sensor's, in this order (the link's frame where a joint shares its name, as before).
FRAME_TYPES = (pin.FrameType.BODY, pin.FrameType.OP_FRAME, pin.FrameType.FIXED_JOINT, pin.FrameType.JOINT,
               pin.FrameType.SENSOR)


def _frame_id(model: pin.Model, name: object, source: str) -> int | None:
    """The frame called ``name``, looked up by name and type (the first type of :data:`FRAME_TYPES` that has one: a
    link's frame when a joint shares its name); None if there is none."""
    if not isinstance(name, str):
        return None
    for kind in FRAME_TYPES:
        if model.existFrame(name, kind):
            try:
                return model.getFrameId(name, kind)
            except ValueError:  # (two frames of one type and name: a model built by hand)
                raise SpecError(source, f"several {kind.name} frames are named {name!r}; give them distinct names") \
                    from None
    return None


def require_independent_actuators(mech: Mechanism, why: str, instead: str) -> None:
    """Nothing where no actuator depends on the others, else (redundant actuation,
    :attr:`Mechanism.dependent_actuators`) a :class:`StructureError` naming them, saying ``why`` the method cannot
    serve such a mechanism, and the independent actuators to load it with ``instead`` (what for)."""
    if mech.dependent_actuators:
        independent = [n for n in mech.actuated_names if n not in mech.dependent_actuators]
        raise StructureError("actuated", f"{mech.name}: actuators {list(mech.dependent_actuators)} depend on the "
                                         f"others (redundant actuation): {why}; load the mechanism with "
                                         f"{independent} actuated {instead}")


def check_mechanism(mech: object, name: str = "mech") -> Mechanism:
    """``mech`` itself if it is a :class:`Mechanism`, else :class:`InvalidInputError` saying how to get one."""
    return instance_of(mech, Mechanism, name, "a pkm.Mechanism (from pkm.load(name) or pkm.build(name, ...))")


