"""Looking at sweeps (pkm.sweeps.figures, `pkm sweep plot|best`): figures, Pareto fronts, best designs as specs."""

from __future__ import annotations

import importlib.util
import json

import numpy as np
import pytest

import pkm
from pkm import cli, sweeps
from pkm.sweeps.results import pareto_front
from tests.papers.figures import inspected


def test_no_submodule_shadows_a_name_of_the_package():
    """A submodule named as one of pkm.sweeps' names replaces that name in the package once imported: with the
    figures in pkm/sweeps/plot.py, `sweeps.write_best` first made `sweeps.plot` that module (not callable)."""
    clash = [n for n in sweeps.__all__ if importlib.util.find_spec(f"pkm.sweeps.{n}") is not None]
    assert not clash
    sweeps.write_best  # noqa: B018 (imports the figures' module)
    assert callable(sweeps.plot) and callable(sweeps.write_best)


def test_pareto_front_of_a_known_set():
    F = np.array([[1, 5], [2, 4], [2, 2], [3, 1], [0, 0], [np.nan, 9], [3, 1]], dtype=float)
    np.testing.assert_array_equal(pareto_front(F), [0, 1, 3, 6])  # duplicates both stay; NaN rows out


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep") / "rrr3.parquet"
    code = cli.main(["sweep", "rrr3", "a=30cm:60cm:4", "h=5cm:20cm:3", "--objective", "gci:step=4cm",
                     "--objective", "cov=coverage:step=4cm", "--scheduler", "serial", "--out", str(out),
                     "--no-progress"])
    assert code == 0
    return out


def test_plots_from_the_results_file(results, tmp_path, capsys):
    """`pkm sweep plot` writes both figures, each with units on its axes and every line in a legend."""
    capsys.readouterr()
    with inspected(paper=False) as found:
        assert cli.main(["sweep", "plot", str(results), "--out", str(tmp_path)]) == 0
    assert found == {"sweep_parameters": [], "sweep_pareto": []}
    paths = json.loads(capsys.readouterr().out)
    assert [p.rsplit("/", 1)[1] for p in paths] == ["sweep_parameters.png", "sweep_pareto.png"]
    assert all((tmp_path / p.rsplit("/", 1)[1]).stat().st_size > 10_000 for p in paths)


def test_the_best_designs_become_closure_specs_that_load(results, tmp_path, capsys):
    capsys.readouterr()
    assert cli.main(["sweep", "best", str(results), "--by", "gci:step=4cm", "--n", "2", "--out", str(tmp_path)]) == 0
    paths = json.loads(capsys.readouterr().out)
    best = sweeps.read(results).best("gci:step=4cm", 2)
    assert best[0]["gci:step=4cm"] >= best[1]["gci:step=4cm"]
    for path, row in zip(paths, best):
        mech = pkm.load(path)
        assert mech.spec.parameters["a"] == pytest.approx(row["a"], abs=1e-12)
        assert mech.spec.parameters["h"] == pytest.approx(row["h"], abs=1e-12)


@pytest.mark.parametrize("args,status,message", [
    (["sweep", "rrr3", "a=30cm:60cm:4", "--objective", "gcii"], 2, "gcii"),
    (["sweep", "rrr3", "a=30cm:60cm", "--sample", "sobol", "--objective", "gci"], 2, "--n"),
    (["sweep", "rrr3", "R=10cm:20cm:3", "--objective", "gci"], 2, "parameter"),
    (["sweep", "best", "missing.parquet", "--by", "gci"], 1, "missing.parquet"),
])
def test_bad_sweep_command_lines_give_one_line(args, status, message, capsys):
    assert cli.main(args) == status
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("pkm: error: ") and message in err[0], err
