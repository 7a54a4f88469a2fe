"""``pkm simulate``: a run under a CSV torque table or a controller file equals :func:`pkm.simulate`'s, written as
CSV or Parquet (units in the metadata), drawn, summarised with its energy balance; bad input as one error line.

The runs are 20 ms long (20 RK4 steps): about 0.1 s each."""

from __future__ import annotations

import csv
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm import cli
from pkm.core.dynamics import samples
from pkm.errors import InvalidInputError, UnitError
from pkm.units import parse_quantity
from tests.cli.helpers import one_error_line, run_process

ROOT = Path(__file__).resolve().parents[2]
ANKLE = ROOT / "examples" / "ankle" / "ankle.closures.toml"
RTOL = 1e-12  # the command and the library take the same route: equal but for the last bits (CSV: repr, exact)
CONTROLLER = """
import numpy as np

TARGET = np.array([0.05, -0.05])


def pd(t, q, v):
    # a PD on the ankle's motors, q and v the whole configuration and its rates
    return 2.0 * (TARGET - q[[ACT_Q]]) - 0.1 * v[[ACT_V]]


def broken(t, q, v):
    raise RuntimeError("sensor unplugged")
"""


def _summary(capsys, *argv: str) -> dict:
    assert cli.main(["simulate", *argv, "--json"]) == 0, capsys.readouterr().err
    return json.loads(capsys.readouterr().out)


def _read_csv(path: Path) -> dict[str, np.ndarray]:
    with path.open() as fh:
        rows = list(csv.reader(fh))
    return {name: np.array([float(r[i]) for r in rows[1:]]) for i, name in enumerate(rows[0])}


def _error(capsys, *argv: str) -> tuple[int, str]:
    status = cli.main(["simulate", *argv])
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("pkm: error: "), err
    return status, err


def _controller_file(tmp_path: Path, mech: pkm.Mechanism) -> Path:
    path = tmp_path / "my_controller.py"
    path.write_text(CONTROLLER.replace("ACT_Q", ", ".join(map(str, mech.act_q)))
                    .replace("ACT_V", ", ".join(map(str, mech.act_v))))
    return path


def test_time_units_convert_to_seconds():
    """``pkm.units`` has a time kind (s, ms, us) for the duration and step; a time is refused for a length."""
    assert parse_quantity("2s", {"time"}) == 2.0 and parse_quantity("1ms", {"time"}) == pytest.approx(1e-3, rel=1e-15)
    assert parse_quantity("250us", {"time"}) == pytest.approx(2.5e-4, rel=1e-15) and pkm.quantity("5ms") == 0.005
    with pytest.raises(UnitError, match="'ms' is a time unit"):
        parse_quantity("5ms", {"length"}, "R", "m")


def test_a_csv_torque_table_round_trip_on_delta(tmp_path, capsys):
    """A torque table written as CSV, simulated by ``pkm simulate delta --torques`` and written as CSV: every column
    equals pkm.simulate on the same table (1e-12 relative), and the summary's energy balance is the library's."""
    mech = pkm.load("delta")
    times = np.array([0.0, 0.01, 0.03])
    table = np.array([[0.1, 0.0, -0.2], [0.3, 0.05, 0.0], [0.0, 0.1, 0.2]])
    torques = tmp_path / "torques.csv"
    torques.write_text("t," + ",".join(mech.actuated_names) + "\n" +
                       "".join(",".join(repr(float(x)) for x in [t, *row]) + "\n" for t, row in zip(times, table)))
    out = _summary(capsys, "delta", "--torques", str(torques), "--duration", "20ms", "--dt", "1ms",
                   "--v0", "motor_2=0.5", "--out", str(tmp_path / "run.csv"))
    sim = pkm.simulate(mech, None, [0.0, 0.5, 0.0], 0.02, 1e-3, torques=(times, table))
    ours = samples.columns(mech, sim)
    written = _read_csv(tmp_path / "run.csv")
    assert list(written) == list(ours) == list(samples.column_units(mech, sim))
    for name, values in ours.items():
        assert np.allclose(written[name], values, rtol=RTOL, atol=1e-15), name
    assert np.allclose(written["tau.motor_1"][[0, 10]], [0.1, 0.3], rtol=RTOL)  # (the table, interpolated)
    assert out["samples"] == 21 and math.isclose(out["final_time"], 0.02, rel_tol=1e-12) and out["event"] is None
    assert math.isclose(out["energy_balance"], samples.energy_balance(sim), rel_tol=1e-9, abs_tol=1e-15)
    # (the balance is the trapezoidal rule's on the work, O(dt^2): 3.3e-3 of the work here, 8.3e-4 at dt = 0.5 ms)
    assert 0.0 < abs(out["energy_balance"]) < 1e-2 * abs(out["work"])
    assert out["units"]["energy_balance"] == "J" and out["saturated"] == {}  # (0.3 N m: within every limit)


