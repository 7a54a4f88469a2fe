"""Maps of any mechanism over a grid of task coordinates: the reachable workspace in one working mode and the
velocity map's indices at every reachable node, through the twin's compiled kernels.

:func:`workspace_map` (formerly ``task_map``, a name kept as a deprecated alias: the task coordinates are
:class:`~pkm.core.kinematics.task.TaskMap`) solves the inverse kinematics at every node of a grid of one, two or three task coordinates (the
others fixed), breadth first from the node nearest the seed configuration: each node's Newton iteration starts from
the solution of the neighbour that reached it, so that the whole reachable region connected to the seed is covered
in the seed's working mode; a node whose solution leaves that mode (the default branch's signs) counts as not
reached. Roots on a coarse sub-grid (every :data:`ROOT_STRIDE` nodes, seeded from the seed configuration) start
new searches for parts of the workspace that are not connected to the first: a part narrower than that, or one
the seed's Newton iteration does not reach in its mode, is missed.

At a reachable node the map keeps the singular values of ``K diag(s)``: ``K`` the inverse Jacobian (actuated
rates per task rate), ``s`` the task rates' scales (1 for lengths, ``1/L`` for angles: the homogenisation by a
characteristic length ``L``). The indices follow from them (:class:`WorkspaceMap`, formerly ``TaskGridMap``): the condition index
``1/kappa`` in the conventions of :mod:`pkm.core.differential.indices` (``"2"``: ``sigma_min / sigma_max``;
``"fro_normalized"``: ``n / (||K||_F ||K^-1||_F)``), the global condition index over a region, Yoshikawa's
manipulability of the forward Jacobian ``J = K^-1`` and its smallest singular value (both 0 at an inverse
singularity: graded singularity measures), the workspace's size.

Newton's convergence is tested on the step (``max |dq| <= step_tol``), then the residual at the node on every
equation (closure and task, ``<= tol``).
"""

from __future__ import annotations

import ctypes
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.collision.interference import checks_collisions, minimum_distances
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.twin.codegen import C_INT as _I
from pkm.core.twin.codegen import C_REAL_P as _P
from pkm.errors import CompilerError, InvalidInputError
from pkm.validation import as_array, as_count, as_scalar, as_tolerance

if TYPE_CHECKING:
    from pkm.core.twin import Kernels

#: Spacing of the root nodes that start a new search where the first did not reach.
ROOT_STRIDE = 16
#: Where the fixed-pivot LU's smallest relative pivot falls under this, the Newton step is taken by QR instead.
PIVOT_FLOOR = 1e-3
#: Grids larger than this are refused (memory: the singular values and states of every node).
MAX_NODES = 50_000_000
#: Machine epsilon: a task coordinate beyond ``tol / EPS`` (4.5e5 m or rad at the default ``tol``) has a float spacing
#: larger than ``tol``, so no node there can be solved to ``tol``: such grids are refused.
EPS = float(np.finfo(float).eps)
KINDS = ("2", "fro_normalized")
#: A map of more nodes than this leaves interference out unless asked (``collisions=True``): its clearance costs
#: 10 to 30 us a node (the 3-RRR's paper map of 641,601 nodes: 2.4 s without, 19 s with).
COLLISION_NODES = 100_000



