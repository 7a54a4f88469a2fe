"""The architecture change of issue 13 changes no row of the report: same ids, published values and match flags,
ours within 1e-12 relative of the rows saved before it (``tests/data/report_rows_before_issue13.json``)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from pkm import papers

BEFORE = json.loads((Path(__file__).parent / "data" / "report_rows_before_issue13.json").read_text())["papers"]


@pytest.mark.parametrize("paper", sorted(BEFORE))
def test_rows_equal_the_rows_before_the_architecture_change(paper):
    rows = papers.module(paper).reproduce()
    assert [r.id for r in rows] == [r["id"] for r in BEFORE[paper]]
    for row, old in zip(rows, BEFORE[paper]):
        assert (row.published, row.unit, row.matches) == (old["published"], old["unit"], old["matches"]), row.id
        new = row.computed
        if isinstance(new, float) and isinstance(old["computed"], (int, float)) and not isinstance(new, bool):
            assert math.isclose(new, old["computed"], rel_tol=1e-12, abs_tol=1e-300), (row.id, new, old["computed"])
        else:
            assert new == old["computed"], row.id
