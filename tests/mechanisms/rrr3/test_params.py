"""pkm.mechanisms.rrr3.params: the planar 3-RRR design dataclass holds the paper's sec. III design, documents a
unit for every field, refuses bad lengths and masses naming the field; its working-mode table and base triangle
are pinned."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pkm.errors import InvalidInputError, InvalidParameterError
from pkm.mechanisms.rrr3 import params as rp
from tests.mechanisms.params_contract import (
    NOT_POSITIVE,
    check_documented_defaults,
    check_refused,
    check_units_metadata,
)


def test_the_docstring_states_the_defaults_and_the_units_of_every_field():
    """The values in the Attributes section (a, b 40 cm, h 10 cm, H 100 cm) are the defaults; each field's [unit]
    is its metadata's (mode, an integer, has none)."""
    check_documented_defaults(rp.Rrr3Params, {"a", "b", "h", "H"})
    check_units_metadata(rp.Rrr3Params)


@pytest.mark.parametrize("field", ["a", "b", "h", "H", "m_proximal", "m_distal", "m_platform"])
def test_lengths_and_masses_must_be_positive_finite_and_not_absurd(field):
    """0, negatives, NaN, +-inf and 2e6 are each refused naming the field."""
    for bad in NOT_POSITIVE:
        check_refused(rp.Rrr3Params, field, bad)


def test_the_eight_modes_are_every_sign_pattern_once():
    """MODES maps mode1..mode8 to the 8 distinct sign triples, mode1 all +; mode_signs takes k or 'modek'."""
    assert list(rp.MODES) == [f"mode{k}" for k in range(1, 9)]
    assert len(set(rp.MODES.values())) == 8 and rp.MODES["mode1"] == (1, 1, 1) and rp.MODES["mode8"] == (-1, -1, -1)
    assert all(rp.mode_signs(k) == rp.mode_signs(f"mode{k}") == rp.MODES[f"mode{k}"] for k in range(1, 9))
    assert rp.mode_signs(np.int64(3)) == rp.MODES["mode3"]
    for bad in (0, 9, True, "Mode1", None):
        with pytest.raises(InvalidInputError, match=r"1\.\.8"):
            rp.mode_signs(bad)


@pytest.mark.parametrize("H", [1.0, 0.37])
def test_base_vertices_form_an_equilateral_triangle_of_side_h_around_the_centroid(H):
    """P at the origin, Q on +x: every side is H (1e-15 relative) and base_centroid is the vertices' mean."""
    p = rp.Rrr3Params(H=H)
    V = rp.base_vertices(p)
    assert V.shape == (3, 2) and tuple(V[0]) == (0.0, 0.0) and V[1, 1] == 0.0 and V[1, 0] > 0
    sides = [np.linalg.norm(V[i] - V[(i + 1) % 3]) for i in range(3)]
    assert sides == pytest.approx([H] * 3, rel=1e-15)
    np.testing.assert_allclose(rp.base_centroid(p), V.mean(axis=0), rtol=1e-15, atol=1e-16)
    assert rp.SQRT3 == math.sqrt(3.0)


def test_base_geometry_refuses_another_object():
    """base_vertices and base_centroid take an Rrr3Params only, naming the class to pass."""
    for fn in (rp.base_vertices, rp.base_centroid):
        with pytest.raises(InvalidParameterError, match="Rrr3Params"):
            fn({"H": 1.0})
