r"""Joint compliance of a closed-loop mechanism with rigid links (the virtual-joint model): the Cartesian stiffness at
the end effector, the deflection under a constant wrench, the natural frequencies.

**The model.** Each one-coordinate joint is

* *sprung*: a spring of stiffness :math:`k_j` [N m/rad, N/m] about its value in ``q``: the stiffness given in
  ``joints=`` (a drive's servo stiffness, an axial leg spring), else, on an actuated joint, its drive's servo
  stiffness (:attr:`Actuator.stiffness <pkm.core.model.actuators.Actuator.stiffness>`, the spec's
  ``[actuators.<joint>] stiffness``; in parallel with a ``[springs]`` spring on the same joint: their sum), else its
  ``[springs.<joint>]`` stiffness in the spec (:mod:`pkm.core.model.springs`); :attr:`Stiffness.sources` says which;
* *locked*: an actuated joint given no stiffness (a position-controlled drive taken as rigid: its
  ``Actuator.stiffness`` left ``inf``);
* *free*: any other joint (a passive joint with no spring); joints of several coordinates (spherical, universal
  written as one joint, a floating base) are free.

The links are rigid. At a closed ``q``, the motions the closures and the locked joints leave are the null space
:math:`N` (nv x d) of :math:`[J_c; E]` (:math:`E` selects the locked joints), taken on the Jacobians homogenised by
the characteristic length :math:`L` (:mod:`pkm.core.model.scale`), so that every rank decision is scale-free. On
them the elastic energy is :math:`\tfrac12 s^\top H s`, :math:`H = N^\top K N` with :math:`K = \mathrm{diag}(k_j)`,
and a wrench :math:`W = (f, m)` at the end effector's origin (world axes) does the work :math:`W^\top T s` with
:math:`T = J_{ee} N`. Equilibrium, :math:`H s = T^\top W`, gives the end effector's small displacement
:math:`\delta x = (\delta p, \delta\theta) = C W` with the compliance

.. math:: C = T H^{+} T^\top

provided every motion no spring resists (the kernel of :math:`H`: idle motions, free joints) leaves the end effector
where it is; else a load moves the mechanism freely (:class:`~pkm.errors.StiffnessError` ``"free"``). The stiffness
:math:`K_x = C^{-1}` exists where :math:`C` has full rank (six degrees of freedom resisted by springs); a mechanism
with fewer is rigid along the others (``"rigid"``): the compliance, its rank and the principal stiffnesses (``inf``
along rigid directions) still answer. With one axial spring per leg of a Gough-Stewart platform and every other
joint free, :math:`K_x` is Gosselin's :math:`J^\top \mathrm{diag}(k) J` (tested against the legs' own geometry).

**Compliant links** (``links={link: Beam(...) or a 6 x 6 compliance}``, :mod:`pkm.core.compliance.links`): each
named link is a beam from its origin to each joint, closure or end-effector frame it carries, a virtual
six-dimensional spring at each; their twists join the motions above (their columns in :math:`J_c` and
:math:`J_{ee}`, their stiffness in :math:`K`). Checked against a frame finite-element model of the 3-RRR (1e-11).

**Assumptions** (stated in every result): ``q`` is the unloaded equilibrium, each spring at rest there (a spec
spring's ``rest`` elsewhere preloads it: warned, its internal forces' geometric stiffness left out); gravity is not
counted (add the weights to the wrench where they matter); a compliant link's mass stays on the rigid link (the
vibrations condense its deformation statically). :meth:`Stiffness.deflection` solves the exact large-displacement equilibrium under a constant wrench
(the forces along the deflected members, hence the geometric stiffness of the loaded mode), with the first-order
:math:`C W` beside it and their gap.

**The loaded mode** (:meth:`Stiffness.loaded`): the tangent stiffness :math:`K_t = \partial W / \partial x` at that
deflected equilibrium, :math:`x` the end effector's world-aligned small twist at its deflected origin, the same sign
as :math:`K` (the wrench's increment per the displacement it causes): :math:`H` becomes
:math:`N^{*\top}(K - \partial_q (J_{ee}^\top W + J_c^\top \lambda^*)) N^*` at the deflected configuration, the
geometric stiffness of the internal forces :math:`\lambda^*` and of the wrench carried by the moving end effector.
Checked against the central differences of :meth:`Stiffness.deflection` with respect to the wrench (2e-9).

**Vibrations.** :func:`vibration_modes`: the generalised eigenproblem :math:`H v = \omega^2 N^\top M N v` on the
same motions (:math:`M` Pinocchio's joint-space mass matrix with the drives' reflected inertia), massless
directions condensed statically; the motions no spring resists are counted as free (zero frequency), not listed.
Checked against the linearised forward dynamics (:func:`pkm.forward_dynamics` with the springs' efforts) and the
Fourier transform of a free vibration simulated by :func:`pkm.simulate`.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.compliance.links import Attachment, Material, attachments, beams_from_collisions, virtual_columns
from pkm.core.differential.idle import MASSLESS, joint_inertia
from pkm.core.kinematics.configuration import Configuration
from pkm.core.kinematics.constraints import check_closed
from pkm.core.kinematics.labels import mode_label
from pkm.core.kinematics.newton import gauss_newton
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.scale import JacobianScales
from pkm.core.model.springs import MAGNITUDE
from pkm.errors import InvalidInputError, ModeChangeWarning, PkmWarning, StiffnessError, UnknownNameError
from pkm.validation import as_scalar, as_tolerance, as_vector, finite_result

#: ``links=``: ``"rigid"``, a :class:`~pkm.core.compliance.links.Material` (each link a beam of its collision
#: primitive), or ``{link: Beam(...) or a 6 x 6 compliance}`` (:mod:`pkm.core.compliance.links`).
Links = str | Material | Mapping[str, object]
#: Rank decisions (motions, stiffnesses, compliance) relative to the largest singular value or eigenvalue, on the
#: homogenised matrices.
RTOL = 1e-9
#: The exact deflection's equilibrium is solved to this, relative (forces to the wrench, closures to ``L``).
DEFLECTION_TOL = 1e-12
#: The smallest load increment is ``1 / MAX_LOAD_STEPS`` of the wrench (increments halve where Newton fails).
MAX_LOAD_STEPS = 64
#: Newton iterations per load increment.
MAX_ITER = 20
#: The central differences' step of the loaded stiffness's geometric term, along the homogenised motions (rad, or
#: characteristic lengths): truncation about its square, rounding about the machine's epsilon over it.
GEOMETRIC_STEP = 1e-5
#: A load whose first-order joint motion exceeds this (rad, or characteristic lengths) is refused at once.
MAX_FIRST_ORDER = math.pi


@dataclass(frozen=True)
class _Springs:
    """Which joints are sprung, locked or free, at one configuration, and the motions they leave."""

    mech: Mechanism
    q: np.ndarray
    k: np.ndarray  # (nv,) the joint stiffness on its velocity coordinate, 0 where none
    sprung: dict[str, float]
    sources: dict[str, str]  # {sprung joint: where its stiffness came from (SOURCES)}
    locked: tuple[str, ...]
    E: np.ndarray  # (n_locked, nv) rows selecting the locked joints
    N: np.ndarray  # (nv + 6 a, d) the motions the closures and the locked joints leave: joint rates, then the links'
    #               virtual twists (a attachments: pkm.core.compliance.links)
    H: np.ndarray  # (d, d) N^T K N
    T: np.ndarray  # (6, d) J_ee N
    length: float
    columns: np.ndarray  # (nv,) the homogenising column factors (L for a length)
    links: tuple[Attachment, ...] = ()
    rigid_links: dict[str, str] = field(default_factory=dict)  # ({link: why}: links=Material's links taken rigid)
    laws: dict[str, object] = field(default_factory=dict)  # ({link: Beam or 6 x 6 compliance}: the compliant links)


#: Where a joint's stiffness comes from (:attr:`Stiffness.sources`): the ``joints=`` argument, the drive's servo
#: stiffness (:attr:`Actuator.stiffness <pkm.core.model.actuators.Actuator.stiffness>`), the spec's ``[springs]``, or
#: the drive's and a spring's in parallel.
SOURCES = ("joints", "actuator", "spring", "actuator+spring")


def _joint_stiffness(mech: Mechanism, joints: Mapping[str, object] | None) -> tuple[dict[str, float], dict[str, str]]:
    """``({joint: k}, {joint: source})``: the spec's springs, the drives' servo stiffnesses (in parallel with a spring
    on the same joint), then ``joints`` over them; each a one-coordinate joint, ``k >= 0`` finite."""
    given: dict[str, float] = {n: float(t.get("stiffness", 0.0)) for n, t in mech.spec.springs.items()}
    sources = dict.fromkeys(given, "spring")
    for a in mech.actuators:
        if math.isfinite(a.stiffness):  # (inf: a rigid drive, locked unless a spring or joints= says otherwise)
            sources[a.joint] = "actuator+spring" if given.get(a.joint, 0.0) > 0.0 else "actuator"
            given[a.joint] = a.stiffness + given.get(a.joint, 0.0)
    if joints is not None:
        if not isinstance(joints, Mapping):
            raise InvalidInputError("joints", "expected a mapping {joint: stiffness} [N m/rad or N/m]", joints)
        for name, value in joints.items():
            if name not in mech.joints:
                raise UnknownNameError("joint", str(name), mech.joints, mech.name)
            if mech.joints[name].nv != 1:
                raise InvalidInputError("joints", f"{name!r} has {mech.joints[name].nv} coordinates: a spring "
                                                  "stiffness is for a one-coordinate joint (revolute, prismatic)", name)
            k = as_scalar(value, f"joints[{name!r}]", low=0.0)
            if k >= MAGNITUDE:  # (as the spec's springs: a unit mistake; a rigid joint is one left out, or locked)
                raise InvalidInputError(f"joints[{name!r}]", f"a stiffness below {MAGNITUDE:g} (N m/rad, N/m); to "
                                                             "hold an actuated joint rigid, leave it out", value)
            given[name], sources[name] = k, "joints"
    return given, sources


def _springs(mech: Mechanism, q: ArrayLike, joints: Mapping[str, object] | None, links: object | None, rtol: float) \
        -> _Springs:
    """The springs, the locked joints and the motions they leave at ``q`` (checked: closed, the joints' names and
    stiffnesses, ``links``; ``rtol`` already checked by the caller)."""
    mech = check_mechanism(mech)
    if links is None:
        links = dict(mech.spec.links)
    if isinstance(links, str) and links == "rigid":
        links = {}
    if not isinstance(links, Mapping | Material):
        raise InvalidInputError("links", "'rigid', a Material, or a mapping {link: Beam(...) or a 6 x 6 compliance}",
                                links)
    q = mech.check_q(q)
    check_closed(mech, q)
    rigid_links: dict[str, str] = {}
    if isinstance(links, Material):
        pin.framesForwardKinematics(mech.model, mech.data, q)
        links, rigid_links = beams_from_collisions(mech, mech.data, links)
        if not links:
            raise InvalidInputError("links", f"{mech.name}: no link is a beam of its collision geometry (" + "; ".join(
                f"{n}: {why}" for n, why in rigid_links.items()) + "): give the links' Beam(...) by name", "Material")
    given, sources = _joint_stiffness(mech, joints)
    sprung = {n: k for n, k in given.items() if k > 0.0}
    locked = tuple(j.name for j in mech.actuated if j.name not in given)
    k = np.zeros(mech.nv)
    for n, value in sprung.items():
        k[mech.joints[n].idx_v] = value
    E = np.zeros((len(locked), mech.nv))
    for row, n in enumerate(locked):
        E[row, mech.joints[n].idx_v] = 1.0
    _preloaded(mech, q, sprung)
    c = Configuration.compute(mech, q)
    scales = JacobianScales.of(mech)
    L = mech.characteristic_length
    att = attachments(mech, mech.data, links) if links else []  # (the frames placed by Configuration.compute)
    Vc, Vee = virtual_columns(mech, mech.data, att)
    columns = np.concatenate([scales.columns, np.tile([L, L, L, 1.0, 1.0, 1.0], len(att))])
    N = _motions(np.hstack([c.constraint_jacobian, Vc]), E, scales.constraint_rows, columns, rtol)
    K = np.zeros((len(columns), len(columns)))
    K[:mech.nv, :mech.nv] = np.diag(k)
    for i, a in enumerate(att):
        K[mech.nv + 6 * i:mech.nv + 6 * i + 6, mech.nv + 6 * i:mech.nv + 6 * i + 6] = a.stiffness
    H = N.T @ K @ N
    return _Springs(mech, q, k, sprung, {n: sources[n] for n in sprung}, locked, E, N, 0.5 * (H + H.T), np.hstack([c.ee_jacobian, Vee]) @ N, L,
                    scales.columns, tuple(att), rigid_links, dict(links))


def _motions(Jc: np.ndarray, E: np.ndarray, rows: np.ndarray, columns: np.ndarray, rtol: float) -> np.ndarray:
    """``N``: the motions the closures (their Jacobian ``Jc``, its rows homogenised by ``rows``) and the locked joints
    (``E``) leave, the null space's orthonormal basis on the columns homogenised by ``columns``, times them."""
    A = np.vstack([rows[:, None] * Jc * columns,
                   np.hstack([E, np.zeros((len(E), Jc.shape[1] - E.shape[1]))])])  # (a locked row: unit in either)
    _, s, Vt = np.linalg.svd(A) if A.size else (None, np.zeros(0), np.eye(len(columns)))
    rank = int(np.sum(s > rtol * s[0])) if s.size and s[0] > 0.0 else 0
    return columns[:, None] * Vt[rank:].T


