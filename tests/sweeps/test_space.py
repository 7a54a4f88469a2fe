"""Design spaces (pkm.sweeps.space): grids, samples with recorded seeds, tables; units at the edges."""

from __future__ import annotations

import numpy as np
import pytest

from pkm import sweeps
from pkm.errors import InvalidInputError, UnitError, UnknownNameError
from pkm.sweeps.family import RegisteredFamily

UNITS = RegisteredFamily("rrr3").units


def test_grid_is_the_product_in_si_first_parameter_slowest():
    d = sweeps.grid(a="30cm:80cm:11", h=[0.1, "15cm"]).designs(UNITS)
    assert d.names == ("a", "h") and d.values.shape == (22, 2)
    np.testing.assert_allclose(d.values[:3], [[0.30, 0.10], [0.30, 0.15], [0.35, 0.10]], rtol=0, atol=1e-15)
    assert not d.values.flags.writeable and d.seed is None


def test_samples_stay_in_their_bounds_and_reproduce_from_the_recorded_seed():
    for draw in (sweeps.sobol, sweeps.latin_hypercube):
        first = draw(64, a="30cm:80cm", h="5cm:20cm").designs(UNITS)
        assert first.seed is not None and first.description["seed"] == first.seed  # drawn, and recorded
        again = draw(64, seed=first.seed, a="30cm:80cm", h="5cm:20cm").designs(UNITS)
        np.testing.assert_array_equal(again.values, first.values)
        assert np.all((first.values >= [0.30, 0.05]) & (first.values <= [0.80, 0.20]))
        other = draw(64, seed=first.seed + 1, a="30cm:80cm", h="5cm:20cm").designs(UNITS)
        assert not np.array_equal(other.values, first.values)
    lhs = sweeps.latin_hypercube(10, seed=3, a=(0.3, 0.8)).designs(UNITS).values[:, 0]
    assert sorted(np.floor((lhs - 0.3) / 0.05).astype(int)) == list(range(10))  # one sample per stratum


def test_tables_from_rows_columns_and_csv(tmp_path):
    rows = sweeps.table([{"a": "40cm", "h": 0.1}, {"a": 0.5, "h": "20cm"}]).designs(UNITS)
    cols = sweeps.table({"a": [0.4, 0.5], "h": [0.1, 0.2]}).designs(UNITS)
    path = tmp_path / "designs.csv"
    path.write_text("a,h\n40cm,0.1\n0.5,20cm\n", encoding="utf-8")
    from_csv = sweeps.table(path).designs(UNITS)
    for d in (cols, from_csv):
        np.testing.assert_allclose(d.values, rows.values, rtol=0, atol=1e-15)


@pytest.mark.parametrize("space,error,match", [
    (lambda: sweeps.grid(a="30cm:80cm"), InvalidInputError, "START:STOP:COUNT"),
    (lambda: sweeps.grid(a="3deg:5deg:3"), UnitError, "deg"),
    (lambda: sweeps.sobol(8, a="80cm:30cm"), InvalidInputError, "LOW < HIGH"),
    (lambda: sweeps.sobol(0, a="30cm:80cm"), InvalidInputError, "number of samples"),
    (lambda: sweeps.grid(**{f"p{k}": "0:1:100" for k in range(5)}), InvalidInputError, "sample the space"),
    (lambda: sweeps.table([{"a": 1}, {"h": 2}]), InvalidInputError, "row 1"),
    (lambda: sweeps.grid(a="30cm:40cm:\u00b2"), InvalidInputError, "COUNT"),  # (a digit to str.isdigit)
    (lambda: sweeps.grid(a="30cm:40cm:1000000000000"), InvalidInputError, "COUNT"),
    (lambda: sweeps.grid(a="-1e308:1e308:3"), InvalidInputError, "overflows"),
])
def test_malformed_spaces_are_refused_with_the_parameter_named(space, error, match):
    with pytest.raises(error, match=match):
        s = space()
        s.designs(lambda n: ({"length"}, "m"))


def test_unknown_parameters_list_the_valid_ones():
    with pytest.raises(UnknownNameError, match="H") as exc:
        UNITS("R")
    assert "a" in exc.value.valid and "branch" in exc.value.valid and "home" not in exc.value.valid
