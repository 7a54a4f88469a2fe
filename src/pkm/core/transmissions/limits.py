"""A transmission's output limits: the largest axis-aligned box of its feasible region that holds the reference (or
a point the user gives), its boundary checked by inverse kinematics.

The feasible region of the outputs is where the sub-mechanism closes within its joints' limits, away from every
singularity (:mod:`pkm.core.analysis.region`: the same rules, ``singularity`` the smallest relative distance):

* two outputs: :func:`pkm.feasible_region` in their plane (a polygon, each vertex naming what stops it), and its
  :meth:`~pkm.core.analysis.region.Region.largest_box` about the point ``around`` (default the reference): the box
  of the largest area inside the polygon that holds the point, not centred on it (a reference near one edge of the
  region gets a box that reaches away from that edge; the point may lie on the box's edge);
* one output: the interval about the reference, followed out each way by ``steps`` steps up to ``reach`` and the
  first step out bisected to ``tol`` (the 1-D case of the same search), its ends the limits; ``reach`` per unit (1 rad,
  :data:`REACH_LENGTHS` characteristic lengths of the sub-mechanism) and ``tol`` relative (:data:`SEARCH_RTOL` rad or characteristic
  lengths), so that a transmission of 5 cm and one of 5 m are searched alike;
* more outputs: not traced (:class:`OutputLimits` with no limits; the export says so).

The box's boundary (its corners and :data:`EDGE_POINTS` points inside each edge; both ends of the interval, through
the point between them) is then solved by the inverse kinematics, walking round it from the reference's
configuration (each point warm-started from the last: one working mode), and checked feasible by the region's own
rule; the box is first pulled towards the point by a millionth (a corner on a joint's limit fails by round-off),
and a point that fails shrinks it towards the point by 1 % until all pass. Where the point itself is not feasible
(a reference within ``singularity`` of a singularity: Gepetto's ``talos_like``), no box holds it: a warning says so
and the box shrinks towards its own middle instead. :attr:`OutputLimits.area_fraction` states the box's area
against the region's; a :class:`~pkm.errors.PkmWarning` says so where it is under :data:`SMALL_BOX`.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.analysis.region import SINGULARITY, _feasible, feasible_region, march
from pkm.core.model.joints import stated_limits
from pkm.core.transmissions.transmission import Transmission
from pkm.errors import InvalidInputError, PkmWarning
from pkm.validation import as_scalar, as_vector

#: Points checked inside each edge of a two-output box, besides its corners.
EDGE_POINTS = 4
#: A box whose area is under this fraction of its feasible region's is said to be small (a warning).
SMALL_BOX = 0.25


@dataclass(frozen=True)
class OutputLimits:
    """The outputs' box limits and the region they come from (module doc).

    Attributes:
        outputs: The output joints, in order.
        lower: The box's lower corner (k,) [rad or m]; None when not traced (more than two outputs) or when no box
            passes the check (a warning says so).
        upper: Its upper corner (k,).
        polygon: The feasible region's boundary (n x 2) for two outputs, the interval's ends (2 x 1) for one.
        binding: What stops each boundary point (:attr:`pkm.core.analysis.region.Region.binding`'s words).
        points_checked: How many points of the box's boundary were solved and found feasible.
        around: The point (k,) the box holds [rad or m]: the reference's outputs unless given.
        area_fraction: The box's area over the region's (its length over the interval's for one output); None
            when not traced.
    """

    outputs: tuple[str, ...]
    lower: np.ndarray | None
    upper: np.ndarray | None
    polygon: np.ndarray | None
    binding: tuple[str, ...]
    points_checked: int
    around: np.ndarray | None = None
    area_fraction: float | None = None


def _bounds(t: Transmission) -> tuple[np.ndarray, np.ndarray]:
    return stated_limits(t.mechanism.model)


def _interval(t: Transmission, singularity: float, reach: float, steps: int, tol: float) \
        -> tuple[np.ndarray, tuple[str, str]]:
    sub, name = t.mechanism, t.outputs[0]
    lo, hi = _bounds(t)
    center = float(t.q_reference[t.out_q[0]])
    ends, why = [], []
    for sign in (-1.0, 1.0):
        def along(r: float, q0: np.ndarray, sign: float = sign) -> tuple[np.ndarray | None, str]:
            return _feasible(sub, {name: center + sign * r}, q0, lo, hi, singularity)

        r_in, stop = march(along, t.q_reference, reach, steps, tol)
        ends.append(center + sign * r_in)
        why.append(stop)
    return np.array(ends), (why[0], why[1])


#: The search's bisection tolerance, relative: in rad, or in characteristic lengths of the sub-mechanism.
SEARCH_RTOL = 1e-8
#: A prismatic output's default reach, in characteristic lengths of the sub-mechanism (a revolute one's: 1 rad); the
#: SDF slider-crank's rail travels 1.07 of them from its reference to its inverse singularity.
REACH_LENGTHS = 8.0


def _boundary(lower: np.ndarray, upper: np.ndarray, point: np.ndarray) -> list[np.ndarray]:
    """The points of the box's boundary checked, in the order they are solved: an interval's lower end, ``point``
    (back inside: the working mode of the reference), its upper end; a rectangle's corners and :data:`EDGE_POINTS`
    points inside each edge, round it."""
    if lower.size == 1:
        return [lower.copy(), point.copy(), upper.copy()]
    corners = [np.array([lower[0], lower[1]]), np.array([upper[0], lower[1]]), np.array([upper[0], upper[1]]),
               np.array([lower[0], upper[1]])]
    points = []
    for a, b in zip(corners, corners[1:] + corners[:1]):
        points += [a + s * (b - a) for s in np.arange(EDGE_POINTS + 1) / (EDGE_POINTS + 1)]
    return points


def _walk(t: Transmission, points: list[np.ndarray], lo: np.ndarray, hi: np.ndarray, singularity: float) -> bool:
    """Whether every point of ``points`` is feasible, each solved from the last one's configuration (the first from
    the reference's)."""
    q = t.q_reference
    for p in points:
        found = _feasible(t.mechanism, dict(zip(t.outputs, map(float, p))), q, lo, hi, singularity)[0]
        if found is None:
            return False
        q = found
    return True


def _stated_box(t: Transmission, point: np.ndarray, around: ArrayLike | None) -> OutputLimits:
    """A differential's (:attr:`Transmission.constant`) limits: its output joints' stated limits, the whole region
    (every point between them closes: no loop; no IK to check); none where a limit is not stated."""
    lo, hi = (b[t.out_q] for b in _bounds(t))
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()):
        return OutputLimits(t.outputs, None, None, None, (), 0, point, None)
    if not ((lo <= point) & (point <= hi)).all():
        raise InvalidInputError("around", f"transmission {t.name!r}: {dict(zip(t.outputs, point.tolist()))} lies "
                                f"outside its outputs' limits {list(zip(lo.tolist(), hi.tolist()))}", around)
    corners = np.array([lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]]) if t.k == 2 else np.array([lo, hi])
    binding = tuple(f"joint {o} at its {side} limit" for o in t.outputs for side in ("low", "high"))
    return OutputLimits(t.outputs, lo.copy(), hi.copy(), corners if t.k <= 2 else None, binding, 0, point, 1.0)


