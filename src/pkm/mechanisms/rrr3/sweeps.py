"""The 3-RRR's closed-form sweep objectives (its registry entry's ``sweeps``): the vectorised condition-index maps
of :mod:`pkm.mechanisms.rrr3.workspace` (the paper's route) behind ``gci``, ``gci_area``, ``coverage``,
``min_area_ci`` and ``workspace_volume`` (an area, m^2). :func:`pkm.sweep` takes them by default (``route=auto``)."""

from __future__ import annotations

import numpy as np

from pkm.sweeps.objectives import ClosedForm

#: The options the maps read (beyond the objectives' own).
OPTIONS = {"step": ("length", None, "3-RRR closed form: grid step (default the library's: 1/100 of the grid's half "
                                   "side a + b + H/sqrt3, as fine relative to every design)"),
           "side": ("length", 0.30, "3-RRR closed form: side of the square area of interest")}


def _map(c, o):
    from pkm.mechanisms.rrr3 import workspace as ws

    d = ws.Design.of(c.params)
    branch = o.get("branch") or c.params.branch  # the option's working mode, else the design's
    return c.cached(("rrr3_map", o["step"], o["kind"], branch), lambda: ws.ci_map(
        d, ws.workspace_grid(d, o["step"]), ws.CiSettings(branch=branch, kind=o["kind"])))


def _centroid(c):
    from pkm.mechanisms.rrr3 import workspace as ws

    return ws.Design.of(c.params).base_centroid


def gci(c, o):
    g = _map(c, o).gci()
    return None if g.empty else g.value


def gci_area(c, o):
    g = _map(c, o).area_gci(o["side"])
    return None if g.empty else g.value


def coverage(c, o):
    g = _map(c, o).area_gci(o["side"])
    return g.reachable / g.nodes


def min_area_ci(c, o):
    m = _map(c, o)
    region = m.grid.square_mask(o["side"], _centroid(c)) & m.reachable
    return float(np.min(m.ci[region])) if region.any() else None


def workspace_volume(c, o):
    m = _map(c, o)
    return float(np.count_nonzero(m.reachable) * m.grid.step**2)


#: objective name -> its closed form.
CLOSED_FORMS = {"gci": ClosedForm(gci, OPTIONS), "gci_area": ClosedForm(gci_area, OPTIONS),
                "coverage": ClosedForm(coverage, OPTIONS), "min_area_ci": ClosedForm(min_area_ci, OPTIONS),
                "workspace_volume": ClosedForm(workspace_volume, OPTIONS, "m^2")}

__all__ = ["CLOSED_FORMS", "OPTIONS"]
