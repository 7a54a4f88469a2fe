"""Every working mode (inverse kinematics) and the tracking of one mode along a path."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import pkm
from pkm.core.modes.assembly import VERIFY_TOL
from pkm.mechanisms.prs3 import kinematics as prs3_kinematics

pytest.importorskip("bertini")


@pytest.mark.parametrize(("name", "count"), [("prs3", 8), ("delta", 8), ("rrr3", 8), ("hexapod", 64)])
def test_every_working_mode_at_the_reference(name, count):
    """Two solutions per leg, every combination: 2^legs working modes, each closing its loops (1e-10), reaching the
    task (1e-9) and distinct; the spec's branches are among them (their joint signs)."""
    mech = pkm.load(name)
    y = pkm.TaskMap.of(mech).value(mech.q_reference)
    modes = pkm.working_modes(mech, y)
    assert modes.complete and len(modes) == count
    for m in modes:
        assert m.residual <= VERIFY_TOL and m.certificate.certified
        assert np.abs(pkm.TaskMap.of(mech).error(y, pkm.TaskMap.of(mech).value(m.q))).max() < 1e-9
    signs = {tuple(mech.branch_signs(m.q).values()) for m in modes}
    assert len(signs) == min(count, 2 ** len(mech.branch().signs))
    assert np.abs(mech.difference(modes[0].q, mech.q_reference)).max() < 1e-8  # mode 0: the reference's


def test_prs3_working_modes_are_the_closed_forms_sliders():
    """The 3-PRS's 8 working modes: each leg's two slider positions of eq. (10) (with its missing square)."""
    prs3 = pkm.load("prs3")
    y = np.array([0.9, 0.05, -0.04])
    modes = pkm.working_modes(prs3, {"z": y[0], "pitch": y[1], "roll": y[2]})
    got = sorted(tuple(np.round(prs3.actuated_q(m.q), 9)) for m in modes)
    want = sorted(tuple(np.round(prs3_kinematics.closed_form_ik(prs3.params, y, branch), 9))
                  for branch in itertools.product(("slider_below", "slider_above"), repeat=3))
    assert got == want


def test_the_gough_stewarts_working_modes_include_negative_lengths_marked_outside_the_limits_and_interference():
    mech = pkm.load("gough_stewart")
    modes = pkm.working_modes(mech, pkm.TaskMap.of(mech).value(mech.q_reference))
    inside = [m for m in modes if not m.outside_limits]
    assert len(modes) == 64 and len(inside) == 1
    assert np.allclose(mech.actuated_q(inside[0].q), mech.actuated_q(mech.q_reference), atol=1e-12)
    # each mode's clearance (legs written as capsules) is pkm.clearance's; the machine's own mode is free, legs
    # pointing down through the base cross others
    assert all(m.clearance == pytest.approx(pkm.clearance(mech, m.q).minimum, abs=1e-12) for m in modes)
    assert inside[0].label not in modes.interfering and 0 < len(modes.interfering) < 64
    assert modes.interfering == tuple(m.label for m in modes if pkm.clearance(mech, m.q).interferes)


def test_a_tracked_assembly_mode_stops_where_it_meets_another():
    """3-RRR: along an actuator path two assembly modes approach each other and vanish together (a direct
    singularity). Both tracks stop at the same sample, the bisection puts the meeting at the same point of the
    interval (1e-6) and pose (1e-3: the modes meet as a square root), with the passive Jacobian nearly singular;
    no track carries on in another mode."""
    mech = pkm.load("rrr3")
    qa0 = mech.actuated_q(mech.q_reference)
    path = qa0 + np.linspace(0.0, 1.5, 61)[:, None] * np.array([1.0, -1.0, 0.0])
    modes = pkm.assembly_modes(mech, qa0)
    tracks = [pkm.track_assembly_mode(mech, m, path) for m in modes]
    assert len(tracks) == 2 and tracks[0].reached == tracks[1].reached < len(path)
    k = tracks[0].reached
    assert np.isnan(tracks[0].q[k:]).all() and np.isfinite(tracks[0].q[:k]).all()
    a, b = (t.meeting for t in tracks)
    assert abs(a.s - b.s) < 1e-6 and max(a.sigma_min, b.sigma_min) < 1e-4
    assert np.abs(pkm.TaskMap.of(mech).value(a.q) - pkm.TaskMap.of(mech).value(b.q)).max() < 1e-3
    before = pkm.assembly_modes(mech, path[k - 1])
    assert len(before) == 2 and len(pkm.assembly_modes(mech, path[k])) == 0
    # every sample reached is on the mode it started from: the nearer of the two at that sample
    for t, m in zip(tracks, modes):
        assert np.abs(mech.difference(t.q[0], m.q)).max() < 1e-9


def test_a_tracked_working_mode_stays_and_reports_its_meeting():
    """The Delta's working mode 0 along x: it stays on its mode (knee signs unchanged) until the arm stretches
    straight (an inverse singularity), where the track stops with the Jacobian nearly singular (1e-4, the distance
    diagnose gives there, 1e-6 relative)."""
    delta = pkm.load("delta")
    y0 = pkm.TaskMap.of(delta).value(delta.q_reference)
    modes = pkm.working_modes(delta, y0)
    ys = y0 + np.linspace(0.0, 0.6, 61)[:, None] * np.array([1.0, 0.0, 0.0])
    t = pkm.track_working_mode(delta, modes[0], ys)
    assert 1 < t.reached < len(ys) and t.meeting.sigma_min < 1e-4
    # the meeting's distance is diagnose's (the Jacobian homogenised by the characteristic length: the Delta's
    # platform slides on prismatic joints; the raw ratio changed with the mechanism's size)
    assert abs(t.meeting.sigma_min - pkm.diagnose(delta, t.meeting.q).inverse_distance) <= 1e-6 * t.meeting.sigma_min
    signs = {tuple(delta.branch_signs(q).values()) for q in t.q[:t.reached]}
    assert len(signs) == 1