@dataclass(frozen=True, eq=False)
class WorkspaceMap:
    """A map over a grid of task coordinates (see the module doc).

    Attributes:
        axes: ``(name, values)`` per grid axis, the first the fastest; arrays are shaped ``(n_last, ..., n_first)``
            (rows along the second axis, as :func:`numpy.meshgrid`).
        fixed: The other task coordinates (the task value laid out as :meth:`TaskMap.value`).
        scale: The task rates' scales (1 for lengths, ``1/L`` for angles).
        reachable: Solved nodes in the working mode.
        singular_values: Of ``K diag(scale)`` per node, descending (NaN where unreachable).
        iterations: Newton iterations per node.
        how: What ran the kernels.
        kinds: Each axis's kind, ``"length"`` or ``"angle"``.
        mechanism: The mechanism's name (the figure's caption).
        q: The configuration solved at each node (shaped as the arrays, then nq; NaN where unreachable), when
            :func:`workspace_map` was asked to keep them (``configurations=True``), else None.
        clearance: The smallest signed distance between the bodies checked for collision at each node [m]
            (:func:`pkm.clearance`'s ``minimum``; negative: two interpenetrate; NaN where unreachable), when the
            mechanism has collision geometry and the map was not asked to leave it out (``collisions=False``),
            else None.
        within_limits: The reachable nodes whose configuration lies within the joints' stated position limits
            (to 1e-9 m or rad, as :meth:`pkm.core.Mechanism.outside_limits`), computed where the map had its
            nodes' configurations (kept, or solved for :attr:`clearance`), else None (the solvers do not enforce
            limits: :attr:`reachable` is the workspace without them).
    """

    axes: tuple[tuple[str, np.ndarray], ...]
    fixed: np.ndarray = field(repr=False)
    scale: np.ndarray
    reachable: np.ndarray = field(repr=False)
    singular_values: np.ndarray = field(repr=False)
    iterations: np.ndarray = field(repr=False)
    how: str = ""
    kinds: tuple[str, ...] = ()
    mechanism: str = ""
    q: np.ndarray | None = field(default=None, repr=False)
    clearance: np.ndarray | None = field(default=None, repr=False)
    within_limits: np.ndarray | None = field(default=None, repr=False)

    @property
    def nodes(self) -> int:
        return int(self.reachable.sum())

    @property
    def interferes(self) -> np.ndarray | None:
        """The reachable nodes where two checked bodies interpenetrate (:attr:`clearance` < 0); None where the
        clearance was not computed."""
        if self.clearance is None:
            return None
        with np.errstate(invalid="ignore"):
            return np.asarray(self.reachable & (self.clearance < 0.0))

    @property
    def feasible(self) -> np.ndarray:
        """The reachable nodes within the joints' position limits (where they were checked, :attr:`within_limits`)
        and free of interference (where it was checked, :attr:`interferes`): the workspace as far as this map
        knows it."""
        out = self.reachable.copy()
        if self.within_limits is not None:
            out &= self.within_limits
        if self.interferes is not None:
            out &= ~self.interferes
        return out

    @property
    def uniform(self) -> bool:
        """Whether every axis of more than one node is evenly spaced (relative 1e-9): then every node's cell is
        :attr:`cell`."""
        return all(len(v) < 3 or np.ptp(np.diff(v)) <= 1e-9 * np.abs(np.diff(v)).max() for _, v in self.axes)

    @property
    def cell(self) -> float:
        """The size of one grid cell: the product of the axes' steps (in :attr:`size_unit`; an axis of one node
        counts 1, no extent).

        Raises:
            InvalidInputError: an axis is unevenly spaced: its nodes' cells differ (:attr:`cells`).
        """
        if not self.uniform:
            raise InvalidInputError("axes", "an axis is unevenly spaced, so the nodes' cells differ: use cells "
                                            "or measure()", [n for n, _ in self.axes])
        return float(np.prod([abs(v[1] - v[0]) if len(v) > 1 else 1.0 for _, v in self.axes]))

    @property
    def cells(self) -> np.ndarray:
        """Each node's cell, shaped as the arrays: the product over the axes of the node's width, half the way to
        each neighbour (an end node's: its gap to its neighbour; an axis of one node: 1). On an evenly spaced grid
        every one is :attr:`cell`."""
        widths = []
        for _, v in self.axes:
            d = np.abs(np.diff(v))
            widths.append(np.ones(1) if len(v) == 1 else np.concatenate([d[:1], (d[:-1] + d[1:]) / 2.0, d[-1:]]))
        out = np.ones(())
        for w in reversed(widths):  # (arrays run from the last axis to the first)
            out = np.multiply.outer(out, w)
        return out

    def measure(self, mask: np.ndarray | None = None) -> float:
        """The size of the nodes of ``mask`` (default: the reachable ones), in :attr:`size_unit`: their count times
        :attr:`cell` on an evenly spaced grid, else the sum of their :attr:`cells`."""
        mask = self.reachable if mask is None else np.asarray(mask, dtype=bool)
        return int(mask.sum()) * self.cell if self.uniform else float(self.cells[mask].sum())

    @property
    def size(self) -> float:
        """The reachable region's length, area or volume (:meth:`measure`; in :attr:`size_unit`)."""
        return self.measure()

    @property
    def size_unit(self) -> str:
        """The unit of :attr:`size` and :attr:`cell`: the product of the units of the axes of more than one node
        (``"m^2"``, ``"m rad"``; ``"1"`` when no axis has two nodes)."""
        units = [("m" if kind == "length" else "rad") for (_, v), kind in zip(self.axes, self.kinds) if len(v) > 1]
        out = [f"{u}^{units.count(u)}" if units.count(u) > 1 else u for u in dict.fromkeys(units)]
        return " ".join(out) or "1"

    def reachable_over(self, axis: str, mode: str = "any") -> np.ndarray:
        """The workspace over one axis (an orientation, say): nodes of the other axes reachable at some value of
        ``axis`` (``"any"``: the maximal workspace) or at every value (``"all"``: the total-orientation workspace)."""
        names = [n for n, _ in self.axes]
        if axis not in names or mode not in ("any", "all"):
            raise InvalidInputError("axis", f"give one of {names} and mode 'any' or 'all'", (axis, mode))
        along = len(names) - 1 - names.index(axis)  # arrays run (last axis, ..., first axis)
        return np.asarray(self.reachable.any(axis=along) if mode == "any" else self.reachable.all(axis=along))

    def condition_index(self, kind: str = "2") -> np.ndarray:
        """``1/kappa`` of ``K diag(scale)`` per node (NaN where unreachable; 0 at a singularity)."""
        s = self.singular_values
        with np.errstate(divide="ignore", invalid="ignore"):
            if kind == "2":
                out = s[..., -1] / s[..., 0]
            elif kind == "fro_normalized":
                out = s.shape[-1] / np.sqrt(np.sum(s * s, axis=-1) * np.sum(1.0 / (s * s), axis=-1))
            else:
                raise InvalidInputError("kind", f"use one of {KINDS}", kind)
        return np.where(self.reachable, np.nan_to_num(out, nan=0.0, posinf=0.0), np.nan)

    def manipulability(self) -> np.ndarray:
        """Yoshikawa's ``sqrt(det(J J^T))`` of the forward Jacobian ``J = (K diag(scale))^-1`` (square maps)."""
        with np.errstate(divide="ignore"):
            return np.where(self.reachable, 1.0 / np.prod(self.singular_values, axis=-1), np.nan)

    def sigma_min(self) -> np.ndarray:
        """The smallest singular value of ``J = (K diag(scale))^-1``: ``1 / sigma_max(K diag(scale))``."""
        return np.where(self.reachable, 1.0 / self.singular_values[..., 0], np.nan)

    def _plane(self, slab: int | None) -> tuple[tuple[tuple[str, np.ndarray], ...], Any]:
        """The 2-D (or 1-D) part of the map to draw: the whole map, or one slab of a 3-D map."""
        if len(self.axes) < 3:
            return self.axes, slice(None)
        if slab is None or not 0 <= slab < len(self.axes[2][1]):
            raise InvalidInputError("slab", f"a 3-D map is drawn one slab at a time: give an index along "
                                            f"{self.axes[2][0]!r} in [0, {len(self.axes[2][1])})", slab)
        return self.axes[:2], slab

    def figure(self, path: str | Path, kind: str = "2", *, slab: int | None = None, title: str = "") -> Path:
        """Draw the condition index (``kind``) over the map as a PNG at ``path``: a colour map with its colour bar
        (2-D), a curve (1-D); unreachable nodes white (said in a legend). Axes in mm or deg; the caption (``title``
        by default) names the mechanism, the reachable nodes and the GCI."""
        from pkm._optional import require

        require("figures", "WorkspaceMap.figure")
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        axes, sl = self._plane(slab)
        ci = self.condition_index(kind)[sl]
        labels, values = [], []
        for (name, v), axis_kind in zip(axes, self.kinds):
            angle = axis_kind == "angle"
            labels.append(f"{name} [{'deg' if angle else 'mm'}]")
            values.append(np.degrees(v) if angle else 1e3 * v)
        fig, ax = plt.subplots(figsize=(6.4, 5.0))
        label = {"2": r"$1/\kappa_2$", "fro_normalized": r"$n/(\|K\|_F\|K^{-1}\|_F)$"}[kind]
        if len(axes) == 1:
            ax.plot(values[0], ci, label=label)
            ax.set_xlabel(labels[0])
            ax.set_ylabel("condition index [-]")
            self._marks(ax, values, sl, ci)
            ax.legend()
        else:
            im = ax.pcolormesh(values[0], values[1], ci, shading="nearest", vmin=0.0, vmax=1.0, cmap="viridis")
            fig.colorbar(im, ax=ax, label=f"condition index {label} [-]")
            ax.set_xlabel(labels[0])
            ax.set_ylabel(labels[1])
            ax.set_aspect("equal" if labels[0][-4:] == labels[1][-4:] else "auto")
            handles = self._marks(ax, values, sl)
            if not self.reachable[sl].all():
                from matplotlib.patches import Patch

                handles.insert(0, Patch(facecolor="white", edgecolor="0.5", label="unreachable"))
            if handles:
                ax.legend(handles=handles, fontsize=7, loc="lower right")
        extra = "" if slab is None else f", {self.axes[2][0]} = {self.axes[2][1][slab]:.4g}"
        ax.set_title(title or f"{self.mechanism or 'map'}: {self.nodes} reachable nodes, GCI "
                              f"{self.gci(kind) or 0.0:.4f}{extra}", fontsize=9)
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        fig.tight_layout()
        fig.savefig(out, dpi=150)
        plt.close(fig)
        return out

    def _marks(self, ax: Any, values: list[np.ndarray], sl: Any, ci: np.ndarray | None = None) -> list[Any]:
        """Mark the reachable nodes outside the joints' limits (white rings) and those that interfere (red crosses)
        on the figure, where the map checked them; the legend's handles (said with their counts)."""
        out = []
        grids = np.meshgrid(*values) if len(values) > 1 else [values[0]]
        outside = None if self.within_limits is None else self.reachable & ~self.within_limits
        for mask, style, what in ((outside, {"marker": "o", "facecolors": "none", "edgecolors": "white", "s": 16,
                                            "linewidths": 0.8}, "outside the joint limits"),
                                  (self.interferes, {"marker": "x", "color": "red", "s": 10, "linewidths": 0.8},
                                   "interferes")):
            if mask is None or not mask[sl].any():
                continue
            m = mask[sl]
            y = ci[m] if ci is not None else grids[1][m]
            out.append(ax.scatter(grids[0][m], y, label=f"{what} ({int(m.sum())})", zorder=3, **style))
        return out

    def write_csv(self, path: str | Path) -> Path:
        """The numbers behind the map: one row per node, the axes' coordinates (SI), ``reachable``, the condition
        indices, the manipulability and the smallest singular value (empty where unreachable); where the map
        checked them, ``within_limits``, ``clearance`` [m] and ``interferes`` (:attr:`within_limits`,
        :attr:`clearance`, :attr:`interferes`)."""
        import csv

        grids = np.meshgrid(*[v for _, v in reversed(self.axes)], indexing="ij")
        cols = {name: g.ravel() for (name, _), g in zip(reversed(self.axes), grids)}
        values = {"ci_2": self.condition_index("2"), "ci_fro_normalized": self.condition_index("fro_normalized"),
                  "manipulability": self.manipulability(), "sigma_min": self.sigma_min()}
        flags = {k: v for k, v in (("within_limits", self.within_limits), ("interferes", self.interferes))
                 if v is not None}
        if self.clearance is not None:
            values["clearance"] = self.clearance
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        names = [n for n, _ in self.axes]
        with out.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow([*names, "reachable", *values, *flags])
            reach = self.reachable.ravel()
            flat = {k: v.ravel() for k, v in values.items()}
            marks = {k: v.ravel() for k, v in flags.items()}
            for i in range(reach.size):
                w.writerow([repr(float(cols[n][i])) for n in names] + [int(reach[i])]
                           + [repr(float(flat[k][i])) if reach[i] else "" for k in values]
                           + [int(marks[k][i]) if reach[i] else "" for k in flags])
        return out

    def gci(self, kind: str = "2", region: ArrayLike | None = None) -> float | None:
        """The mean condition index over the reachable nodes of ``region`` (a boolean mask; default all): the
        global condition index as a node average. None when no node of the region is reachable."""
        ci = self.condition_index(kind)
        mask = self.reachable if region is None else self.reachable & np.asarray(region, dtype=bool)
        return float(ci[mask].mean()) if mask.any() else None


