"""Pose selection (O1) and the measurement table's refusals; the write-back read again by pkm.load."""

from __future__ import annotations

import numpy as np
import pytest

import pkm
from pkm.core.calibration.estimate import calibrate
from pkm.core.calibration.identifiable import stacked_jacobian
from pkm.core.calibration.poses import calibration_poses, candidates
from pkm.core.calibration.tolerance import tolerance_table
from pkm.core.calibration.writeback import SIZE_FACTOR, read_data, write_calibrated, write_data
from tests.core.calibration.conftest import model, simulated


def _log_o1(m, readings, cols) -> float:
    W = stacked_jacobian(m, readings)[:, cols]
    return float(np.sum(np.log(np.linalg.svd(W / np.linalg.norm(W, axis=0), compute_uv=False))))


def test_chosen_poses_beat_random_ones_on_o1() -> None:
    m = model("prs3")
    plan = calibration_poses(m, 12, spread=0.2, pool=36)
    cols = list(plan.base.independent)
    random = candidates(m, 12, spread=0.2, seed=5)
    assert _log_o1(m, plan.readings, cols) > _log_o1(m, random, cols)
    assert not any(m.mech.outside_limits(q) for q in m.close(None, plan.readings))
    with pytest.raises(pkm.errors.InvalidInputError, match="base parameters"):
        calibration_poses(m, 4, spread=0.2, pool=12)


def test_bad_tables_are_refused_naming_row_and_column(tmp_path) -> None:
    s = simulated("prs3")
    m = s.model
    path = write_data(m, tmp_path / "data.csv", s.readings, s.measured)
    M, Y = read_data(m, path)
    assert np.allclose(M, s.readings) and np.allclose(Y, s.measured, atol=1e-15)
    text = path.read_text().splitlines()
    cases = {"x": ("millimetres", lambda c: c.__setitem__(3, str(float(c[3]) * 1000)), r"row 3, column 'x'.*mm"),
             "roll": ("degrees", lambda c: c.__setitem__(6, "57.3"), r"row 3, column 'roll'.*degrees"),
             "nan": ("NaN", lambda c: c.__setitem__(1, "nan"), r"row 3, column 'm.slider_2'.*not a finite"),
             "out": ("workspace", lambda c: c.__setitem__(0, "6.5"), r"row 3, columns m.slider_1"),
             }
    for label, (_, change, message) in cases.items():
        cells = text[3].split(",")
        change(cells)
        bad = tmp_path / f"{label}.csv"
        bad.write_text("\n".join(text[:3] + [",".join(cells)] + text[4:]) + "\n")
        with pytest.raises(pkm.errors.InvalidInputError, match=message):
            read_data(m, bad)
    with pytest.raises(pkm.errors.InvalidInputError, match="missing column"):
        read_data(m, {"m.slider_1": [0.1]})
    header = text[0].split(",")
    away = 2.0 * SIZE_FACTOR * m.mech.characteristic_length  # (a tracker twice the size bound away from the base:
    far = [",".join(str(float(v) + away) if header[k] in ("x", "y", "z") else v for k, v in enumerate(row.split(",")))
           for row in text[1:]]  # its frame is estimated; before, every row was refused as a unit mistake)
    (tmp_path / "far.csv").write_text("\n".join([text[0], *far]) + "\n")
    assert np.allclose(read_data(m, tmp_path / "far.csv")[0], s.readings)
    with pytest.raises(pkm.errors.InvalidInputError, match=r"30 residuals for 34 base parameters: give more poses"):
        calibrate(m, s.readings[:5], s.measured[:5], base=s.cal.base)


def test_written_back_mechanism_predicts_as_the_calibrated_model(tmp_path) -> None:
    s = simulated("prs3")
    spec, toml = write_calibrated(s.cal, tmp_path)
    other = pkm.load(spec)
    v = s.cal.values()
    assert f"'slider_1.gain' = {v['slider_1.gain']!r}" in toml.read_text()
    qa = [v[f"{a}.gain"] * r + v[f"{a}.offset"] for a, r in zip(other.actuated_names, s.readings[0])]
    q = pkm.close_loops(other, qa, tol=1e-13).q
    x = s.cal.x.copy()
    for k, n in enumerate(s.model.names):
        if n.startswith(("tracker.", "target.")):
            x[k] = 0.0
    import pinocchio as pin
    data = other.model.createData()
    pin.framesForwardKinematics(other.model, data, q)
    assert np.max(np.abs(s.model.measure(x, s.readings[:1])[0, :3] - data.oMf[other.ee_frame].translation)) < 1e-11


