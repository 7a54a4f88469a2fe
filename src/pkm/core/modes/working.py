"""Every working mode (inverse kinematics) of a mechanism: each leg's actuators for the platform's pose, by
homotopy continuation on the leg's own small system, and every combination verified by the core.

With the platform placed, the legs are independent: each reduced leg (:mod:`~pkm.core.modes.reduce`) imposes
``|B - A(u)|^2 = |r(u)|^2`` (and, for a circle, its plane) on its unknown actuated joints ``u``, written from the
tree as polynomials (a revolute as ``(cos, sin)`` with its unit circle, a prismatic joint as its coordinate;
joints the task fixes, such as the hexapod's ``beta_1``, and mimic joints are numbers). Each leg's system is
solved by Bertini (a few paths), its real solutions are the leg's working modes, and the mechanism's are their
combinations, each turned into a full configuration by the core and checked.

The platform's pose comes from the task. Where the task does not fix every coordinate of the platform's motion
(the 3-PRS: its parasitic ``x, y, yaw``), the pose is the one the core's inverse kinematics reaches from the
reference, and the working modes are those at that pose (the 3-PRS's leg planes fix the parasitic motion whatever
the sliders do, so this is not a restriction there; it would be for a mechanism whose other poses also fit).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.kinematics.solve import solve_ik
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.modes.assembly import _generic, recover
from pkm.core.modes.certify import Certificate, alpha_test, polish
from pkm.core.modes.continuation import Path, solve
from pkm.core.modes.modeset import REAL_TOL, Mode, ModeSet, _check, _clearance, by_distance
from pkm.core.modes.polynomial import Poly, System, dot
from pkm.core.modes.reduce import Leg, reduce_mechanism
from pkm.core.modes.tree import PolyTree
from pkm.errors import StructureError, UnreachableError


class _LegSystem:
    """One leg's equations in its unknown actuated joints (see the module doc)."""

    def __init__(self, mech: Mechanism, leg: Leg, d: pin.Data, B: np.ndarray, unknown: list[int]):
        self.tree = tree = PolyTree(mech, d, unknown)
        self.leg, self.unknown = leg, unknown
        polys: list[Poly] = list(tree.circles)
        jc, a = leg.center
        jt, tip = leg.tip
        A = tree.up(jc, a)
        r = [p - float(c) for p, c in zip(tree.up(jt, tip, jc), a)]
        polys.append(dot([B[i] - A[i] for i in range(3)], [B[i] - A[i] for i in range(3)]) - dot(r, r))
        if leg.axis is not None:
            nvec = tree.up(jc, leg.axis, point=False)
            polys.append(dot(nvec, [B[i] - A[i] for i in range(3)]) - dot(leg.axis, r))
        size = max(1.0, float(np.abs(B).max()), float(np.abs(np.asarray(a, dtype=float)).max()))
        polys = [p.cleaned(size ** 2) for p in polys]
        self.constants = [p for p in polys if p.degree == 0]
        self.polys = [p for p in polys if p.degree > 0]
        if len(self.polys) != tree.n:
            raise StructureError(leg.name, f"{len(self.polys)} equations in {tree.n} unknowns of its actuated joints: "
                                           "the working modes of this leg are not isolated")