def _preloaded(mech: Mechanism, q: np.ndarray, sprung: Mapping[str, float]) -> None:
    """Warn where a spec spring's rest lies elsewhere than ``q`` puts its joint (a preload left out: module doc)."""
    off = []
    for n in sprung:
        rest = mech.spec.springs.get(n, {}).get("rest")
        if rest is None:
            continue
        j = mech.joints[n]
        value = float(q[j.idx_q]) if j.nq == 1 else math.atan2(q[j.idx_q + 1], q[j.idx_q])  # (an unbounded revolute)
        tol = 1e-9 * (mech.characteristic_length if j.kind.startswith("JointModelP") else 1.0)
        if abs(value - rest) > tol:
            off.append(f"{n} ({value:.6g} against its rest {rest:.6g})")
    if off:
        warnings.warn(PkmWarning(f"{mech.name}: springs not at rest in q: {', '.join(off)}; the stiffness is taken "
                                 "about q, their preload's geometric stiffness left out"), stacklevel=4)


def _homogeneous_rows(L: float) -> np.ndarray:
    """Factors of a twist ``(v, w)`` (or of a compliance's rows) that make every entry a length: ``w`` times ``L``."""
    return np.array([1.0, 1.0, 1.0, L, L, L])


def _resisted(sp: _Springs, rtol: float) -> tuple[np.ndarray, np.ndarray]:
    """``(w, V)``: the eigenvalues [N m] and eigenvectors of ``H`` over the motions some spring resists (the motion
    coordinates are homogeneous: ``N`` is the homogenised null space's orthonormal basis times the column factors,
    so ``H``'s entries are all N m), after checking that no other motion moves the end effector.

    Raises:
        StiffnessError: ``"free"``, naming the joints of the unresisted motion that moves the end effector most.
    """
    w, V = np.linalg.eigh(sp.H) if sp.H.size else (np.zeros(0), np.zeros((0, 0)))
    top = float(np.max(w, initial=0.0))
    keep = w > rtol * top if top > 0.0 else np.zeros(len(w), dtype=bool)
    free = V[:, ~keep]
    Th = _homogeneous_rows(sp.length)[:, None] * sp.T
    scale = float(np.linalg.norm(Th, 2)) if Th.size else 0.0
    if free.shape[1] and scale > 0.0:
        moved = np.linalg.norm(Th @ free, axis=0)
        worst = int(np.argmax(moved))
        if moved[worst] > math.sqrt(rtol) * scale:
            motion = (sp.N[:sp.mech.nv] / sp.columns[:, None]) @ free[:, worst]
            big = 1e-6 * float(np.max(np.abs(motion)))
            names = [j.name for j in sp.mech.joints.values()
                     if j.nv and float(np.max(np.abs(motion[j.idx_v:j.idx_v + j.nv]))) > big]
            raise StiffnessError("free", f"{sp.mech.name}: a motion no spring resists moves the end effector (it "
                                         f"moves {', '.join(names)}): give one of those joints a stiffness, or "
                                         "hold the actuators rigid (give them none)", names)
    return w[keep], V[:, keep]


