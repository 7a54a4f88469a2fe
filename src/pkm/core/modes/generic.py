"""Every assembly and working mode without a platform: the loop closures themselves as polynomials in every unknown
joint, solved by homotopy continuation.

The reduction of :mod:`~pkm.core.modes.reduce` needs a platform on legs; a mechanism whose task point sits on a leg
(a five-bar measured at the tip of one distal link, a 3-RPR measured on a leg's rod) has none. Here every unknown
joint is a variable (a revolute as ``(cos, sin)`` with its unit circle, a prismatic joint as its coordinate,
:class:`~pkm.core.modes.tree.PolyTree`), the others numbers, and each point closure says that its two frames'
origins meet: ``p_a(x) - p_b(x) = 0``, three rows (two in the plane of a planar mechanism: the normal row vanishes).

* forward kinematics (:func:`assembly_modes_generic`): the unknowns are the passive joints, the actuators held;
* inverse kinematics (:func:`working_modes_generic`): every joint is unknown but the task's joint outputs; the task's
  rows add ``p_ee(x) = target`` (``x``, ``y``, ``z``) and, for a planar mechanism whose plane is normal to ``z``, the
  yaw: ``sin(yaw) e_x(x) . X - cos(yaw) e_x(x) . Y = 0`` (``e_x`` the end effector's first axis; the solution at
  ``yaw + pi`` it also admits is dropped by checking the task).

Each equation is linear in each joint's group of variables but for the circles, so Bertini's multihomogeneous
start (one group per joint) tracks far fewer paths than the total degree. Every real solution is turned into a
configuration directly and checked by the core (the closure residual, and the task for inverse kinematics).

Covered: revolute and prismatic joints, point closures, a task of positions (and planar yaw); anything else is
refused with a :class:`~pkm.errors.StructureError` that names the class and what to use instead. The set is as
complete as the homotopy says (every path ended), but a solution set of positive dimension (a mechanism with more
freedom than its actuators fix, a redundant closure) has no isolated solutions: the count of equations against
unknowns refuses the first kind, and a failed path marks the set incomplete.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.kinematics.blocks import block_triangular
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism
from pkm.core.modes.certify import Certificate, alpha_test, polish
from pkm.core.modes.continuation import Continuation, solve
from pkm.core.modes.modeset import REAL_TOL, Mode, ModeSet, _check, _clearance, by_distance
from pkm.core.modes.polynomial import Poly, System, fix
from pkm.core.modes.tree import REVOLUTE, PolyTree, joint_axis
from pkm.errors import StructureError

_ALTERNATIVE = ("; for one solution use pkm.close_loops / pkm.solve_ik from a seed in the mode wanted, or "
                "pkm.track_assembly_mode from a known mode")


def _plane(mech: Mechanism, d: pin.Data) -> np.ndarray | None:
    """The normal of a planar mechanism (every revolute axis parallel, every prismatic one normal to it), else
    None."""
    m = mech.model
    axes: list[np.ndarray] = []
    slides: list[np.ndarray] = []
    for j in range(1, m.njoints):
        if m.joints[j].nv == 0:
            continue
        kind, w = joint_axis(m, j)
        (axes if kind == "R" else slides).append(d.oMi[j].rotation @ w)
    if not axes:
        return None
    n = axes[0]
    if all(abs(abs(w @ n) - 1.0) < 1e-9 for w in axes) and all(abs(w @ n) < 1e-9 for w in slides):
        return n / np.linalg.norm(n)
    return None


def _closure_rows(mech: Mechanism, tree: PolyTree, normal: np.ndarray | None) -> list[Poly | float]:
    """Each point closure's rows ``p_a - p_b`` (world; in the plane's two axes for a planar mechanism)."""
    rows: list[Poly | float] = []
    for c, (fa, fb) in zip(mech.spec.closures, mech.closure_frames):
        if c.type != "point":
            raise StructureError(f"closure {c.name!r}", "a frame (weld) closure: the whole-mechanism polynomial "
                                                        "route covers point closures only" + _ALTERNATIVE)
        pa, pb = tree.frame_point(fa), tree.frame_point(fb)
        diff = [pa[i] - pb[i] for i in range(3)]
        rows += _in_plane(diff, normal)
    return rows


def _in_plane(v: list[Any], normal: np.ndarray | None) -> list[Any]:
    if normal is None:
        return v
    u = np.cross(normal, [1.0, 0.0, 0.0])
    if np.linalg.norm(u) < 0.5:
        u = np.cross(normal, [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    w = np.cross(normal, u)
    return [sum(v[i] * float(a[i]) for i in range(3)) for a in (u, w)]


def _unknowns(mech: Mechanism, joints: list[int]) -> None:
    m = mech.model
    for j in joints:
        kind = m.joints[j].shortname().removeprefix("JointModel")
        if kind not in REVOLUTE and not kind.startswith("P"):
            raise StructureError(f"joint {m.names[j]!r}", f"a {kind} joint: the whole-mechanism polynomial route "
                                                         "writes revolute and prismatic joints only" + _ALTERNATIVE)


def _square(polys: list[Poly], n: int, what: str, d: pin.Data) -> list[Poly]:
    """The equations that are not constants (rounding below 1e-12 of the mechanism's size dropped), as many as the
    unknowns, else a StructureError (also where there is no unknown: the given values fix every joint)."""
    if n == 0:
        raise StructureError(what, "no unknown joint: the given values fix every joint (every joint actuated, or in "
                                   "the task), so there is no mode to find; pkm.close_loops tells whether they close "
                                   "the loops")
    size = max(1.0, max(float(np.linalg.norm(M.translation)) for M in d.oMi))
    polys = [q for q in (p.cleaned(size) for p in polys) if q.degree > 0]
    if len(polys) != n:
        raise StructureError(what, f"{len(polys)} independent equations in {n} unknowns: the solutions are not "
                                   "isolated points (a freedom no input fixes, or redundant closures)" + _ALTERNATIVE)
    return polys


def _solutions(polys: list[Poly], groups: list[list[int]], precision: str) \
        -> tuple[list[Continuation], list[tuple[np.ndarray, Certificate, list[int]]], int]:
    """Every finite real solution, polished and certified on the whole system (``(point, certificate, paths)``,
    the path in each block's homotopy), the continuations and the count of complex ends.

    The system is solved block by block in its block triangular order (:func:`~pkm.core.kinematics.blocks.block_triangular`
    on which variables each equation uses): a five-bar's inverse kinematics is its two legs, two homotopies of a few
    paths instead of one of 64. Each real solution of a block is substituted into the next; a complex one ends its
    branch (it can give no real solution of the whole)."""
    n = polys[0].n
    nz = np.array([[any(e[v] for e in p.terms) for v in range(n)] for p in polys])
    try:
        blocks = block_triangular(nz, ordered=True)
    except ValueError:
        raise StructureError("the closures", "some unknowns appear in no equation that can fix them (structurally "
                                             "singular): the solutions are not isolated points" + _ALTERNATIVE) from None
    conts: list[Continuation] = []
    n_complex = 0
    partial: list[tuple[dict[int, float], list[int]]] = [({}, [])]
    for rows, block_cols in blocks:
        cols = sorted(block_cols)
        sub_groups = [[cols.index(v) for v in g if v in cols] for g in groups]
        sub_groups = [g for g in sub_groups if g]
        grown = []
        for known, paths in partial:
            sub = []
            for r in rows:
                p = polys[r]
                for i in sorted(range(n), reverse=True):
                    if i not in cols:
                        p = fix(p, i, known.get(i, 0.0))
                sub.append(p.cleaned(max((abs(c) for c in p.terms.values()), default=1.0)))  # (what the known values cancel)
            cont = solve(sub, sub_groups, precision=precision)
            conts.append(cont)
            S = System(sub)
            seen: list[np.ndarray] = []
            for path in cont.paths:
                if path.point is None:
                    continue
                x = path.point if path.singular else polish(S, path.point)  # (as assembly.real_solutions)
                if np.abs(x.imag).max() > REAL_TOL * max(1.0, float(np.abs(x).max())):
                    n_complex += 1
                    continue
                if any(np.abs(s - x.real).max() < 1e-7 for s in seen):
                    continue
                seen.append(x.real)
                grown.append(({**known, **{v: float(x.real[k]) for k, v in enumerate(cols)}}, [*paths, path.index]))
        partial = grown
    S = System(polys)
    found = []
    for known, paths in partial:
        x = polish(S, np.array([known[v] for v in range(n)], dtype=complex))
        found.append((x.real, alpha_test(S, x), paths))
    return conts, found, n_complex


def _mode_set(mech: Mechanism, conts: list[Continuation], modes: list[tuple], n_complex: int, what: str) -> ModeSet:
    out = tuple(Mode(k, *m) for k, m in enumerate(by_distance(mech, modes)))
    how = (f"{len(conts)} multihomogeneous homotop{'y' if len(conts) == 1 else 'ies'}, block by block, on the loop "
           f"closures in {what} (Bertini 2, {conts[0].settings.get('mptype')} precision)")
    return ModeSet(out, all(c.complete for c in conts), how, sum(len(c.paths) for c in conts),
                   sum(c.bound for c in conts), n_complex, sum(c.count("infinite") for c in conts), 0,
                   tuple(p for c in conts for p in c.failed),
                   f"no platform: the closures in {what} (pkm.core.modes.generic)", sum(c.seconds for c in conts))


def assembly_modes_generic(mech: Mechanism, qa: np.ndarray, *, precision: str = "adaptive") -> ModeSet:
    """Every real assembly mode at the actuator values ``qa`` (spec order, checked by the caller) [rad or m], from
    the closures in every passive joint (module doc)."""
    m = mech.model
    q = mech.with_actuated(mech.q_reference, qa)
    d = m.createData()
    pin.forwardKinematics(m, d, q)
    fixed = {j.id for j in mech.actuated}
    unknown = [j for j in range(1, m.njoints) if m.joints[j].nv > 0 and j not in fixed]
    _unknowns(mech, unknown)
    tree = PolyTree(mech, d, unknown)
    rows = _closure_rows(mech, tree, _plane(mech, d))
    polys = _square([*tree.circles, *(p for p in rows if isinstance(p, Poly))], tree.n, mech.name, d)
    conts, found, n_complex = _solutions(polys, tree.groups, precision)
    modes = []
    for x, cert, paths in found:
        qq = tree.configuration(q, x, mech.q_reference)
        modes.append((qq, _check(mech, qq), x, cert, tuple(paths), mech.outside_limits(qq), _clearance(mech, qq)))
    return _mode_set(mech, conts, modes, n_complex, "every passive joint")


def working_modes_generic(mech: Mechanism, task: ArrayLike | Mapping[str, Any], *, precision: str = "adaptive") \
        -> ModeSet:
    """Every real working mode at the task coordinates ``task`` (:meth:`~pkm.core.kinematics.task.TaskMap.parse`),
    from the closures and the task in every joint (module doc)."""
    m = mech.model
    tm = TaskMap.of(mech)
    y = tm.parse(task)
    comps = mech.spec.task.components
    q = mech.q_reference.copy()
    for k, j in enumerate(mech.task_joints):
        q[j.idx_q] = y[len(y) - len(mech.task_joints) + k]
    d = m.createData()
    pin.forwardKinematics(m, d, q)
    normal = _plane(mech, d)
    if mech.spec.task.frames or any(c not in ("x", "y", "z", "yaw") for c in comps) or (
            "yaw" in comps and (normal is None or abs(abs(normal[2]) - 1.0) > 1e-9)):
        raise StructureError(mech.name, f"task {list(comps)}: the whole-mechanism polynomial route takes positions "
                                        "x, y, z (and yaw in a plane normal to z) of the end effector only"
                             + _ALTERNATIVE)
    fixed = {j.id for j in mech.task_joints}
    unknown = [j for j in range(1, m.njoints) if m.joints[j].nv > 0 and j not in fixed]
    _unknowns(mech, unknown)
    tree = PolyTree(mech, d, unknown)
    rows = _closure_rows(mech, tree, normal)
    p = tree.frame_point(mech.ee_frame)
    named = dict(zip(tm.keys, [float(v) for v in y]))
    for c in comps:
        if c == "yaw":
            ex = tree.frame_axis(mech.ee_frame, 0)
            rows.append(math.sin(named[c]) * ex[0] - math.cos(named[c]) * ex[1])
        else:
            rows.append(p["xyz".index(c)] - named[c])
    polys = _square([*tree.circles, *(r for r in rows if isinstance(r, Poly))], tree.n, mech.name, d)
    conts, found, n_complex = _solutions(polys, tree.groups, precision)
    modes = []
    for x, cert, paths in found:
        qq = tree.configuration(q, x, mech.q_reference)
        if np.abs(tm.error(y, tm.value(qq))).max() > 1e-9:  # the yaw's other half-turn
            continue
        modes.append((qq, _check(mech, qq), x, cert, tuple(paths), mech.outside_limits(qq), _clearance(mech, qq)))
    return _mode_set(mech, conts, modes, n_complex, "every joint and the task")
