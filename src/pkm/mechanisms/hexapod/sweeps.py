"""The hexapod's closed-form sweep objectives (its registry entry's ``sweeps``), at its reference pose: the exact
reachable intervals of the reconfiguration angle beta (:func:`~pkm.mechanisms.hexapod.reconfiguration.reachable_intervals`)
behind ``reachable_interval`` (rad), and the gain of the best beta (:func:`~pkm.mechanisms.hexapod.reconfiguration.optimal_beta`)
behind ``beta_gain``. :func:`pkm.sweep` takes them by default (``route=auto``)."""

from __future__ import annotations

import numpy as np

from pkm.errors import InvalidInputError
from pkm.sweeps.objectives import ClosedForm


def _pose(c, o):
    from pkm.mechanisms.hexapod import kinematics as hk

    if o.get("pose"):
        raise InvalidInputError("pose", "the hexapod's closed form scores its reference pose; use route=generic "
                                        "for another pose")
    R, P, _ = hk.reference_pose(c.params)
    return R, P


def reachable_interval(c, o):
    from pkm.errors import UnreachableError
    from pkm.mechanisms.hexapod.reconfiguration import reachable_intervals

    R, P = _pose(c, o)
    try:
        spans = reachable_intervals(c.params, R, P)
    except UnreachableError:
        return 0.0
    return float(sum(hi - lo for lo, hi in spans))


def beta_gain(c, o):
    from pkm.mechanisms.hexapod import indices as hi
    from pkm.mechanisms.hexapod.reconfiguration import optimal_beta

    R, P = _pose(c, o)
    best = optimal_beta(c.params, R, P, o["index"])
    nominal = hi.PoseIndex(c.params, [(R, P)], o["index"])([0], [c.params.home_beta])
    return float(best.value / float(np.ravel(nominal)[0]) - 1.0)


#: objective name -> its closed form.
CLOSED_FORMS = {"reachable_interval": ClosedForm(reachable_interval, unit="rad"), "beta_gain": ClosedForm(beta_gain)}

__all__ = ["CLOSED_FORMS"]
