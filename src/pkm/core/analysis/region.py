"""The feasible region of two task coordinates: a polygon, each vertex with the limit that stops it.

Where may a parallel ankle point? Hand-written code answers with a box (``MAX_PITCH_DEG 35``, ``MAX_ROLL_DEG 20``);
the set of poses where every leg closes within its joints' limits, away from every singularity, is not a box.
:func:`feasible_region` traces it in the plane of two task coordinates (the others fixed) as the polygon of its
boundary points along ``directions`` rays from the reference pose: along each ray the inverse kinematics is
followed outward (warm-started, so one working mode), ``steps`` steps up to ``reach``, then the first step out is
bisected to ``tol``. A pose is **feasible** where

* the inverse kinematics converges (every leg closes);
* every joint lies within its limits: the model's, and ``limits`` (``{joint: (low, high)}`` [rad or m], e.g. the
  motors' travel, which URDFs often leave out);
* the distance to a direct and to an inverse singularity (:func:`pkm.diagnose`'s ``direct_distance``,
  ``inverse_distance``) is at least ``singularity``.

Each vertex carries what stops it (:attr:`Region.binding`): ``"joint <name> at its low|high limit"``,
``"direct singularity"``, ``"inverse singularity"``, ``"closure"`` (the legs no longer close: the workspace's own
edge), or ``"reach"`` (nothing stopped it within ``reach``: a :class:`~pkm.errors.PkmWarning` says how many rays
were cut so). The region is star-shaped about the reference by
construction (a ray's first exit); a region with holes or a second component beyond a first exit is not traced.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.kinematics.task import TaskMap
from pkm.core.model.joints import stated_limits
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import InvalidInputError, PkmError, PkmWarning
from pkm.validation import as_count, as_scalar

SINGULARITY = 1e-2  # default smallest relative distance to a singularity inside the region


@dataclass(frozen=True)
class Region:
    """A feasible region (module doc).

    Attributes:
        axes: The two task coordinates, in order; ``fixed``: the others.
        center: The reference pose in the plane (the rays' origin).
        vertices: The boundary points (directions x 2), counter-clockwise from the first axis.
        binding: What stops each vertex (module doc).
        angles: The rays' angles in the plane [rad, of the plane's own coordinates].
        singularity: The distance bound used.
    """

    axes: tuple[str, str]
    fixed: dict[str, float]
    center: np.ndarray
    vertices: np.ndarray
    binding: tuple[str, ...]
    angles: np.ndarray
    singularity: float

    @property
    def area(self) -> float:
        """The polygon's area (shoelace) [in the axes' units squared]."""
        x, y = self.vertices[:, 0], self.vertices[:, 1]
        return float(0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))

    def contains(self, point: ArrayLike) -> bool:
        """Whether ``point`` (in the plane) lies inside the polygon (even-odd ray casting)."""
        x, y = np.asarray(point, dtype=float)
        xs, ys = self.vertices[:, 0], self.vertices[:, 1]
        inside = False
        for i in range(len(xs)):
            x1, y1, x2, y2 = xs[i - 1], ys[i - 1], xs[i], ys[i]
            if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
                inside = not inside
        return inside

    def box(self) -> np.ndarray:
        """The half-sides of the largest box about the center, in the proportions of the polygon's extents along
        the two axes, whose corners and edge midpoints lie inside the polygon (bisection to 1e-9): what a box
        limit ("MAX_PITCH_DEG") can claim of this region."""
        d = self.vertices - self.center
        shape = np.abs(d).max(axis=0)
        signs = [np.array(s) for s in ((1, 1), (1, -1), (-1, 1), (-1, -1), (1, 0), (-1, 0), (0, 1), (0, -1))]

        def fits(t: float) -> bool:
            return all(self.contains(self.center + t * shape * s) for s in signs)

        lo, hi = 0.0, 1.0
        while hi - lo > 1e-9:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if fits(mid) else (lo, mid)
        return lo * shape

    def largest_box(self, around: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(lower, upper)``: the axis-aligned box of the largest area inside the polygon that holds ``around`` (a
        point of the plane inside it; default the center), not necessarily centred on it (:func:`largest_box`)."""
        point = self.center if around is None else np.asarray(around, dtype=float)
        if point.shape != (2,) or not np.isfinite(point).all() or not self.contains(point):
            raise InvalidInputError("around", f"expected a point of the plane ({self.axes[0]}, {self.axes[1]}) inside "
                                    "the feasible region", around)
        return largest_box(self.vertices, point)


