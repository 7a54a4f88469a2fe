"""Robots published in their makers' own repositories, shipped with their licence and source and loaded by name
(:mod:`pkm.core.formats.catalogue`): Stanford's ToddlerBot (``toddlerbot:toddlerbot``, ``hshi74/toddlerbot``, MIT,
meshes removed: ``urdf/toddlerbot/toddlerbot/SOURCE.txt``), a 30-motor humanoid whose knees and neck pitch are rod
linkages closed by six welds (planar loops: each weld's out-of-plane rows redundant), nine gear pairs stated as
joint equalities, a waist differential stated as two limited fixed tendons, its ``<default>`` classes last. Each is
checked against MuJoCo on the same file (the bench extra), finite differences and round trips. One robot is loaded
per module (0.2 s)."""

from __future__ import annotations

import numpy as np
import pytest

import pkm
from pkm.core.differential.idle import joint_inertia
from pkm.core.formats.catalogue import catalogue_path
from pkm.core.kinematics import constraints
from pkm.errors import PkmWarning, TransmissionError
from tests.fd import constraint_jacobian_error
from tests.shipped import (
    MujocoAt,
    check_closes_from_a_moved_seed,
    check_mjcf_round_trip,
    check_round_trip,
    check_shipped,
)

KNEES = ("left_knee_act", "right_knee_act")


@pytest.fixture(scope="module")
def toddlerbot() -> pkm.Mechanism:
    return pkm.load("toddlerbot:toddlerbot")


def test_it_ships_with_its_licence_and_source_and_no_mesh():
    text = check_shipped("toddlerbot:toddlerbot", "toddlerbot.xml", "Haochen Shi", (
        "hshi74/toddlerbot", "toddlerbot/descriptions/toddlerbot/toddlerbot.xml",
        "62cee1b25468be91bf0b9f4b9c66003ce2fd8336", "MIT"))
    assert 'geom2="floor"' not in text
    folder = catalogue_path("toddlerbot:toddlerbot").parent
    assert sum(f.stat().st_size for f in folder.iterdir()) < 100_000


def test_it_loads_at_its_home_key_closed_inside_every_limit(toddlerbot):
    """Its ``home`` key is the reference (closed by moving the passive joints by 2.5e-5 rad at most: the published
    six digits), its loops closed to 1e-10 inside every limit with no dependent actuator; the nine gear equalities
    are mimic couplings (the motors on the four ``*_drive`` gears of the hips and wrists read on the driven joint),
    the waist's tendons, which no motor drives, are named as not read, and its yaw and roll are the two idle
    motions they leave."""
    q = toddlerbot.q_reference
    assert toddlerbot.na == 30 and toddlerbot.base is not None and len(toddlerbot.spec.closures) == 6
    assert constraints.worst_closure(toddlerbot, constraints.residual(toddlerbot, q))[0] <= 1e-10
    assert toddlerbot.outside_limits(q, tol=0.0) == () and toddlerbot.dependent_actuators == ()
    notes = " ".join(toddlerbot.notes)
    assert "<key name='home'>" in notes and notes.count("read as a mimic coupling") == 9
    assert "tendons no actuator drives (waist_roll_coupling, waist_yaw_coupling) not read" in notes
    assert pkm.diagnose(toddlerbot, q).idle_motions == 2


def test_it_assembles_its_loops_close_from_a_moved_seed_and_their_jacobian_is_the_differences(toddlerbot):
    """Assembly closes to 1e-12; from a seed moved by 0.02 rad the loops close again (1e-10) with the motors held
    (1e-12); the closures' Jacobian equals central differences to 1e-7 relative (measured 7e-11)."""
    assert pkm.assemble(toddlerbot).residual <= 1e-12
    check_closes_from_a_moved_seed(toddlerbot)
    assert constraint_jacobian_error(toddlerbot, toddlerbot.q_reference) <= 1e-7


def test_mujoco_puts_every_body_where_pkm_does_and_finds_its_equalities_held(toddlerbot):
    """MuJoCo on the same file at pkm's closed pose moved 0.1 rad on every motor but the neck's (the mimic joints at
    their gear ratios): every body at pkm's position (1e-12 m) and every equality row (six welds, nine gears) held
    to 1e-9 of the robot's size (m, and rad times it); every off-diagonal entry of pkm's joint-space mass matrix equal
    to MuJoCo's (``mj_fullM`` through the gear couplings) to 1e-12 of the largest (measured 2e-15; Pinocchio 4.1's
    ``crba`` left the neck yaw's coupling to its pitch rods out, 2.2e-7 kg m^2, and drifted call after call on one
    ``Data``: the diagonals differ by the armature pkm does not read on joints no motor drives). pkm's MJCF of it, read
    back, closes there with every joint in place (1e-12 m)."""
    step = np.full(toddlerbot.na, 0.1)
    step[toddlerbot.actuated_names.index("neck_pitch_act")] = 0.0  # (the neck's rods lock it: see the neck's test)
    q = pkm.close_loops(toddlerbot, toddlerbot.actuated_q(toddlerbot.q_reference) + step, toddlerbot.q_reference).q
    mj = MujocoAt(toddlerbot, "toddlerbot:toddlerbot", q)
    mj.forward()
    assert mj.body_gap() <= 1e-12
    rows = mj.equality_rows()
    assert rows.size == 6 * 6 + 9 and np.abs(rows).max() <= 1e-9 * toddlerbot.characteristic_length
    M_mj = np.zeros((mj.m.nv, mj.m.nv))
    mj.mujoco.mj_fullM(mj.m, mj.d, M_mj)
    T = np.column_stack([mj.dofs(e) for e in np.eye(toddlerbot.nv)])  # (MuJoCo's rates from Pinocchio's)
    off = ~np.eye(toddlerbot.nv, dtype=bool)
    gap = (joint_inertia(toddlerbot, q) - T.T @ M_mj @ T)[off]
    assert np.abs(gap).max() <= 1e-12 * np.abs(M_mj).max()
    check_mjcf_round_trip(toddlerbot, step)


def test_its_knees_are_transmissions_and_its_neck_is_refused_by_name(toddlerbot):
    """Each knee (its motor, two rods to the calf) is a transmission: motors +0.1 rad -> outputs -> motors back to
    1e-10, the effort map the transpose of the differences of the outputs (1e-7 relative). The neck's two rods
    over-constrain the head's pitch, and its published six digits leave them 1.3e-7 apart (the model's rank test takes
    the two loops as one, so no actuator is dependent, but moved by 0.1 rad its loops stay open by 9.5e-10 m, a
    ConvergenceError): its output is refused by a named TransmissionError (skip_unfit leaves it out with a PkmWarning), never another
    exception."""
    with pytest.raises(TransmissionError) as err:
        pkm.transmissions(toddlerbot)
    assert err.value.transmission.startswith("neck_rod") and err.value.reason == "singular"
    with pytest.warns(PkmWarning, match="neck_rod"):
        found = pkm.transmissions(toddlerbot, skip_unfit=True)
    by_motor = {t.motors: t for t in found}
    assert set(by_motor) == {(k,) for k in KNEES}
    h = 1e-6
    for motor in KNEES:
        t = by_motor[(motor,)]
        qm, q_sub = check_round_trip(t)
        J = (t.outputs_from_motors(qm + h, q_sub)[0] - t.outputs_from_motors(qm - h, q_sub)[0]) / (2 * h)
        assert np.abs(t.effort_map(q_sub) - J.T).max() <= 1e-7 * np.abs(J).max(), t.name