def test_a_controller_file_on_a_spec_file_writes_parquet_and_a_figure(tmp_path, capsys):
    """``pkm simulate ankle.closures.toml --controller FILE.py:pd`` (a PD imported from its path): the Parquet
    table equals pkm.simulate with the same function, carries each column's unit and the run's metadata; the
    figure passes the figure check (units on every axis, every line in a legend)."""
    pq = pytest.importorskip("pyarrow.parquet")
    pytest.importorskip("matplotlib")
    from tests.papers.figures import inspected

    mech = pkm.load(ANKLE)
    path = _controller_file(tmp_path, mech)
    with inspected(paper=False) as found:
        out = _summary(capsys, str(ANKLE), "--controller", f"{path}:pd", "--duration", "0.02s", "--q0",
                       "motor_left=2deg", "--no-limits", "--method", "rk4", "--out", str(tmp_path / "run.parquet"),
                       "--plot", str(tmp_path / "run.png"))
    assert found == {"run": []} and (tmp_path / "run.png").stat().st_size > 10_000
    table = pq.read_table(tmp_path / "run.parquet")
    namespace: dict = {}
    exec(path.read_text(), namespace)
    qa = mech.actuated_q(mech.q_reference)
    qa[0] = math.radians(2)
    sim = pkm.simulate(mech, qa, None, 0.02, 1e-3, namespace["pd"], limits=False)
    ours = samples.columns(mech, sim)
    assert table.column_names == list(ours)
    for name, values in ours.items():
        assert np.allclose(table[name].to_numpy(), values, rtol=RTOL, atol=1e-15), name
    assert table.schema.field("tau.motor_left").metadata[b"unit"] == b"N m"
    meta = json.loads(table.schema.metadata[b"pkm"])
    assert meta["mechanism"] == "ankle" and meta["units"]["qd.motor_right"] == "rad/s" and meta["event"] is None
    assert out["out"] == str(tmp_path / "run.parquet") and out["samples"] == 21
    assert abs(ours["tau.motor_left"][0] - 2.0 * (0.05 - math.radians(2))) < 1e-12  # (the controller's law)


def test_a_run_stopped_early_reports_its_event(tmp_path, capsys):
    """The Delta let fall (no effort, a coarse step) outruns its servos (2.97 rad/s) within 0.05 s and, with the
    limits unwatched (--no-limits), reaches a direct singularity: the summary names the event, and the text says it
    stopped early."""
    (tmp_path / "zero.py").write_text("def zero(t, q, v):\n    return [0.0, 0.0, 0.0]\n")
    out = _summary(capsys, "delta", "--controller", f"{tmp_path / 'zero.py'}:zero", "--duration", "1s", "--dt",
                   "5ms", "--out", str(tmp_path / "fast.csv"))
    assert out["event"]["kind"] == "velocity_limit" and out["final_time"] < 0.05
    assert "speed limit 2.97404" in out["event"]["detail"]
    out = _summary(capsys, "delta", "--controller", f"{tmp_path / 'zero.py'}:zero", "--duration", "1s", "--dt",
                   "5ms", "--no-limits", "--out", str(tmp_path / "fall.csv"))
    assert out["event"]["kind"] == "singularity" and out["final_time"] < 1.0
    assert math.isclose(out["event"]["time"], out["final_time"], rel_tol=1e-12)
    assert out["samples"] == len(_read_csv(tmp_path / "fall.csv")["time"])


