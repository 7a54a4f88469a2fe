"""pkm.core.identification.estimate: exact efforts give back the base parameters; efforts with noise (1 % of each
actuator's range) give estimates within their stated standard deviations; bad data is refused by row; too few
equations, and poorly identified parameters (not told from zero, their deviation a share of the efforts), are warned
of (PoorIdentificationWarning); a parameter zero by symmetry, determined, is not."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

from pkm.core.identification.base import base_parameters, random_states
from pkm.core.identification.estimate import POOR_EFFORT_SHARE, POOR_RELATIVE_STD, estimate
from pkm.core.identification.regressor import regressor
from pkm.errors import InvalidInputError, PoorIdentificationWarning, SingularityError
from tests.core.dynamics.test_model import mechanism


def _data(name: str, n: int):
    mech = mechanism(name)
    base = base_parameters(mech, precise=False)
    states = random_states(mech, n, seed=11)
    Q, QD, QDD = (np.array([s[i] for s in states]) for i in range(3))
    TAU = np.array([regressor(mech, *s) @ base.parameters.values for s in states])
    return mech, base, Q, QD, QDD, TAU


@pytest.mark.parametrize("name", ["delta", "prs3"])
def test_noisy_efforts_give_estimates_within_their_standard_deviations(name):
    """Weighted least squares on 300 random states: the errors over the stated deviations behave as a standard
    normal sample (at least 95 % within 3, none beyond 4); without noise the estimate is exact (1e-8 relative) and
    warns of nothing (issue 52: the parameters zero by symmetry, their relative deviations 0/0, were 'poor')."""
    mech, base, Q, QD, QDD, TAU = _data(name, 300)
    with warnings.catch_warnings():
        warnings.simplefilter("error", PoorIdentificationWarning)
        exact = estimate(mech, Q, QD, QDD, TAU, base=base, weighted=False)
    assert np.abs(exact.values - base.values).max() <= 1e-8 * np.abs(base.values).max()
    assert exact.warnings == () and np.max(exact.relative_std) > POOR_RELATIVE_STD
    rng = np.random.default_rng(5)
    noisy = TAU + 0.01 * np.ptp(TAU, axis=0) * rng.standard_normal(TAU.shape)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        est = estimate(mech, Q, QD, QDD, noisy, base=base)
    # 900 equations or more: no warning of too few; one naming exactly the poorly identified parameters (above
    # 100 % and a deviation worth more than 1 % of the efforts), its sentence kept in est.warnings; parameters zero
    # by symmetry whose deviation is worth little of the efforts are above 100 % but not poor
    poor = [n for n, r, e in zip(base.names, est.relative_std, est.effort_share)
            if r > POOR_RELATIVE_STD and e > POOR_EFFORT_SHARE]
    found = [w.message for w in caught if isinstance(w.message, PoorIdentificationWarning)]
    assert poor and len(found) == 1 and [n for n, _ in found[0].poor] == poor == list(np.array(base.names)[est.poor])
    assert est.warnings == (str(found[0]),) and f"{len(poor)} of {len(base)} base parameters" in est.warnings[0]
    assert np.sum(est.relative_std > POOR_RELATIVE_STD) > len(poor)
    # the share, by another route: the weighted efforts predicted with one parameter moved by its deviation
    Y = np.vstack([regressor(mech, *s) for s in zip(Q, QD, QDD)])
    w = np.tile(est.weights, len(Q))
    for i in (int(np.argmax(est.effort_share)), int(np.argmin(est.effort_share))):
        moved = dataclasses.replace(est, values=est.values + est.std[i] * np.eye(len(base))[i])
        change = np.linalg.norm((moved.predict(Y) - est.predict(Y)) * w) / np.linalg.norm(noisy.reshape(-1) * w)
        assert change == pytest.approx(est.effort_share[i], rel=1e-9)
    z = (est.values - base.values) / est.std
    assert est.method == "wls" and np.mean(np.abs(z) <= 3.0) >= 0.95 and np.abs(z).max() <= 4.0
    assert np.allclose(est.residual_rms, 0.01 * np.ptp(TAU, axis=0), rtol=0.15)  # (the noise, found again)
    Y = regressor(mech, Q[0], QD[0], QDD[0])
    assert np.abs(est.predict(Y) - TAU[0]).max() <= 5.0 * est.residual_rms.max()


def test_bad_data_is_refused_by_row_and_too_little_motion_says_so():
    mech, base, Q, QD, QDD, TAU = _data("delta", 20)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        est = estimate(mech, Q, QD, QDD, TAU, base=base)
    w = caught[0].message
    assert isinstance(w, PoorIdentificationWarning) and w.equations == est.rows == 60 and w.n_base == 48
    assert "20 samples (60 equations) for 48 base parameters" in est.warnings[0] and "--tie-legs" in est.warnings[0]
    bad = TAU.copy()
    bad[7, 1] = np.nan
    with pytest.raises(InvalidInputError, match="row 7 is not finite"):
        estimate(mech, Q, QD, QDD, bad, base=base)
    with pytest.raises(InvalidInputError, match="N x 3"):
        estimate(mech, Q, QD, QDD, TAU[:, :2], base=base)
    with pytest.raises(InvalidInputError, match="give more samples"):
        estimate(mech, Q[:5], QD[:5], QDD[:5], TAU[:5], base=base)
    still = np.repeat(Q[:1], 20, axis=0), np.zeros((20, 3)), np.zeros((20, 3))
    with pytest.raises(SingularityError, match="do not excite"):
        estimate(mech, *still, np.zeros((20, 3)), base=base)
    # (the fuzz's repro, issue 47: efforts all zero gave every relative deviation 0/0, inf; refused)
    with pytest.raises(InvalidInputError, match="every effort is zero"):
        estimate(mech, Q, QD, QDD, np.zeros_like(TAU), base=base)


def test_efforts_near_the_ends_of_the_float_range_scale_exactly_or_are_refused():
    """Issue 47's repro (the 3-RRR, 82 states, efforts of order 1e300): their squares overflowed, giving infinite
    deviations and residuals (ordinary least squares) and a NaN 'singularity' (weighted); validating such an
    estimate gave infinite errors and NaN ratios. The fit and the validation now run on the efforts divided by a
    power of two: every result is the one of the same efforts at order 1, scaled (linearity, to 1e-9), at 1e300
    and at 1e-300; efforts whose estimate itself overflows are refused, named."""
    from pkm.core.identification.export import validate
    from pkm.core.identification.measurements import Measurements

    mech, base, Q, QD, QDD, TAU = _data("rrr3", 82)
    tau = np.random.default_rng(3).standard_normal(TAU.shape)  # (not a fit: residuals and deviations not zero)
    t, refs = np.arange(82.0), {}
    for weighted in (False, True):
        ref = estimate(mech, Q, QD, QDD, tau, base=base, weighted=weighted)
        for k in (1e300, 1e-300):
            est = estimate(mech, Q, QD, QDD, tau * k, base=base, weighted=weighted)
            for got, want in ((est.values, ref.values * k), (est.std, ref.std * k),
                              (est.residual_rms, ref.residual_rms * k),
                              (est.weights, ref.weights / (k if weighted else 1)),
                              (est.relative_std, ref.relative_std)):
                assert np.all(np.isfinite(got)) and np.allclose(got, want, rtol=1e-9, atol=0), (weighted, k)
        val, val_ref = (validate(mech, e, Measurements(t, Q, QD, QDD, tau * k, 1.0, 1.0, 1))
                        for e, k in ((est, 1e-300), (ref, 1.0)))
        assert np.allclose(val.rms, val_ref.rms * 1e-300, rtol=1e-9, atol=0)
        assert np.allclose(val.relative, val_ref.relative, rtol=1e-9, atol=0)
        refs[weighted] = val_ref
    val = validate(mech, estimate(mech, Q, QD, QDD, tau * 1e300, base=base, weighted=False),
                   Measurements(t, Q, QD, QDD, tau * 1e300, 1.0, 1.0, 1))
    assert np.all(np.isfinite(val.relative)) and np.allclose(val.relative, refs[False].relative, rtol=1e-9, atol=0)
    with pytest.raises(InvalidInputError, match=r"efforts up to 1\.7e\+308 \[N m, N\] overflow the estimate"):
        estimate(mech, Q, QD, QDD, 1.7e308 * np.sign(tau), base=base, weighted=False)


def test_a_spring_is_identified_with_the_base_parameters():
    """A spring on the Delta's passive knee (3.5 N m/rad about -2 rad) in simulated efforts (the forward model's,
    pkm.actuator_model, springs applied there): estimate(springs=["knee_1"]) gives back its stiffness and rest
    (1e-6 relative) and the base parameters, whether the model states the spring or not (it is a parameter, not a
    known effort); a spring on a motor is not excited apart from its drive's offset, and says so."""
    import pkm

    plain = mechanism("delta")
    sprung = pkm.from_strings(plain.urdf, dataclasses.replace(
        plain.spec, springs={"knee_1": {"stiffness": 3.5, "rest": -2.0}}), plain.params, "sprung delta")
    base = base_parameters(plain, precise=False)
    states = random_states(sprung, 40, seed=11)
    Q, QD, QDD = (np.array([s[i] for s in states]) for i in range(3))
    TAU = np.array([pkm.actuator_model(sprung, q, qd).efforts(qdd) for q, qd, qdd in states])
    for model in (sprung, plain):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PoorIdentificationWarning)  # (40 samples: fewer than 3 rows a parameter)
            est = estimate(model, Q, QD, QDD, TAU, base=base, weighted=False, springs=["knee_1"])
        (s,) = est.springs
        assert s.joint == "knee_1" and abs(s.stiffness - 3.5) <= 1e-6 * 3.5 and abs(s.rest + 2.0) <= 1e-6 * 2.0
        assert s.stiffness_std < 1e-6 * 3.5 and s.rest_std < 1e-6 * 2.0
        assert np.abs(est.values - base.values).max() <= 1e-8 * np.abs(base.values).max()
    with pytest.raises(SingularityError, match=r"rest of a spring on an actuated joint, \['motor_1'\], is its drive"):
        estimate(sprung, Q, QD, QDD, TAU, base=base, springs=["motor_1"])
    with pytest.raises(InvalidInputError, match="expected a list of joint names"):
        estimate(sprung, Q, QD, QDD, TAU, base=base, springs="knee_1")