def test_tolerance_table_matches_the_closed_mechanism() -> None:
    """The first-order pose errors against the loops closed again with the change: to 1e-4 for small changes; for
    the default 0.1 mm / 0.1 degree, the first order is within 5 % (the slider's tilt moves the tool 2.3 mm)."""
    m = model("prs3")
    readings = simulated("prs3").readings[:4]
    y0 = m.measure(None, readings)
    for delta, tol in (({"m": 1e-7, "rad": 1e-6, "1": 1e-7}, 1e-4), (None, 5e-2)):
        rows = tolerance_table(m, readings, delta)
        assert rows[0].position[1] >= rows[-1].position[1] and not any(r.name.startswith("tracker") for r in rows)
        for row in (rows[0], rows[len(rows) // 2]):
            x = m.parameters.nominal.copy()
            x[m.names.index(row.name)] += row.delta
            err = np.linalg.norm(m.measure(x, readings)[:, :3] - y0[:, :3], axis=1).max()
            assert err == pytest.approx(row.position[1], rel=tol)


def test_an_mjcf_mechanism_self_calibrates_and_is_written_back_as_mjcf_too(tmp_path) -> None:
    """The MJCF four-bar example, its passive joints read by encoders: calibrated, written as spec + URDF and as
    MJCF, both loading to the same calibrated geometry (the coupler's reading predicted alike)."""
    from pathlib import Path

    from pkm.core.calibration.estimate import perturbed, simulate
    from pkm.core.calibration.measurement import CalibrationModel

    mech = pkm.load(str(Path(__file__).parents[3] / "examples" / "mjcf_fourbar" / "fourbar.xml"))
    m = CalibrationModel(mech, "passive")
    readings = calibration_poses(m, 12, spread=0.3, pool=14).readings
    cal = calibrate(m, readings, simulate(m, perturbed(m, seed=1), readings, seed=2))
    assert cal.after.position[1] < 3 * 20e-6 < 1e-3 < cal.before.position[1]
    spec, _, mjcf = write_calibrated(cal, tmp_path)
    v = cal.values()
    qa = [v["crank_joint.gain"] * readings[0, 0] + v["crank_joint.offset"]]
    angles = []
    for other in (pkm.load(spec), pkm.load(mjcf)):
        q = pkm.close_loops(other, qa, tol=1e-13).q
        angles.append(q[other.joints["coupler_joint"].idx_q])
    predicted = m.measure(cal.x, readings[:1])[0, m.sensors.index("coupler_joint")] - v["coupler_joint.offset"]
    assert abs(angles[0] - predicted) < 1e-10 and abs(angles[1] - predicted) < 1e-6


def test_deviations_that_do_not_exist_are_refused() -> None:
    """Enough rows but one pose repeated: the estimated parameters are not determined, and their deviations are
    refused (before: a pseudo-inverse's finite, meaningless numbers, or an inverse of a singular matrix)."""
    s = simulated("prs3")
    n = len(s.cal.base) // 6 + 2  # (more rows than parameters, all from the first pose)
    with pytest.raises(pkm.errors.SingularityError, match="not all determined by these poses") as err:
        calibrate(s.model, np.repeat(s.readings[:1], n, axis=0), np.repeat(s.measured[:1], n, axis=0),
                  base=s.cal.base)
    assert err.value.kind == "calibration" and err.value.distance < 1e-10


def test_candidates_spread_per_unit_by_default() -> None:
    """Without a spread, a prismatic reading moves by up to SPREAD characteristic lengths (the 3-PRS's sliders:
    0.19 m), the same draw as a mapping's value for its unit; on the Delta (revolute) by up to SPREAD rad."""
    from pkm.core.calibration.poses import SPREAD

    for name, bound in (("prs3", SPREAD * model("prs3").mech.characteristic_length), ("delta", SPREAD)):
        m = model(name, "pose")
        ref = m.mech.actuated_q(m.mech.q_reference)
        drawn = candidates(m, 6, seed=2)
        assert 0.5 * bound < np.abs(drawn - ref).max() <= bound
        assert np.array_equal(candidates(m, 6, seed=2, spread={"rad": SPREAD, "m": bound}), drawn)


@pytest.mark.filterwarnings("ignore::pkm.errors.ImplausibleModelWarning")  # (the 0.1 copy's masses are the original's)
def test_the_singularity_margin_is_the_same_for_a_copy_scaled_in_size() -> None:
    """The candidates' singularity margin (conditioning, homogenised by the characteristic length) at three poses of
    the 3-PRS (prismatic actuators: their rows and columns in lengths) equals its copies' scaled by 0.1 and 10 (1e-9
    relative). (Before, on the raw matrix in m and rad, the copies' were 0.106 and 0.54 times the original's: a margin
    that meant another thing at every size.)"""
    from pkm.core.calibration.measurement import CalibrationModel
    from pkm.core.calibration.poses import conditioning

    m = model("prs3", "pose")
    readings = candidates(m, 3, seed=5)
    mine = conditioning(m, readings)
    assert np.all(mine > 1e-3)
    for s in (0.1, 10.0):
        copy = CalibrationModel(pkm.scaled_mechanism(m.mech, s), "pose")
        np.testing.assert_allclose(conditioning(copy, readings * s), mine, rtol=1e-9)  # (sliders: lengths)


def test_columns_given_as_a_dict_take_the_identification_route(tmp_path) -> None:
    """``read_data`` reads a dict of columns as ``pkm.measurements`` does (one route: ``read_columns``): text is
    refused naming its column (before: numpy turned "0.1" into 0.1), columns of unequal length are refused naming
    theirs (before: numpy's raw error), and the same table as a dict and as a file reads the same."""
    s = simulated("prs3")
    m = s.model
    path = write_data(m, tmp_path / "data.csv", s.readings, s.measured)
    from pkm.core.identification.measurements import read_table

    cols = read_table(path)
    M, Y = read_data(m, cols)
    assert np.array_equal(M, read_data(m, path)[0]) and np.array_equal(Y, read_data(m, path)[1])
    with pytest.raises(pkm.errors.InvalidInputError, match=r"m\.slider_2") as err:
        read_data(m, dict(cols, **{"m.slider_2": [str(v) for v in cols["m.slider_2"]]}))
    assert err.value.name == "m.slider_2"
    with pytest.raises(pkm.errors.InvalidInputError, match=r"column 'z' has shape") as err:
        read_data(m, dict(cols, z=cols["z"][:-1]))


def test_a_pose_the_robot_does_not_reach_is_left_out_and_the_next_best_taken() -> None:
    """Issue 52: the hexapod's simulated robot did not reach a third of the poses O1 picked on the nominal one, and
    ``pkm calibrate plan --simulate`` failed. A 3-PRS 1 cm and 1 degree off does not reach one of 12: pkm's own
    loop closure on the mechanism written with that geometry fails there too (a second solver) and closes at the
    pose taken instead; the picks before the refused one are the plain choice's to the bit; a robot that reaches
    none is refused naming the options."""
    from pkm.core.calibration.estimate import perturbed, simulate

    m = model("prs3")
    truth = perturbed(m, 1, length=0.01, angle=0.02)
    plain = calibration_poses(m, 12, spread=0.2, pool=18)
    reached = m.reaches(truth, plain.readings)
    assert reached.sum() == 11
    with pytest.raises(pkm.errors.ConvergenceError, match=r"does not reach this pose.*reachable="):
        simulate(m, truth, plain.readings)
    with pytest.warns(pkm.errors.PkmWarning, match=r"does not reach 1 of the 13 poses .*of the 18 candidates: \d+;"):
        plan = calibration_poses(m, 12, spread=0.2, pool=18, reachable=lambda r: bool(m.reaches(truth, r)[0]))
    first = int(np.argmin(reached))
    assert np.array_equal(plan.refused, plain.readings[first:first + 1])
    assert np.array_equal(plan.readings[:first], plain.readings[:first]) and len(plan.readings) == 12
    assert m.reaches(truth, plan.readings).all() and simulate(m, truth, plan.readings).shape == (12, 12)
    robot, values = m.mechanism(truth), dict(zip(m.names, truth))
    for r, closes in ((plan.refused[0], False), (plan.readings[first], True)):
        qa = [values[f"{a}.gain"] * v + values[f"{a}.offset"] for a, v in zip(robot.actuated_names, r)]
        try:
            pkm.close_loops(robot, qa, m.close(None, r[None])[0])
            assert closes
        except pkm.errors.ConvergenceError:
            assert not closes
    assert plain.refused.shape == (0, 3)
    with pytest.raises(pkm.errors.InvalidInputError, match=r"reaches only 0 of the 18 .*--poses, --spread"):
        calibration_poses(m, 12, spread=0.2, pool=18, reachable=lambda r: False)
