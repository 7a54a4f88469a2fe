"""The measurement models: the implicit-function Jacobian against finite differences (the loops closed anew at each
perturbed parameter vector), and the model's prediction against Pinocchio on the mechanism written with the same
parameters (an independent route: the URDF re-read, the loops closed by the generic core)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.calibration.measurement import CalibrationModel
from pkm.core.calibration.parameters import calibration_parameters
from tests.core.calibration.conftest import mechanism, model
from tests.fd import rel, richardson


@pytest.mark.parametrize(("name", "kind"), [("prs3", "pose"), ("delta", "position"), ("delta", "planar"),
                                            ("gepetto:5bar_linkage", "passive")])
def test_jacobian_matches_finite_differences(name: str, kind: str) -> None:
    m = model(name, kind)
    mech = m.mech
    rng = np.random.default_rng(0)
    readings = mech.actuated_q(mech.q_reference) + rng.uniform(-0.02, 0.02, (3, mech.na))
    x = m.parameters.nominal + rng.uniform(-1e-3, 1e-3, len(m.names))
    _, J, _ = m.evaluate(x, readings)
    cols = rng.choice(len(x), 8, replace=False)

    def diff(h: float) -> np.ndarray:
        out = []
        for k in cols:
            e = np.zeros(len(x))
            e[k] = h
            out.append((m.measure(x + e, readings) - m.measure(x - e, readings)) / (2 * h))
        return np.stack(out, axis=-1)

    assert rel(J[:, :, cols], richardson(diff, 1e-4)) < 1e-7


def test_prediction_matches_pinocchio_on_the_written_mechanism() -> None:
    """Joint origins, actuator offsets and gains and the tracker's and target's frames all changed: the model's pose
    equals ``T^-1 oMf E`` from Pinocchio on the mechanism :meth:`CalibrationModel.mechanism` builds (the URDF
    written with the origins and read again), to 1e-12 m."""
    mech = mechanism("gough_stewart")
    m = CalibrationModel(mech, "pose")
    rng = np.random.default_rng(1)
    x = m.parameters.nominal + rng.uniform(-2e-3, 2e-3, len(m.names))
    reading = mech.actuated_q(mech.q_reference) + 0.01
    y = m.measure(x, reading[None])[0]
    v = dict(zip(m.names, x))
    other = m.mechanism(x)
    qa = [v[f"{a}.gain"] * r + v[f"{a}.offset"] for a, r in zip(mech.actuated_names, reading)]
    q = pkm.close_loops(other, qa, tol=1e-13).q
    data = other.model.createData()
    pin.framesForwardKinematics(other.model, data, q)

    def frame(name: str) -> pin.SE3:
        return pin.SE3(pin.rpy.rpyToMatrix(*(v[f"{name}.{c}"] for c in ("roll", "pitch", "yaw"))),
                       np.array([v[f"{name}.{c}"] for c in "xyz"]))

    M = frame("tracker").inverse() * data.oMf[other.ee_frame] * frame("target")
    assert np.max(np.abs(y[:3] - M.translation)) < 1e-12
    assert np.max(np.abs(y[3:].reshape(3, 3).T - M.rotation)) < 1e-12


def test_an_out_of_plane_error_of_a_planar_loop_is_dropped_and_said() -> None:
    """The five-bar's loop is planar, closed by a 6-D closure: an origin's out-of-plane components would open it."""
    m = model("gepetto:5bar_linkage")
    assert m.inadmissible and all(n not in m.names for n in m.inadmissible)
    assert {"free1.x", "free1.y", "free1.yaw"} <= set(m.names) and "free1.z" in m.inadmissible


def test_bad_parameters_and_sensors_are_refused() -> None:
    mech = mechanism("gepetto:5bar_linkage")
    with pytest.raises(pkm.errors.InvalidInputError, match="idle motion"):
        CalibrationModel(mech, "passive", sensors=["closedloop1_A"])
    with pytest.raises(pkm.errors.InvalidInputError, match="no end effector"):
        CalibrationModel(mech, "pose")
    with pytest.raises(pkm.errors.UnknownNameError):
        calibration_parameters(mechanism("prs3"), "pose", joints=["nope"])
    with pytest.raises(pkm.errors.InvalidInputError, match="row 2"):
        model("prs3").close(None, [[0.1, 0.1, 0.1], [np.nan, 0.1, 0.1]])


@pytest.mark.filterwarnings("ignore::pkm.errors.ImplausibleModelWarning")  # (the 0.1 copy's masses are the original's)
def test_the_closure_tolerance_counts_lengths_in_the_characteristic_length(monkeypatch) -> None:
    """The calibration model's loop closure on the 3-PRS and its copies scaled by 0.1 and 10, each perturbed alike
    (its lengths by 2 mm times the scale), stopped after one Newton pass: the residual its ConvergenceError states is
    the same at every size (1e-9 relative: lengths over L), against CLOSURE_TOL, and the message says so (issue 52:
    before, CLOSURE_TOL * max(1, L) bounded a residual in m, so the copy 10 times smaller stated one 10 times
    smaller)."""
    from pkm.core.calibration import measurement
    from pkm.core.calibration.estimate import perturbed
    from pkm.errors import ConvergenceError

    monkeypatch.setattr(measurement, "MAX_NEWTON", 1)
    m = model("prs3", "pose")
    readings = m.mech.actuated_q(m.mech.q_reference)[None] + 0.05 * m.mech.characteristic_length
    stated = []
    for s in (1.0, 0.1, 10.0):
        copy = m if s == 1.0 else CalibrationModel(pkm.scaled_mechanism(m.mech, s), "pose")
        with pytest.raises(ConvergenceError, match="characteristic length") as err:
            copy.close(perturbed(copy, seed=1, length=2e-3 * s), readings * s)  # (the sliders' readings: lengths)
        assert err.value.tolerance == measurement.CLOSURE_TOL
        stated.append(err.value.residual)
    assert stated[0] > 1e-6 and np.allclose(stated[1:], stated[0], rtol=1e-9, atol=0.0), stated
