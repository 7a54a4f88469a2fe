"""Scale-free singularity measures (issue 41): every mechanism pkm ships (and the tests' five-bar), every one of the
acceptance set and every Gepetto robot that loads, scaled in size by 0.1 and by 10 (:func:`scaled_mechanism`: every
length of its URDF and spec), keeps at its reference configuration its assembly, its classification, its "near"
flags, its rank and mobility, and its dimensionless distances to a direct and an inverse singularity (1e-9
relative); its characteristic length and its homogenised smallest singular values scale with it (1e-9 relative).

Before the Jacobians were homogenised by the characteristic length, Gepetto's ``robot_delta`` (6-D loops: rotation
rows in rad beside translation rows in m) was "near" both singularities at every configuration (0.00022 and 0.0002)
and 10 times larger it was not: its distances moved with its size."""

from __future__ import annotations

import math

import numpy as np
import pytest

import pkm
from pkm.core.kinematics import constraints
from pkm.core.model.builder import scaled_mechanism
from pkm.core.model.scale import scale_configuration
from tests.test_acceptance import ACCEPTANCE
from tests.test_acceptance import load as acceptance
from tests.test_gepetto_robots import ROBOTS, gepetto

CASES = ([("shipped", n) for n in sorted({*pkm.MECHANISMS, "fivebar"})] + [("acceptance", n) for n in ACCEPTANCE]
         + [("gepetto", n) for n in ROBOTS])
FACTORS = (0.1, 10.0)
REL = 1e-9


def original(kind: str, name: str) -> pkm.Mechanism:
    return pkm.load(name) if kind == "shipped" else acceptance(name) if kind == "acceptance" else gepetto(name)


@pytest.mark.parametrize(("kind", "name"), CASES, ids=[f"{k}:{n}" for k, n in CASES])
def test_a_mechanism_scaled_in_size_keeps_its_classification_and_distances(kind, name):
    mech = original(kind, name)
    q = mech.q_reference
    d = pkm.diagnose(mech, q)
    for s in FACTORS:
        big = scaled_mechanism(mech, s)
        qs = scale_configuration(mech, q, s)
        L = big.characteristic_length
        assert math.isclose(L, s * mech.characteristic_length, rel_tol=REL), (s, L)
        # its assembly: the scaled copy's own reference is the scaled reference, and closed
        assert np.abs(big.difference(big.q_reference, qs)).max() <= REL * max(1.0, L), s
        assert constraints.worst_closure(big, constraints.residual(big, qs))[0] <= 1e-10 * s
        e = pkm.diagnose(big, qs)
        assert (e.classification, e.near, e.constraint_rank, e.mobility, e.idle_motions, e.dependent_actuators) \
            == (d.classification, d.near, d.constraint_rank, d.mobility, d.idle_motions, d.dependent_actuators), s
        for mine, theirs in ((d.direct_distance, e.direct_distance), (d.inverse_distance, e.inverse_distance)):
            if mine > 1e-7:  # (at a singularity both are round-off)
                assert math.isclose(theirs, mine, rel_tol=REL), (s, mine, theirs)
        for mine, theirs in ((d.sigma_direct, e.sigma_direct), (d.sigma_inverse, e.sigma_inverse)):
            if mine > 1e-7 * mech.characteristic_length and np.isfinite(mine):
                assert math.isclose(theirs, s * mine, rel_tol=REL), (s, mine, theirs)


#: Mechanisms whose solves are compared at three sizes, and a move of their actuators out of reach (None: none tried).
SOLVED = (("gepetto", "robot_delta", None), ("shipped", "prs3", (1.0, -1.0, 0.0)))


@pytest.mark.parametrize(("kind", "name", "away"), SOLVED, ids=[f"{k}:{n}" for k, n, _ in SOLVED])
def test_a_mechanism_scaled_in_size_solves_in_the_same_iterations(kind, name, away):
    """close_loops and solve_ik on the copies scaled by 0.1 and 10 (issue 52: their tolerance, Newton step cap and
    continuation steps in the characteristic length): the same verdicts, iterations and continuation steps, the same
    configurations scaled (1e-9), each relative residual within the tolerance; a target out of reach fails alike,
    its relative residual the same (1e-9 relative: the 3-PRS's sliders moved apart by 2 L; its iterations within 2,
    the stall test's 1 % deciding the last on round-off). (Before, in m and rad: the 3-PRS's sliders moved by 0.2 L took 2
    continuation steps at its size and 20 ten times larger, its platform raised by 0.05 L 3 Newton iterations and 30;
    robot_delta's motors turned by 0.2 rad 13, 14 and 15 iterations at 0.1, 1 and 10.)"""
    mech = original(kind, name)
    q0, L = mech.q_reference, mech.characteristic_length
    rev = np.array([j.revolute for j in mech.actuated], dtype=bool)
    near = mech.actuated_q(q0) + np.where(rev, 0.17, 0.17 * L)  # (several continuation steps)
    far = None if away is None else mech.actuated_q(q0) + np.where(rev, 1.0, L) * np.array(away)
    solves = {}
    for s in (1.0, *FACTORS):
        m = mech if s == 1.0 else scaled_mechanism(mech, s)
        units = np.where(rev, 1.0, s)
        fk = pkm.close_loops(m, units * near)
        target = pkm.TaskMap.of(m).value(pkm.close_loops(m, units * near, max_step=0.01).q)
        ik = pkm.solve_ik(m, target)
        out = fk if far is None else pkm.close_loops(m, units * far, raise_on_failure=False)
        solves[s] = (m, fk, ik, out)
    m1, fk1, ik1, out1 = solves[1.0]
    assert fk1.converged and ik1.converged and out1.converged == (far is None)
    for s in FACTORS:
        m, fk, ik, out = solves[s]
        for mine, theirs in ((fk1, fk), (ik1, ik)):
            assert (theirs.converged, theirs.iterations, theirs.steps) == (mine.converged, mine.iterations, mine.steps), s
        for mine, theirs in ((fk1, fk), (ik1, ik)):
            assert max(mine.relative_residual, theirs.relative_residual) <= 1e-12
            assert np.abs(m.difference(scale_configuration(m1, mine.q, s), theirs.q)).max() <= REL * max(1.0, s), s
        if far is not None:  # (its last iterations stall: a count one apart from round-off, not from the size)
            assert not out.converged and abs(out.iterations - out1.iterations) <= 2, (s, out1, out)
            assert math.isclose(out.relative_residual, out1.relative_residual, rel_tol=REL), (s, out1, out)
