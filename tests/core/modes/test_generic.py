"""Every assembly and working mode where the task point sits on a leg (no platform): the generic route of
pkm.core.modes.generic, checked against the core (closures, FK back to the same actuators) and the known counts."""

from __future__ import annotations

import numpy as np
import pytest

import pkm
from pkm.core.kinematics.labels import mode_label
from pkm.core.modes.assembly import VERIFY_TOL
from pkm.errors import StructureError

pytest.importorskip("bertini")


def test_a_fivebar_has_its_two_assembly_modes_and_four_working_modes(built):
    """The toy five-bar (its task point the tip of a distal link: no platform for the reduction): 2 assembly modes at
    the reference actuators (two circles meet twice), 4 working modes at the reference task (2 elbows per leg), each
    closing its loops, keeping the actuators or reaching the task, and closed again by the core from its own q."""
    mech = built("fivebar")
    qa = mech.actuated_q(mech.q_reference)
    fk = pkm.assembly_modes(mech, qa)
    assert fk.complete and len(fk) == 2 and "no platform" in fk.reduction
    assert {mode_label(mech, m.q).assembly for m in fk} == {(1,), (-1,)}  # the two sides of the tip
    y = pkm.TaskMap.of(mech).value(mech.q_reference)
    ik = pkm.working_modes(mech, y)
    assert ik.complete and len(ik) == 4
    assert {mode_label(mech, m.q).working for m in ik} == {(1, 1), (1, -1), (-1, 1), (-1, -1)}  # 2 elbows per leg
    for modes in (fk, ik):
        for m in modes:
            assert m.residual <= VERIFY_TOL and m.certificate.certified
            back = pkm.close_loops(mech, mech.actuated_q(m.q), m.q)  # FK back to the same actuators: the same q
            assert np.abs(mech.difference(back.q, m.q)).max() < 1e-9
    for m in fk:
        assert np.abs(mech.actuated_q(m.q) - qa).max() < 1e-12
    for m in ik:
        assert np.abs(pkm.TaskMap.of(mech).error(y, pkm.TaskMap.of(mech).value(m.q))).max() < 1e-9
    assert np.abs(mech.difference(fk[0].q, mech.q_reference)).max() < 1e-8  # mode 0: the reference's
    assert np.abs(mech.difference(ik[0].q, mech.q_reference)).max() < 1e-8


def test_the_generic_route_refuses_with_the_class_and_the_alternative(built):
    """A spatial joint is outside both routes: the StructureError names the joint class, the reduction's reason and
    what to use instead."""
    gs = pkm.load("gough_stewart")
    with pytest.raises(StructureError, match=r"FreeFlyer joint.*revolute and prismatic joints only.*pkm\.close_loops"):
        pkm.assembly_modes(gs, gs.actuated_q(gs.q_reference), method="generic")


def test_with_every_joint_actuated_there_is_no_mode_to_find(all_actuated):
    """No unknown joint (every one actuated): a StructureError saying so (it was an IndexError on the empty system)."""
    with pytest.raises(StructureError, match=r"no unknown joint: the given values fix every joint"):
        pkm.assembly_modes(all_actuated, all_actuated.actuated_q(all_actuated.q_reference))
