"""pkm.core.identification.measurements: the zero-phase filter does not delay the motion, the derivatives are the
motion's, and every kind of bad table is refused naming its column or row."""

from __future__ import annotations

import numpy as np
import pytest

from pkm.core.identification.measurements import measurements
from pkm.errors import InvalidInputError
from tests.core.dynamics.test_model import mechanism


def _sine(mech, n=2000, dt=0.002, amplitude=0.05, hz=0.5):
    t = np.arange(n) * dt
    qa0 = mech.actuated_q(mech.q_reference)
    cols = {"time": t}
    for k, j in enumerate(mech.actuated_names):
        cols[f"q.{j}"] = qa0[k] + amplitude * np.sin(2 * np.pi * hz * t + k)
        cols[f"tau.{j}"] = np.cos(2 * np.pi * hz * t)
    return cols


def test_the_filter_has_no_delay_and_the_derivatives_are_the_motions():
    """A 0.5 Hz sine through the 5 Hz filter: rates within 1e-3 and accelerations within 2e-3 of the exact amplitudes (no
    phase lag: a delay of one sample would be 6e-3; the 1e-3 is the end effects of a run that stops mid-period),
    the efforts unchanged to 1e-4."""
    mech = mechanism("delta")
    cols = _sine(mech)
    data = measurements(mech, cols, cutoff=5.0)
    w, k = 2 * np.pi * 0.5, np.arange(mech.na)
    qd = 0.05 * w * np.cos(w * data.t[:, None] + k)
    qdd = -0.05 * w**2 * np.sin(w * data.t[:, None] + k)
    assert np.abs(data.QD - qd).max() <= 1e-3 * 0.05 * w
    assert np.abs(data.QDD - qdd).max() <= 2e-3 * 0.05 * w**2
    assert np.abs(data.TAU[:, 0] - np.cos(w * data.t)).max() <= 1e-4
    assert data.decimate == int(data.rate / (2 * 5.0)) and data.rate == pytest.approx(500.0)


@pytest.mark.parametrize("spoil, match", [
    (lambda c: c.pop("tau.motor_2"), "missing column tau.motor_2"),
    (lambda c: c["q.motor_1"].__setitem__(17, np.nan), "row 18, column 'q.motor_1'"),
    (lambda c: c["time"].__setitem__(40, c["time"][39]), "row 41: time"),
    (lambda c: c["time"].__setitem__(slice(100, None), c["time"][100:] + 0.001), "row 101: step"),
    (lambda c: c.__setitem__("q.motor_3", np.degrees(c["q.motor_3"]) + 200.0), "in degrees"),
])
def test_bad_tables_are_refused_naming_the_column_or_row(spoil, match):
    mech = mechanism("delta")
    cols = _sine(mech)
    spoil(cols)
    with pytest.raises(InvalidInputError, match=match):
        measurements(mech, cols)


def test_bad_files_and_too_few_rows(tmp_path):
    mech = mechanism("delta")
    bad = tmp_path / "bad.csv"
    bad.write_text("time,q.motor_1\n0.0,abc\n")
    with pytest.raises(InvalidInputError, match="'abc' is not a number"):
        measurements(mech, bad)
    with pytest.raises(InvalidInputError, match="no such file"):
        measurements(mech, tmp_path / "none.csv")
    with pytest.raises(InvalidInputError, match="rows; the filter"):
        measurements(mech, _sine(mech, n=60), cutoff=20.0)
    with pytest.raises(InvalidInputError, match="cutoff"):
        measurements(mech, _sine(mech), cutoff=400.0)
