"""pkm.core.identification.regressor: ``Y_a θ_true`` equals the efforts (``pkm.inverse_dynamics`` plus the drives'
friction) to 1e-10 relative at random closed states, on every shipped mechanism and the acceptance set; Pinocchio's
regressor and the linearity route agree where both run."""

from __future__ import annotations

import numpy as np
import pytest

import pkm
from pkm.core.identification.regressor import (
    BODY_FIELDS,
    _linear_columns,
    parameters,
    regressor,
    regressor_batch,
    tree_regressor,
)
from pkm.errors import InvalidInputError
from tests.core.dynamics.test_model import mechanism
from tests.test_acceptance import ACCEPTANCE

NAMES = ("delta", "prs3", "rrr3", "hexapod", "gough_stewart", *(f"acceptance/{n}" for n in ACCEPTANCE), "geared")
RTOL = 1e-10


def _mech(name: str) -> pkm.Mechanism:
    if name == "geared":
        return pkm.with_actuators(mechanism("delta"), {"motor_1": {"rotor_inertia": 1e-3, "gear_ratio": 10.0,
                                                                   "viscous": 0.2, "coulomb": 0.3}})
    return mechanism(name)


def _states(mech: pkm.Mechanism, n: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        qa = mech.actuated_q(mech.q_reference) + 0.02 * rng.standard_normal(mech.na)
        yield pkm.close_loops(mech, qa, mech.q_reference).q, rng.standard_normal(mech.na), rng.standard_normal(mech.na)


@pytest.mark.parametrize("name", NAMES)
def test_the_regressor_times_the_parameters_is_the_efforts(name):
    mech = _mech(name)
    P = parameters(mech)
    assert len(P) == P.n_body + 4 * mech.na and len(P.names) == len(set(P.names)) == len(P.units)
    for q, qd, qdd in _states(mech, 2):
        model = pkm.actuator_model(mech, q, qd)
        a = model.joint_accelerations(qdd)
        tau = pkm.inverse_dynamics(mech, q, model.v, a) - model.friction
        Y = regressor(mech, q, qd, qdd)
        assert Y.shape == (mech.na, len(P))
        assert np.abs(Y @ P.values - tau).max() <= RTOL * np.abs(tau).max()


@pytest.mark.parametrize("name", ["delta", "acceptance/ankle", "acceptance/rssr"])
def test_pinocchios_regressor_and_the_linearity_route_agree(name):
    """The route taken for mimic joints (the hexapod) against Pinocchio's regressor, where both run (1e-12 of the
    largest entry: rounding only, the route has no step)."""
    mech = _mech(name)
    for q, qd, qdd in _states(mech, 1, seed=3):
        model = pkm.actuator_model(mech, q, qd)
        a = model.joint_accelerations(qdd)
        Y = tree_regressor(mech, q, model.v, a)
        assert np.abs(Y - _linear_columns(mech, q, model.v, a)).max() <= 1e-12 * np.abs(Y).max()


def test_the_parameters_are_named_by_body_and_drive():
    P = parameters(mechanism("delta"))
    assert P.names[:10] == tuple(f"{P.bodies[0]}.{f}" for f in BODY_FIELDS)
    assert P.names[-4:] == ("motor_3.armature", "motor_3.viscous", "motor_3.coulomb", "motor_3.offset")
    assert P.units[0] == "kg" and P.units[4] == "kg m^2"


def test_a_batch_stacks_the_samples_and_bad_input_is_refused():
    mech = mechanism("delta")
    states = list(_states(mech, 2))
    Q, QD, QDD = (np.array([s[i] for s in states]) for i in range(3))
    W = regressor_batch(mech, Q, QD, QDD, backend="python")
    assert np.array_equal(W[3:], regressor(mech, *states[1]))
    with pytest.raises(InvalidInputError, match="as many samples"):
        regressor_batch(mech, Q, QD[:1], QDD)
    with pytest.raises(InvalidInputError):
        regressor(mech, Q[0], [0.0, np.nan, 0.0], QDD[0])


def test_springs_and_passive_damping_are_known_efforts_the_estimate_takes_out(tmp_path):
    """On the sprung four-bar (springs on its three hinges, damping on the passive coupler): the efforts the
    actuator supplies (``M_a q̈_a + h_a - f_a``) are ``Y_a θ_true`` plus :func:`known_efforts` (1e-10 relative), and
    pkm.estimate fits them to rounding (1e-9 N m); the known efforts are a good share of the efforts."""
    from pkm.core.identification.regressor import known_efforts
    from tests.core.dynamics.test_springs import FOURBAR, SPRUNG

    text = FOURBAR.read_text()
    for old, new in SPRUNG.items():
        text = text.replace(old, new)
    (tmp_path / "fourbar.xml").write_text(text)
    mech = pkm.load(tmp_path / "fourbar.xml")
    states = list(_states(mech, 36))
    Q, QD, QDD = (np.array([s[i] for s in states]) for i in range(3))
    TAU = np.array([(lambda m: m.efforts(qdd) - m.friction)(pkm.actuator_model(mech, q, qd))
                    for q, qd, qdd in states])
    known = known_efforts(mech, Q, QD)
    theta = parameters(mech).values
    for k in range(len(Q)):
        assert np.linalg.norm(regressor(mech, Q[k], QD[k], QDD[k]) @ theta + known[k] - TAU[k]) <= \
            RTOL * np.linalg.norm(TAU[k])
    assert np.abs(known).min() > 0.1 * np.abs(TAU).max()  # (the springs carry a good share of the efforts)
    est = pkm.estimate(mech, Q, QD, QDD, TAU, base=pkm.base_parameters(mech, 40, precise=False))
    assert est.residual_rms.max() <= 1e-9
