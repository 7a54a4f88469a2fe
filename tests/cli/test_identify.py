"""``pkm excite`` and ``pkm identify``: the Delta identified end to end from the command line (an optimal excitation
written as a table, noise added as a robot's encoders and drives would, the physically consistent estimate written as
a spec that pkm loads back and that predicts a second table), with figures; bad input as one error line."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import pkm
from pkm import cli
from pkm.core.identification.regressor import parameters
from tests.cli.helpers import one_error_line, run


def _noisy(src, dst, seed):
    rows = list(csv.reader(src.open()))
    header, data = rows[0], np.array(rows[1:], dtype=float)
    rng = np.random.default_rng(seed)
    for i, name in enumerate(header):
        if name.startswith("q."):
            data[:, i] += 1e-4 * rng.standard_normal(len(data))
        if name.startswith("tau."):
            data[:, i] += 0.01 * np.ptp(data[:, i]) * rng.standard_normal(len(data))
    with dst.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(data.tolist())
    return dst


@pytest.fixture(scope="module")
def excited(tmp_path_factory):
    pytest.importorskip("matplotlib")
    folder = tmp_path_factory.mktemp("identify")
    argv = ["excite", "delta", "--duration", "10s", "--periods", "2", "--out", str(folder / "exc.csv"),
            "--plot", str(folder / "exc.png"), "--iterations", "15", "--motion", str(folder / "exc.toml"), "--json"]
    return folder, argv


def test_excite_then_identify_the_delta(excited, capsys):
    pytest.importorskip("cvxpy")
    folder, argv = excited
    assert cli.main(argv) == 0, capsys.readouterr().err
    summary = json.loads(capsys.readouterr().out)
    assert summary["condition"] < summary["condition_start"] and (folder / "exc.png").stat().st_size > 1000
    from pkm.motion import load_motions

    assert load_motions(summary["motion"])["excitation"].space == "actuated"
    train = _noisy(folder / "exc.csv", folder / "train.csv", 1)
    check = _noisy(folder / "exc.csv", folder / "check.csv", 2)
    out = folder / "ident" / "delta.closures.toml"
    assert cli.main(["identify", "delta", str(train), "--out", str(out), "--consistent", "--cutoff", "2",
                     "--validate", str(check), "--plot", str(folder / "fit.png"), "--json"]) == 0, \
        capsys.readouterr().err
    result = json.loads(capsys.readouterr().out)
    assert result["routes_agree"] is True and len(result["base"]) == 48
    # the base parameters reported are the model written's (issue 41: the consistent estimate's, not least
    # squares'), read back from the URDF written, to the digits of the file (repr: exact; 1e-12 for the inertia's
    # change of point)
    from pkm.core.identification.base import base_parameters

    delta = pkm.load("delta")
    written = base_parameters(delta, precise=False).map @ parameters(pkm.load(out)).values
    reported = np.array([row["value"] for row in result["base"]])
    assert np.allclose(reported, written, rtol=1e-9, atol=1e-12 * np.abs(written).max())
    # least squares gives a negative mass where the consistent estimate cannot
    i = [row["name"] for row in result["base"]].index("guide_y.m")
    assert result["base"][i]["value"] >= 0.0 and result["base"][i]["least_squares"] != result["base"][i]["value"]
    # the rows used and why so few: two periods of 10 s at 500 Hz, one row in int(rate / (2 cutoff)) kept (124: the
    # rate read from the times' steps is a hair under 500 Hz)
    assert result["table_rows"] == 10001 and result["decimate"] == 124
    assert result["equations"] == 3 * result["samples"] and result["cutoff_hz"] == 2.0
    poor = [r["name"] for r in result["base"] if r["poor"]]
    assert all(r["relative_std_percent"] > 100.0 and r["effort_share"] > 0.01 for r in result["base"] if r["poor"])
    assert poor and any(f"{len(poor)} of 48 base parameters" in w for w in result["warnings"])
    assert result["smallest_pseudo_inertia_eigenvalue"] >= -1e-9
    # least squares alone, on so few samples, is no real mechanism: the error says so and names --consistent
    assert cli.main(["identify", "delta", str(train), "--out", str(folder / "ls" / "d.closures.toml"),
                     "--cutoff", "2"]) != 0
    assert "--consistent writes the physically consistent estimate" in capsys.readouterr().err
    assert max(result["validation"]["relative_percent"].values()) <= 0.1  # (measured 0.02-0.03 %)
    identified = pkm.load(out)
    assert len(parameters(identified)) == len(parameters(delta))
    q = delta.q_reference
    tau_true = pkm.actuator_model(delta, q, [0.3, -0.2, 0.1]).efforts([1.0, 0.5, -0.7])
    tau_identified = pkm.actuator_model(identified, q, [0.3, -0.2, 0.1]).efforts([1.0, 0.5, -0.7])
    assert np.allclose(tau_identified, tau_true, rtol=0.02, atol=1e-3 * np.abs(tau_true).max())


def test_bad_input_is_one_error_line(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("time,q.motor_1,q.motor_2,q.motor_3,tau.motor_1,tau.motor_2\n0,0,0,0,0,0\n")
    line = one_error_line(run("identify", "delta", str(bad), "--out", str(tmp_path / "x.closures.toml")))
    assert "tau.motor_3" in line
    line = one_error_line(run("excite", "delta", "--harmonics", "5", "--samples", "4", "--out",
                              str(tmp_path / "e.csv")))
    assert "samples" in line


def test_cutoff_help_states_the_decimation(capsys):
    """Issue 52: ``--cutoff 2`` kept 29 of 5,001 rows and its help did not say that it decimates."""
    assert cli.main(["identify", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "decimated to one in rate / (2 cutoff)" in text and "rows kept are reported" in text


def test_a_mechanism_with_idle_motions_is_refused_before_any_work(tmp_path):
    """Issue 52: pkm identify refused the humanoid ankle (two rods spinning between balls: idle motions, which the
    precise rank's twin regressor cannot take) only after pkm excite had run (73 s) and the table was read. Both
    refuse up front, with the SpecError pkm.base_parameters raises, naming the double-precision route: identify before
    it reads its table (here a file that does not exist), excite before it writes one."""
    from pkm.core.identification.base import base_parameters
    from pkm.errors import SpecError

    ankle = "examples/humanoid_ankle/ankle.closures.toml"
    for args in (("identify", ankle, str(tmp_path / "missing.csv"), "--out", str(tmp_path / "id.closures.toml")),
                 ("excite", ankle, "--out", str(tmp_path / "exc.csv"))):
        line = one_error_line(run(*args))
        assert "idle motions" in line and "humanoid_ankle has 2" in line and "precise=False" in line, line
    assert not (tmp_path / "exc.csv").exists()
    with pytest.raises(SpecError, match="has 2: pass precise=False"):
        base_parameters(pkm.load(ankle))
