"""pkm.core.identification.base: the base parameters reproduce the efforts (``Y_β β = Y θ`` on fresh states, 1e-10
relative), their count does not depend on the samples drawn, and the rank decision states its gap and says when
double precision cannot decide."""

from __future__ import annotations

import numpy as np
import pytest

import pkm
from pkm.core.identification.base import CLEAR_GAP, base_parameters, decide_rank, random_states
from pkm.core.identification.regressor import regressor
from pkm.errors import InvalidInputError, StructureError
from tests.core.dynamics.test_model import mechanism

#: the counts measured at this commit (two seeds agree; the test checks that they do, not these numbers alone)
COUNTS = {"rrr3": 22, "delta": 48, "prs3": 28, "gough_stewart": 106}


@pytest.mark.parametrize("name", sorted(COUNTS))
def test_the_base_parameters_reproduce_the_efforts_and_their_count_is_the_samples_own(name):
    mech = mechanism(name)
    base = base_parameters(mech, precise=False)
    assert len(base) == len(base_parameters(mech, seed=1, precise=False)) == COUNTS[name]
    assert not base.decision.ambiguous and base.decision.gap > CLEAR_GAP
    assert base.map.shape == (len(base), len(base.parameters))
    Y = np.vstack([regressor(mech, *state) for state in random_states(mech, 4, seed=7)])
    tau = Y @ base.parameters.values
    assert np.abs(base.regressor(Y) @ base.values - tau).max() <= 1e-10 * np.abs(tau).max()
    assert np.allclose(base.map @ base.parameters.values, base.values, rtol=0.0, atol=0.0)


def test_names_read_as_combinations():
    """The 3-RRR's first leg: the distal link's mass is identified with the inertias about the joints it loads, in
    the ratio of its length squared (0.4 m: 0.16 m^2), and the name says so."""
    base = base_parameters(mechanism("rrr3"), precise=False)
    names = base.parameters.names
    m, izz = names.index("distal_1.m"), names.index("proximal_1.Izz")
    (row,) = [k for k in range(len(base)) if base.map[k, m] and base.map[k, izz]]
    assert base.map[row, m] / base.map[row, izz] == pytest.approx(0.16, rel=1e-9)
    assert "distal_1.m" in base.names[row] and "proximal_1.Izz" in base.names[row]


def test_the_rank_decision_skips_rounding_and_says_when_it_cannot_decide():
    """Pivots under 1e-10 are the double-precision regressor's rounding (never kept); a planted parameter whose
    column lies 1e-9 under the rest with rounding at 1e-14 leaves two drops of 1e5: ambiguous, and said so."""
    clear = decide_rank([1.0, 0.5, 1e-3, 3e-15, 1e-16, 4e-17, 0.0])
    assert clear.rank == 3 and clear.gap == pytest.approx(1e-3 / 3e-15) and not clear.ambiguous
    trap = decide_rank([1.0, 1e-4, 1e-9, 1e-14])
    assert trap.ambiguous and trap.gap == pytest.approx(1e5)
    assert decide_rank([1.0, 0.3]).rank == 2
    with pytest.raises(InvalidInputError):
        decide_rank([])
    with pytest.raises(InvalidInputError, match="positive integer"):
        base_parameters(mechanism("delta"), 0)
    with pytest.raises(InvalidInputError, match="as many rows as parameters"):
        base_parameters(mechanism("delta"), 5)


#: tied legs (one parameter set per kind of leg), measured at this commit
TIED = {"rrr3": 10, "delta": 18, "prs3": 16, "gough_stewart": 46}


@pytest.mark.parametrize("name", sorted(TIED))
def test_tied_legs_lower_the_count_and_still_give_the_efforts(name):
    """The shipped mechanisms' legs are built alike, so tying them loses nothing: the tied base parameters give the
    same efforts (1e-10 relative) with fewer parameters, and the count does not depend on the samples."""
    mech = mechanism(name)
    tied = base_parameters(mech, tie_legs=True, precise=False)
    assert len(tied) == len(base_parameters(mech, tie_legs=True, seed=1, precise=False)) == TIED[name] < COUNTS[name]
    assert any("_*." in n for n in tied.tied_names) and not tied.decision.ambiguous
    Y = np.vstack([regressor(mech, *state) for state in random_states(mech, 3, seed=7)])
    tau = Y @ tied.parameters.values
    assert np.abs(tied.regressor(Y) @ tied.values - tau).max() <= 1e-10 * np.abs(tau).max()
    assert np.allclose(tied.map @ tied.parameters.values, tied.values, rtol=1e-12, atol=1e-15)


def test_amounts_are_per_unit_and_one_number_is_refused_where_the_units_mix():
    """``per_unit``: a mapping gives each actuator its unit's value; one number serves where every actuator has the
    same unit, and is refused where revolute and prismatic actuators mix (it would mean rad and m alike)."""
    from types import SimpleNamespace

    from pkm.core.identification.base import per_unit

    joints = {"crank": SimpleNamespace(revolute=True), "slider": SimpleNamespace(revolute=False)}
    mixed = SimpleNamespace(joints=joints, actuated_names=("crank", "slider"), na=2)
    assert per_unit(mixed, {"rad": 0.3, "m": 0.03}, "spread").tolist() == [0.3, 0.03]
    with pytest.raises(InvalidInputError, match="revolute and prismatic joints alike"):
        per_unit(mixed, 0.1, "spread")
    with pytest.raises(InvalidInputError, match="no value for the m joints"):
        per_unit(mixed, {"rad": 0.3}, "spread")
    alone = SimpleNamespace(joints=joints, actuated_names=("slider",), na=1)
    assert per_unit(alone, 0.2, "spread").tolist() == [0.2]
    with pytest.raises(InvalidInputError, match="spread"):
        per_unit(alone, -0.2, "spread")


def test_random_states_of_a_redundantly_actuated_mechanism_are_refused_saying_why(all_actuated, redundant):
    """Every joint actuated, or one elbow too: readings drawn one by one never agree with the actuators the others fix
    ("only 0 of 42 random states closed", after 1.5 s of failed closures, before); refused at once naming the
    dependent actuators and the independent ones to load instead: pkm.excite, pkm.base_parameters and the
    calibration's candidate poses draw through the same closed_draws."""
    for mech, dependent in ((all_actuated, r"\['elbow_1', 'elbow_2'\]"), (redundant, r"\['elbow_1'\]")):
        for call, args in ((pkm.excite, (mech,)), (random_states, (mech, 3))):
            with pytest.raises(StructureError, match=dependent + r" depend on the others \(redundant actuation\).*"
                               r"\['motor_1', 'motor_2'\] actuated"):
                call(*args)
