"""The Delta's closed-form sweep objectives (its registry entry's ``sweeps``): the workspace grid of
:mod:`pkm.mechanisms.delta.workspace` behind ``workspace_volume``, ``conditioned_volume`` and ``weighted_volume``
(m^3), and the paper's eq. 12 Jacobians (:func:`pkm.mechanisms.delta.design.condition_vs_radius`) behind
``condition``. :func:`pkm.sweep` takes them by default (``route=auto``)."""

from __future__ import annotations

import numpy as np

from pkm.errors import UnknownNameError
from pkm.sweeps.objectives import ClosedForm
from pkm.units import parse_quantity

#: Cells across the grid's half side ``La + Lb`` by default (8 mm at the paper's design), so that every design's
#: grid is as fine relative to its size: a fixed step made a small design's volume 6 % off (15 %: 13 cells).
CELLS = 55

#: The option the workspace grid reads (beyond the objectives' own).
OPTIONS = {"spacing": ("length", None, f"Delta closed form: workspace grid step (default (La + Lb) / {CELLS})")}


def _spacing(c, o) -> float:
    return o["spacing"] if o["spacing"] is not None else (c.params.La + c.params.Lb) / CELLS


def _grid(c, o, conditioned: bool = True):
    """The design's workspace grid, with its condition numbers of ``o["kind"]`` (``conditioned``) or without (the
    reachable nodes only: no SVD a node), made once a design; a conditioned grid made already serves both."""
    from pkm.mechanisms.delta.workspace import workspace

    kind, spacing = o["kind"], _spacing(c, o)
    key = ("delta_grid", spacing, kind, o["branch"])
    if not conditioned and c.peek(key) is None:
        key, kind = ("delta_grid", spacing, None, o["branch"]), None
    return c.cached(key, lambda: workspace(c.params, spacing, o["branch"] or "knee_out", (kind,) if kind else ()))


def _K(c, o):
    g = _grid(c, o)
    return g.K[o["kind"]][g.reachable]


def workspace_volume(c, o):
    return float(_grid(c, o, conditioned=False).volume)


def conditioned_volume(c, o):
    return float(np.count_nonzero(_K(c, o) <= o["k_max"]) * _spacing(c, o) ** 3)


def weighted_volume(c, o):  # (summed in ascending K, as the serial study's sorted nodes: the same float)
    return float(np.sum(1.0 / np.sort(_K(c, o))) * _spacing(c, o) ** 3)


def condition(c, o):
    from pkm.mechanisms.delta import reference_pose
    from pkm.mechanisms.delta.design import condition_vs_radius

    p = np.array(reference_pose(c.params), dtype=float)
    for n, v in (o.get("pose") or {}).items():
        if n not in ("x", "y", "z"):
            raise UnknownNameError("task coordinate", n, ("x", "y", "z"), "delta")
        p["xyz".index(n)] = parse_quantity(v, {"length"}, n, "m")
    kind = o["kind"]
    return float(condition_vs_radius(c.params, p, [c.params.R], o["branch"] or "knee_out", (kind,))[kind][0])


#: objective name -> its closed form.
CLOSED_FORMS = {"workspace_volume": ClosedForm(workspace_volume, OPTIONS, "m^3"),
                "conditioned_volume": ClosedForm(conditioned_volume, OPTIONS, "m^3"),
                "weighted_volume": ClosedForm(weighted_volume, OPTIONS, "m^3"),
                "condition": ClosedForm(condition)}

__all__ = ["CLOSED_FORMS", "OPTIONS"]
