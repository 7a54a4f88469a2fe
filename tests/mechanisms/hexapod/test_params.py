"""pkm.mechanisms.hexapod.params: the hexapod's design dataclass holds the paper's Table 1 values, documents a unit
for every field, refuses bad lengths, masses, layouts and home rotations naming the field, and its leg frames are
the rotations the paper's equations use."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pkm.mechanisms.hexapod import params as hp
from tests.mechanisms.params_contract import (
    NOT_POSITIVE,
    check_documented_defaults,
    check_refused,
    check_units_metadata,
)


def test_defaults_are_table_1_of_the_paper():
    """Sanchez-Alonso et al. 2016, Table 1: Rf 50, Rr 150, R2 450, H0 200, LA 200, LB 400, h 34, r 50 mm; legs at
    35, 155, 275, 25, 145, 265 deg; sector layout, level platform, beta 0."""
    p = hp.HexapodParams()
    assert (p.Rf, p.Rr, p.R2, p.H0, p.LA, p.LB, p.h, p.r) == (0.050, 0.150, 0.450, 0.200, 0.200, 0.400, 0.034, 0.050)
    np.testing.assert_allclose(np.degrees(p.theta), [35, 155, 275, 25, 145, 265], atol=1e-12)
    assert (p.layout, p.home_rotation, p.home_position, p.home_beta) == ("sector", None, None, 0.0)
    assert hp.Params is hp.HexapodParams and hp.ACTUATED[-1] == "beta_1" and len(hp.ACTUATED) == 7


def test_the_docstring_states_the_defaults_and_the_units_of_every_field():
    """The values in the Attributes section (theta's six angles too) are the defaults; each [unit] is its metadata's."""
    check_documented_defaults(hp.HexapodParams, {"Rf", "Rr", "R2", "H0", "LA", "LB", "h", "r", "theta", "link_radius"})
    check_units_metadata(hp.HexapodParams)


@pytest.mark.parametrize("field", ["Rf", "Rr", "R2", "LA", "LB", "h", "r", "m_recon", "m_arm", "m_rod", "m_platform",
                                   "link_radius"])
def test_lengths_and_masses_must_be_positive_finite_and_not_absurd(field):
    """0, negatives, NaN, +-inf and 2e6 are each refused naming the field."""
    for bad in NOT_POSITIVE:
        check_refused(hp.HexapodParams, field, bad)


@pytest.mark.parametrize("field", ["H0", "home_beta"])
def test_signed_quantities_may_be_negative_or_zero_but_must_be_finite(field):
    """H0 (a depth) and home_beta (an angle) take any sign; NaN, inf and 2e6 are refused naming the field."""
    assert getattr(hp.HexapodParams(**{field: -0.1}), field) == -0.1
    assert getattr(hp.HexapodParams(**{field: 0.0}), field) == 0.0
    for bad in (math.nan, math.inf, -2e6):
        check_refused(hp.HexapodParams, field, bad)


def test_layout_must_be_a_known_name():
    """Only 'sector' and 'literal' (the two readings of the paper's platform) are layouts; the error lists them."""
    assert set(hp.LAYOUTS) == {"sector", "literal"}
    hp.HexapodParams(layout="literal")
    err = check_refused(hp.HexapodParams, "layout", "Sector")
    assert "['literal', 'sector']" in str(err)


def test_home_rotation_tolerance_is_that_of_printed_matrices():
    """A home rotation off orthonormal by less than HOME_ROTATION_TOL (1e-2) is accepted (a matrix printed to a few
    digits), by more it is refused naming home_rotation."""
    c, s = math.cos(0.3), math.sin(0.3)
    R = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    hp.HexapodParams(home_rotation=tuple((R + 0.002).ravel()))
    err = check_refused(hp.HexapodParams, "home_rotation", tuple((R * 1.05).ravel()))
    assert "rotation" in str(err)


@pytest.mark.parametrize("theta_deg", [35.0, 155.0, 275.0, -90.0])
def test_leg_frame_is_ry_of_minus_theta(theta_deg):
    """leg_frame(th) is a rotation whose y column is the hexapod's axis Y and whose e_r column is (cos th, 0, sin th)
    (Ry(-th), as stated; to 1e-15)."""
    th = math.radians(theta_deg)
    L = hp.leg_frame(th)
    np.testing.assert_allclose(L.T @ L, np.eye(3), atol=1e-15)
    assert np.linalg.det(L) == pytest.approx(1.0, abs=1e-15)
    np.testing.assert_allclose(L[:, 1], [0.0, 1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(L[:, 0], [math.cos(th), 0.0, math.sin(th)], atol=1e-15)


def test_branch_signs():
    """elbow_out is the default, with negative knee angles; elbow_in positive."""
    assert hp.BRANCHES == {"elbow_out": -1, "elbow_in": 1} and hp.DEFAULT_BRANCH == "elbow_out"
