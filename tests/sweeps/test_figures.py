"""pkm.sweeps.figures, called on a tiny in-memory SweepResult (four 3-RRR designs scored by callables, one failing):
the parameter figure alone when no objective has a sense, both figures passing the figure check when asked for a
front, the axis labels carrying units and senses, nothing to plot refused, and the best designs written as specs
that load with their values. (The same through ``pkm sweep plot|best`` on a results file is
``tests/sweeps/test_plot.py``.)"""

from __future__ import annotations

import pytest

import pkm
from pkm import sweeps
from pkm.errors import InvalidInputError, SweepError
from pkm.sweeps import figures
from pkm.sweeps.results import SweepResult
from tests.papers.figures import inspected


def area(design):
    """The platform triangle's area [m^2]; design 2 fails (a made-up failure, recorded, not raised)."""
    if design.values["a"] == 0.5:
        raise ValueError("made-up failure")
    return 3**0.5 / 4 * design.values["h"] ** 2


def reach(design):
    return design.values["a"] + 0.4


def size(design):
    return design.values["a"] + design.values["h"]


def never(design):
    """No value for any design (a null, not a failure)."""
    return None


def _without(res: SweepResult, *columns: str) -> SweepResult:
    """``res`` with objectives ``columns`` left out (table and manifest)."""
    kept = [o for o in res.manifest["objectives"] if o["column"] not in columns]
    return SweepResult(res.table.drop_columns(list(columns)), {**res.manifest, "objectives": kept})


@pytest.fixture(scope="module")
def result() -> SweepResult:
    space = sweeps.table({"a": [0.3, 0.4, 0.5, 0.6], "h": [0.1, 0.05, 0.1, 0.2]})
    objectives = [sweeps.objective(area, unit="m^2"), sweeps.objective(reach, sense="max", unit="m"),
                  sweeps.objective(size, sense="min", unit="m"), sweeps.objective(never, sense="max")]
    return pkm.sweep("rrr3", space, objectives, scheduler="serial", progress=False)


def test_with_one_sensed_objective_only_the_parameter_figure_is_drawn(result, tmp_path):
    """A front needs two objectives with a sense: with one, a single PNG, sweep_parameters.png, with no figure
    problem (units on the axes, every plotted set in the legend)."""
    with inspected(paper=False) as found:
        paths = figures.plot(_without(result, "size", "never"), tmp_path)
    assert [p.name for p in paths] == ["sweep_parameters.png"] and found == {"sweep_parameters": []}
    assert paths[0].stat().st_size > 5_000


def test_the_objectives_with_a_sense_get_a_front(result, tmp_path):
    """The objectives with a sense (reach, size; not area, and never, which has no value) are paired: both figures,
    no problem; naming an objective without a sense for the front is refused."""
    with inspected(paper=False) as found:
        paths = figures.plot(_without(result, "never"), tmp_path)
    assert [p.name for p in paths] == ["sweep_parameters.png", "sweep_pareto.png"]
    assert found == {"sweep_parameters": [], "sweep_pareto": []}
    with pytest.raises(InvalidInputError, match="area has no sense"):
        figures.plot(_without(result, "size"), tmp_path, pareto=["area", "reach"])


def test_labels_carry_units_and_senses(result):
    """A parameter's label has its unit from the manifest; an objective's its unit and, with a sense, which way is
    better; no unit is '-'."""
    assert figures._label(result, "a") == "a [m]"
    assert figures._label(result, "reach") == "reach [m] (higher is better)"
    assert figures._label(result, "area") == "area [m^2]"
    assert figures._family_title(result) == "rrr3"


def test_nothing_to_plot_is_refused(result, tmp_path):
    """A result without objectives is an InvalidInputError before any figure is made."""
    bare = _without(result, "area", "reach", "size", "never")
    with pytest.raises(InvalidInputError, match="nothing to plot"):
        figures.plot(bare, tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_the_best_designs_are_written_as_specs_that_load(result, tmp_path):
    """The two best by size (smallest a + h: designs 0 and 1) as best1/best2 closure specs whose parameters are the
    designs'; an objective no design has a value of is a SweepError."""
    paths = figures.write_best(result, "size", tmp_path, n=2)
    assert [p.name for p in paths] == ["best1.closures.toml", "best2.closures.toml"]
    assert [(pkm.load(p).spec.parameters["a"], pkm.load(p).spec.parameters["h"]) for p in paths] == [(0.3, 0.1),
                                                                                                      (0.4, 0.05)]
    with pytest.raises(SweepError):
        figures.write_best(result, "never", tmp_path)
