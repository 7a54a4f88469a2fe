"""Every assembly mode (forward kinematics) of a mechanism: the reduced system solved by homotopy continuation,
each real solution turned into a full configuration by the core and verified.

:func:`assembly_modes` reduces the mechanism (:mod:`~pkm.core.modes.reduce`), builds the reduced equations for the
actuator values (:mod:`~pkm.core.modes.equations`), tracks every path of a total-degree homotopy with Bertini 2
(:mod:`~pkm.core.modes.continuation`), keeps the real solutions that are poses, polishes and certifies each
(Smale's alpha test, :mod:`~pkm.core.modes.certify`), places the platform, closes every leg with the core
(:func:`pkm.core.kinematics.solve.assemble`, the actuators and the platform held) and checks the closure residual. The
:class:`ModeSet` it returns states its completeness: the paths tracked, the bound they start from, the solutions
at infinity, on the exceptional set and complex, and every failed path; one failed path and it is not complete.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.kinematics.solve import _levenberg_marquardt, assemble
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.modes.certify import Certificate, alpha_test, polish
from pkm.core.modes.continuation import Continuation, solve, track
from pkm.core.modes.equations import FKSystem, equations
from pkm.core.modes.generic import assembly_modes_generic, working_modes_generic
from pkm.core.modes.modeset import REAL_TOL, VERIFY_TOL, Mode, ModeSet, _check, _clearance, by_distance
from pkm.core.modes.polynomial import System, variables
from pkm.core.modes.reduce import Reduction, reduce_mechanism
from pkm.core.modes.starts import generic_start, path_parameters
from pkm.errors import AssemblyError, ConvergenceError, InvalidInputError, StructureError


def _place_platform(mech: Mechanism, red: Reduction, q: np.ndarray, T: pin.SE3, rng: np.random.Generator) \
        -> np.ndarray:
    """``q`` with the joints that carry the platform moved so that it sits at ``T`` (a free-flyer is set; a chain is
    solved by Levenberg-Marquardt from a few starts)."""
    m = mech.model
    jp = red.platform_joint
    if red.group == "SE3" and len(red.chain) == 1 and m.joints[jp].shortname() == "JointModelFreeFlyer":
        M = m.jointPlacements[jp].inverse() * T
        q = q.copy()
        q[m.joints[jp].idx_q:m.joints[jp].idx_q + 7] = pin.SE3ToXYZQUAT(M)
        return q
    cols = np.zeros(m.nv, dtype=bool)
    for name in red.chain:
        j = mech.joints[name]
        cols[j.idx_v:j.idx_v + j.nv] = True
    d = m.createData()

    def fun(qq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        pin.forwardKinematics(m, d, qq)
        err = pin.log6(T.actInv(d.oMi[jp])).vector
        J = pin.Jlog6(T.actInv(d.oMi[jp])) @ pin.computeJointJacobian(m, d, qq, jp)
        J[:, ~cols] = 0.0
        return err, J

    best = (math.inf, q)
    for k in range(12):
        q0 = q if k == 0 else pin.integrate(m, q, np.where(cols, rng.normal(scale=1.0, size=m.nv), 0.0))
        qq, F, _ = _levenberg_marquardt(mech, fun, q0, 1e-13, 100)
        if np.abs(F).max() < best[0]:
            best = (float(np.abs(F).max()), qq)
        if best[0] <= 1e-12:
            break
    if best[0] > 1e-10:
        raise ConvergenceError("placing the platform on its chain", best[0], 0, 1e-10)
    return best[1]


def recover(mech: Mechanism, red: Reduction, q_actuated: ArrayLike, R: np.ndarray, t: np.ndarray, *,
            seed: int = 0) -> np.ndarray:
    """The full configuration of a platform displacement ``(R, t)`` (world, from the reference pose) at the given
    actuator values: the platform placed, every leg closed by :func:`pkm.core.kinematics.solve.assemble` (the actuators
    and the platform held). Raises :class:`~pkm.errors.ConvergenceError` when a leg does not close to
    :data:`VERIFY_TOL`."""
    rng = np.random.default_rng(seed)
    T = pin.SE3(R, t) * red.platform_ref
    q = mech.with_actuated(mech.q_reference, q_actuated)
    q = _place_platform(mech, red, q, T, rng)
    hold = [j.name for j in mech.actuated] + list(red.chain)
    try:
        q = assemble(mech, q, hold=hold, tol=1e-12, restarts=24, seed=seed).q
    except AssemblyError as exc:
        raise ConvergenceError("closing the legs on a solution of the reduced equations", exc.deficit, 0,
                               VERIFY_TOL, detail=str(exc)) from None
    return q


def real_solutions(cont: Continuation, sys_: FKSystem, distinct: float = 1e-7) \
        -> tuple[list[tuple[np.ndarray, Certificate, list[int]]], int, int]:
    """The finite real solutions of a continuation, polished and certified, merged when closer than ``distinct``;
    returns ``(solutions, n_complex, n_exceptional)`` with solutions ``[(point, certificate, paths)]``."""
    found: list[tuple[np.ndarray, Certificate, list[int]]] = []
    n_complex = n_exc = 0
    for p in cont.paths:
        if p.point is None:
            continue
        polys, x, k = sys_.affine(p.point)
        S = System(polys)
        x = x if p.singular else polish(S, x)  # (Newton at a singular end is no polish: it leaves the end)
        cert = alpha_test(S, x)
        full = x if k is None else np.insert(x, k, 1.0)
        if not sys_.is_pose(full):
            n_exc += 1
            continue
        if np.abs(full.imag).max() > REAL_TOL * max(1.0, np.abs(full).max()):
            n_complex += 1
            continue
        full = full.real / (np.linalg.norm(full.real[:4]) if sys_.projective else 1.0)
        for f in found:
            if min(np.abs(f[0] - full).max(), np.abs(f[0] + full).max() if sys_.projective else math.inf) < distinct:
                f[2].append(p.index)
                break
        else:
            found.append((full, cert, [p.index]))
    return found, n_complex, n_exc


def parameter_homotopy(system: FKSystem, *, precision: str = "auto", threads: int = 2) -> Continuation:
    """The system solved from its family's generic start (:mod:`pkm.core.modes.starts`): a path per generic
    solution, along the straight line from the generic parameters to this system's."""
    start = generic_start(system.signature)
    n = system.polys[0].n
    x = variables(n + 1)
    H = equations(system.red.group, path_parameters(system.params, start, x[n]), x[:n])
    cont = track(H, system.polys, start.points, projective=system.projective, precision=precision,
                 threads=threads)
    cont.settings.update(generic_paths=start.total_degree, start_complete=start.complete)
    return cont