def _library(kernels: Kernels) -> tuple[Any, tuple[int, int], str]:
    return kernels.cached("map", lambda: _compile(kernels))  # type: ignore[return-value]


def _compile(kernels: Kernels) -> tuple[Any, tuple[int, int], str]:
    from pkm.core.twin.codegen import compile_library, map_source

    step, qr_step, index = (kernels.function(k) for k in ("map_newton", "map_newton_qr", "map_indices"))
    lib, how = compile_library([step, qr_step, index], directory=kernels.directory,
                               text=map_source(step, qr_step, index, PIVOT_FLOOR))
    if lib is None:
        raise CompilerError("maps need a C compiler", how)
    grid = getattr(lib, f"{step.name()}_grid")
    grid.argtypes = [ctypes.POINTER(_I), _I, _P, _P, _P, _P, ctypes.POINTER(_I), _I, _I, ctypes.c_double,
                     ctypes.c_double, ctypes.POINTER(ctypes.c_byte), _P, ctypes.POINTER(_I), _P, _P]
    grid.restype = ctypes.c_int
    return grid, index.size_out(0), how


def workspace_map(mech: Mechanism, axes: Mapping[str, object], fixed: Mapping[str, object] | None = None, *,
                  branch: str | None = None, length: float | None = None, seed: ArrayLike | None = None,
                  tol: float = 1e-10,
                  step_tol: float = 1e-8, max_iter: int = 40, kernels: Kernels | None = None,
                  configurations: bool = False, collisions: bool | None = None) -> WorkspaceMap:
    """The map of ``mech`` over the grid ``axes`` (see the module doc).

    Args:
        mech: Any mechanism pkm loads whose task has as many coordinates as it has degrees of freedom; idle motions
            (a rod spinning between two balls) are held in the Newton steps, one coordinate each (the indices, of
            the actuated rates, do not depend on them).
        axes: Task coordinate name -> values (SI) of 1 to 3 axes, the first the fastest; names among
            :attr:`TaskMap.keys` that are entries of the task value (a pose task's ``x y z``).
        fixed: The other task coordinates by name (the rest from the seed configuration).
        branch: The working mode (default: the spec's default branch); its signs are checked at every node.
        length: Characteristic length ``L`` [m] dividing the angular task rates; needed when the task mixes lengths
            and angles.
        seed: A configuration in the working mode to start from (default: the reference, or the branch's seed).
        tol: Largest residual of any equation at a solved node [m, rad].
        step_tol: Newton's convergence test on the step [m, rad].
        max_iter: Newton iterations allowed per node; a node whose step stops shrinking (by 10 % an iteration
            from the third) is given up earlier. Near an inverse singularity the root is (nearly) double and the
            step only halves: those nodes take tens of iterations.
        kernels: A :class:`pkm.Kernels` of ``mech`` to reuse; or kernels with design inputs bound to ``mech``'s design
            (``Kernels(family_mech, design=names).at(values, mech)``): one compiled library for every design.
        configurations: Keep each node's configuration (:attr:`WorkspaceMap.q`: nq numbers a node), for indices
            computed afterwards (:func:`pkm.core.analysis.capability.map_capability`).
        collisions: Where ``mech`` has collision geometry (:mod:`pkm.core.collision`), the smallest distance
            between its checked bodies at every reachable node (:attr:`WorkspaceMap.clearance`, 10 to 30 us a
            node) and whether each lies within the joints' limits (:attr:`WorkspaceMap.within_limits`): the nodes'
            configurations are solved for them (nq numbers a node, held while the map is made). None (default):
            on a grid of at most :data:`COLLISION_NODES` nodes; True: on any; False: not. A mechanism without
            geometry is mapped as before (no field, no warning).

    Raises:
        InvalidInputError: bad axes, a missing ``length``, or a grid beyond :data:`MAX_NODES`.
        CompilerError: no C compiler on the machine (the maps run only compiled: a grid of 10^6 nodes through the
            virtual machine would take an hour), or the compiled driver failed (out of memory).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> grid = {"x": np.linspace(-0.1, 0.1, 5), "y": np.linspace(-0.1, 0.1, 5)}
        >>> wmap = pkm.workspace_map(delta, grid, {"z": -0.35})
        >>> wmap.reachable.shape, int(wmap.reachable.sum())
        ((5, 5), 25)
        >>> round(float(wmap.gci()), 4)
        0.3788
    """
    from pkm.core.twin import Kernels

    mech = check_mechanism(mech)
    tol, step_tol = as_tolerance(tol, "tol"), as_tolerance(step_tol, "step_tol")
    max_iter = as_count(max_iter, "max_iter", high=1000)
    if length is not None:
        length = as_scalar(length, "length", low=0.0, strict_low=True, unit="m")
    task = TaskMap(mech)
    kernels = Kernels(mech) if kernels is None else kernels
    if not isinstance(kernels, Kernels) or kernels.mech is not mech:
        raise InvalidInputError("kernels", "give the pkm.Kernels of this mechanism (or kernels with design inputs "
                                           "bound to it: Kernels.at(values, mech))", kernels)
    if not isinstance(axes, Mapping) or not 1 <= len(axes) <= 3:
        raise InvalidInputError("axes", "give 1 to 3 task coordinates as {name: values}", axes)
    names = list(task.value_names)
    grid_axes = []
    for name, values in axes.items():
        if name not in task.keys or name not in names:
            raise InvalidInputError("axes", f"{name!r} is not a task coordinate a grid can run along: use one of "
                                            f"{[k for k in task.keys if k in names]}", name)
        v = as_array(values, "axes", f"values of {name!r} (SI)").ravel()
        if v.size == 0 or not np.all(np.isfinite(v)):
            raise InvalidInputError("axes", f"{name!r}: give finite values (SI)", values)
        if np.abs(v).max() > tol / EPS:
            raise InvalidInputError("axes", f"{name!r}: {np.abs(v).max():.6g} is beyond {tol / EPS:.6g} (SI), where "
                                            f"the spacing of floating-point numbers exceeds tol = {tol:g}: no node "
                                            "there could be solved to tol", values)
        grid_axes.append((name, v))
    dims = [len(v) for _, v in grid_axes]
    total = int(np.prod(dims))
    if total > MAX_NODES:
        raise InvalidInputError("axes", f"{total} nodes exceed {MAX_NODES}; map in parts", dims)
    q0 = mech.q_reference.copy() if seed is None else mech.check_q(seed, "seed")
    base = task.parse(dict(fixed or {}), base=q0)
    if np.abs(base).max(initial=0.0) > tol / EPS:
        raise InvalidInputError("fixed", f"a task coordinate of {np.abs(base).max():.6g} (SI) is beyond {tol / EPS:.6g}, "
                                         f"where the spacing of floating-point numbers exceeds tol = {tol:g}", fixed)
    scale = task.rate_scale(length)  # (a pose's tangent: x y z then three angles, in the order of its keys)

    targets = np.empty((total, len(base)))
    targets[:] = base
    mesh = np.meshgrid(*[v for _, v in grid_axes], indexing="ij")  # axis 0 first: flattened below, axis 0 fastest
    for (name, _), m in zip(grid_axes, mesh):
        targets[:, names.index(name)] = m.ravel(order="F")
    signs = np.zeros(0)
    if mech.spec.default_branch is not None:
        chosen = mech.branch(branch)
        default = mech.branch()
        if set(chosen.signs) != set(default.signs):
            raise InvalidInputError("branch", f"branch {chosen.name!r} fixes other joints than the default branch")
        signs = np.array([float(chosen.signs[n]) for n in default.signs])
        if branch is not None and seed is None:
            from pkm.core.kinematics.solve import branch_seed

            q0 = branch_seed(mech, chosen.name)
    y0 = task.value(q0)
    first = int(np.argmin(np.sum((targets - y0) ** 2, axis=1)))
    coarse = np.meshgrid(*[np.arange(0, n, ROOT_STRIDE) for n in dims], indexing="ij")
    strides = np.cumprod([1] + dims[:-1])
    roots = np.concatenate([[first], sum(c.ravel() * s for c, s in zip(coarse, strides))]).astype(np.int64)

    grid, (m, n), how = _library(kernels)
    design = np.ascontiguousarray(kernels.design_values, dtype=float)
    nsv = min(m, n)
    state = np.zeros(total, dtype=np.int8)
    sv = np.empty((total, nsv))
    its = np.zeros(total, dtype=np.int64)
    check = (total <= COLLISION_NODES if collisions is None else bool(collisions)) and checks_collisions(mech)
    q_out = np.full((total, mech.nq), np.nan) if configurations or check else None
    c_dims = np.array(dims, dtype=np.int64)
    arrays = [np.ascontiguousarray(a, dtype=float) for a in (targets, q0, scale, signs if signs.size else np.zeros(1))]
    flag = grid(c_dims.ctypes.data_as(ctypes.POINTER(_I)), len(dims), *[a.ctypes.data_as(_P) for a in arrays],
                roots.ctypes.data_as(ctypes.POINTER(_I)), len(roots), max_iter, step_tol, tol,
                state.ctypes.data_as(ctypes.POINTER(ctypes.c_byte)), sv.ctypes.data_as(_P),
                its.ctypes.data_as(ctypes.POINTER(_I)), None if q_out is None else q_out.ctypes.data_as(_P),
                design.ctypes.data_as(_P) if design.size else None)
    if flag:
        raise CompilerError("the compiled map driver failed", "out of memory" if flag == 2 else f"code {flag}")
    shape = tuple(reversed(dims))
    reach = state == 1
    clear = within = None
    if q_out is not None:
        within = within_limits(mech, q_out) & reach
    if check:
        assert q_out is not None
        clear = np.full(total, np.nan)
        clear[reach] = minimum_distances(mech, q_out[reach])
    return WorkspaceMap(tuple(grid_axes), base, scale, reach.reshape(shape), sv.reshape(shape + (nsv,)),
                        its.reshape(shape), how, tuple(task.kinds[name] for name, _ in grid_axes), mech.name,
                        q_out.reshape(shape + (mech.nq,)) if configurations and q_out is not None else None,
                        None if clear is None else clear.reshape(shape),
                        None if within is None else within.reshape(shape))


