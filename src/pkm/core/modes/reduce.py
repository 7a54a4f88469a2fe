"""A mechanism reduced to the few equations its legs impose on its platform: the small polynomial system behind
every assembly mode.

Writing every passive joint of every leg as a ``(cos, sin)`` pair gives systems whose Bezout bounds run to
millions of paths. Instead, the platform's displacement from its reference pose is the unknown, and each leg is
reduced, from the Pinocchio tree itself, to what it imposes on the point where it holds the platform:

* **sphere**: the leg's passive joints form a group of rotations about one point ``A`` (a spherical or
  universal joint, or two or more concurrent revolutes) and, beyond it, rotations about the platform point ``B``
  (or nothing: the point closure is the ball joint). With the actuators held, ``A`` is fixed and ``|B - A|``
  constant: one distance equation (RUS, UPS, SS, UU legs; the Delta's parallelograms as centre lines);
* **circle**: a single passive revolute at ``A``: ``B`` stays on a circle about its axis ``n``, a distance and a
  plane ``n . (B - A) = d`` (the 3-PRS's PRS legs);

and the platform moves in the group its own chain allows:

* ``SE3``: a free-flyer platform, or one carried by a leg ending in a spherical group; unknowns: Study parameters
  ``(e, g)`` in P^7 with the Study quadric ``e . g = 0``;
* ``SE2``: a planar mechanism (every revolute axis parallel to one normal ``n``; the legs' equations become
  distances in the plane); unknowns ``(x, y, cos, sin)`` with ``cos^2 + sin^2 = 1``;
* ``T3``: a platform on three independent prismatic joints (a translational guide); unknowns: the translation.

A leg carrying the platform (the 3-RRR's first leg) is reduced the same way, its end group being the platform's
rotation about ``B``. Anything else is refused with a :class:`~pkm.errors.StructureError` that names the leg and
why: passive prismatic joints, frame (weld) closures, closures between two legs, rotation groups that are not
concurrent, legs sharing passive joints, and leg counts that do not give as many equations as the platform has
degrees of freedom.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from pkm.core.model.mechanism import Mechanism
from pkm.errors import StructureError

#: Incidence tolerance (relative to the mechanism's size) for "this axis passes through that point".
_INCIDENCE = 1e-9
_ROTATIONS = {"RX", "RY", "RZ", "RevoluteUnaligned", "RUBX", "RUBY", "RUBZ"}
_PRISMATIC = {"PX", "PY", "PZ", "PrismaticUnaligned"}


@dataclass(frozen=True)
class Leg:
    """One leg reduced to a sphere or a circle about ``A`` through the platform point ``B``.

    Attributes:
        name: The closure's name (or ``"platform chain"`` for the leg carrying the platform).
        kind: ``"sphere"`` or ``"circle"``.
        joints: The leg's passive joints (root to tip), recovered from the pose afterwards.
        center: ``(joint id, point)``: ``A`` in the frame of the first joint of the group about it.
        axis: The circle's axis in that frame (None for a sphere).
        tip: ``(joint id, point)``: the leg's end ``B`` in its joint's frame.
        platform_point: ``B`` on the platform at the reference, world [m].
        actuated: The leg's actuated joints (names), root to tip.
    """

    name: str
    kind: str
    joints: tuple[str, ...]
    center: tuple[int, np.ndarray]
    axis: np.ndarray | None
    tip: tuple[int, np.ndarray]
    platform_point: np.ndarray
    actuated: tuple[str, ...]

    @property
    def n_equations(self) -> int:
        return 2 if self.kind == "circle" else 1

    def geometry(self, d: pin.Data) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """``(A, B - A, n)`` in world axes from the placements in ``d``: the actuators where the caller put them,
        the passive joints anywhere (``|B - A|``, and ``n . (B - A)`` for a circle, do not depend on them)."""
        jc, a = self.center
        jt, b = self.tip
        A = d.oMi[jc].act(a)
        n = None if self.axis is None else d.oMi[jc].rotation @ self.axis
        return A, d.oMi[jt].act(b) - A, n


@dataclass(frozen=True)
class Reduction:
    """A mechanism as a platform and its legs (module doc).

    Attributes:
        group: ``"SE3"``, ``"SE2"`` or ``"T3"``.
        normal: The plane's normal for ``SE2`` (world), else None.
        platform_joint: The Pinocchio joint whose body is the platform.
        platform_ref: The platform joint's placement at the reference.
        legs: The reduced legs (the platform chain first when there is one).
        chain: The passive joints that carry the platform (solved first, to place it).
    """

    group: str
    normal: np.ndarray | None
    platform_joint: int
    platform_ref: pin.SE3
    legs: tuple[Leg, ...]
    chain: tuple[str, ...]

    def describe(self) -> str:
        kinds = ", ".join(f"{leg.name}: {leg.kind}" for leg in self.legs)
        return f"platform in {self.group}; legs {kinds}"


#: A passive joint as a rotation element: ``("point", o, None)`` or ``("line", o, axis)`` (the axis typed Any: the
#: kind, not the type, says whether it is None).
_RotationElement = tuple[str, np.ndarray, Any]


def _elements(mech: Mechanism, d: pin.Data, jid: int) -> _RotationElement:
    """A passive joint as a rotation element at the reference: ``("point", o, None)`` for a spherical or universal
    joint (its axes meet at its origin), ``("line", o, axis)`` for a revolute."""
    m = mech.model
    kind = m.joints[jid].shortname().removeprefix("JointModel")
    M = d.oMi[jid]
    if kind in ("Spherical", "SphericalZYX", "Universal"):
        return ("point", M.translation.copy(), None)
    if kind in _ROTATIONS:
        jd = m.joints[jid].createData()
        m.joints[jid].calc(jd, pin.neutral(m)[m.joints[jid].idx_q:m.joints[jid].idx_q + m.joints[jid].nq])
        w = np.asarray(jd.S, dtype=float).reshape(6, -1)[3:, 0]
        return ("line", M.translation.copy(), M.rotation @ (w / np.linalg.norm(w)))
    raise StructureError(f"joint {m.names[jid]!r}", f"a passive {kind} joint in a leg: the reduction covers "
                                                   "passive revolute, universal and spherical joints only")


def _through(el: _RotationElement, p: np.ndarray, tol: float) -> bool:
    kind, o, w = el
    r = p - o
    return bool(np.linalg.norm(r if kind == "point" else r - (r @ w) * w) <= tol)


def _concurrent(els: list[_RotationElement], tol: float, what: str) -> np.ndarray:
    """The common point of rotation elements (points and lines), or a StructureError."""
    pts = [o for k, o, _ in els if k == "point"]
    if pts:
        c = pts[0]
    else:
        (_, o1, w1), (_, o2, w2) = els[0], els[1]
        # closest points of the two lines
        M = np.array([[w1 @ w1, -w1 @ w2], [w1 @ w2, -w2 @ w2]])
        if abs(np.linalg.det(M)) < 1e-12:
            raise StructureError(what, "parallel passive revolutes at one end of the leg: not a spherical group")
        s, t = np.linalg.solve(M, [(o2 - o1) @ w1, (o2 - o1) @ w2])
        c = 0.5 * (o1 + s * w1 + o2 + t * w2)
    if not all(_through(el, c, tol) for el in els):
        raise StructureError(what, "its passive joints do not all turn about one point (not a sphere or circle "
                                   "leg: not covered by the reduction)")
    return c


def _rank(els: list[_RotationElement]) -> int:
    if any(k == "point" for k, _, _ in els):
        return 3
    return int(np.linalg.matrix_rank(np.array([w for _, _, w in els]), tol=1e-9))


def _analyse(mech: Mechanism, d: pin.Data, chain: list[int], B: np.ndarray, name: str, tol: float,
             platform_end: bool) -> tuple[np.ndarray, tuple[int, np.ndarray], np.ndarray | None, int,
                                         list[_RotationElement], list[str], tuple[str, ...]]:
    """Split a leg's chain (joint ids, root to tip) into the rotation groups about ``A`` and about ``B``."""
    m = mech.model
    actuated = {j.id for j in mech.actuated}
    passive = [j for j in chain if j not in actuated and m.joints[j].nv > 0]
    els = {j: _elements(mech, d, j) for j in passive}
    end: list[int] = []
    if platform_end:  # the platform's own rotation group ends the chain: B is its centre
        for j in reversed(passive):
            trial = [els[k] for k in end + [j]]
            try:
                B = _concurrent(trial, tol, name) if len(trial) > 1 or trial[0][0] == "point" else trial[0][1]
            except StructureError:
                break
            end.append(j)
        end_group = [els[j] for j in end]
    else:
        for j in reversed(passive):
            if not _through(els[j], B, tol):
                break
            end.append(j)
        end_group = []
    group_a = [j for j in passive if j not in end]
    if not group_a:
        raise StructureError(name, "no passive joint between the actuators and the platform point: a leg that "
                                   "fixes the point is not covered")
    first, last = chain.index(group_a[0]), chain.index(group_a[-1])
    A = _concurrent([els[j] for j in group_a], tol, name) if len(group_a) > 1 or els[group_a[0]][0] == "point" \
        else None
    if A is None:  # one revolute: a circle about its axis, A the foot of B on it
        _, o, w = els[group_a[0]]
        A = o + ((B - o) @ w) * w
    for j in chain[first:last + 1]:
        if j in actuated and not _through(_elements(mech, d, j), A, tol):
            raise StructureError(name, f"actuated joint {m.names[j]!r} sits inside the group of passive joints about "
                                       "one point: not covered")
    rank = _rank([els[j] for j in group_a])
    jc = group_a[0]
    center = (jc, d.oMi[jc].actInv(A))
    axis = None
    if rank < 2:
        axis = d.oMi[jc].rotation.T @ els[jc][2]
    return B, center, axis, rank, end_group, [m.names[j] for j in passive], \
        tuple(m.names[j] for j in chain if j in actuated)


