"""The rank decision shared by the base parameters' two routes: where the relative pivots of a pivoted QR drop.

:func:`decide_rank` keeps the pivots above the largest drop among those under :data:`SMALL`, the last kept above the
arithmetic's rounding floor (:data:`FLOOR` in double precision; :mod:`~pkm.core.identification.precise` passes its
own); a largest drop under :data:`CLEAR_GAP` makes the decision ``ambiguous``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pkm.errors import InvalidInputError

CLEAR_GAP = 1e6  # a rank decision whose gap is smaller than this is reported as ambiguous
SMALL = 1e-6  # the rank is decided among relative |R_kk| under this
FLOOR = 1e-10  # relative |R_kk| under this are the double-precision regressor's rounding: never kept

@dataclass(frozen=True)
class RankDecision:
    """Where the relative pivots ``|R_kk| / |R_00|`` of the scaled regressor drop: ``rank`` of them are kept.

    Attributes:
        rank: The number of identifiable combinations.
        pivots: The relative pivots, descending.
        gap: ``pivots[rank - 1] / pivots[rank]`` (inf when every pivot is kept or the next is exactly zero).
        ambiguous: The gap is under :data:`CLEAR_GAP`.
    """

    rank: int
    pivots: np.ndarray
    gap: float
    ambiguous: bool


def decide_rank(pivots: ArrayLike, floor: float = FLOOR) -> RankDecision:
    """The rank from relative pivots (descending, the first 1): at the largest drop among those under ``SMALL``,
    the last pivot kept above ``floor`` (the arithmetic's rounding: :data:`FLOOR` in double precision)."""
    d = np.abs(np.asarray(pivots, dtype=float))
    if d.ndim != 1 or d.size == 0 or not np.all(np.isfinite(d)):
        raise InvalidInputError("pivots", "expected a non-empty vector of finite pivots", pivots)
    d = d / d[0] if d[0] > 0.0 else d
    small = np.flatnonzero(d < SMALL)
    if small.size == 0:
        return RankDecision(int(d.size), d, np.inf, False)
    ks = small[(small > 0) & (d[np.maximum(small - 1, 0)] > floor)]
    if ks.size == 0:
        return RankDecision(0, d, np.inf, False)
    ratios = np.array([d[k - 1] / d[k] if d[k] > 0.0 else np.inf for k in ks])
    r = int(ks[int(np.argmax(ratios))])
    gap = float(ratios.max())
    return RankDecision(r, d, gap, gap < CLEAR_GAP)



__all__ = ["CLEAR_GAP", "FLOOR", "SMALL", "RankDecision", "decide_rank"]