def within_limits(mech: Mechanism, Q: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """Whether each of ``Q`` (N x nq) lies within the joints' stated position limits to ``tol`` (m or rad): the
    mask of :meth:`pkm.core.Mechanism.outside_limits` over many configurations (NaN rows: False)."""
    Q = np.asarray(Q, dtype=float)
    out = np.all(np.isfinite(Q), axis=1)
    for name, (lo, hi) in mech.limits.items():
        if name in mech.joints:
            x = Q[:, mech.joints[name].idx_q]
            with np.errstate(invalid="ignore"):
                out &= (lo - tol <= x) & (x <= hi + tol)
    return out


#: The former name of :class:`WorkspaceMap` (deprecated since 0.2.0).
TaskGridMap = WorkspaceMap


def task_map(*args: Any, **kwargs: Any) -> WorkspaceMap:
    """Deprecated alias of :func:`workspace_map` (0.2.0: "task map" is the task coordinates, :class:`TaskMap`).

    Examples:
        >>> import warnings
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> with warnings.catch_warnings(record=True) as caught:
        ...     warnings.simplefilter("always")
        ...     wmap = pkm.task_map(delta, {"x": [-0.05, 0.0, 0.05]}, {"y": 0.0, "z": -0.35})
        ...
        >>> caught[0].category.__name__, type(wmap).__name__
        ('DeprecationWarning', 'WorkspaceMap')
    """
    warnings.warn("pkm.task_map is now pkm.workspace_map (pkm 0.2.0)", DeprecationWarning, stacklevel=2)
    return workspace_map(*args, **kwargs)


__all__ = ["COLLISION_NODES", "KINDS", "MAX_NODES", "PIVOT_FLOOR", "ROOT_STRIDE", "TaskGridMap", "WorkspaceMap", "task_map",
           "within_limits", "workspace_map"]
