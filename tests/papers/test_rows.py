"""The row contract shared by the paper studies."""

import math

import pytest

from pkm import papers
from pkm.errors import InvalidInputError, UnknownNameError


def test_numeric_rows_match_within_their_tolerance():
    """|computed - published| <= tolerance is a match; beyond it, or non-finite, is not."""
    assert papers.Row("x", 1.0, 1.04, "N", 0.05, "Fig. 1").matches is True
    assert papers.Row("x", 1.0, 1.06, "N", 0.05, "Fig. 1").matches is False
    assert papers.Row("x", 1.0, math.nan, "N", 0.05, "Fig. 1").matches is False
    assert papers.Row("x", 1.0, 2.0, "N", None, "Fig. 1").matches is None


def test_qualitative_rows_compare_by_equality_and_serialise():
    """Booleans and strings match when equal; rows without a published value compare to nothing."""
    row = papers.Row("x", True, True, "", None, "sec. 5")
    assert row.matches is True and row.to_dict()["matches"] is True
    assert papers.Row("x", "1,8", "1,8", "", None, "Fig. 8").matches is True
    assert papers.Row("x", None, 3.0, "", None, "").matches is None


def test_unknown_paper_names_are_refused():
    with pytest.raises(UnknownNameError):
        papers.module("stewart")


def test_bounds_compare_in_their_direction():
    """A published bound or baseline: "<=" matches at or under it, ">=" at or over it."""
    assert papers.Row("x", 860, 333, "", None, "sec. 4", relation="<=").matches is True
    assert papers.Row("x", 0.1, 0.2, "", None, "sec. 5", relation="<=").matches is False
    assert papers.Row("x", 0.0, 0.5, "", None, "Fig. 9", relation=">=").matches is True
    with pytest.raises(InvalidInputError, match="relation"):
        papers.Row("x", 1, 1, "", None, "", relation="~")
