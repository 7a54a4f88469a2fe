"""pkm.mechanisms.prs3.params: the 3-PRS design dataclass takes its defaults from Table 2 as stored, documents a
unit for every field, refuses bad lengths, masses, rail angles, actuations and inertias naming the field; Table 2's
reader refuses a damaged file; ``as_task`` checks the task vector. (Table 2's values against the paper are pinned in
``test_kinematics.py``.)"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from pkm.errors import InvalidInputError, SpecError
from pkm.mechanisms.prs3 import params as pp
from tests.mechanisms.params_contract import (
    NOT_POSITIVE,
    check_documented_defaults,
    check_refused,
    check_units_metadata,
)

#: Field -> its Table 2 key.
FROM_TABLE2 = {"gamma": "gamma", "l": "l", "h": "h", "g": "g", "m_slider": "m1", "m_coupler": "m2",
               "m_platform": "mp", "Ixx3": "Ixx3", "Iyy3": "Iyy3", "Izz3": "Izz3", "Ixy3": "Ixy3", "Ixz3": "Ixz3",
               "Iyz3": "Iyz3"}


def test_defaults_are_the_stored_table_2():
    """Every numeric default is Table 2's entry (read from dynamics/prs3_table2.toml), slider actuation, no pose."""
    p, t = pp.Prs3Params(), pp.table2()
    assert {f: getattr(p, f) for f in FROM_TABLE2} == {f: t[k] for f, k in FROM_TABLE2.items()}
    assert (p.actuation, p.reference) == ("P", None) and pp.Params is pp.Prs3Params
    np.testing.assert_array_equal(p.platform_inertia, np.diag([0.3125, 0.3125, 0.625]))


def test_the_docstring_states_the_defaults_and_the_units_of_every_field():
    """The values in the Attributes section (l 1 m, h 0.5 m, g 1 m, masses) are the defaults; each [unit] is its
    metadata's (the Table 2 fields' metadata is written by _from_table2)."""
    check_documented_defaults(pp.Prs3Params, {"l", "h", "g", "m_slider", "m_coupler", "m_platform", "link_radius",
                                             "slider_size", "platform_thickness", "base_thickness"})
    check_units_metadata(pp.Prs3Params)


def test_table_2_is_read_only():
    """The cached table cannot be changed by a caller (every later Prs3Params would get the change)."""
    with pytest.raises(TypeError):
        pp.table2()["l"] = 2.0  # type: ignore[index]


@pytest.mark.parametrize("field", ["l", "h", "g", "m_platform", "link_radius", "slider_size", "platform_thickness",
                                   "base_thickness"])
def test_lengths_and_platform_mass_must_be_positive_finite_and_not_absurd(field):
    """0, negatives, NaN, +-inf and 2e6 are each refused naming the field."""
    for bad in NOT_POSITIVE:
        check_refused(pp.Prs3Params, field, bad)


@pytest.mark.parametrize("field", ["m_slider", "m_coupler"])
def test_link_masses_may_be_zero_but_not_negative(field):
    """A massless slider or coupler is a valid (idealised) design; a negative or non-finite mass is refused."""
    assert getattr(pp.Prs3Params(**{field: 0.0}), field) == 0.0
    for bad in (-0.1, math.nan, math.inf):
        check_refused(pp.Prs3Params, field, bad)


def test_rail_angle_lies_strictly_between_0_and_pi():
    """gamma in (0, pi): both ends refused naming gamma and the interval; just inside accepted."""
    for bad in (0.0, math.pi, -0.2):
        assert "(0, pi)" in str(check_refused(pp.Prs3Params, "gamma", bad))
    assert pp.Prs3Params(gamma=1e-3).gamma == 1e-3


def test_actuation_is_p_or_r():
    """'P' (sliders) and 'R' (knees) are the actuations; others (lower case too) are refused."""
    assert pp.ACTUATIONS == {"P": "slider", "R": "knee"}
    for bad in ("p", "PR", 1):
        check_refused(pp.Prs3Params, "actuation", bad)