def _rank(C: np.ndarray, length: float, rtol: float) -> int:
    """The rank of a compliance, decided on its homogenised form (twist ``(v, w L)``, wrench ``(f, m / L)``)."""
    R = _homogeneous_rows(length)
    e = np.linalg.eigvalsh(R[:, None] * C * R[None, :])
    top = float(np.max(e, initial=0.0))
    return int(np.sum(e > rtol * top)) if top > 0.0 else 0


def _wrench(value: ArrayLike) -> np.ndarray:
    """A wrench ``(f [N], m [N m])`` at the end effector's origin, world axes (6,), finite."""
    return as_vector(value, 6, "wrench")


@dataclass(frozen=True)
class Deflection:
    """The end effector's displacement under a constant wrench (:meth:`Stiffness.deflection`).

    Attributes:
        q: The deflected equilibrium configuration (nq,).
        displacement: The exact displacement ``(dp [m], dtheta [rad])``: the origin's move and the rotation vector of
            ``R R0^T`` (world axes).
        first_order: The small-displacement prediction ``C W``, same layout.
        gap: ``|displacement - first_order|`` over ``|displacement|``, each homogenised by ``L`` (the first-order
            model's relative error at this load).
        load_steps: The load increments the equilibrium was followed in (1: the full wrench at once; each failed
            increment halved, each success doubling the next; 0: a zero wrench, ``q`` itself).
        outside_limits: The joints ``q`` puts outside their position limits (empty: none).
    """

    q: np.ndarray
    displacement: np.ndarray
    first_order: np.ndarray
    gap: float
    load_steps: int
    outside_limits: tuple[str, ...]


