"""Polynomial homotopy continuation by Bertini 2 (``pip install bertini2``): every isolated complex solution of a
square polynomial system, with the account of every path.

:func:`solve` hands a list of :class:`~pkm.core.modes.polynomial.Poly` to Bertini's ``ZeroDimSolver`` (total-degree
start system, or the multihomogeneous one for several variable groups; adaptive precision, power-series endgame)
and returns a :class:`Continuation`: one :class:`Path` per start point, classified from Bertini's own metadata as

* ``finite``: the endgame succeeded at a finite point (``singular`` says whether its Jacobian is);
* ``infinite``: the path went to infinity (``GoingToInfinity`` / ``SecurityMaxNormReached``): a solution at
  infinity of the start's compactification, not a solution;
* ``failed``: anything else (step failures, cycle detection failed, ...): a path that says nothing, so a set with
  one such path is not known to be complete; so is a path that ended at another's nonsingular end (a path
  crossing: one of the two jumped, ``PathCrossing``).

Why Bertini 2: it is the Bertini team's maintained library, with adaptive multiprecision path tracking (paths near
singular ends or ill-conditioned stretches switch to higher precision instead of jumping to another path) and
the endgames that make singular ends detectable. It is GPL-3; pkm (BSD-3) imports it only here, on first use, as
the optional extra ``pkm-robotics[homotopy]``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from fractions import Fraction
from types import ModuleType
from typing import Any

import numpy as np

from pkm.core.modes.polynomial import Poly
from pkm.errors import MissingDependencyError

#: Steps a path may take in :func:`track`'s double-precision pass (``"auto"``) before it is given up to adaptive
#: precision (Bertini's own bound: 100,000). The 3-PRS's paths near its singular ends took up to 8 s of CPU in double
#: precision, where adaptive precision tracks all 16 in 2 s; at 2,000 steps its double pass takes 1.2-1.7 s and
#: hands 2-3 paths on (at 500: 4 paths, and the hexapod's double pass hands on 10 of 40, not 3).
DOUBLE_MAX_STEPS = 2000

#: Bertini's success codes of paths that went to infinity.
_INFINITE = {"GoingToInfinity", "SecurityMaxNormReached"}


@dataclass(frozen=True)
class Path:
    """One tracked path and where it ended.

    Attributes:
        index: The path's number (Bertini's).
        status: ``"finite"``, ``"infinite"`` or ``"failed"`` (module doc).
        code: Bertini's endgame success code.
        point: The end point (complex, the system's variables; for a projective group, normalised so that its
            largest coordinate is 1), None unless finite.
        singular: Bertini's verdict on the end point's Jacobian.
        condition: The Jacobian's condition number at the end point.
        residual: ``|F|`` at the end point.
        cycle: The endgame's winding number (> 1 at a singular end).
    """

    index: int
    status: str
    code: str
    point: np.ndarray | None
    singular: bool
    condition: float
    residual: float
    cycle: int


@dataclass(frozen=True)
class Continuation:
    """The outcome of one homotopy: every path, the bound they start from, and the settings.

    Attributes:
        paths: One :class:`Path` per start point.
        bound: The number of start points: the total-degree Bezout number (product of the degrees) for one
            group, the multihomogeneous Bezout number for several.
        start: ``"total-degree homotopy"``, ``"multihomogeneous homotopy"`` or ``"parameter homotopy"``.
        seconds: Wall time of the solve [s].
        settings: Bertini's settings used (precision mode, endgame, threads).
    """

    paths: tuple[Path, ...]
    bound: int
    start: str
    seconds: float
    settings: dict = field(default_factory=dict)

    def count(self, status: str) -> int:
        return sum(p.status == status for p in self.paths)

    @property
    def failed(self) -> tuple[Path, ...]:
        return tuple(p for p in self.paths if p.status == "failed")

    @property
    def complete(self) -> bool:
        """Every start path ended at a finite point or at infinity: the finite ends hold every isolated solution
        (with probability one, Bertini's gamma trick). One failed path and this is False."""
        return len(self.paths) == self.bound and not self.failed

    def without(self, indices: Sequence[int]) -> Continuation:
        """The same run with the paths ``indices`` marked failed (``code="dropped"``): what a lost path looks like,
        for tests of the bookkeeping downstream."""
        drop = set(indices)
        paths = tuple(Path(p.index, "failed", "dropped", None, False, math.nan, math.nan, 0) if p.index in drop else p
                      for p in self.paths)
        return Continuation(paths, self.bound, self.start, self.seconds, self.settings)


def _bertini() -> ModuleType:
    try:
        import bertini
    except ImportError as exc:  # pragma: no cover - the dev install has it
        raise MissingDependencyError("bertini2", "homotopy", "every assembly mode (polynomial homotopy "
                                     "continuation)") from exc
    bertini.recording(False)  # (by default it writes ./bertini_output and reuses old results)
    return bertini


def _coefficient(b: ModuleType, c: complex) -> Any:  # (bertini is untyped: its expressions are Any)
    """An exact Bertini coefficient from a double (its binary value, as a fraction: no digits invented)."""
    re, im = Fraction(float(c.real)), Fraction(float(c.imag))
    out = b.coefficient(re) if re else None
    if im:
        out = (b.I * b.coefficient(im)) if out is None else out + b.I * b.coefficient(im)
    return b.coefficient(0) if out is None else out


def _expression(b: ModuleType, p: Poly, xs: Sequence[Any]) -> Any:
    out = None
    for e, c in p.terms.items():
        term = _coefficient(b, c)
        for i, k in enumerate(e):
            if k:
                term = term * (xs[i] ** k if k > 1 else xs[i])
        out = term if out is None else out + term
    return _coefficient(b, 0.0) if out is None else out


def bezout(polys: Sequence[Poly], groups: Sequence[Sequence[int]]) -> int:
    """The Bezout number of the start system Bertini builds: total degree for one group; for several, the
    multihomogeneous count (the coefficient of ``prod z_g^{dim_g}`` in ``prod_f sum_g deg_g(f) z_g``)."""
    if len(groups) == 1:
        return math.prod(p.degree for p in polys)
    dims = [len(g) for g in groups]
    degs = [[max((sum(e[i] for i in g) for e in p.terms), default=0) for g in groups] for p in polys]
    # expand the product group by group: states are remaining-dimension tuples
    states = {tuple(dims): 1}
    for row in degs:
        nxt: dict[tuple[int, ...], int] = {}
        for rem, c in states.items():
            for g, d in enumerate(row):
                if d and rem[g]:
                    r = list(rem)
                    r[g] -= 1
                    nxt[tuple(r)] = nxt.get(tuple(r), 0) + c * d
        states = nxt
    return states.get((0,) * len(groups), 0)


def solve(polys: Sequence[Poly], groups: Sequence[Sequence[int]] | None = None, *, projective: bool = False,
          precision: str = "adaptive", endgame: str = "powerseries", threads: int = 1) -> Continuation:
    """Every isolated solution of the square system ``polys`` by homotopy continuation (module doc).

    Args:
        polys: As many polynomials as unknowns (or, with ``projective``, one fewer: homogeneous ones).
        groups: Variable indices per group (default: one group of every variable). Several groups take
            Bertini's multihomogeneous start system, which tracks fewer paths when the groups fit the equations.
        projective: The single group is homogeneous coordinates of a projective space (each polynomial
            homogeneous); Bertini works on a random affine patch of it.
        precision: Bertini's ``mptype``: ``"adaptive"`` (default: the safe one), ``"double"``, ``"multiple"``;
            ``"auto"`` (:func:`track`'s default) is ``"adaptive"`` here: a start system's paths going to infinity
            are the rule, not a sign of a jump, so double precision first would re-track most of them.
        endgame: ``"powerseries"`` or ``"cauchy"``.
        threads: Bertini's worker threads.
    """
    b = _bertini()
    n = polys[0].n
    groups = [list(range(n))] if groups is None else [list(g) for g in groups]
    if projective and len(groups) != 1:
        raise ValueError("a projective system takes one variable group")
    if projective and not all(p.homogeneous() for p in polys):
        raise ValueError("a projective system's polynomials must be homogeneous")
    xs = b.variables([f"x{i}" for i in range(n)])
    system = b.System()
    for g in groups:
        group = b.VariableGroup([xs[i] for i in g])
        (system.add_hom_variable_group if projective else system.add_variable_group)(group)
    for p in polys:
        system.add_function(_expression(b, p, xs))
    start = "total-degree homotopy" if len(groups) == 1 else "multihomogeneous homotopy"
    bound = bezout(polys, groups)
    t0 = time.perf_counter()
    precision = "adaptive" if precision == "auto" else precision
    zd = b.ZeroDimSolver(system, startsystem="infer", endgame=endgame, mptype=precision)
    zd.set(num_threads=threads)
    zd.solve(show_progress=False)
    settings = {"mptype": precision, "endgame": endgame, "threads": threads, "projective": projective}
    return Continuation(_crossings(_paths(zd, projective)), bound, start, time.perf_counter() - t0, settings)


def track(homotopy: Sequence[Poly], target: Sequence[Poly], start_points: Sequence[np.ndarray], *,
          projective: bool = False, precision: str = "auto", endgame: str = "powerseries",
          threads: int = 1, start: str = "parameter homotopy") -> Continuation:
    """Track the given start points along a homotopy to the target system (a parameter homotopy).

    Args:
        homotopy: Polynomials in the target's ``n`` variables and a last one, the path variable ``t``: at
            ``t = 1`` they vanish at ``start_points``, at ``t = 0`` they are ``target``.
        target: The target system (``n`` variables).
        start_points: The start system's solutions (complex, ``n`` coordinates).
        projective: The variables are homogeneous coordinates (one group).
        precision: Bertini's ``mptype`` for every path (``"adaptive"``, ``"double"``, ``"multiple"``), or
            ``"auto"`` (default): every path in double precision (at most :data:`DOUBLE_MAX_STEPS` steps), then
            in adaptive precision each path that did not end at a nonsingular finite point of its own (failed,
            at infinity, singular, or at another path's end), until no double-precision end is shared
            (:func:`_retrack`). A path tracked in double
            precision can jump to another path; where the jump is seen (two paths at one end, a path lost to
            infinity or to a singular end), both are tracked again adaptively; a jump unseen is a permutation of
            nonsingular ends, which loses no solution. ``settings["retracked"]`` lists the paths tracked again.
    """
    b = _bertini()
    n = target[0].n
    xs = b.variables([f"x{i}" for i in range(n)])
    t = b.variables(["t"])[0]
    H, T = b.System(), b.System()
    for s in (H, T):
        (s.add_hom_variable_group if projective else s.add_variable_group)(b.VariableGroup(list(xs)))
    H.add_path_variable(t)
    for p in homotopy:
        H.add_function(_expression(b, p, [*xs, t]))
    for p in target:
        T.add_function(_expression(b, p, xs))
    points = [np.asarray(x, dtype=complex) for x in start_points]
    if projective:
        H.auto_patch()
        T.copy_patches(H)
        points = [np.asarray(H.rescale_point_to_fit_patch(x), dtype=complex) for x in points]
    t0 = time.perf_counter()
    settings = {"mptype": precision, "endgame": endgame, "threads": threads, "projective": projective}

    def run(indices: Sequence[int], mptype: str) -> list[Path]:
        solver = b.HomotopySolver(H, [points[i] for i in indices], T, mptype=mptype, endgame=endgame)
        solver.set(num_threads=threads)
        if mptype == "double":  # (a path that needs more steps is one for adaptive precision)
            solver.configure(stepping={"max_num_steps": DOUBLE_MAX_STEPS})
        solver.solve(show_progress=False)
        return [replace(p, index=indices[p.index]) for p in _paths(solver, projective)]

    everyone = list(range(len(points)))
    if precision != "auto":
        paths = run(everyone, precision)
    else:
        paths, retracked = _retrack(run(everyone, "double"), lambda idx: run(idx, "adaptive"))
        settings["retracked"] = retracked
    return Continuation(_crossings(paths), len(points), start, time.perf_counter() - t0, settings)


def _retrack(paths: list[Path], adaptive: Callable[[list[int]], list[Path]]) -> tuple[list[Path], list[int]]:
    """Double-precision ``paths`` made safe (:func:`track`'s ``"auto"``): each that did not end at a nonsingular
    finite point, or whose end another path shares, is tracked again by ``adaptive`` (its indices -> their
    paths), round after round, until no double-precision path shares its end (each round takes at least one more
    path). Returns the paths (in index order) and the re-tracked indices."""
    by_index = {p.index: p for p in paths}
    again: set[int] = set()
    todo = {p.index for p in paths if p.status != "finite" or p.singular} | _shared_ends(paths)
    while todo:
        for p in adaptive(sorted(todo)):
            by_index[p.index] = p
        again |= todo
        todo = _shared_ends(list(by_index.values())) - again
    return [by_index[i] for i in sorted(by_index)], sorted(again)


def _same_end(x: np.ndarray, y: np.ndarray, tol: float = 1e-8) -> bool:
    return bool(np.abs(x - y).max() <= tol * max(1.0, float(np.abs(x).max())))


def _shared_ends(paths: list[Path]) -> set[int]:
    """The paths that ended at a nonsingular finite point another path ended at too (:func:`_same_end`)."""
    ends = [(p.index, p.point) for p in paths if p.point is not None and not p.singular]
    return {i for k, (a, x) in enumerate(ends) for b, y in ends[k + 1:] if _same_end(x, y) for i in (a, b)}


def _paths(solver: Any, projective: bool) -> list[Path]:
    """A finished Bertini solver's paths, classified from its metadata (module doc), numbered from 0."""
    paths = []
    for k, (pt, md) in enumerate(zip(solver.all_solutions(), solver.solution_metadata())):
        code = str(md.endgame_success_code).rsplit(".", 1)[-1]
        if code == "Success" and md.is_finite:
            x = np.array([complex(float(v[0]), float(v[1])) if isinstance(v, tuple) else complex(v) for v in pt])
            if projective:
                x = x / x[np.argmax(np.abs(x))]
            paths.append(Path(k, "finite", code, x, bool(md.is_singular), float(md.condition_number),
                              float(md.function_residual), int(md.cycle_num)))
        else:
            status = "infinite" if code in _INFINITE or (code == "Success" and not md.is_finite) else "failed"
            paths.append(Path(k, status, code, None, False, math.nan, math.nan, int(md.cycle_num)))
    return paths


def _crossings(paths: list[Path]) -> tuple[Path, ...]:
    """Paths that ended at the nonsingular end of another: one of them jumped (a path crossing) and a solution
    may be lost, so every such later path is marked failed (``PathCrossing``). Several paths may end at one
    *singular* point (its multiplicity); a nonsingular point ends exactly one."""
    out: list[Path] = []
    seen: list[np.ndarray] = []
    for p in paths:
        if p.point is not None and not p.singular:
            x = p.point
            if any(_same_end(x, y) for y in seen):
                out.append(Path(p.index, "failed", "PathCrossing", None, False, p.condition, p.residual, p.cycle))
                continue
            seen.append(x)
        out.append(p)
    return tuple(out)
