"""pkm.mechanisms.gough_stewart.params: the Gough-Stewart design dataclass holds the textbook semi-regular hexagons
its module states, documents a unit for every field, normalises and checks its six points, its leg stroke, masses
and reference pose, naming the field."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pkm.mechanisms.gough_stewart import params as gp
from tests.mechanisms.params_contract import NOT_POSITIVE, check_refused, check_units_metadata


def _angles_deg(points: np.ndarray) -> np.ndarray:
    return np.sort(np.degrees(np.arctan2(points[:, 1], points[:, 0])) % 360.0)


def test_defaults_are_the_semi_regular_hexagons_of_the_module_doc():
    """Base: six points on a 0.5 m circle at 0/120/240 +- 15 deg; platform: on a 0.3 m circle at +- 40 deg; all at
    z = 0; legs 0.5 to 1 m; masses 1 and 5 kg; no stated pose."""
    p = gp.GoughStewartParams()
    B, P = p.base_points, p.platform_points
    assert B.shape == P.shape == (6, 3) and not B[:, 2].any() and not P[:, 2].any()
    np.testing.assert_allclose(np.linalg.norm(B, axis=1), 0.5, rtol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(P, axis=1), 0.3, rtol=1e-15)
    np.testing.assert_allclose(_angles_deg(B), sorted((c + s * 15) % 360 for c in (0, 120, 240) for s in (-1, 1)),
                               atol=1e-12)
    np.testing.assert_allclose(_angles_deg(P), sorted((c + s * 40) % 360 for c in (0, 120, 240) for s in (-1, 1)),
                               atol=1e-12)
    assert (p.leg_min, p.leg_max, p.m_leg, p.m_platform, p.reference) == (0.5, 1.0, 1.0, 5.0, None)


def test_every_field_documents_its_units():
    """Each field's [unit] in the docstring is its metadata's; the point fields have length 6."""
    check_units_metadata(gp.GoughStewartParams)


def test_points_may_be_given_flat_or_as_arrays_and_are_stored_as_tuples():
    """18 numbers in leg order, or a (6, 3) array, become six (x, y, z) tuples of floats."""
    flat = np.asarray(gp.BASE).ravel().tolist()
    p = gp.GoughStewartParams(base=flat, platform=np.asarray(gp.PLATFORM))
    assert p.base == gp.BASE and p.platform == gp.PLATFORM
    assert isinstance(p.base, tuple) and all(type(c) is float for row in p.platform for c in row)


@pytest.mark.parametrize("bad", [np.zeros((5, 3)), np.zeros(17), "hexagon", [[0, 0, math.nan]] + [[1, 0, 0]] * 5,
                                 np.full((6, 3), 2e3)])
@pytest.mark.parametrize("field", ["base", "platform"])
def test_malformed_point_sets_are_refused_naming_the_field(field, bad):
    """Another count, text, a NaN or coordinates beyond 1 km: refused, saying what six points are."""
    assert "six points" in str(check_refused(gp.GoughStewartParams, field, bad))


@pytest.mark.parametrize("field", ["base", "platform"])
def test_collinear_points_are_refused(field):
    """Six points on a line leave the platform free to turn about it: refused naming the field."""
    line = [(0.1 * k, 0.05 * k, 0.0) for k in range(6)]
    assert "collinear" in str(check_refused(gp.GoughStewartParams, field, line))


@pytest.mark.parametrize("field", ["leg_min", "leg_max", "m_platform"])
def test_stroke_and_platform_mass_must_be_positive_finite_and_not_absurd(field):
    """0, negatives, NaN, +-inf and 2e6 are each refused naming the field."""
    for bad in NOT_POSITIVE:
        check_refused(gp.GoughStewartParams, field, bad)


def test_the_stroke_must_be_an_interval_and_massless_legs_are_allowed():
    """leg_max must exceed leg_min (equal refused, as leg_max); m_leg may be 0 but not negative."""
    assert "must exceed leg_min" in str(check_refused(gp.GoughStewartParams, "leg_max", 0.5))
    assert gp.GoughStewartParams(m_leg=0.0).m_leg == 0.0
    check_refused(gp.GoughStewartParams, "m_leg", -1.0)


def test_reference_is_six_finite_numbers_stored_as_floats():
    """A reference (x, y, z, roll, pitch, yaw) is kept as six floats; another length or a NaN is refused."""
    assert gp.GoughStewartParams(reference=np.array([0, 0, 0.7, 0, 0, 0])).reference == (0.0, 0.0, 0.7, 0.0, 0.0, 0.0)
    for bad in ((0.0, 0.0, 0.7), (0.0, 0.0, math.nan, 0.0, 0.0, 0.0), "up"):
        check_refused(gp.GoughStewartParams, "reference", bad)