@dataclass(frozen=True)
class Stiffness:
    """The end effector's stiffness at a configuration (:func:`stiffness`; module doc).

    Attributes:
        compliance: ``C`` (6 x 6): the small displacement ``(dp, dtheta)`` per wrench ``(f, m)`` at the end
            effector's origin, world axes [m/N, m/(N m); rad/N, rad/(N m)].
        rank: The rank of ``C`` (6: every direction resisted by springs; fewer: rigid along the others).
        sprung: ``{joint: stiffness}`` of the springs counted [N m/rad or N/m].
        sources: ``{joint: source}`` for each of ``sprung``: where its stiffness came from (:data:`SOURCES`:
            ``"joints"`` the argument, ``"actuator"`` the drive's servo stiffness, ``"spring"`` the spec's
            ``[springs]``, ``"actuator+spring"`` both in parallel).
        locked: The actuated joints held rigid (given no stiffness).
        q: The configuration (nq,).
        links: ``{link: Beam or 6 x 6 compliance}``: the compliant links counted (``links=``'s, or those a
            :class:`~pkm.core.compliance.links.Material` made beams of their collision primitive).
        rigid_links: ``{link: why}``: with ``links=Material(...)``, the links that carry something and were taken
            rigid (no collision geometry, not one cylinder or capsule, a disc, a span of no length or across the
            primitive's axis); empty otherwise.
        outside_limits: The joints ``q`` puts outside the position limits the model states
            (:meth:`pkm.core.Mechanism.outside_limits`, as :attr:`SolveResult.outside_limits
            <pkm.core.kinematics.solve.SolveResult.outside_limits>`): the stiffness is computed there all the same,
            and the repr says so.
    """

    compliance: np.ndarray
    rank: int
    sprung: Mapping[str, float]
    sources: Mapping[str, str]
    locked: tuple[str, ...]
    q: np.ndarray
    links: Mapping[str, object]
    rigid_links: Mapping[str, str]
    outside_limits: tuple[str, ...]
    _springs: _Springs = field(repr=False, compare=False)
    _rtol: float = field(repr=False, compare=False, default=RTOL)

    def __repr__(self) -> str:
        k = self.principal("force")[0]
        parts = [f"rank {self.rank}", f"sprung {len(self.sprung)}", f"locked {len(self.locked)}",
                 "translational stiffness " + ", ".join(f"{v:.4g}" for v in k) + " N/m"]
        if self.links:
            parts.append(f"compliant links {len(self.links)}" + (f" ({len(self.rigid_links)} rigid: "
                                                                  f"{', '.join(self.rigid_links)})"
                                                                  if self.rigid_links else ""))
        if self.outside_limits:
            parts.append(f"OUTSIDE the position limits: {', '.join(self.outside_limits)}")
        return f"Stiffness({self._springs.mech.name}: {'; '.join(parts)})"

    @property
    def matrix(self) -> np.ndarray:
        """``K = C^-1`` (6 x 6), twist order ``(v, w)``, at the end effector's origin, world axes [N/m, N/rad;
        N m/m, N m/rad].

        Raises:
            StiffnessError: ``"rigid"`` where ``rank < 6`` (the stiffness is infinite along some directions: use
                :attr:`compliance` or :meth:`principal`).
        """
        if self.rank < 6:
            raise StiffnessError("rigid", f"{self._springs.mech.name}: the end effector's compliance has rank "
                                          f"{self.rank} of 6: it is rigid along {6 - self.rank} directions (rigid "
                                          "links, locked drives or fewer degrees of freedom than six), where the "
                                          "stiffness is infinite (the compliance and the principal stiffnesses "
                                          "answer)", rank=self.rank)
        return finite_result(np.linalg.inv(self.compliance), "stiffness matrix")

    def principal(self, load: str = "force") -> tuple[np.ndarray, np.ndarray]:
        """The principal stiffnesses and their directions under a pure force (``load="force"``: ``1 / eig(C_vf)``
        [N/m], the translational block) or a pure moment (``"moment"``: ``1 / eig(C_wm)`` [N m/rad]), stiffest
        last; ``inf`` along a direction the end effector cannot move.

        Returns:
            ``(k, directions)``: ``k`` (3,), ascending; the unit directions as columns (3 x 3), world axes.
        """
        if load not in ("force", "moment"):
            raise InvalidInputError("load", "'force' or 'moment'", load)
        block = self.compliance[:3, :3] if load == "force" else self.compliance[3:, 3:]
        c, U = np.linalg.eigh(block)
        top = float(np.max(c, initial=0.0))
        with np.errstate(divide="ignore"):
            k = np.where(c > self._rtol * top, 1.0 / np.where(c > 0.0, c, 1.0), np.inf) if top > 0.0 \
                else np.full(3, np.inf)
        return k[::-1].copy(), U[:, ::-1].copy()

    def vibration_modes(self) -> VibrationModes:
        """:func:`vibration_modes` with these springs at this configuration (the null space and the stiffness this
        result was computed from, not gathered again: a map's nodes)."""
        return _modes(self._springs, self._rtol)

    def deflection(self, wrench: ArrayLike, *, tol: float = DEFLECTION_TOL) -> Deflection:
        """The exact equilibrium under the constant wrench ``(f [N], m [N m])`` at the end effector's origin, world
        axes (large displacements: the springs' forces and the wrench at the deflected configuration), with the
        first-order ``C W`` beside it (module doc).

        The equilibrium ``K (q - q0) = J_ee(q)^T W + J_c(q)^T lambda + E^T mu`` with the closures and the locked
        joints held is solved by Newton's method on the configuration manifold (its Jacobian by forward differences:
        the residual is exact to ``tol`` whatever their accuracy), the load applied in increments where the whole
        does not converge at once (halved on failure, down to ``1 / MAX_LOAD_STEPS`` of it).

        An equilibrium in another assembly or working mode than ``q``'s (the load snapped the mechanism through a
        singularity) warns (:class:`~pkm.errors.ModeChangeWarning`); joints past their limits are listed in the
        result.

        Raises:
            ConvergenceError: an increment of ``1 / MAX_LOAD_STEPS`` of the load finds no equilibrium (a load past
                what the springs hold: the mechanism snaps through, or leaves its workspace), or the load turns a
                joint by more than :data:`MAX_FIRST_ORDER` rad (or characteristic lengths) at first order.
        """
        return self._deflect(_wrench(wrench), tol)[0]

    def _deflect(self, W: np.ndarray, tol: float) -> tuple[Deflection, np.ndarray]:
        """:meth:`deflection` and the multipliers at the equilibrium (:func:`_equilibrium`)."""
        tol = as_tolerance(tol, "tol")
        sp = self._springs
        if sp.links:
            raise InvalidInputError("links", "the exact deflection takes rigid links (compliant links: the first "
                                             "order, .compliance @ wrench)", tuple(a.link for a in sp.links))
        q, steps, multipliers = _equilibrium(sp, W, tol)
        first = self.compliance @ W
        exact = _displacement(sp, q)
        R = _homogeneous_rows(sp.length)
        size = float(np.linalg.norm(R * exact))
        gap = float(np.linalg.norm(R * (exact - first))) / size if size > 0.0 else 0.0
        before, after = mode_label(sp.mech, sp.q), mode_label(sp.mech, q)
        changed = before.differs(after)
        if changed:
            warnings.warn(ModeChangeWarning("deflection under the wrench", changed, before, after), stacklevel=2)
        return Deflection(q, exact, first, gap, steps, sp.mech.outside_limits(q)), multipliers

    def loaded(self, wrench: ArrayLike, *, tol: float = DEFLECTION_TOL) -> LoadedStiffness:
        r"""The tangent stiffness at the deflected equilibrium under the constant wrench ``(f [N], m [N m])`` at the
        end effector's origin, world axes (:meth:`deflection`): how much more wrench a further small displacement
        takes there, the geometric stiffness of the loaded members included (module doc; rigid links).

        At the equilibrium :math:`q^*` with the closures' and locked joints' multipliers :math:`\lambda^*`, the
        motions :math:`N^*` the closures and locked joints leave there and :math:`T^* = J_{ee}(q^*) N^*`:

        .. math:: H_t = N^{*\top} \Big(K - \frac{\partial}{\partial q}\big(J_{ee}^\top W + J_c^\top
                  \lambda^*\big)\Big) N^*, \qquad C_t = T^* H_t^{+} T^{*\top}, \qquad K_t = C_t^{-1},

        the derivative of the closures' and the wrench's generalised forces taken by central differences along
        :math:`N^*`'s columns (steps of :data:`GEOMETRIC_STEP` rad or characteristic lengths). ``W = 0`` gives
        :attr:`matrix`. :math:`K_t` need not be symmetric: a constant moment in world axes is not conservative.
        On an over-constrained mechanism :math:`\lambda^*` is the statically admissible set the equilibrium's Newton
        solve found (least-norm increments): rigid-body statics does not fix it.

        Raises:
            InvalidInputError: compliant links (the exact equilibrium takes rigid links).
            ConvergenceError: as :meth:`deflection`.
        """
        W = _wrench(wrench)
        d, mult = self._deflect(W, tol)
        sp = self._springs
        mech, m, nc = sp.mech, sp.mech.model, sp.mech.n_constraints
        c = Configuration.compute(mech, d.q)
        N = _motions(c.constraint_jacobian, sp.E, JacobianScales.of(mech).constraint_rows, sp.columns, self._rtol)

        def force(q: np.ndarray) -> np.ndarray:
            ck = Configuration.compute(mech, q)
            return ck.ee_jacobian.T @ W + ck.constraint_jacobian.T @ mult[:nc]

        dF = np.empty_like(N)
        if W.any():
            for i in range(N.shape[1]):
                step = GEOMETRIC_STEP * N[:, i]
                dF[:, i] = (force(pin.integrate(m, d.q, step)) - force(pin.integrate(m, d.q, -step))) \
                    / (2.0 * GEOMETRIC_STEP)
        else:
            dF[:] = 0.0
        Ht = N.T @ (sp.k[:, None] * N) - N.T @ dF
        T = c.ee_jacobian @ N
        C = finite_result(T @ np.linalg.pinv(Ht, rcond=self._rtol) @ T.T if N.size else np.zeros((6, 6)),
                          "loaded compliance")
        R = _homogeneous_rows(sp.length)
        sv = np.linalg.svd(R[:, None] * C * R[None, :], compute_uv=False)
        rank = int(np.sum(sv > self._rtol * sv[0])) if sv[0] > 0.0 else 0
        return LoadedStiffness(C, rank, W, d, mech.name)


