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
