"""Following one mode a short way (:mod:`pkm.core.modes.tracking`), far from any singularity: the track reaches every
sample with no meeting, and where it ends is the same mode as the polynomial solve finds there (a second route),
one track per mode, and back again. (Tracks that stop where two modes meet: ``test_working.py``.)"""

from __future__ import annotations

import numpy as np
import pytest

import pkm
from pkm.core.kinematics import constraints

pytest.importorskip("bertini")

#: A short actuator path of the 3-RRR from its reference [rad]: 0.1 rad on motors 1 and 2, in 5 steps.
STEPS = np.linspace(0.0, 0.1, 6)[:, None] * np.array([1.0, -1.0, 0.0])


def _nearest(mech, q, modes) -> tuple[int, float]:
    gaps = [float(np.abs(mech.difference(q, m.q)).max()) for m in modes]
    return int(np.argmin(gaps)), min(gaps)


def test_assembly_modes_followed_a_short_way_end_on_distinct_modes_and_come_back(built):
    """3-RRR, both assembly modes along 0.1 rad: every sample reached (no meeting), each closing its loops (1e-9) at
    the actuators asked for; the two ends are the two modes the homotopy finds at the last sample (1e-9), one each;
    each followed back along the reversed path returns to the mode it started from (1e-9)."""
    mech = built("rrr3")
    path = mech.actuated_q(mech.q_reference) + STEPS
    start, end = pkm.assembly_modes(mech, path[0]), pkm.assembly_modes(mech, path[-1])
    assert len(start) == len(end) == 2
    ends = []
    for mode in start:
        t = pkm.track_assembly_mode(mech, mode, path)
        assert t.label == mode.label and t.reached == len(path) and t.meeting is None
        assert np.abs(mech.difference(t.q[0], mode.q)).max() <= 1e-9
        for q, qa in zip(t.q, path):
            assert np.abs(constraints.residual(mech, q)).max() <= 1e-9
            assert np.abs(mech.actuated_q(q) - qa).max() <= 1e-12
        k, gap = _nearest(mech, t.q[-1], end)
        assert gap <= 1e-9
        ends.append(k)
        back = pkm.track_assembly_mode(mech, end[k], path[::-1])
        assert back.meeting is None and np.abs(mech.difference(back.q[-1], mode.q)).max() <= 1e-9
    assert sorted(ends) == [0, 1]


def test_working_modes_followed_a_short_way_keep_their_signs_and_end_on_their_mode(built):
    """3-RRR, its 8 working modes along 1 cm of x: every sample reached on the task asked for (1e-12), the elbow signs
    constant along each track, and each end one of the 8 working modes found at the last sample (1e-9), all distinct."""
    mech = built("rrr3")
    y0 = pkm.TaskMap.of(mech).value(mech.q_reference)
    ys = y0 + np.linspace(0.0, 0.01, 5)[:, None] * np.array([1.0, 0.0, 0.0])
    start, end = pkm.working_modes(mech, ys[0]), pkm.working_modes(mech, ys[-1])
    assert len(start) == len(end) == 8
    ends = []
    for mode in start:
        t = pkm.track_working_mode(mech, mode, ys)
        assert t.reached == len(ys) and t.meeting is None
        assert all(np.abs(pkm.TaskMap.of(mech).value(q) - y).max() <= 1e-12 for q, y in zip(t.q, ys))
        assert len({tuple(mech.branch_signs(q).values()) for q in t.q}) == 1
        k, gap = _nearest(mech, t.q[-1], end)
        assert gap <= 1e-9
        ends.append(k)
    assert sorted(ends) == list(range(8))
