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
    is its metadata's (branch, an integer, has none)."""
    check_documented_defaults(rp.Rrr3Params, {"a", "b", "h", "H", "link_radius", "platform_thickness"})
    check_units_metadata(rp.Rrr3Params)


@pytest.mark.parametrize("field", ["a", "b", "h", "H", "m_proximal", "m_distal", "m_platform", "link_radius",
                                   "platform_thickness"])
def test_lengths_and_masses_must_be_positive_finite_and_not_absurd(field):
    """0, negatives, NaN, +-inf and 2e6 are each refused naming the field."""
    for bad in NOT_POSITIVE:
        check_refused(rp.Rrr3Params, field, bad)


def test_the_eight_modes_are_every_sign_pattern_once():
    """MODES maps mode1..mode8 to the 8 distinct sign triples, mode1 all +; branch_signs takes k or 'modek'."""
    assert list(rp.MODES) == [f"mode{k}" for k in range(1, 9)]
    assert len(set(rp.MODES.values())) == 8 and rp.MODES["mode1"] == (1, 1, 1) and rp.MODES["mode8"] == (-1, -1, -1)
    assert all(rp.branch_signs(k) == rp.branch_signs(f"mode{k}") == rp.MODES[f"mode{k}"] for k in range(1, 9))
    assert rp.branch_signs(np.int64(3)) == rp.MODES["mode3"]
    for bad in (0, 9, True, "Mode1", None):
        with pytest.raises(InvalidInputError, match=r"1\.\.8"):
            rp.branch_signs(bad)


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


# ---------------------------------------------------------------------- the former names (deprecated in 0.2.0)
def test_the_working_mode_field_is_branch_and_mode_its_former_name():
    """The field is branch (the word of every mechanism's working modes); Rrr3Params(mode=k), pkm.design_params and
    pkm.build(..., mode=k) and the read of .mode still work for one release, each with a DeprecationWarning naming
    branch, and give the same design."""
    import dataclasses

    import pkm

    names = [f.name for f in dataclasses.fields(rp.Rrr3Params)]
    assert "branch" in names and "mode" not in names and dict(rp.Rrr3Params.RENAMED) == {"mode": "branch"}
    new = rp.Rrr3Params(a=0.45, branch=3)
    with pytest.warns(DeprecationWarning, match="'mode' is now 'branch'"):
        old = rp.Rrr3Params(a=0.45, mode=3)
    assert old == new and old.branch == 3
    with pytest.warns(DeprecationWarning, match="'mode' is now 'branch'"):
        assert new.mode == 3
    with pytest.warns(DeprecationWarning, match="'mode' is now 'branch'"):
        assert pkm.design_params("rrr3", mode=3) == rp.Rrr3Params(branch=3)
    with pytest.warns(DeprecationWarning, match="'mode' is now 'branch'"):
        mech = pkm.build("rrr3", mode=3)
    assert mech.params == rp.Rrr3Params(branch=3) and mech.spec.default_branch == "mode3"


def test_the_former_name_is_attributed_to_the_callers_line():
    """The warning names the caller's file (not pkm's), so that Python's default filters show it in a script."""
    with pytest.warns(DeprecationWarning) as record:
        rp.Rrr3Params(mode=2)
    assert record[0].filename == __file__


@pytest.mark.parametrize("value", [0, 9, True, "mode1", 1.0])
def test_a_bad_mode_under_the_former_name_is_refused_as_before(value):
    """A bad value given as mode= warns and raises the InvalidParameterError of branch=; both names at once are
    refused."""
    with pytest.raises(InvalidParameterError) as new:
        rp.Rrr3Params(branch=value)
    with pytest.warns(DeprecationWarning), pytest.raises(InvalidParameterError) as old:
        rp.Rrr3Params(mode=value)
    assert (old.value.name, str(old.value)) == (new.value.name, str(new.value)) == ("branch", str(new.value))
    with pytest.raises(InvalidInputError, match="former name of 'branch'"):
        rp.Rrr3Params(mode=2, branch=2)


def test_mode_signs_is_the_former_name_of_branch_signs():
    """mode_signs warns naming branch_signs and gives its signs; a bad mode raises the same InvalidInputError."""
    for k in (1, 3, "mode8"):
        with pytest.warns(DeprecationWarning, match="'mode_signs' is now 'branch_signs'"):
            assert rp.mode_signs(k) == rp.branch_signs(k)
    with pytest.warns(DeprecationWarning), pytest.raises(InvalidInputError, match=r"1\.\.8") as exc:
        rp.mode_signs(9)
    assert exc.value.name == "branch"


def test_the_command_line_takes_the_former_name_with_a_warning():
    """pkm ... --param mode=3 is --param branch=3, with the DeprecationWarning."""
    from pkm.cli import parse_params

    assert parse_params("rrr3", ["branch=3"]) == {"branch": 3}
    with pytest.warns(DeprecationWarning, match="'mode' is now 'branch'"):
        assert parse_params("rrr3", ["mode=3"]) == {"branch": 3}