def reduce_mechanism(mech: Mechanism) -> Reduction:
    """The platform and the legs' equations of ``mech`` (module doc), at its reference configuration."""
    m = mech.model
    d = m.createData()
    q = mech.q_reference
    pin.framesForwardKinematics(m, d, q)
    scale = max(1.0, max(float(np.linalg.norm(M.translation)) for M in d.oMi))
    tol = _INCIDENCE * scale
    if mech.ee_frame == 0:
        raise StructureError(mech.name, "no end-effector frame: the platform is unknown")
    jp = m.frames[mech.ee_frame].parentJoint
    chain = [j for j in m.supports[jp] if j > 0 and m.joints[j].nv > 0]
    kinds = {j: m.joints[j].shortname().removeprefix("JointModel") for j in range(1, m.njoints)}
    legs: list[Leg] = []
    chain_names: tuple[str, ...] = ()
    normal = None
    # the plane of a planar mechanism: every revolute axis parallel, no spatial joint
    axes = [w for j in range(1, m.njoints) if kinds[j] in _ROTATIONS and (w := _elements(mech, d, j)[2]) is not None]
    spatial = any(kinds[j] in ("Spherical", "SphericalZYX", "Universal", "FreeFlyer") for j in range(1, m.njoints))
    planar = bool(axes) and not spatial and all(abs(abs(w @ axes[0]) - 1.0) < 1e-9 for w in axes)
    if len(chain) == 1 and kinds[chain[0]] == "FreeFlyer":
        group = "SE3"
        chain_names = (m.names[chain[0]],)
    elif chain and all(kinds[j] in _PRISMATIC for j in chain) and len(chain) == 3:
        group = "T3"
        chain_names = tuple(m.names[j] for j in chain)
    elif chain:
        group = "SE2" if planar else "SE3"
        B, center, axis, rank, end, joints, act = _analyse(mech, d, chain, np.zeros(3), "platform chain", tol,
                                                             platform_end=True)
        need = 1 if planar else 3
        if not end or _rank(end) < need:
            raise StructureError("platform chain", "the platform does not turn freely about the chain's last point "
                                                   f"(a {'revolute' if planar else 'spherical'} group is needed)")
        kind = "circle" if (axis is not None and not planar) else "sphere"
        legs.append(Leg("platform chain", kind, tuple(joints), center, axis, (jp, d.oMi[jp].actInv(B)), B, act))
        chain_names = tuple(joints)
    else:
        raise StructureError(mech.name, "the platform is fixed to the base")
    if planar and group != "T3":
        group, normal = "SE2", axes[0] / np.linalg.norm(axes[0])
    platform = set(j for j in range(1, m.njoints) if jp in m.supports[j])
    used = set(chain)
    for c, (fa, fb) in zip(mech.spec.closures, mech.closure_frames):
        ja, jb = m.frames[fa].parentJoint, m.frames[fb].parentJoint
        if (ja in platform) == (jb in platform):
            raise StructureError(f"closure {c.name!r}", "it does not join a leg to the platform: not covered")
        if c.type != "point":
            raise StructureError(f"closure {c.name!r}", "a frame (weld) closure: the reduction covers point "
                                                        "closures (ball joints) only")
        leg_f, plat_f = (fa, fb) if jb in platform else (fb, fa)
        jl = m.frames[leg_f].parentJoint
        leg_chain = [j for j in m.supports[jl] if j > 0 and m.joints[j].nv > 0]
        shared = [j for j in leg_chain if j in used and j not in {a.id for a in mech.actuated}]
        if shared:
            raise StructureError(f"closure {c.name!r}", f"its leg shares passive joint {m.names[shared[0]]!r} with "
                                                        "another leg: not covered")
        used |= set(leg_chain)
        B = d.oMf[plat_f].translation.copy()
        B, center, axis, rank, _, joints, act = _analyse(mech, d, leg_chain, B, f"closure {c.name!r}", tol,
                                                           platform_end=False)
        kind = "sphere" if (rank >= 2 or group == "SE2") else "circle"
        legs.append(Leg(c.name, kind, tuple(joints), center, axis if kind == "circle" else None,
                        (jl, m.frames[leg_f].placement.translation.copy()), B, act))
    loose = [m.names[j] for j in range(1, m.njoints)
             if m.joints[j].nv > 0 and j not in used and j not in platform and j != jp]
    if loose:
        raise StructureError(f"joint {loose[0]!r}", "a joint on no leg: not covered")
    n_eq = sum(1 if group == "SE2" else leg.n_equations for leg in legs)
    dof = 6 if group == "SE3" else 3
    if n_eq != dof:
        raise StructureError(mech.name, f"the legs impose {n_eq} equations on a platform with {dof} degrees of "
                                        f"freedom in {group}: the reduction needs as many")
    return Reduction(group, normal, jp, d.oMi[jp].copy(), tuple(legs), chain_names)
