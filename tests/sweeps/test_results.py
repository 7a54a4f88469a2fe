"""A sweep's results asked the wrong thing (pkm.sweeps.results): pkm's errors, never pyarrow's or numpy's. A sweep
whose every design fails writes its failures and ends `pkm sweep` with one line naming them."""

from __future__ import annotations

import numpy as np
import pyarrow.parquet as pq
import pytest

import pkm
from pkm import cli, sweeps
from pkm.errors import InvalidInputError, SweepError, UnknownNameError
from pkm.sweeps.results import SweepResult, pareto_front

OBJECTIVES = ["gci:step=5cm", "cov=coverage:step=5cm"]


@pytest.fixture(scope="module")
def good() -> SweepResult:
    return pkm.sweep("rrr3", sweeps.table({"h": [0.1, 0.15]}), OBJECTIVES, scheduler="serial")


@pytest.fixture(scope="module")
def failed() -> SweepResult:
    return pkm.sweep("rrr3", sweeps.table({"h": [-0.1, -0.15]}), OBJECTIVES, scheduler="serial")


def test_a_sweep_whose_every_design_fails_writes_them_and_ends_in_one_line(tmp_path, capsys):
    """`pkm sweep` of designs that all fail: exit status 1, one line naming how many failed and the first one's
    message, and the output holds the failures' table (the parameters, the error and message of each design)."""
    out = tmp_path / "r.parquet"
    code = cli.main(["sweep", "rrr3", "h=-10cm:-5cm:2", "--objective", OBJECTIVES[0], "--scheduler", "serial",
                     "--out", str(out), "--no-progress"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1 and len(err) == 1, err
    assert err[0].startswith("pkm: error: all 2 designs failed") and "InvalidParameterError" in err[0], err
    assert "h: must be a finite number > 0" in err[0] and f"error is in {out}" in err[0], err
    rows = pq.read_table(out).to_pylist()
    assert [r["h"] for r in rows] == pytest.approx([-0.10, -0.05])
    assert {r["status"] for r in rows} == {"failed"} and all("h: must be" in r["message"] for r in rows)


def test_best_and_pareto_without_a_value_are_sweep_errors(failed, good):
    """Nothing to rank (every design failed): SweepError saying so, the first failure's message included."""
    for ask in (lambda: failed.best("cov"), lambda: failed.pareto(["gci:step=5cm", "cov"]),
                lambda: sweeps.write_best(failed, "cov", "unused")):
        with pytest.raises(SweepError, match=r"no design has a value of .*all 2 designs failed.*h: must be"):
            ask()
    with pytest.raises(SweepError, match=r"^all 2 designs failed; the first, design 0 \(h=-0\.1 m\): "):
        failed.check()
    assert good.check() is good


def test_misnamed_columns_and_objectives(good):
    with pytest.raises(UnknownNameError, match=r"objective 'nope'.*'gci:step=5cm', 'cov'"):
        good.best("nope")
    with pytest.raises(InvalidInputError, match="h is a parameter"):
        good.pareto(["h", "cov"])
    for names in (3, [["cov"]], [None, "cov"], "cov", []):
        with pytest.raises(InvalidInputError, match="objectives"):
            good.pareto(names)
    with pytest.raises(InvalidInputError, match="by"):
        good.best(["cov"])
    with pytest.raises(InvalidInputError, match="status holds text"):
        good.column("status")
    np.testing.assert_array_equal(good.column("design"), [0, 1])


@pytest.mark.parametrize("bad", [None, 3, b"r.parquet"])
def test_reading_something_that_is_not_a_path(bad):
    with pytest.raises(InvalidInputError, match="path"):
        sweeps.read(bad)


@pytest.mark.parametrize("F", [[1.0, 2.0], [["a", "b"]], [[10**400, 1]], np.zeros((2, 2, 2)), None])
def test_pareto_front_of_something_that_is_not_a_matrix(F):
    with pytest.raises(InvalidInputError, match="F"):
        pareto_front(F)


def test_the_plots_of_a_sweep_whose_every_design_failed(failed, tmp_path):
    """Where the designs fail is worth a look: both figures are drawn (the fronts empty), not a SweepError."""
    paths = sweeps.plot(failed, tmp_path)
    assert [p.name for p in paths] == ["sweep_parameters.png", "sweep_pareto.png"]