@pytest.mark.parametrize("argv,status,message", [
    (["--torques", "absent.csv"], 1, "absent.csv: no such file"),
    (["--controller", "absent.py:f"], 1, "absent.py: no such file"),
    (["--controller", "no_function_named"], 1, "expected FILE.py:FUNCTION"),
    (["--torques", "T", "--dt", "0"], 1, "dt: must be > 0"),
    (["--torques", "T", "--duration", "2kg"], 2, "'kg' is a mass unit but --duration is in [s]"),
    (["--torques", "T", "--q0", "motor_1=1s"], 2, "'s' is a time unit but motor_1 is in [rad]"),
])
def test_bad_input_is_one_error_line(argv, status, message, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "T").write_text("t,motor_1,motor_2,motor_3\n0,0,0,0\n")
    got, err = _error(capsys, "delta", *argv, "--out", "x.csv")
    assert got == status and message in err, err
    assert not (tmp_path / "x.csv").exists()


def test_a_torque_table_must_name_the_actuators_in_order(tmp_path, capsys):
    """A header other than ``t`` and the actuated names, in order, is refused naming the header expected; so are a
    short row and text where numbers belong."""
    for header, rows, message in (("t,motor_2,motor_1,motor_3", "0,0,0,0", "must read t,motor_1,motor_2,motor_3"),
                                  ("time,motor_1,motor_2,motor_3", "0,0,0,0", "got time,motor_1,motor_2,motor_3"),
                                  ("t,motor_1,motor_2,motor_3", "0,0,0", "line 2: 3 values, expected 4"),
                                  ("t,motor_1,motor_2,motor_3", "0,a,0,0", "line 2: not numbers"),
                                  ("t,motor_1,motor_2,motor_3", "", "no row of values")):
        (tmp_path / "bad.csv").write_text(f"{header}\n{rows}\n")
        status, err = _error(capsys, "delta", "--torques", str(tmp_path / "bad.csv"), "--out", str(tmp_path / "x.csv"))
        assert status == 1 and message in err, err
    from pkm.cli.commands.simulate import read_torques

    with pytest.raises(InvalidInputError, match="--torques"):
        read_torques(pkm.load("delta"), str(tmp_path / "bad.csv"))


def test_a_controller_that_raises_or_is_missing(tmp_path, capsys):
    """A controller that raises: the run stops with one line naming its exception and the time (exit 1); a function
    the file does not define: the file's functions listed (exit 2); a file whose import raises: exit 1."""
    mech = pkm.load(ANKLE)
    path = _controller_file(tmp_path, mech)
    status, err = _error(capsys, str(ANKLE), "--controller", f"{path}:broken", "--duration", "20ms",
                         "--out", str(tmp_path / "x.csv"))
    assert status == 1 and "the controller at t = 0 s: raised RuntimeError: sensor unplugged" in err
    status, err = _error(capsys, str(ANKLE), "--controller", f"{path}:pid", "--out", str(tmp_path / "x.csv"))
    assert status == 2 and "'pid' does not exist" in err and "'pd'" in err
    (tmp_path / "bad_import.py").write_text("import not_a_module_anywhere\n")
    status, err = _error(capsys, str(ANKLE), "--controller", f"{tmp_path / 'bad_import.py'}:f",
                         "--out", str(tmp_path / "x.csv"))
    assert status == 1 and "importing" in err and "ModuleNotFoundError" in err


def test_parquet_without_pyarrow_names_the_extra(tmp_path, capsys, monkeypatch):
    """Without pyarrow, a Parquet output is refused before the run, naming ``pip install "pkm-robotics[sweeps]"``; a
    CSV one needs nothing."""
    monkeypatch.setitem(sys.modules, "pyarrow", None)
    (tmp_path / "T.csv").write_text("t,motor_1,motor_2,motor_3\n0,0,0,0\n")
    status, err = _error(capsys, "delta", "--torques", str(tmp_path / "T.csv"), "--out", str(tmp_path / "r.parquet"))
    assert status == 1 and 'pip install "pkm-robotics[sweeps]"' in err and not (tmp_path / "r.parquet").exists()


