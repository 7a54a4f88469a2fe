"""Running sweeps (pkm.sweeps.engine): Dask against the serial loop, Parquet results, resume after a kill,
failing designs recorded, an existing scheduler reached by its address."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm import sweeps
from pkm.errors import SweepError
from pkm.mechanisms.rrr3 import workspace as maps
from pkm.papers import rrr3 as paper
from tests import bounded

COLUMNS = [f"{c}={c}:step=0.04" for c in ("gci", "gci_area", "coverage", "min_area_ci")]
SMALL = sweeps.grid(a="30cm:60cm:4", b="40cm", h="5cm:20cm:4")


def serial_columns(res: maps.SweepResult) -> list[np.ndarray]:
    return [np.ma.filled(res.gci, np.nan), np.ma.filled(res.area_gci, np.nan), res.coverage,
            np.ma.filled(res.min_area_ci, np.nan)]


@pytest.fixture(scope="module")
def two_workers():
    """A client of the 2-worker local cluster pkm.sweep starts without a scheduler (pkm.sweeps.engine.local_cluster:
    its worker processes, allocator and Dask settings), started once for the tests that need real worker
    processes: their start (each worker's imports, about 2 s of CPU) paid once, not once a test. Dask's retries set to
    none (the scheduler reads the setting when it starts): a design that kills its worker fails at once."""
    import dask
    import dask.distributed  # (before the setting: _dask_settings)

    from pkm.sweeps.engine import local_cluster

    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), local_cluster(2) as cluster, \
            dask.distributed.Client(cluster, set_as_default=False) as client:
        yield client


def test_the_paper_sweep_on_two_local_workers_equals_the_serial_loop_exactly(two_workers):
    """The 1,000 designs of sec. VII on a 2-worker LocalCluster give, bit for bit, what the serial loop of
    pkm.mechanisms.rrr3.workspace.sweep gives; so does the paper module's own route."""
    designs = paper.paper_sweep_designs()
    space = sweeps.table({k: [getattr(d, k) for d in designs] for k in ("a", "b", "h", "H")})
    two_workers.wait_for_workers(2, timeout=120)  # (a worker a test before ended is started again)
    res = pkm.sweep("rrr3", space, COLUMNS, client=two_workers, progress=False)
    assert res.stats.workers == 2 and res.stats.chunks >= 2 * 16 and res.stats.failed == 0
    loop = maps.sweep(designs, step=0.04, progress=False)
    for name, expected in zip(("gci", "gci_area", "coverage", "min_area_ci"), serial_columns(loop)):
        np.testing.assert_array_equal(res.column(name), expected)
    np.testing.assert_array_equal(res.column("design"), np.arange(1000))
    assert np.isnan(res.column("gci")).any() and res.ok.all()  # empty workspaces: nulls, not failures
    loaded = two_workers.run(eval, "__import__('sys').modules.keys() & {'yourdfpy', 'trimesh'}")
    assert not any(loaded.values()), loaded  # (the maps read no file: the loaders' imports, a second a worker, unpaid)


def test_a_failing_design_is_recorded_and_the_others_go_on(tmp_path):
    bad = sweeps.table([{"a": 0.4, "h": 0.1}, {"a": 0.4, "h": -0.1}, {"a": 0.5, "h": 0.1}])
    res = pkm.sweep("rrr3", bad, ["gci:step=4cm"], scheduler="serial", out=tmp_path / "r.parquet")
    assert res.ok.tolist() == [True, False, True] and res.stats.failed == 1
    (fail,) = res.failures()
    assert fail["design"] == 1 and fail["error"] == "InvalidParameterError" and "h" in fail["message"]
    assert np.isnan(res.column("gci:step=4cm")[1]) and np.isfinite(res.column("gci:step=4cm")[[0, 2]]).all()
    again = sweeps.read(tmp_path / "r.parquet")
    assert again.table.equals(res.table) and again.failures() == res.failures()


def test_a_finished_output_is_not_evaluated_again_and_another_sweep_is_refused(tmp_path):
    out = tmp_path / "r.parquet"
    first = pkm.sweep("rrr3", SMALL, ["gci:step=4cm"], scheduler="serial", out=out)
    second = pkm.sweep("rrr3", SMALL, ["gci:step=4cm"], scheduler="serial", out=out)
    assert second.stats.evaluated == 0 and second.table.equals(first.table)
    with pytest.raises(SweepError, match="another sweep"):
        pkm.sweep("rrr3", SMALL, ["gci:step=2cm"], scheduler="serial", out=out)
    third = pkm.sweep("rrr3", SMALL, ["gci:step=2cm"], scheduler="serial", out=out, overwrite=True)
    assert third.stats.evaluated == len(third)
    sampled = sweeps.sobol(8, a="30cm:60cm", h="5cm:20cm")  # no seed: drawn, recorded, and found again
    drawn = pkm.sweep("rrr3", sampled, ["gci:step=4cm"], scheduler="serial", out=out, overwrite=True)
    again = pkm.sweep("rrr3", sampled, ["gci:step=4cm"], scheduler="serial", out=out)
    assert again.stats.evaluated == 0 and again.manifest["space"]["seed"] == drawn.manifest["space"]["seed"]


KILLER = '''
import os, signal
from pkm.mechanisms.rrr3 import workspace as ws

def area(design):
    """The platform triangle's area, and a SIGKILL of this process at the design named by PKM_TEST_KILL_AT."""
    at = os.environ.get("PKM_TEST_KILL_AT")
    if at and max(abs(float(x) - design.values[k]) for x, k in zip(at.split(","), "ah")) < 1e-12:
        os.kill(os.getpid(), signal.SIGKILL)
    return 3 ** 0.5 / 4 * design.values["h"] ** 2
'''


def test_a_killed_sweep_resumes_where_it_stopped_and_gives_the_uninterrupted_table(tmp_path):
    """`pkm sweep` killed (SIGKILL, mid-sweep) leaves the chunks it finished; the same sweep run again evaluates
    only the others and gives the table of a run that was never interrupted."""
    objective_file = tmp_path / "killer.py"
    objective_file.write_text(KILLER, encoding="utf-8")
    out = tmp_path / "r.parquet"
    objectives = ["gci:step=4cm", f"{objective_file}:area@max"]
    args = [sys.executable, "-m", "pkm", "sweep", "rrr3", "a=30cm:60cm:4", "b=40cm", "h=5cm:20cm:4",
            "--objective", *objectives[:1], "--objective", objectives[1], "--scheduler", "serial", "--chunk", "1",
            "--out", str(out), "--no-progress"]
    env = {**os.environ, "PKM_TEST_KILL_AT": "0.5,0.15"}  # design 4 * 2 + 2 = 10 of 16
    proc = bounded.run(args, env=env, cpu=120)
    assert proc.returncode == -signal.SIGKILL, proc.stderr
    parts = sorted((tmp_path / "r.parquet.parts").glob("part-*.parquet"))
    assert len(parts) == 10 and not out.exists()
    (parts[0].parent / "part-000000002-000000003.parquet").write_bytes(parts[2].read_bytes())  # overlapping parts,
    # as runs with other chunk sizes leave: each design once in the result
    resumed = pkm.sweep("rrr3", SMALL, ["gci:step=4cm", objectives[1]], scheduler="serial", out=out)
    assert resumed.stats.evaluated == 6 and not (tmp_path / "r.parquet.parts").exists()
    whole = pkm.sweep("rrr3", SMALL, ["gci:step=4cm", objectives[1]], scheduler="serial")
    assert resumed.table.equals(whole.table)
    assert resumed.manifest["objectives"][1]["sense"] == "max"


# _dask_settings: distributed is imported before a test sets dask.config: dask.config.set's exit drops the keys that
# did not exist when it was entered, the defaults importing distributed adds among them, and the next cluster of the
# process (another test's, on the same pytest-xdist worker) would fail with KeyError: 'comm'.


def test_an_existing_scheduler_and_worker_started_as_processes(tmp_path):
    """`dask scheduler` and `dask worker` as separate processes on this machine (the worker without a nanny: one
    process, not a nanny and the worker it spawns); the sweep goes to the scheduler's address and gives the serial
    loop's table."""
    dask = Path(sys.executable).with_name("dask")
    file = tmp_path / "scheduler.json"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    common = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    sched = subprocess.Popen([str(dask), "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                              "--scheduler-file", str(file)], **common)
    worker = None
    try:
        deadline = time.monotonic() + 60
        while not file.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        address = json.loads(file.read_text())["address"]
        worker = subprocess.Popen([str(dask), "worker", address, "--no-nanny", "--nthreads", "1",
                                   "--no-dashboard"], **common)
        res = pkm.sweep("rrr3", SMALL, ["gci:step=4cm"], scheduler=address, workers=1, progress=False)
        assert res.stats.workers == 1
        serial = pkm.sweep("rrr3", SMALL, ["gci:step=4cm"], scheduler="serial")
        assert res.table.equals(serial.table)
    finally:
        for p in (worker, sched):
            if p is not None:
                p.terminate()
                p.wait(timeout=30)


def test_an_unreachable_scheduler_is_a_clear_error():
    import dask
    import dask.distributed  # (before the setting: _dask_settings)

    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}), \
            pytest.raises(SweepError, match=r"cannot reach the Dask scheduler at tcp://127\.0\.0\.1:9"):
        pkm.sweep("rrr3", SMALL, ["gci:step=4cm"], scheduler="tcp://127.0.0.1:9")


EXIT = '''
import os

def area(design):
    """The platform triangle's area; the worker process ends (os._exit) at h = 10 cm, a = 30 cm."""
    if abs(design.values["h"] - 0.10) < 1e-12 and abs(design.values["a"] - 0.30) < 1e-12:
        os._exit(1)
    return 3 ** 0.5 / 4 * design.values["h"] ** 2
'''


def test_a_design_that_kills_its_worker_fails_alone(tmp_path, two_workers):
    """On a 2-worker cluster, the design whose evaluation ends its worker process is recorded as failed
    (KilledWorker; Dask's retries set to none to keep the test short); the others of its chunk and every other
    chunk are evaluated, and the sweep's context survives the dead workers. (Two chunks of four, one such design in
    the first: two worker deaths, the chunk's and the design's retried alone, each a worker process started
    again.)"""
    (tmp_path / "exit.py").write_text(EXIT, encoding="utf-8")
    space = sweeps.grid(a="30cm:60cm:2", h="5cm:20cm:4")
    two_workers.wait_for_workers(2, timeout=120)
    res = pkm.sweep("rrr3", space, [f"{tmp_path / 'exit.py'}:area"], client=two_workers, chunk_size=4, progress=False)
    h = res.column("h")
    failed = ~res.ok
    assert np.array_equal(failed, np.isclose(h, 0.10) & np.isclose(res.column("a"), 0.30))
    assert failed.sum() == 1 and res.stats.chunks == 2
    assert {f["error"] for f in res.failures()} == {"KilledWorker"}
    np.testing.assert_allclose(res.column("area")[~failed], 3**0.5 / 4 * h[~failed] ** 2, rtol=1e-15)