@dataclass(frozen=True)
class LoadedStiffness:
    """The tangent stiffness at the deflected equilibrium under a constant wrench (:meth:`Stiffness.loaded`).

    Attributes:
        compliance: ``C_t`` (6 x 6): the further small displacement ``(dp, dtheta)`` of the end effector (world
            axes, at its deflected origin) per further wrench ``(df, dm)`` there; not symmetric in general.
        rank: Its rank (6: every direction resisted).
        wrench: The constant wrench ``W`` it is loaded with (6,) [N, N m].
        deflection: The deflected equilibrium (:class:`Deflection`).
        mechanism: The mechanism's name.
    """

    compliance: np.ndarray
    rank: int
    wrench: np.ndarray
    deflection: Deflection
    mechanism: str

    @property
    def matrix(self) -> np.ndarray:
        """``K_t = C_t^-1`` (6 x 6): ``dW / dx`` at the deflected equilibrium, twist order ``(v, w)``, world axes
        (the sign of :attr:`Stiffness.matrix`: the wrench's increment per the displacement it causes).

        Raises:
            StiffnessError: ``"rigid"`` where ``rank < 6``.
        """
        if self.rank < 6:
            raise StiffnessError("rigid", f"{self.mechanism}: the loaded compliance has rank {self.rank} of 6: rigid "
                                          f"along {6 - self.rank} directions", rank=self.rank)
        return finite_result(np.linalg.inv(self.compliance), "loaded stiffness matrix")