def largest_box(vertices: np.ndarray, point: np.ndarray, *, cells: int = 64, rounds: int = 6) \
        -> tuple[np.ndarray, np.ndarray]:
    """``(lower, upper)``: the axis-aligned box of the largest area inside the polygon ``vertices`` (n x 2) that
    holds ``point`` (inside it). For a span ``[a, b]`` of the first axis about the point, every edge's part over the
    span lies wholly above the point (it bounds the box's top by its lowest y), wholly below (the bottom by its
    highest y), or crosses the point's level (no box over that span): the tallest box of each span, exactly; the
    spans are searched on a ``cells`` x ``cells`` grid, refined ``rounds`` times about the best (each round a grid
    of four cells' width), so the area found is the optimum's to the last round's cell. A box so bounded meets no
    edge and holds a point inside: it lies inside the polygon."""
    x0, y0 = (float(v) for v in point)
    p, q = vertices, np.roll(vertices, -1, axis=0)
    lo_x, hi_x = float(vertices[:, 0].min()), float(vertices[:, 0].max())

    def tallest(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The tallest box over each span ``[a, b]`` (arrays): its bottom, top and area (0 where none)."""
        a, b = a[..., None], b[..., None]
        dx = q[:, 0] - p[:, 0]
        flat = np.abs(dx) <= 1e-300
        with np.errstate(divide="ignore", invalid="ignore"):
            ta, tb = (a - p[:, 0]) / dx, (b - p[:, 0]) / dx
        t0 = np.where(flat, 0.0, np.clip(np.minimum(ta, tb), 0.0, 1.0))
        t1 = np.where(flat, 1.0, np.clip(np.maximum(ta, tb), 0.0, 1.0))
        inside = np.where(flat, (p[:, 0] >= a) & (p[:, 0] <= b), (t0 <= t1) & ~((ta < 0) & (tb < 0))
                          & ~((ta > 1) & (tb > 1)))
        ya, yb = p[:, 1] + t0 * (q[:, 1] - p[:, 1]), p[:, 1] + t1 * (q[:, 1] - p[:, 1])
        ymin, ymax = np.minimum(ya, yb), np.maximum(ya, yb)
        top = np.where(inside & (ymin > y0), ymin, np.inf).min(axis=-1)
        bottom = np.where(inside & (ymax < y0), ymax, -np.inf).max(axis=-1)
        crossed = (inside & (ymin <= y0) & (ymax >= y0)).any(axis=-1)
        area = np.where(crossed | ~np.isfinite(top - bottom), 0.0, (b[..., 0] - a[..., 0]) * (top - bottom))
        return bottom, top, area

    ranges = [(lo_x, x0), (x0, hi_x)]
    best = (x0, x0)
    for _ in range(rounds + 1):
        a, b = np.meshgrid(np.linspace(*ranges[0], cells + 1), np.linspace(*ranges[1], cells + 1), indexing="ij")
        area = tallest(a, b)[2]
        i, j = np.unravel_index(int(np.argmax(area)), area.shape)
        if area[i, j] > 0.0:
            best = (float(a[i, j]), float(b[i, j]))
        wa, wb = 2.0 * (ranges[0][1] - ranges[0][0]) / cells, 2.0 * (ranges[1][1] - ranges[1][0]) / cells
        ranges = [(max(lo_x, best[0] - wa), min(x0, best[0] + wa)), (max(x0, best[1] - wb), min(hi_x, best[1] + wb))]
    bottom, top, _ = tallest(np.array(best[0]), np.array(best[1]))
    if not np.isfinite(top - bottom):
        return np.array(point, dtype=float), np.array(point, dtype=float)
    return np.array([best[0], float(bottom)]), np.array([best[1], float(top)])


def _feasible(mech: Mechanism, target: dict[str, float], q0: np.ndarray, lo: np.ndarray, hi: np.ndarray,
              singularity: float) -> tuple[np.ndarray | None, str]:
    """The closed configuration at ``target`` (warm-started from ``q0``) if feasible, else None and why."""
    from pkm.core.differential.velocity import singularity_distances
    from pkm.core.kinematics.solve import solve_ik

    try:
        q = solve_ik(mech, target, q0).q
    except PkmError:
        return None, "closure"
    low, high = np.flatnonzero(q < lo), np.flatnonzero(q > hi)
    if low.size or high.size:
        i, side = (int(low[0]), "low") if low.size else (int(high[0]), "high")
        return None, f"joint {_joint_of(mech, i)} at its {side} limit"
    try:
        direct, inverse = singularity_distances(mech, q)
    except PkmError:
        return None, "direct singularity"
    if direct < singularity:
        return None, "direct singularity"
    if inverse < singularity:
        return None, "inverse singularity"
    return q, ""


def other_coordinates(mech: Mechanism, axes: object, fixed: Mapping[str, float] | None) -> dict[str, float]:
    """The task coordinates off ``axes`` by name: the reference's, those in ``fixed`` replaced (SI).

    Raises:
        InvalidInputError: a name in ``fixed`` that is not a task coordinate off the axes, or not a number.
    """
    if fixed is not None and not isinstance(fixed, Mapping):
        raise InvalidInputError("fixed", "expected {task coordinate: value}", fixed)
    reference = TaskMap.of(mech).named(mech.q_reference)
    rest = {k: float(x) for k, x in reference.items() if k not in axes}  # type: ignore[operator]
    for k, x in (fixed or {}).items():
        if k not in rest:
            raise InvalidInputError("fixed", f"{k!r} is not a task coordinate off the axes; those are {list(rest)}", k)
        rest[k] = as_scalar(x, f"fixed[{k}]")
    return rest


def _joint_of(mech: Mechanism, iq: int) -> str:
    model = mech.model
    for j in range(1, model.njoints):
        if model.joints[j].idx_q <= iq < model.joints[j].idx_q + model.joints[j].nq:
            return str(model.names[j])
    return f"q[{iq}]"


def march(at: Callable[[float, np.ndarray], tuple[np.ndarray | None, str]], q0: np.ndarray, reach: float,
          steps: int, tol: float) -> tuple[float, str]:
    """How far a ray stays feasible: ``at(r, q_seed)`` is the configuration at distance ``r`` (seeded with the last
    feasible one) or None and what stops it; ``steps`` equal steps out to ``reach``, then a bisection to ``tol`` on
    the first step that fails. Returns the last feasible distance and what stops the ray there (``"reach"``: nothing
    within ``reach``). Shared by :func:`feasible_region` and the transmissions' output limits."""
    r_in, q_in, why = 0.0, q0, "reach"
    r_out = None
    for step in range(1, steps + 1):
        r = reach * step / steps
        q, reason = at(r, q_in)
        if q is None:
            r_out, why = r, reason
            break
        r_in, q_in = r, q
    if r_out is not None:
        while r_out - r_in > tol:
            r = 0.5 * (r_in + r_out)
            q, reason = at(r, q_in)
            if q is None:
                r_out, why = r, reason
            else:
                r_in, q_in = r, q
    return r_in, why


def feasible_region(mech: Mechanism, axes: tuple[str, str], *, fixed: Mapping[str, float] | None = None,
                    limits: Mapping[str, tuple[float, float]] | None = None, singularity: float = SINGULARITY,
                    reach: float = 1.0, directions: int = 36, steps: int = 20, tol: float = 1e-8) -> Region:
    """The feasible region of ``mech`` in the plane of the task coordinates ``axes`` (module doc): ``reach`` [their
    unit] the largest radius searched, ``directions`` rays, ``steps`` steps out along each, the boundary bisected
    to ``tol``.

    Raises:
        InvalidInputError: axes that are not two distinct task coordinates, a limit for an unknown joint or with
            ``low >= high``, the reference pose itself not feasible (what stops it named).

    Examples:
        >>> import pkm
        >>> prs3 = pkm.load("prs3")
        >>> region = pkm.feasible_region(prs3, ("pitch", "roll"), singularity=0.05, reach=2.0, directions=8)
        >>> region.binding[:2]
        ('direct singularity', 'direct singularity')
        >>> round(region.area, 3), region.contains([0.1, -0.1])
        (1.762, True)
    """
    mech = check_mechanism(mech)
    names = list(TaskMap.of(mech).kinds)
    if not isinstance(axes, (tuple, list)) or len(axes) != 2 or axes[0] == axes[1] or any(a not in names
                                                                                        for a in axes):
        raise InvalidInputError("axes", f"expected two distinct task coordinates among {names}", axes)
    singularity = as_scalar(singularity, "singularity")
    reach = as_scalar(reach, "reach")
    n_dir, n_steps = as_count(directions, "directions"), as_count(steps, "steps")
    tol = as_scalar(tol, "tol")
    if not (reach > 0 and n_dir >= 3 and n_steps >= 1 and tol > 0):
        raise InvalidInputError("reach", "expected reach > 0, directions >= 3, steps >= 1, tol > 0",
                                (reach, n_dir, n_steps, tol))
    lo, hi = stated_limits(mech.model)  # (a placeholder 0/0 is no limit)
    if limits is not None and not isinstance(limits, Mapping):
        raise InvalidInputError("limits", "expected {joint: (low, high)}", limits)
    for joint, bounds in (limits or {}).items():
        if not isinstance(joint, str) or not mech.model.existJointName(joint):
            raise InvalidInputError("limits", f"{joint!r} is not a joint of {mech.name}", joint)
        if not isinstance(bounds, (tuple, list)) or len(bounds) != 2:
            raise InvalidInputError("limits", f"{joint}: expected (low, high)", bounds)
        low, high = (as_scalar(x, f"limits[{joint}]") for x in bounds)
        if not low < high:
            raise InvalidInputError("limits", f"{joint}: low {low} is not below high {high}", bounds)
        jm = mech.model.joints[mech.model.getJointId(joint)]
        lo[jm.idx_q:jm.idx_q + jm.nq] = low
        hi[jm.idx_q:jm.idx_q + jm.nq] = high
    rest = other_coordinates(mech, axes, fixed)
    reference = TaskMap.of(mech).named(mech.q_reference)
    center = np.array([reference[axes[0]], reference[axes[1]]], dtype=float)

    def at(point: np.ndarray, q0: np.ndarray) -> tuple[np.ndarray | None, str]:
        return _feasible(mech, dict(rest, **{axes[0]: float(point[0]), axes[1]: float(point[1])}), q0, lo, hi,
                         singularity)

    q_center, why = at(center, mech.q_reference)
    if q_center is None:
        raise InvalidInputError("mech", f"the reference pose is not feasible: {why}", why)
    angles = np.arange(n_dir) * 2.0 * np.pi / n_dir
    vertices, binding = [], []
    for a in angles:
        u = np.array([np.cos(a), np.sin(a)])
        def along(r: float, q0: np.ndarray, u: np.ndarray = u) -> tuple[np.ndarray | None, str]:
            return at(center + r * u, q0)

        r_in, why = march(along, q_center, reach, n_steps, tol)
        vertices.append(center + r_in * u)
        binding.append(why)
    cut = binding.count("reach")
    if cut:
        warnings.warn(PkmWarning(f"{cut} of {n_dir} rays found no limit within reach = {reach:g} (in the axes' "
                                 f"units): the region is cut there, not bounded; raise reach"), stacklevel=2)
    return Region((axes[0], axes[1]), rest, center, np.array(vertices), tuple(binding), angles, singularity)


__all__ = ["SINGULARITY", "Region", "feasible_region", "largest_box", "march", "other_coordinates"]
