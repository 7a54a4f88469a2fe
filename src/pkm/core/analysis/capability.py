"""Capability under actuator limits: the task wrenches, twists and accelerations the actuators can produce at a pose.

Everything here is in the mechanism's **task coordinates** ``y`` (:meth:`pkm.TaskMap.of(mech)
<pkm.core.kinematics.task.TaskMap.of>`), with the forward Jacobian ``J`` (``ẏ = J q̇_a``,
:func:`pkm.forward_jacobian`); the efforts ``w`` conjugate to them are those whose power is the actuators'
(``wᵀ ẏ = τ_aᵀ q̇_a``, so ``τ_a = Jᵀ w``): forces [N] on length coordinates, moments [N m] about an
angle coordinate's own axis on angles (at zero angles, the platform frame's axes).

* **Wrenches** (static): ``{w : τ_min ≤ Jᵀ w + g_a ≤ τ_max}``: what the platform can hold, the actuators also
  holding the mechanism's own weight and its joint springs ``g_a`` (:func:`pkm.gravity_efforts`, the static
  efforts; ``gravity=False`` leaves both out).
* **Twists**: ``{J q̇_a : |q̇_a| ≤ q̇_max}``, from the actuators' speed limits.
* **Accelerations** (from rest): ``{J M_a⁻¹ (τ - h_a) : τ_min ≤ τ ≤ τ_max}`` (``M_a``, ``h_a``:
  :func:`pkm.actuator_model`; at rest ``h_a`` is the static efforts ``g_a`` and the ``J̇ q̇`` term vanishes).

Each is a :class:`Polytope` (vertices and half-spaces ``A x ≤ b``), the affine image or preimage of the limits' box,
exact: with ``J`` square and regular the map is one-to-one, so the vertices are the box's ``2^na`` corners mapped
and the half-spaces its faces pulled back (no vertex enumeration, no hull). Indices (:class:`Capability`): the
largest value along each task axis in each direction (the polytope's extent through the origin), the largest
isotropic value of each unit group (the radius of the largest ball about the origin inside the polytope, in the
axes of one unit: forces alone, moments alone), and, for comparison, the Yoshikawa-type ellipsoid (the image of the
limits' inscribed ellipsoid: its semi-axes and their directions), which under-states the box (by up to
``sqrt(na)`` along a corner).

Why not ``pycapacity`` (evaluated, version 2.1.9: its ``force_polytope(J, t_max, t_min)`` takes this ``J``
directly, as a serial arm's): it requires ``cvxopt`` (GPL-3, compiled) and ``matplotlib`` on install, and for the
square Jacobians of non-redundant parallel mechanisms its vertex search (hyper-plane shifting) is not needed: the
polytope is a linear image of a box, exact in closed form. Redundantly actuated mechanisms (more actuators than
task coordinates) would need it, or a hull: refused here with the reason.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.scale import JacobianScales
from pkm.errors import InvalidInputError, SingularityError
from pkm.validation import as_choice

if TYPE_CHECKING:
    from pkm.core.analysis.maps import WorkspaceMap
    from pkm.core.twin import Kernels

KINDS = ("wrench", "twist", "acceleration")
UNITS = {"wrench": {"length": "N", "angle": "N m"}, "twist": {"length": "m/s", "angle": "rad/s"},
         "acceleration": {"length": "m/s^2", "angle": "rad/s^2"}}


@dataclass(frozen=True)
class Polytope:
    """A convex polytope in task coordinates: ``vertices`` (k x n) and half-spaces ``A x ≤ b``.

    Attributes:
        vertices: Its corners (the limits' box corners mapped).
        A: Half-space normals (m x n); ``b``: their offsets (m,).
        axes: The task coordinates, in order; ``units``: each one's unit.
    """

    vertices: np.ndarray
    A: np.ndarray
    b: np.ndarray
    axes: tuple[str, ...]
    units: tuple[str, ...]

    def contains(self, x: ArrayLike, tol: float = 1e-9) -> bool:
        """Whether ``x`` satisfies every half-space (to ``tol`` relative to each row's offset scale)."""
        x = np.asarray(x, dtype=float)
        scale = np.maximum(np.abs(self.b), np.linalg.norm(self.A, axis=1) * np.abs(x).max(initial=0.0))
        return bool(np.all(self.A @ x - self.b <= tol * np.maximum(scale, 1e-300)))

    def reach(self, direction: ArrayLike) -> float:
        """The largest ``t ≥ 0`` with ``t d`` inside (``d`` normalised; the origin inside): ``min b_i / (A_i d)``
        over the rows that ``d`` approaches."""
        d = np.asarray(direction, dtype=float)
        return float(_reach(self.b, self.A @ (d / np.linalg.norm(d))))

    def inscribed_radius(self, axes: ArrayLike | None = None) -> float:
        """The radius of the largest ball about the origin inside, in the coordinates ``axes`` (indices; the others
        held at zero; default all): ``min b_i / |A_i|`` over those columns."""
        cols = np.arange(self.A.shape[1]) if axes is None else np.asarray(axes, dtype=int)
        return float(_reach(self.b, np.linalg.norm(self.A[:, cols], axis=1)))


def _reach(b: np.ndarray, rate: np.ndarray) -> np.ndarray:
    """``min b_i / rate_i`` over the rows whose rate is positive (the last axis), ``inf`` where none is: how far a
    direction (``rate = A d``) or a ball (``rate = |A_i|``) goes inside ``A x ≤ b`` from the origin; one polytope or
    a stack of them (``(n, m)`` arrays)."""
    ahead = rate > 1e-300
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.min(np.where(ahead, b / np.where(ahead, rate, 1.0), np.inf), axis=-1)


@dataclass(frozen=True)
class Capability:
    """One kind of capability at a pose, with its indices (module doc).

    Attributes:
        kind: ``"wrench"``, ``"twist"`` or ``"acceleration"``.
        polytope: The set (:class:`Polytope`).
        along: ``{axis: (largest positive, largest negative magnitude)}`` through the origin, in the axis' unit.
        isotropic: ``{unit: radius}``: the largest value reachable in every direction of that unit's axes.
        ellipsoid_axes: The Yoshikawa-type ellipsoid's semi-axes (descending) and ``ellipsoid_directions`` their
            directions (columns), in the task axes' units (mixed where the task mixes them), about
            ``ellipsoid_center`` (the image of zero efforts or rates: the weight's share, for wrenches).
        origin_inside: Whether the origin is inside (a wrench set that excludes it: the actuators cannot even hold
            the weight; its indices are then 0).
    """

    kind: str
    polytope: Polytope
    along: dict[str, tuple[float, float]]
    isotropic: dict[str, float]
    ellipsoid_axes: np.ndarray
    ellipsoid_directions: np.ndarray
    ellipsoid_center: np.ndarray
    origin_inside: bool


def _limits(mech: Mechanism, kind: str) -> tuple[np.ndarray, np.ndarray]:
    if kind == "twist":
        hi = np.array([a.velocity_limit for a in mech.actuators], dtype=float)
        what = "velocity_limit"
    else:
        hi = np.array([a.effort_limit for a in mech.actuators], dtype=float)
        what = "effort_limit"
    bad = np.flatnonzero(~np.isfinite(hi) | ~(hi > 0.0))
    if bad.size:
        j = int(bad[0])
        raise InvalidInputError(f"{mech.actuated_names[j]}.{what}", f"the {kind} capability needs a finite positive "
                                                                   f"{what.replace('_', ' ')} on every actuator; "
                                                                   f"{mech.actuated_names[j]} has {hi[j]}", hi[j])
    return -hi, hi


def _box_map(L: np.ndarray, c: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray,
                                                                                    np.ndarray]:
    """``{L u + c : lo ≤ u ≤ hi}`` for square regular ``L``: vertices, and ``A x ≤ b`` from ``u = L⁻¹ (x - c)``."""
    Li = np.linalg.inv(L)
    corners = np.array(list(itertools.product(*zip(lo, hi))))
    V = corners @ L.T + c
    A = np.vstack([Li, -Li])
    b = np.concatenate([hi + Li @ c, -lo - Li @ c])
    return V, A, b


def capability(mech: Mechanism, q: ArrayLike, kind: str = "wrench", *, gravity: bool = True) -> Capability:
    """The ``kind`` capability of ``mech`` at the closed configuration ``q`` (module doc).

    Raises:
        InvalidInputError: an unknown kind, an actuator without a finite positive limit of that kind (named), a
            mechanism with more actuators than task coordinates, a ``q`` whose loops are not closed
            (:func:`~pkm.core.kinematics.constraints.check_closed`).
        SingularityError: ``J`` (or ``M_a``) singular at ``q``: no finite polytope.

    Examples:
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> cap = pkm.capability(delta, delta.q_reference)
        >>> cap.polytope.units
        ('N', 'N', 'N')
        >>> {k: tuple(round(x, 2) for x in v) for k, v in cap.along.items()}
        {'x': (48.39, 48.39), 'y': (41.91, 45.96), 'z': (101.6, 111.42)}
        >>> round(cap.isotropic["N"], 2)
        38.74
    """
    from pkm.core.differential.velocity import forward_jacobian
    from pkm.core.kinematics.constraints import check_closed

    mech = check_mechanism(mech)
    kind = as_choice(kind, KINDS, "kind")
    q = mech.check_q(q)
    check_closed(mech, q)
    J = forward_jacobian(mech, q)
    if J.shape[0] != J.shape[1]:
        raise InvalidInputError("mech", f"{J.shape[1]} actuators for {J.shape[0]} task coordinates: the capability of "
                                        "redundant actuation needs a hull (pycapacity's force_polytope)", J.shape)
    s = np.linalg.svd(JacobianScales.of(mech).forward(J), compute_uv=False)  # (homogenised: the same at any size)
    if not s[-1] > 1e-12 * s[0]:
        raise SingularityError("inverse" if s[-1] == 0.0 else "direct", float(s[-1]),
                               "the forward Jacobian is singular here: the capability is unbounded or flat",
                               distance=float(s[-1] / s[0]) if s[0] > 0.0 else 0.0)
    lo, hi = _limits(mech, kind)
    n = J.shape[0]
    if kind == "twist":
        L, c = J, np.zeros(n)
    else:
        from pkm.core.dynamics.model import actuator_model, gravity_efforts

        if kind == "wrench":  # (τ = Jᵀ w + g: w = J⁻ᵀ (τ - g))
            g = gravity_efforts(mech, q) if gravity else np.zeros(mech.na)
            L, c = np.linalg.inv(J.T), -np.linalg.solve(J.T, g)
        else:  # (ÿ = J M⁻¹ (τ - h) at rest)
            model = actuator_model(mech, q, np.zeros(mech.na))
            L = J @ np.linalg.inv(model.M)
            c = -L @ (model.h if gravity else model.h - model.g)
    V, A, b = _box_map(L, c, lo, hi)
    kinds = TaskMap.of(mech).kinds
    axes = tuple(kinds)
    units = tuple(UNITS[kind][kinds[a]] for a in axes)
    poly = Polytope(V, A, b, axes, units)
    inside = bool(np.all(b > 0.0))
    along = {a: (poly.reach(np.eye(n)[i]) if inside else 0.0, poly.reach(-np.eye(n)[i]) if inside else 0.0)
             for i, a in enumerate(axes)}
    iso = {u: (poly.inscribed_radius([i for i, x in enumerate(units) if x == u]) if inside else 0.0)
           for u in dict.fromkeys(units)}
    U, S, _ = np.linalg.svd(L @ np.diag(0.5 * (hi - lo)))
    return Capability(kind, poly, along, iso, S, U, c, inside)


def capability_indices(mech: Mechanism, Q: ArrayLike, kind: str = "wrench", *, gravity: bool = True,
                       kernels: Kernels | None = None) -> tuple[dict[str, tuple[np.ndarray, np.ndarray]],
                                                                dict[str, np.ndarray], np.ndarray, np.ndarray]:
    """The indices of :func:`capability` at many closed configurations ``Q`` (n x nq) at once, from the compiled
    kernels (:class:`pkm.Kernels`: ``J``, ``g_a``, ``M_a`` in batches) and the half-spaces in closed form: the set
    is ``{x : A x ≤ b}``, ``A = [P; -P]``, ``b = [hi - s; s - lo]``, with ``P = Jᵀ, s = g_a`` (wrenches),
    ``P = J⁻¹, s = 0`` (twists), ``P = M_a J⁻¹, s = g_a`` (accelerations from rest); along a unit direction ``d``
    the extent is ``min b_r / (A d)_r`` over the rows ``d`` approaches, and the isotropic value of a unit group
    ``min b_r / |A_r|`` on that group's columns, as :class:`Polytope` computes them one pose at a time (one rule,
    ``_reach``). Returns ``(along, isotropic, regular, inside)``: ``{axis: (plus, minus)}`` and ``{unit: values}`` (n
    each; 0 where the origin is outside, NaN where ``J`` is singular, as :func:`capability` refuses), the mask of
    the regular samples and that of the samples whose set holds the origin (the actuators hold the weight there).

    Raises:
        InvalidInputError: as :func:`capability` (kind, limits, redundant actuation).
    """
    from pkm.core.twin import Kernels

    mech = check_mechanism(mech)
    kind = as_choice(kind, KINDS, "kind")
    kernels = Kernels(mech) if kernels is None else kernels
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    lo, hi = _limits(mech, kind)
    J = kernels.forward_jacobian(Q)
    if J.shape[1] != J.shape[2]:
        raise InvalidInputError("mech", f"{J.shape[2]} actuators for {J.shape[1]} task coordinates: the capability "
                                        "of redundant actuation needs a hull", J.shape[1:])
    s = np.linalg.svd(JacobianScales.of(mech).forward(J), compute_uv=False)
    regular = s[:, -1] > 1e-12 * s[:, 0]
    J = np.where(regular[:, None, None], J, np.eye(J.shape[1]))  # (singular samples: NaN below)
    shift = kernels.gravity(Q) if gravity and kind != "twist" else np.zeros((len(Q), mech.na))
    if kind == "wrench":
        P = np.transpose(J, (0, 2, 1))
    elif kind == "twist":
        P = np.linalg.inv(J)
    else:
        P = kernels.mass_matrix(Q) @ np.linalg.inv(J)
    A = np.concatenate([P, -P], axis=1)  # (n, 2 na, t): A x <= b
    b = np.concatenate([hi - shift, -lo + shift], axis=1)
    inside = np.all(b > 0.0, axis=1)
    kinds = TaskMap.of(mech).kinds
    axes = tuple(kinds)
    units = tuple(UNITS[kind][kinds[a]] for a in axes)

    def finish(x: np.ndarray) -> np.ndarray:
        return np.where(regular, np.where(inside, x, 0.0), np.nan)

    along = {a: (finish(_reach(b, A[:, :, i])), finish(_reach(b, -A[:, :, i]))) for i, a in enumerate(axes)}
    iso = {u: finish(_reach(b, np.linalg.norm(A[:, :, [i for i, x in enumerate(units) if x == u]], axis=2)))
           for u in dict.fromkeys(units)}
    return along, iso, regular, inside & regular


def map_capability(mech: Mechanism, wmap: WorkspaceMap, kind: str = "wrench", *, gravity: bool = True,
                   kernels: Kernels | None = None) -> CapabilityMap:
    """The ``kind`` capability's indices over a compiled workspace map (:func:`pkm.workspace_map` with
    ``configurations=True``: every node solved in C, breadth first, in one working mode), computed at all its
    reachable nodes at once (:func:`capability_indices`): the route for large grids (10⁶ nodes) where
    :func:`capability_map` solves each node's inverse kinematics in Python.

    Raises:
        InvalidInputError: ``wmap`` kept no configurations, or is not ``mech``'s; as :func:`capability_indices`.
    """
    mech = check_mechanism(mech)
    if wmap.q is None or wmap.q.shape[-1] != mech.nq or wmap.mechanism != mech.name:
        raise InvalidInputError("wmap", "give a map of this mechanism made with workspace_map(..., "
                                        "configurations=True)", wmap)
    shape = wmap.reachable.shape
    nodes = np.flatnonzero(wmap.reachable.ravel())
    along_n, iso_n, regular, inside_n = capability_indices(mech, wmap.q.reshape(-1, mech.nq)[nodes], kind,
                                                           gravity=gravity, kernels=kernels)

    def spread(values: np.ndarray) -> np.ndarray:
        out = np.full(int(np.prod(shape)), np.nan)
        out[nodes] = values
        return out.reshape(shape)

    reachable = np.zeros(int(np.prod(shape)), dtype=bool)
    reachable[nodes[regular]] = True
    inside = np.zeros(int(np.prod(shape)), dtype=bool)
    inside[nodes[inside_n]] = True
    kinds = TaskMap.of(mech).kinds
    names = {n for n, _ in wmap.axes}
    fixed = {k: float(v) for k, v in zip(TaskMap.of(mech).value_names, wmap.fixed) if k not in names}
    return CapabilityMap(kind, wmap.axes, fixed, reachable.reshape(shape),
                         {a: (spread(p), spread(m)) for a, (p, m) in along_n.items()},
                         {u: spread(v) for u, v in iso_n.items()},
                         {a: UNITS[kind][kinds[a]] for a in kinds}, dict(kinds), mech.name, inside.reshape(shape))


MAX_MAP_NODES = 250_000  # nodes of a capability map at most (each an IK solve and a capability: about 2 ms)


@dataclass(frozen=True)
class CapabilityMap:
    """A capability index over a grid of task coordinates (:func:`capability_map`).

    Attributes:
        kind: ``"wrench"``, ``"twist"`` or ``"acceleration"``.
        axes: ``(name, values)`` per grid axis (1 or 2), the first the fastest; arrays are shaped
            ``(n_last, ..., n_first)``.
        fixed: The other task coordinates by name.
        reachable: Nodes solved (inverse kinematics converged, the Jacobian regular); where the set does not hold
            the origin (the actuators cannot hold the weight there) the node counts, its indices 0 (:attr:`inside`).
        along: ``{axis: (plus, minus)}`` arrays: the largest value along each task axis each way (NaN where
            unreachable).
        isotropic: ``{unit: array}``: the largest isotropic value of each unit group.
        units: Each task axis' unit (of the capability); ``kinds``: each task coordinate's kind (``"length"``,
            ``"angle"``).
        mechanism: The mechanism's name.
        inside: The reachable nodes whose set holds the origin (elsewhere the indices are 0: the actuators cannot
            hold the weight there); None: every reachable node's does.
    """

    kind: str
    axes: tuple[tuple[str, np.ndarray], ...]
    fixed: dict[str, float]
    reachable: np.ndarray
    along: dict[str, tuple[np.ndarray, np.ndarray]]
    isotropic: dict[str, np.ndarray]
    units: dict[str, str]
    kinds: dict[str, str]
    mechanism: str = ""
    inside: np.ndarray | None = None

    @property
    def below_weight(self) -> int:
        """How many reachable nodes' sets exclude the origin: the actuators cannot hold the weight there (their
        indices are 0)."""
        return 0 if self.inside is None else int(np.count_nonzero(self.reachable & ~self.inside))

    def figure(self, path: str, unit: str | None = None, *, along: str | None = None, negative: bool = False) \
            -> str:
        """Draw the largest isotropic value of ``unit`` (default the first) over the map as a PNG at ``path``, or
        with ``along`` the largest value along that task axis (its positive direction, or ``negative``: a pure-pitch
        torque map) (1 axis: a curve; 2 axes: a colour map with its colour bar; unreachable nodes blank).

        Raises:
            MissingDependencyError: matplotlib is not installed (``pip install "pkm-robotics[figures]"``).
            InvalidInputError: an unknown unit or axis.
        """
        from pathlib import Path

        from pkm._optional import require

        require("figures", "the figure of a capability map")
        from pkm._plot import figure, pyplot

        if along is not None:
            if along not in self.along:
                raise InvalidInputError("along", f"one of {list(self.along)}, got {along!r}", along)
            values = self.along[along][1 if negative else 0]
            label = f"largest {'-' if negative else '+'}{along} {self.kind} [{self.units.get(along, '')}]"
        else:
            unit = next(iter(self.isotropic)) if unit is None else unit
            if unit not in self.isotropic:
                raise InvalidInputError("unit", f"one of {list(self.isotropic)}, got {unit!r}", unit)
            values = self.isotropic[unit]
            label = f"largest isotropic {self.kind} [{unit}]"
        fig, ax = figure()
        (n1, v1) = self.axes[0]

        def axis_label(name: str) -> str:
            return f"{name} [{'m' if self.kinds[name] == 'length' else 'rad'}]"

        if len(self.axes) == 1:
            ax.plot(v1, values, label=label)
            ax.set_xlabel(axis_label(n1))
            ax.set_ylabel(label)
            ax.legend()
        else:
            (n2, v2) = self.axes[1]
            mesh = ax.pcolormesh(v1, v2, np.ma.masked_invalid(values), shading="nearest")
            fig.colorbar(mesh, ax=ax, label=label)
            ax.set_xlabel(axis_label(n1))
            ax.set_ylabel(axis_label(n2))
        fixed = ", ".join(f"{k} = {v:.4g}" for k, v in self.fixed.items())
        ax.set_title(f"{self.mechanism}: {label}{' at ' + fixed if fixed else ''}\nno figure (capability map)",
                     fontsize=9)
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        fig.tight_layout()
        fig.savefig(out, dpi=150)
        pyplot().close(fig)
        return str(out)


    def write_csv(self, path: str) -> str:
        """One row per node: the axes' coordinates (SI), ``reachable``, ``origin_inside`` (0: the actuators cannot
        hold the weight there, the indices are 0), the largest value along each task axis each
        way (``<axis>_plus``, ``<axis>_minus``) and the isotropic values (``isotropic [<unit>]``; NaN where
        unreachable)."""
        import csv
        from pathlib import Path

        mesh = np.meshgrid(*[v for _, v in reversed(self.axes)], indexing="ij")
        cols = {name: m.ravel() for (name, _), m in zip(reversed(self.axes), mesh)}
        cols["reachable"] = self.reachable.ravel().astype(float)
        if self.inside is not None:
            cols["origin_inside"] = self.inside.ravel().astype(float)
        for a, (plus, minus) in self.along.items():
            cols[f"{a}_plus"], cols[f"{a}_minus"] = plus.ravel(), minus.ravel()
        for u, v in self.isotropic.items():
            cols[f"isotropic [{u}]"] = v.ravel()
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        with out.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(list(cols))
            w.writerows(zip(*[c.tolist() for c in cols.values()]))
        return str(out)

    def summary(self) -> dict:
        """The indices' ranges over the reachable nodes: ``{"along": {axis: {"plus": [min, max], "minus": [...]}},
        "isotropic": {unit: [min, max]}, "units": ..., "below_weight": n}`` (empty where no node is reachable;
        ``below_weight``: the nodes where the actuators cannot hold the weight, whose indices are 0)."""
        if not self.reachable.any():
            return {"along": {}, "isotropic": {}, "units": self.units, "below_weight": 0}
        span = lambda v: [float(np.nanmin(v[self.reachable])), float(np.nanmax(v[self.reachable]))]
        return {"along": {a: {"plus": span(p), "minus": span(m)} for a, (p, m) in self.along.items()},
                "isotropic": {u: span(v) for u, v in self.isotropic.items()}, "units": self.units,
                "below_weight": self.below_weight}


def capability_map(mech: Mechanism, axes: Mapping[str, ArrayLike], fixed: Mapping[str, float] | None = None,
                   kind: str = "wrench", *, gravity: bool = True) -> CapabilityMap:
    """The ``kind`` capability's indices over a grid of task coordinates: ``axes`` (1 or 2 of them, values SI, the
    first the fastest), ``fixed`` the other task coordinates (default the reference's). Each node's inverse
    kinematics is warm-started from its neighbour's solution (so the map stays in the reference's working mode);
    a node that does not solve or is singular is left unreachable.

    Raises:
        InvalidInputError: unknown or repeated axes, empty or more than two axes, more than :data:`MAX_MAP_NODES`
            nodes; the capability's own refusals (a missing limit).
    """
    from pkm.core.analysis.region import other_coordinates
    from pkm.core.kinematics.solve import solve_ik
    from pkm.errors import PkmError
    from pkm.validation import as_array

    mech = check_mechanism(mech)
    kind = as_choice(kind, KINDS, "kind")
    names = list(TaskMap.of(mech).kinds)
    if not isinstance(axes, Mapping) or not 1 <= len(axes) <= 2:
        raise InvalidInputError("axes", "expected one or two task coordinates by name", axes)
    grid = []
    for name, values in axes.items():
        if name not in names:
            raise InvalidInputError("axes", f"{name!r} is not a task coordinate; they are {names}", name)
        v = np.atleast_1d(as_array(values, f"axes[{name}]"))
        if v.ndim != 1 or v.size == 0 or not np.all(np.isfinite(v)):
            raise InvalidInputError(f"axes[{name}]", "expected a non-empty vector of finite values", values)
        grid.append((name, v))
    if np.prod([len(v) for _, v in grid]) > MAX_MAP_NODES:
        raise InvalidInputError("axes", f"more than {MAX_MAP_NODES} nodes", [len(v) for _, v in grid])
    rest = other_coordinates(mech, axes, fixed)
    _limits(mech, kind)  # (the refusal before any solve)
    shape = tuple(len(v) for _, v in reversed(grid))
    reachable = np.zeros(shape, dtype=bool)
    inside = np.zeros(shape, dtype=bool)
    along = {a: (np.full(shape, np.nan), np.full(shape, np.nan)) for a in names}
    iso: dict[str, np.ndarray] = {}
    units: dict[str, str] = {}
    q_row = mech.q_reference
    second = grid[1][1] if len(grid) == 2 else np.array([0.0])
    for j, y2 in enumerate(second):
        q = q_row
        for i, y1 in enumerate(grid[0][1]):
            target = dict(rest, **{grid[0][0]: float(y1)})
            if len(grid) == 2:
                target[grid[1][0]] = float(y2)
            idx = (j, i) if len(grid) == 2 else (i,)
            try:
                q = solve_ik(mech, target, q).q
                c = capability(mech, q, kind, gravity=gravity)
            except PkmError:
                continue
            if i == 0:
                q_row = q
            reachable[idx], inside[idx] = True, c.origin_inside  # (outside: indices 0, the node counts)
            for a in names:
                along[a][0][idx], along[a][1][idx] = c.along[a]
            units = dict(zip(c.polytope.axes, c.polytope.units))
            for u, r in c.isotropic.items():
                iso.setdefault(u, np.full(shape, np.nan))[idx] = r
    return CapabilityMap(kind, tuple(grid), rest, reachable, along, iso, units, dict(TaskMap.of(mech).kinds), mech.name,
                         inside)


__all__ = ["KINDS", "MAX_MAP_NODES", "UNITS", "Capability", "CapabilityMap", "Polytope", "capability", "capability_map"]