def test_platform_inertia_must_be_physical():
    """A negative principal moment, or moments breaking the triangle inequality (after rotation by the products
    too), is refused as Ixx3 (the inertia's first field); products that keep it physical (the default flat disc is on
    the triangle's edge: a thicker one) are accepted and placed symmetrically."""
    check_refused(pp.Prs3Params, "Ixx3", 1.0)  # 1.0 > 0.3125 + 0.625
    check_refused(pp.Prs3Params, "Ixx3", 0.3125, Ixy3=0.5)  # eigenvalues of [[.3125, .5], [.5, .3125]]: one < 0
    p = pp.Prs3Params(Izz3=0.5, Ixy3=0.01, Ixz3=-0.02)
    I = p.platform_inertia
    np.testing.assert_array_equal(I, I.T)
    assert (I[0, 1], I[0, 2], I[1, 2]) == (0.01, -0.02, 0.0)


@pytest.mark.parametrize("y, match", [((0.8, 0.0), "3 finite numbers"), ((0.8, math.nan, 0.0), "3 finite numbers"),
                                      ((0.8, math.pi / 2, 0.0), "pitch beta"), ((0.8, -2.0, 0.0), "pitch beta"),
                                      ("0.8", "3 numbers")])
def test_as_task_refuses_other_shapes_non_finite_values_and_gimbal_lock(y, match):
    """A task vector is (z_p, beta, phi), finite, with |beta| < pi/2 (Z-Y-X angles), else InvalidInputError."""
    with pytest.raises(InvalidInputError, match=match) as info:
        pp.as_task(y, "y")
    assert info.value.name == "y"


def test_a_reference_is_checked_as_a_task_and_stored_as_floats():
    """reference passes through as_task: stored as a tuple of floats, or refused as an InvalidParameterError."""
    assert pp.Prs3Params(reference=np.array([0.81, 0, 0])).reference == (0.81, 0.0, 0.0)
    check_refused(pp.Prs3Params, "reference", (0.81, 1.6, 0.0))


@pytest.mark.parametrize("text, match", [
    ('format = "pkm.prs3_table2/2"\n', "this pkm reads 'pkm.prs3_table2/1'"),
    ('format = "pkm.prs3_table2/1"\n[kinematics]\ngamma = 1.0\nl = 1.0\nh = 0.5\ng = 1.0\n', r"missing table \[dynamics\]"),
    ('format = "pkm.prs3_table2/1"\n[kinematics]\ngamma = 1.0\nl = true\nh = 0.5\ng = 1.0\n', r"\[kinematics\]\.l must be"),
    ('format = "pkm.prs3_table2/1"\n[kinematics]\ngamma = nan\nl = 1.0\nh = 0.5\ng = 1.0\n', r"\.gamma must be a finite"),
    ("not toml [", None),
])
def test_a_damaged_table_2_file_is_a_spec_error(monkeypatch, tmp_path, text, match):
    """Another format, a missing section, a boolean or a NaN entry, or text that is not TOML: SpecError naming the
    file (the cache is cleared before and after, so the real table is read again)."""
    path = tmp_path / "prs3_table2.toml"
    path.write_text(text, encoding="utf-8")
    monkeypatch.setattr(pp, "dynamics_path", lambda name: path)
    pp.table2.cache_clear()
    try:
        with pytest.raises(SpecError, match=match) as info:
            pp.table2()
        assert info.value.source == str(path)
    finally:
        pp.table2.cache_clear()
    monkeypatch.undo()
    assert pp.table2()["l"] == 1.0


def test_every_table_2_key_has_a_field_or_is_the_dynamics_model_s():
    """The kinematic keys and the masses/inertias are fields; Izz2, mx2, my2 (the coupler's) are derived from them
    by the dynamics model, not fields."""
    fields = {f.name for f in dataclasses.fields(pp.Prs3Params)}
    assert set(FROM_TABLE2) <= fields
    assert set(pp.TABLE2_KEYS["kinematics"]) | set(pp.TABLE2_KEYS["dynamics"]) == set(FROM_TABLE2.values()) | {
        "Izz2", "mx2", "my2"}
