"""A transmission's output limits: the largest box inside its feasible region, every corner checked.

The feasible region of the outputs is where the sub-mechanism closes within its joints' limits, away from every
singularity (:mod:`pkm.core.analysis.region`: the same rules, ``singularity`` the smallest relative distance):

* two outputs: :func:`pkm.feasible_region` in their plane (a polygon, each vertex naming what stops it), and its
  :meth:`~pkm.core.analysis.region.Region.box` (the largest box about the reference in the polygon's proportions);
* one output: the interval about the reference, followed out each way by ``steps`` steps up to ``reach`` and the
  first step out bisected to ``tol`` (the 1-D case of the same search), its ends the limits; ``reach`` per unit (1 rad,
  :data:`REACH_LENGTHS` characteristic lengths of the sub-mechanism) and ``tol`` relative (:data:`SEARCH_RTOL` rad or characteristic
  lengths), so that a transmission of 5 cm and one of 5 m are searched alike;
* more outputs: not traced (:class:`OutputLimits` with no limits; the export says so).

Every corner of the box (both ends of the interval) is then solved by the inverse kinematics from the reference and
checked feasible by the region's own rule; the box is first pulled in by a millionth (a corner on a joint's limit
fails by round-off), and a corner that fails shrinks it by 1 % until all pass.
"""

from __future__ import annotations

import itertools
import warnings
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from pkm.core.analysis.region import SINGULARITY, _feasible, feasible_region, march
from pkm.core.model.joints import stated_limits
from pkm.core.transmissions.transmission import Transmission
from pkm.errors import PkmWarning
from pkm.validation import as_scalar


@dataclass(frozen=True)
class OutputLimits:
    """The outputs' box limits and the region they come from (module doc).

    Attributes:
        outputs: The output joints, in order.
        lower: The box's lower corner (k,) [rad or m]; None when not traced (more than two outputs) or when no box
            passes the corner check (a warning says so).
        upper: Its upper corner (k,).
        polygon: The feasible region's boundary (n x 2) for two outputs, the interval's ends (2 x 1) for one.
        binding: What stops each boundary point (:attr:`pkm.core.analysis.region.Region.binding`'s words).
        corners_checked: How many corners were solved and found feasible.
    """

    outputs: tuple[str, ...]
    lower: np.ndarray | None
    upper: np.ndarray | None
    polygon: np.ndarray | None
    binding: tuple[str, ...]
    corners_checked: int


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


def output_limits(t: Transmission, *, singularity: float = SINGULARITY,
                  reach: float | Mapping[str, float] | None = None, directions: int = 24, steps: int = 20,
                  tol: float = SEARCH_RTOL) -> OutputLimits:
    """The box limits of ``t``'s outputs and their feasible region (module doc); ``reach`` the largest distance
    searched from the reference per output unit (``{"rad": ..., "m": ...}``, or one number where the outputs share
    their unit: :func:`~pkm.core.identification.base.per_unit`'s rule), default 1 rad or :data:`REACH_LENGTHS`
    characteristic lengths of the sub-mechanism; ``tol`` the bisection's, relative (rad, or characteristic lengths); ``directions`` rays for
    two outputs (two outputs of different units: their plane's rays take the larger reach and the smaller
    tolerance)."""
    from pkm.core.identification.base import per_unit

    sub = t.mechanism
    revolute = np.array([sub.joints[o].revolute for o in t.outputs])
    unit = np.where(revolute, 1.0, sub.characteristic_length)  # (1 rad, or one characteristic length)
    far = np.where(revolute, 1.0, REACH_LENGTHS * unit) if reach is None else per_unit(sub, reach, "reach", t.outputs)
    tol = float(as_scalar(tol, "tol", low=0.0, strict_low=True) * unit.min())
    reach = float(far.max())
    binding: tuple[str, ...]
    if t.k == 1:
        ends, binding = _interval(t, singularity, reach, steps, tol)
        polygon: np.ndarray | None = ends[:, None]
        half, mid = np.array([ends[1] - ends[0]]) / 2.0, np.array([ends[1] + ends[0]]) / 2.0  # (the interval)
    elif t.k == 2:
        region = feasible_region(sub, (t.outputs[0], t.outputs[1]), singularity=singularity, reach=reach,
                                 directions=directions, steps=steps, tol=tol)
        polygon, binding = region.vertices, region.binding
        half, mid = region.box(), region.center
    else:
        return OutputLimits(t.outputs, None, None, None, (), 0)
    lo, hi = _bounds(t)
    scale = 1.0 - 1e-6  # (a corner on a joint's limit itself fails by round-off: pulled in by a millionth)
    for _ in range(100):
        corners = [mid + scale * half * np.array(s) for s in itertools.product((-1.0, 1.0), repeat=t.k)]
        if all(_feasible(sub, dict(zip(t.outputs, map(float, c))), t.q_reference, lo, hi, singularity)[0] is not None
               for c in corners):
            return OutputLimits(t.outputs, mid - scale * half, mid + scale * half, polygon, tuple(binding),
                                len(corners))
        scale *= 0.99
    warnings.warn(PkmWarning(f"transmission {t.name!r}: no box about the reference has all its corners feasible "
                             "(shrunk to 37 %): its outputs get no limits"), stacklevel=2)
    return OutputLimits(t.outputs, None, None, polygon, tuple(binding), 0)


__all__ = ["REACH_LENGTHS", "SEARCH_RTOL", "OutputLimits", "output_limits"]