def output_limits(t: Transmission, *, around: ArrayLike | None = None, singularity: float = SINGULARITY,
                  reach: float | Mapping[str, float] | None = None, directions: int = 24, steps: int = 20,
                  tol: float = SEARCH_RTOL) -> OutputLimits:
    """The box limits of ``t``'s outputs and their feasible region (module doc); ``around`` (k,) [rad or m] the point
    the box holds (default the reference's outputs; inside the traced region); ``reach`` the largest distance
    searched from the reference per output unit (``{"rad": ..., "m": ...}``, or one number where the outputs share
    their unit: :func:`~pkm.core.identification.base.per_unit`'s rule), default 1 rad or :data:`REACH_LENGTHS`
    characteristic lengths of the sub-mechanism; ``tol`` the bisection's, relative (rad, or characteristic
    lengths); ``directions`` rays for two outputs (two outputs of different units: their plane's rays take the
    larger reach and the smaller tolerance).

    Raises:
        InvalidInputError: ``around`` of the wrong size or outside the traced region.
    """
    from pkm.core.identification.base import per_unit

    sub = t.mechanism
    revolute = np.array([sub.joints[o].revolute for o in t.outputs])
    unit = np.where(revolute, 1.0, sub.characteristic_length)  # (1 rad, or one characteristic length)
    far = np.where(revolute, 1.0, REACH_LENGTHS * unit) if reach is None else per_unit(sub, reach, "reach", t.outputs)
    tol = float(as_scalar(tol, "tol", low=0.0, strict_low=True) * unit.min())
    reach = float(far.max())
    binding: tuple[str, ...]
    reference = t.q_reference[t.out_q]
    point = reference.copy() if around is None else as_vector(around, t.k, "around")
    if t.constant:
        return _stated_box(t, point, around)
    if t.k == 1:
        ends, binding = _interval(t, singularity, reach, steps, tol)
        polygon: np.ndarray | None = ends[:, None]
        if not ends[0] <= point[0] <= ends[1]:
            raise InvalidInputError("around", f"transmission {t.name!r}: {t.outputs[0]} = {point[0]:.6g} lies outside "
                                    f"its feasible interval [{ends[0]:.6g}, {ends[1]:.6g}]", around)
        lower, upper, fraction = ends[:1], ends[1:], 1.0
    elif t.k == 2:
        region = feasible_region(sub, (t.outputs[0], t.outputs[1]), singularity=singularity, reach=reach,
                                 directions=directions, steps=steps, tol=tol)
        polygon, binding = region.vertices, region.binding
        lower, upper = region.largest_box(point)
        fraction = float(np.prod(upper - lower)) / region.area if region.area > 0.0 else 0.0
    else:
        return OutputLimits(t.outputs, None, None, None, (), 0)
    lo, hi = _bounds(t)
    anchor = point
    why = _feasible(sub, dict(zip(t.outputs, map(float, point))), t.q_reference, lo, hi, singularity)[1]
    if why:  # (Gepetto's talos_like: its reference 0.2 % from a direct singularity, under the bound)
        anchor = (lower + upper) / 2.0
        warnings.warn(PkmWarning(f"transmission {t.name!r}: {dict(zip(t.outputs, np.round(point, 6).tolist()))} is "
                                 f"not feasible ({why}): no box holds it; the box is shrunk towards its middle "
                                 "instead and leaves it out"), stacklevel=2)
    scale = 1.0 - 1e-6  # (a corner on a joint's limit itself fails by round-off: pulled in by a millionth)
    for _ in range(100):
        box = anchor + scale * (lower - anchor), anchor + scale * (upper - anchor)
        points = _boundary(*box, anchor)
        if _walk(t, points, lo, hi, singularity):
            found = scale ** t.k * fraction
            if found < SMALL_BOX:
                warnings.warn(PkmWarning(f"transmission {t.name!r}: its box limits hold {100 * found:.3g} % of the "
                                         f"{'area' if t.k > 1 else 'length'} of its feasible region (the region is far from a box about "
                                         f"{dict(zip(t.outputs, np.round(point, 6).tolist()))}): the serial model "
                                         "leaves the rest out (OutputLimits.polygon: the whole region)"), stacklevel=2)
            return OutputLimits(t.outputs, box[0], box[1], polygon, tuple(binding), len(points), point, found)
        scale *= 0.99
    warnings.warn(PkmWarning(f"transmission {t.name!r}: no box about {dict(zip(t.outputs, point.tolist()))} has its "
                             "boundary feasible (shrunk to 37 %): its outputs get no limits"), stacklevel=2)
    return OutputLimits(t.outputs, None, None, polygon, tuple(binding), 0, point, None)


__all__ = ["EDGE_POINTS", "REACH_LENGTHS", "SEARCH_RTOL", "SMALL_BOX", "OutputLimits", "output_limits"]
