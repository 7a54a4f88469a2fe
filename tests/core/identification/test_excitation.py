"""pkm.core.identification.excitation: the optimised trajectory conditions the base regressor better than its start,
keeps every limit on a resampling four times finer (passive joints and singularity distance included), and is
refused, naming the limit, where no motion can meet it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import pkm
from pkm.core.differential.velocity import diagnose
from pkm.core.identification.excitation import SINGULARITY, excite, fourier, write_csv
from pkm.core.identification.measurements import read_table
from pkm.errors import InvalidInputError
from tests.core.dynamics.test_model import mechanism
from tests.core.identification.conftest import excitation
from tests.fd import richardson


def test_the_series_derivatives_are_exact():
    """Rates and accelerations of the Fourier series against Richardson differences of the positions (1e-8)."""
    rng = np.random.default_rng(0)
    offset, a, b = rng.normal(size=2), rng.normal(size=(2, 3)), rng.normal(size=(2, 3))
    t0 = 0.37
    q, qd, qdd = fourier(np.array([t0]), offset, a, b, 1.3)

    def central(i):
        return lambda h: (fourier(np.array([t0 + h]), offset, a, b, 1.3)[i][0]
                          - fourier(np.array([t0 - h]), offset, a, b, 1.3)[i][0]) / (2 * h)

    d1, d2 = richardson(central(0), 1e-3), richardson(central(1), 1e-3)
    assert np.allclose(qd[0], d1, atol=1e-8) and np.allclose(qdd[0], d2, atol=1e-8)
    period = 2 * np.pi / 1.3  # (periodic)
    assert np.allclose(fourier(np.array([t0 + period]), offset, a, b, 1.3)[0], q, atol=1e-12)


def test_the_delta_excitation_is_better_conditioned_and_keeps_its_limits():
    mech = mechanism("delta")
    e = excitation("delta")
    assert e.condition < 0.2 * e.condition_start  # (measured: 2.3e5 -> 7.1e3)
    assert min(e.margins.values()) >= 0.0 and e.margins["singularity"] >= 1.0
    # a fresh resampling, off the optimisation's and the check's grids
    t = np.linspace(0.01, e.period, 97)
    qa = e(t)[0]
    q = mech.q_reference
    for k in range(0, len(t), 8):
        q = pkm.close_loops(mech, qa[k], q).q
        assert not mech.outside_limits(q)
        d = diagnose(mech, q)
        assert min(d.direct_distance, d.inverse_distance) >= 0.9 * SINGULARITY
    lo = mech.model.lowerPositionLimit[mech.act_q]
    hi = mech.model.upperPositionLimit[mech.act_q]
    assert np.all(qa >= lo) and np.all(qa <= hi)
    assert np.abs(qa - mech.actuated_q(mech.q_reference)).max() <= 0.3 + 1e-9  # (the default amplitude)
    ref = mech.actuated_q(mech.q_reference)  # the bounds used, stated: the tighter of the limits and ref +- 0.3
    assert np.allclose(e.bounds, np.column_stack([np.maximum(lo, ref - 0.3), np.minimum(hi, ref + 0.3)]), rtol=0,
                       atol=1e-15)
    assert np.all(qa >= e.bounds[:, 0] - 1e-12) and np.all(qa <= e.bounds[:, 1] + 1e-12)


def test_the_samples_table_holds_the_motion(tmp_path):
    """The CSV written reads back: its positions are the series' (1e-12), its efforts the model's."""
    mech = mechanism("delta")
    e = excitation("delta")
    path = write_csv(mech, e, tmp_path / "excitation.csv", dt=0.05)
    cols = read_table(path)
    qa, _, _ = e(cols["time"])
    assert np.abs(np.column_stack([cols[f"q.{j}"] for j in mech.actuated_names]) - qa).max() <= 1e-12
    k = len(cols["time"]) // 3
    q = pkm.close_loops(mech, qa[k], e.Q[0]).q
    tau = pkm.actuator_model(mech, q, [cols[f"qd.{j}"][k] for j in mech.actuated_names]).efforts(
        [cols[f"qdd.{j}"][k] for j in mech.actuated_names])
    assert np.allclose([cols[f"tau.{j}"][k] for j in mech.actuated_names], tau, rtol=1e-9, atol=1e-12)


def test_the_motion_file_reads_back(tmp_path):
    """Written as a pkm.motion/1 file (space "actuated", one fourier law per motor), loaded by pkm.motion: the same
    positions, rates and accelerations to 1e-12."""
    from pkm.core.identification.excitation import write_motion
    from pkm.motion import load_motions

    mech = mechanism("delta")
    e = excitation("delta")
    (motion,) = load_motions(write_motion(mech, e, tmp_path / "excitation.toml", dt=0.05)).values()
    assert motion.space == "actuated" and motion.coordinates == tuple(mech.actuated_names)
    t, Y, Yd, Ydd = motion.sample()
    for got, want in zip((Y, Yd, Ydd), e(t)):
        assert np.abs(got - want).max() <= 1e-12 * max(1.0, np.abs(want).max())


def test_an_excitation_that_cannot_meet_its_limits_is_refused_naming_the_limit():
    """Gravity alone needs 0.18 N m at each Delta motor: a 0.1 N m limit is refused before any optimisation."""
    mech = pkm.load("delta")
    weak = {a.joint: dataclasses.replace(a, effort_limit=0.1) for a in mech.actuators}
    with pytest.raises(InvalidInputError, match="effort limit") as info:
        excite(pkm.with_actuators(mech, weak), max_iter=1)
    assert "motor_1" in str(info.value) and "0.1" in str(info.value)
    with pytest.raises(InvalidInputError, match="samples"):
        excite(mech, harmonics=5, samples=8)


def test_a_finite_speed_limit_beside_an_infinite_one_is_checked():
    """The dense check skipped every speed (and effort) margin as soon as one actuator's limit was infinite, and
    reported 1.0 ("unused") though a finite limit bound the motion: each finite limit counts, an infinite one gives
    a margin of 1 (the 3-RRR at rest at its reference, one actuator turning at 0.1 rad/s against 0.2 rad/s)."""
    from pkm.core.identification.excitation import _check, _limits

    mech = pkm.load("rrr3")
    lo, hi, _, _ = _limits(mech, None)
    q = np.repeat(mech.q_reference[None], 3, axis=0)
    qa, qd = q[:, mech.act_q], np.zeros((3, mech.na))
    qd[:, 0] = 0.1
    W, theta = np.zeros((3 * mech.na, 1)), np.zeros(1)
    for speed, margin in (([0.2, np.inf, 100.0], 0.5), ([np.inf, np.inf, np.inf], 1.0)):
        out = _check(mech, (qa, qd, None, q, W, np.zeros((3, mech.na))), lo, hi, (hi - lo) / 2, np.array(speed),
                     np.full(mech.na, np.inf), theta, 1e-9)
        assert out is not None and out["speed"] == pytest.approx(margin, rel=1e-12) and out["effort"] == 1.0