def test_the_command_runs_as_a_process(tmp_path):
    """``python -m pkm simulate`` with a wrong table: one error line, exit status 1, nothing written."""
    (tmp_path / "T.csv").write_text("t,motor_1\n0,0\n")
    proc = run_process("simulate", "delta", "--torques", "T.csv", "--out", "run.csv", cwd=tmp_path)
    assert proc.returncode == 1 and "the header must read t,motor_1,motor_2,motor_3" in one_error_line(proc)
    assert not (tmp_path / "run.csv").exists()


def test_without_a_drive_the_mechanism_is_released(tmp_path, capsys):
    """Neither ``--torques`` nor ``--controller``: no effort, as ``pkm.simulate`` without a controller; the Delta
    falls to its direct singularity (its limits unwatched: it outruns its servos first) and the summary says so."""
    out = _summary(capsys, "delta", "--duration", "0.3s", "--no-limits", "--out", str(tmp_path / "free.csv"))
    sim = pkm.simulate(pkm.load("delta"), duration=0.3, limits=False)
    assert out["samples"] == len(sim.time) and out["event"]["kind"] == sim.event.kind == "singularity"
    assert math.isclose(out["final_time"], sim.time[-1], rel_tol=1e-12)
    assert out["work"] == 0.0


def test_the_initial_configuration_takes_passive_joints_as_the_closure_s_seed(tmp_path, capsys, built):
    """``--q0`` names actuated joints (the initial state) and passive ones (the loop closure's seed): the toy
    five-bar at the actuator values of its other assembly mode starts there when its elbows are given, and in the
    reference's mode (pkm.close_loops from the reference, the command's default) when they are not."""
    import warnings

    mech = built("fivebar")
    spec = pkm.save(mech, tmp_path / "five.closures.toml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pkm.errors.ModeChangeWarning)
        far = pkm.solve_ik(mech, pkm.TaskMap.of(mech).value(mech.q_reference) + [0.0, -0.3])  # (the other mode)
    near = pkm.close_loops(mech, mech.actuated_q(far.q))
    start = {}
    for label, names in (("far", list(mech.joints)), ("near", list(mech.actuated_names))):
        q0 = [f"{n}={float(far.q[mech.joints[n].idx_q])!r}" for n in names]
        _summary(capsys, str(spec), "--q0", *q0, "--duration", "1ms", "--out", str(tmp_path / f"{label}.csv"))
        table = _read_csv(tmp_path / f"{label}.csv")
        start[label] = np.array([table[f"task.{k}"][0] for k in pkm.TaskMap.of(mech).keys])
    assert np.allclose(start["far"], pkm.TaskMap.of(mech).value(far.q), rtol=0, atol=1e-9)
    assert np.allclose(start["near"], pkm.TaskMap.of(mech).value(near.q), rtol=0, atol=1e-9)
    assert np.abs(start["far"] - start["near"]).max() > 0.1


def test_the_initial_state_takes_joints_and_rates_with_units(tmp_path, capsys):
    """``--joints motor_1=-30deg --v0 motor_2=30deg/s`` (a configuration as every command takes one; a rate with
    its unit, which was "not a number"): the run is pkm.simulate's from the loops closed at those values with the
    SI rates, every column to 1e-12."""
    mech = pkm.load("delta")
    _summary(capsys, "delta", "--joints", "motor_1=-30deg", "--v0", "motor_2=30deg/s", "--duration", "5ms",
             "--dt", "1ms", "--out", str(tmp_path / "run.csv"))
    qa = mech.actuated_q(mech.q_reference)
    qa[0] = -math.pi / 6
    sim = pkm.simulate(mech, pkm.close_loops(mech, qa).q, [0.0, math.pi / 6, 0.0], 0.005, 1e-3)
    written = _read_csv(tmp_path / "run.csv")
    for name, values in samples.columns(mech, sim).items():
        assert np.allclose(written[name], values, rtol=RTOL, atol=1e-15), name