def stiffness(mech: Mechanism, q: ArrayLike, *, joints: Mapping[str, object] | None = None, links: Links | None = None,
              rtol: float = RTOL) -> Stiffness:
    """The end effector's stiffness at the closed configuration ``q`` (module doc: the model and its assumptions).

    Args:
        mech: The mechanism.
        q: A closed configuration (nq,): the unloaded equilibrium.
        joints: ``{joint: stiffness}`` [N m/rad for a revolute, N/m for a prismatic joint], over the drives'
            servo stiffnesses (:attr:`Actuator.stiffness <pkm.core.model.actuators.Actuator.stiffness>`) and the
            spec's ``[springs.<joint>]``: a drive's servo stiffness, a leg's axial stiffness; ``0`` frees a joint. An
            actuated joint left out whose drive states no stiffness is locked (rigid). :attr:`Stiffness.sources`
            says where each came from.
        links: ``None`` (default): the spec's ``[links.<link>] compliance`` tables (:attr:`ClosureSpec.links
            <pkm.core.model.spec.ClosureSpec.links>`), rigid links where it states none; ``"rigid"``: every link
            rigid; or ``{link: Beam(...) or a 6 x 6 compliance}``: those links compliant
            (:mod:`pkm.core.compliance.links`; the exact :meth:`Stiffness.deflection` takes rigid links); or a
            :class:`~pkm.core.compliance.links.Material`: every link that carries something a solid circular beam of
            its collision geometry's radius where that is one cylinder or capsule along its span
            (:func:`~pkm.core.compliance.links.beams_from_collisions`), the others rigid and named in
            :attr:`Stiffness.rigid_links`.
        rtol: Rank decisions, relative, on homogenised matrices.

    Raises:
        StiffnessError: ``"free"``: a motion no spring resists moves the end effector.
        InvalidInputError: ``q`` not closed; a stiffness not finite or negative; a joint of several coordinates;
            a link's law neither a :class:`~pkm.core.compliance.links.Beam` nor a symmetric positive definite 6 x 6
            compliance, or a link that carries nothing; ``links=Material(...)`` where no link is a beam of its
            collision geometry (the message lists each link's reason).
        UnknownNameError: a joint or a link that does not exist.

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> gs = pkm.load("gough_stewart")
        >>> legs = {j: 1e6 for j in gs.actuated_names}  # N/m: one axial spring per leg
        >>> K = pkm.stiffness(gs, gs.q_reference, joints=legs)
        >>> K.rank, round(float(K.matrix[2, 2]) / 1e6, 3)  # vertical stiffness [MN/m]
        (6, 5.274)
    """
    rtol = as_tolerance(rtol, "rtol")
    sp = _springs(mech, q, joints, links, rtol)
    w, V = _resisted(sp, rtol)
    TV = sp.T @ V
    C = finite_result((TV / w) @ TV.T if len(w) else np.zeros((6, 6)), "compliance")
    C = 0.5 * (C + C.T)
    return Stiffness(C, _rank(C, sp.length, rtol), dict(sp.sprung), dict(sp.sources), sp.locked, sp.q.copy(),
                     dict(sp.laws), dict(sp.rigid_links), sp.mech.outside_limits(sp.q), sp, rtol)