def _precision(cont: Continuation) -> str:
    """How a continuation's paths were tracked, in words."""
    if cont.settings.get("mptype") != "auto":
        return f"{cont.settings.get('mptype')} precision"
    again = len(cont.settings.get("retracked", ()))
    return f"double precision, {again} of its {len(cont.paths)} paths again in adaptive precision"


def _generic(mech: Mechanism, refused: StructureError, precision: str, *, qa: np.ndarray | None = None,
             task: Any = None) -> ModeSet:
    """The generic route (:mod:`pkm.core.modes.generic`) where the reduction refused ``mech``: the assembly modes at
    the actuator values ``qa``, else the working modes at ``task``. A refusal names both reasons."""
    try:
        if qa is not None:
            return assembly_modes_generic(mech, qa, precision=precision)
        return working_modes_generic(mech, task, precision=precision)
    except StructureError as exc:
        raise StructureError(exc.part, f"{str(exc).removeprefix(exc.part + ': ')}; the platform reduction refuses "
                                       f"it too ({refused})") from None


def assembly_modes(mech: Mechanism, q_actuated: ArrayLike, *, method: str = "auto", precision: str = "auto",
                   threads: int = 2, continuation: Continuation | None = None) -> ModeSet:
    """Every real assembly mode of ``mech`` at the actuator values ``q_actuated`` (module doc).

    Args:
        mech: Any mechanism the reduction covers (:mod:`pkm.core.modes.reduce`) or, failing that, the generic route
            (:mod:`pkm.core.modes.generic`: revolute and prismatic joints, point closures); others are refused with
            a :class:`~pkm.errors.StructureError` naming both reasons.
        q_actuated: The actuated coordinates in spec order [rad or m].
        method: ``"total-degree"`` (Bertini's total-degree start), ``"parameter"`` (a parameter homotopy from the
            family's generic solutions, :mod:`pkm.core.modes.starts`), ``"generic"`` (no reduction: the closures in
            every passive joint, :mod:`pkm.core.modes.generic`) or ``"auto"`` (parameter for a spatial platform,
            total degree for the small planar and translational systems, generic where the reduction finds no
            platform: a task point on a leg).
        precision: Bertini's precision mode: ``"auto"`` (default) tracks a parameter homotopy's paths in double
            precision and again in adaptive precision each that did not end at a nonsingular finite point of its
            own (:func:`pkm.core.modes.continuation.track`; the hexapod 16 -> 4 s of CPU, the same modes), and
            every other homotopy in adaptive precision; ``"adaptive"``, ``"double"`` or ``"multiple"`` for every
            path.
        threads: Bertini's tracking threads.
        continuation: A finished :class:`~pkm.core.modes.continuation.Continuation` of this very system to use
            instead of solving (tests plant failures this way).

    Returns:
        A :class:`ModeSet`; its modes sorted by distance from the reference configuration.

    Raises:
        StructureError: the mechanism's structure is outside the reduction and the generic route.
        MissingDependencyError: bertini2 is not installed.
        ConvergenceError: a real solution whose legs the core cannot close (a defect: the reduction and the tree
            disagree).

    Examples:
        >>> import pkm
        >>> rrr3 = pkm.load("rrr3")
        >>> modes = pkm.assembly_modes(rrr3, rrr3.actuated_q(rrr3.q_reference))
        >>> len(modes.modes), modes.complete, modes.n_paths
        (2, True, 16)
        >>> [m.certificate.certified for m in modes.modes]
        [True, True]
    """
    mech = check_mechanism(mech)
    qa = mech.check_actuated(q_actuated, positions=True)
    if method not in ("auto", "parameter", "total-degree", "generic"):
        raise InvalidInputError("method", "expected 'auto', 'parameter', 'total-degree' or 'generic'", method)
    if method == "generic":
        return assembly_modes_generic(mech, qa, precision=precision)
    try:
        red = reduce_mechanism(mech)
    except StructureError as exc:
        if method != "auto" or continuation is not None:
            raise
        return _generic(mech, exc, precision, qa=qa)
    d = mech.model.createData()
    pin.forwardKinematics(mech.model, d, mech.with_actuated(mech.q_reference, qa))
    system = FKSystem(red, d)
    if continuation is not None:
        cont = continuation
    elif method == "parameter" or (method == "auto" and red.group == "SE3"):
        cont = parameter_homotopy(system, precision=precision, threads=threads)
    else:
        cont = solve(system.polys, system.groups, projective=system.projective, precision=precision,
                     threads=threads)
    found, n_complex, n_exc = real_solutions(cont, system)
    modes = []
    for x, cert, paths in found:
        R, t = system.displacement(x)
        q = recover(mech, red, qa, R, t)
        modes.append((q, _check(mech, q), x, cert, tuple(paths), mech.outside_limits(q), _clearance(mech, q)))
    out = tuple(Mode(k, *m) for k, m in enumerate(by_distance(mech, modes)))
    how = f"a {cont.start} (Bertini 2, {_precision(cont)})"
    if cont.start == "parameter homotopy":
        how += (f" from the {cont.bound} generic solutions of family {system.signature} (a "
                f"{cont.settings['generic_paths']}-path total-degree solve)")
    complete = cont.complete and cont.settings.get("start_complete", True)
    return ModeSet(out, complete, how, len(cont.paths), cont.bound, n_complex, cont.count("infinite"), n_exc,
                   cont.failed, red.describe(), cont.seconds)