def working_modes(mech: Mechanism, task: ArrayLike | Mapping[str, Any], *, precision: str = "adaptive") -> ModeSet:
    """Every real working mode of ``mech`` at the task coordinates ``task`` (module doc).

    Args:
        mech: Any mechanism the reduction covers (:mod:`pkm.core.modes.reduce`) or, where it finds no platform
            (a task point on a leg), the generic route covers (:mod:`pkm.core.modes.generic`).
        task: Task coordinates (:meth:`pkm.core.kinematics.task.TaskMap.parse`: a vector or a mapping by name, with units).
        precision: Bertini's precision mode.

    Returns:
        A :class:`~pkm.core.modes.assembly.ModeSet`: its modes the combinations of the legs' real solutions,
        sorted by distance from the reference (those outside the joints' stated limits included, and marked);
        its counts (paths, complex solutions, at infinity) summed over the legs' homotopies.

    Raises:
        UnreachableError: the task is out of reach, or a leg has no real solution (which leg).
        StructureError: the structure is outside the reduction and the generic route.

    Examples:
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> modes = pkm.working_modes(delta, [0.02, 0.0, -0.36])
        >>> len(modes.modes), modes.complete
        (8, True)
        >>> sorted({pkm.mode_label(delta, m.q).working for m in modes.modes})[:3]
        [(1, -1, -1, -1), (1, -1, -1, 1), (1, -1, 1, -1)]
    """
    mech = check_mechanism(mech)
    try:
        red = reduce_mechanism(mech)
    except StructureError as exc:
        return _generic(mech, exc, precision, task=task)
    q0 = solve_ik(mech, task).q  # the platform's pose (and the task joints)
    d = mech.model.createData()
    pin.forwardKinematics(mech.model, d, q0)
    T = d.oMi[red.platform_joint]
    G = T * red.platform_ref.inverse()
    known = {j.id for j in mech.task_joints}
    actuated = {j.id for j in mech.actuated} - known
    legs, conts = [], []
    n_complex = 0
    for number, leg in enumerate(red.legs, start=1):
        jt = leg.tip[0]
        unknown = [j for j in mech.model.supports[jt] if j in actuated]
        if not unknown:
            continue
        B = G.act(leg.platform_point)
        ls = _LegSystem(mech, leg, d, B, unknown)
        if any(abs(p.terms.get((0,) * p.n, 0.0)) > 1e-9 for p in ls.constants):
            raise UnreachableError(number, max(abs(p.terms.get((0,) * p.n, 0.0)) for p in ls.constants), "m^2",
                                   f"the pose leaves the plane of leg {leg.name!r}")
        cont = solve(ls.polys, precision=precision)
        n_complex += sum(p.point is not None for p in cont.paths)
        sols: list[tuple[np.ndarray, Certificate, int]] = []
        S = System(ls.polys)
        for p in cont.paths:
            if p.point is None:
                continue
            x = polish(S, p.point)
            if np.abs(x.imag).max() <= REAL_TOL * max(1.0, float(np.abs(x).max())):
                n_complex -= 1
                if not any(np.abs(x.real - s[0]).max() < 1e-9 for s in sols):
                    sols.append((x.real, alpha_test(S, x), p.index))
        if not sols:
            raise UnreachableError(number, 0.0, "m", f"leg {leg.name!r}: its actuators have no real solution for "
                                                     "this pose")
        legs.append((ls, sols))
        conts.append(cont)
    modes = []
    ref = mech.q_reference
    for combo in itertools.product(*[sols for _, sols in legs]):
        qa_q = q0.copy()
        for (ls, _), (x, _, _) in zip(legs, combo):
            qa_q = ls.tree.configuration(qa_q, x, ref)  # (an angle on the turn nearest the reference's)
        R, t = G.rotation, G.translation
        q = recover(mech, red, mech.actuated_q(qa_q), R, t)
        for tj in mech.task_joints:
            q[tj.idx_q] = q0[tj.idx_q]
        point = np.concatenate([x for x, _, _ in combo])
        worst = max(combo, key=lambda s: s[1].alpha)[1]
        modes.append((q, _check(mech, q), point, worst, tuple(p for _, _, p in combo), mech.outside_limits(q), _clearance(mech, q)))
    out = tuple(Mode(k, *m) for k, m in enumerate(by_distance(mech, modes)))
    failed: tuple[Path, ...] = tuple(p for c in conts for p in c.failed)
    return ModeSet(out, all(c.complete for c in conts), f"one total-degree homotopy per leg ({len(conts)} legs, "
                   f"Bertini 2, {precision} precision)", sum(len(c.paths) for c in conts), sum(c.bound for c in conts),
                   n_complex, sum(c.count("infinite") for c in conts), 0, failed, red.describe(),
                   sum(c.seconds for c in conts))