def _pose(sp: _Springs, q: np.ndarray) -> pin.SE3:
    m, d = sp.mech.model, sp.mech.data
    pin.framesForwardKinematics(m, d, q)
    return d.oMf[sp.mech.ee_frame].copy()


def _displacement(sp: _Springs, q: np.ndarray) -> np.ndarray:
    """``(p - p0, log(R R0^T))`` of the end effector from ``sp.q`` to ``q`` (world axes)."""
    a, b = _pose(sp, sp.q), _pose(sp, q)
    return np.concatenate([b.translation - a.translation, pin.log3(b.rotation @ a.rotation.T)])


def _equilibrium(sp: _Springs, W: np.ndarray, tol: float) -> tuple[np.ndarray, int, np.ndarray]:
    """The deflected configuration under ``W``, the load increments taken (:meth:`Stiffness.deflection`) and the
    multipliers there: the closures' forces (``J_c^T lambda``'s ``lambda``), then the locked joints' efforts.

    Unknowns: ``q`` (its steps homogenised: a prismatic joint's in ``L``) and the multipliers of the closures and the
    locked joints, scaled by the load's size (``energy / L``, a rotation row's and a revolute's times ``L``), so that
    every unknown and every residual is a pure number and Newton's step bound means the same on any robot."""
    from pkm.errors import ConvergenceError

    mech, m = sp.mech, sp.mech.model
    nv, nq, nc, ne = mech.nv, mech.nq, mech.n_constraints, len(sp.locked)
    L, cols = sp.length, sp.columns
    energy = max(float(np.max(np.abs(W[:3]))) * L, float(np.max(np.abs(W[3:]))), 1e-300)  # [N m]
    rows = JacobianScales.of(mech).constraint_rows
    unit = np.concatenate([rows * energy / L, energy / (sp.E @ cols) if ne else np.zeros(0)])  # (multipliers)

    def residual(q: np.ndarray, lam: np.ndarray, Wk: np.ndarray) -> tuple[np.ndarray, Configuration]:
        c = Configuration.compute(mech, q)
        dq = pin.difference(m, sp.q, q)
        mu = lam * unit
        force = sp.k * dq - c.ee_jacobian.T @ Wk - c.constraint_jacobian.T @ mu[:nc] - sp.E.T @ mu[nc:]
        return np.concatenate([cols * force / energy, rows * c.residual[:nc] / L, sp.E @ (dq / cols)]), c

    def solve(q: np.ndarray, lam: np.ndarray, Wk: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        def jacobian(x: np.ndarray, r: np.ndarray) -> np.ndarray:
            qx, lx = x[:nq], x[nq:]
            J = np.zeros((len(r), nv + nc + ne))
            h = 1e-7
            for i in range(nv):  # (forward differences in the homogenised joint motions)
                e = np.zeros(nv)
                e[i] = h * cols[i]
                J[:, i] = (residual(pin.integrate(m, qx, e), lx, Wk)[0] - r) / h
            Jc = Configuration.compute(mech, qx).constraint_jacobian
            J[:nv, nv:nv + nc] = -(cols[:, None] * Jc.T) * unit[:nc] / energy  # (linear in the multipliers)
            J[:nv, nv + nc:] = -(cols[:, None] * sp.E.T) * unit[nc:] / energy
            return J

        def retract(x: np.ndarray, dx: np.ndarray) -> np.ndarray:
            return np.concatenate([pin.integrate(m, x[:nq], cols * dx[:nv]), x[nq:] + dx[nv:]])

        x, res, _ = gauss_newton(lambda x: residual(x[:nq], x[nq:], Wk)[0], np.concatenate([q, lam]), tol=tol,
                                 max_iter=MAX_ITER, max_step=0.1, retract=retract, jacobian=jacobian)
        return x[:nq], x[nq:], res

    w, V = _resisted(sp, RTOL)
    reach = float(np.max(np.abs(sp.N / cols[:, None] @ (V @ ((V.T @ (sp.T.T @ W)) / w))), initial=0.0))
    if reach > MAX_FIRST_ORDER:  # (no equilibrium near q to follow: refused at once, not after 64 increments)
        raise ConvergenceError("deflection under the wrench", math.inf, 0, tol, None,
                               f"the load turns a joint by {reach:.3g} rad (or moves it {reach:.3g} L) at first "
                               f"order, over {MAX_FIRST_ORDER:.3g}: far past what the springs hold near q")
    q, lam, res = sp.q.copy(), np.zeros(nc + ne), math.inf
    if not W.any():
        return q, 0, lam
    done, step, steps = 0.0, 1.0, 0
    while done < 1.0:  # (the load in increments: halved where Newton fails, doubled again after a success)
        target = min(1.0, done + step)
        qk, lk, res = solve(q, lam, W * target)
        if res <= tol:
            q, lam, done, steps = qk, lk, target, steps + 1
            step *= 2.0
            continue
        step *= 0.5
        if step < 1.0 / MAX_LOAD_STEPS:
            raise ConvergenceError("deflection under the wrench", res, steps, tol, None,
                                   f"no equilibrium past {done:.0%} of the load (increments down to "
                                   f"1/{MAX_LOAD_STEPS}): the springs do not hold this load near q (snap-through, "
                                   "or past the workspace)")
    return q, steps, lam * unit


@dataclass(frozen=True)
class VibrationModes:
    """The small free vibrations about a configuration (:func:`vibration_modes`; module doc).

    Attributes:
        frequencies: The natural frequencies [Hz], ascending (the motions some spring resists).
        shapes: Their mode shapes as joint rates (nv x k), each of unit modal mass (``v^T M v = 1``).
        twists: The end effector's twist ``(v, w)`` of each shape (6 x k).
        free: How many motions no spring resists (zero frequency: idle motions, free joints), not listed.
    """

    frequencies: np.ndarray
    shapes: np.ndarray
    twists: np.ndarray
    free: int


def vibration_modes(mech: Mechanism, q: ArrayLike, *, joints: Mapping[str, object] | None = None,
                    links: Links | None = None,
                    rtol: float = RTOL) -> VibrationModes:
    """The natural frequencies and mode shapes at the closed configuration ``q`` with the springs of
    :func:`stiffness` (same ``joints``, ``links`` and ``rtol``; the locked drives held): ``H v = w^2 N^T M N v``
    (module doc).

    Examples:
        >>> import pkm
        >>> gs = pkm.load("gough_stewart")
        >>> modes = pkm.vibration_modes(gs, gs.q_reference, joints={j: 1e6 for j in gs.actuated_names})
        >>> modes.frequencies.round(1)  # [Hz]: sway (twice), heave, tilt (twice), twist
        array([ 29. ,  29. ,  51.3, 130.2, 158.6, 158.6])
    """
    rtol = as_tolerance(rtol, "rtol")
    return _modes(_springs(mech, q, joints, links, rtol), rtol)


def _modes(sp: _Springs, rtol: float) -> VibrationModes:
    """:func:`vibration_modes` of springs already gathered."""
    from scipy.linalg import eigh

    Nj = sp.N[:sp.mech.nv]  # (the links' virtual motions carry no mass: condensed below)
    Ms = Nj.T @ joint_inertia(sp.mech, sp.q) @ Nj
    Ms = 0.5 * (Ms + Ms.T)
    H = sp.H
    m, U = np.linalg.eigh(Ms) if Ms.size else (np.zeros(0), np.zeros((0, 0)))
    massive = m > MASSLESS * max(float(np.max(m, initial=0.0)), 1e-300)
    Ua, Ub = U[:, massive], U[:, ~massive]
    Hab, Hbb_inv = Ua.T @ H @ Ub, np.linalg.pinv(Ub.T @ H @ Ub, rcond=rtol, hermitian=True)
    Hc = Ua.T @ H @ Ua - Hab @ Hbb_inv @ Hab.T  # (massless motions: static)
    Hc = 0.5 * (Hc + Hc.T)
    w2, Va = eigh(Hc, Ua.T @ Ms @ Ua) if Hc.size else (np.zeros(0), np.zeros((0, 0)))
    top = float(np.max(np.abs(w2), initial=0.0))
    resisted = w2 > rtol * top if top > 0.0 else np.zeros(len(w2), dtype=bool)
    s = Ua @ Va[:, resisted]
    if Ub.shape[1]:
        s = s - Ub @ (Hbb_inv @ (Hab.T @ Va[:, resisted]))
    h = np.linalg.eigvalsh(H) if H.size else np.zeros(0)
    free = int(np.sum(h <= rtol * float(np.max(h, initial=0.0)))) if h.size else 0
    return VibrationModes(np.sqrt(w2[resisted]) / (2.0 * math.pi), Nj @ s, sp.T @ s, free)


__all__ = ["DEFLECTION_TOL", "GEOMETRIC_STEP", "MAX_FIRST_ORDER", "MAX_ITER", "MAX_LOAD_STEPS", "RTOL", "SOURCES",
           "Deflection", "LoadedStiffness", "Stiffness",
           "VibrationModes", "stiffness", "vibration_modes"]
