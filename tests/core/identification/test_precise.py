"""pkm.core.identification.precise: the second route to the base parameters' rank (50 digits on the same samples)
agrees with double precision on the shipped mechanisms, and catches a rank trap that double precision misses."""

from __future__ import annotations

import math

import casadi as cs
import mpmath
import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.identification.base import base_parameters, random_states
from pkm.core.identification.precise import (
    BITS,
    DIGITS,
    MODEL_FLOOR,
    Program,
    _fixed,
    precise_regressor,
    recognise,
    to_mp,
)
from pkm.core.identification.regressor import regressor
from pkm.errors import SpecError
from tests.core.dynamics.test_model import mechanism


def test_constants_are_recognised_as_the_numbers_they_round():
    """0.4 is 2/5, cos(fl(π/2)) is 0, fl(√3/2) is √3/2, each to 50 digits; an arbitrary double is kept as it is."""
    with mpmath.workdps(DIGITS):
        two_fifths, ok = recognise(0.4)
        assert ok and abs(two_fifths - mpmath.mpf(2) / 5) < mpmath.mpf(10) ** -49
        zero, ok = recognise(math.cos(math.pi / 2))
        assert ok and zero == 0
        half_root3, ok = recognise(math.sqrt(3) / 2)
        assert ok and abs(half_root3 - mpmath.sqrt(3) / 2) < mpmath.mpf(10) ** -49
        x = 0.12345678912345678
        kept, ok = recognise(x)
        assert not ok and kept == mpmath.mpf(x)


def test_the_evaluator_runs_casadi_operations_as_casadi_does():
    """A function with every kind of operation the twin emits (and a few more) gives CasADi's own values to 1e-15
    relative when run in 50 digits; an operation it does not run is named."""
    x = cs.SX.sym("x", 3)
    y = cs.vertcat(cs.sin(x[0]) * cs.cos(x[1]) + cs.atan2(x[2], x[0]), cs.sqrt(x[2]) / x[1] - x[0] ** 2,
                   cs.fmax(x[0], x[1]) - cs.fabs(x[1]) + cs.tanh(x[2]) + cs.if_else(x[0] > 0.5, x[1], 0.0),
                   2 * x[0] - x[1] ** 3.0 + cs.exp(x[2]) * cs.log(x[2]) + 1.0 / x[0])
    f = cs.Function("f", [x], [y])
    X = np.array([[0.3, 0.7, 1.2], [1.1, -0.4, 0.5]]).T
    with mpmath.workdps(DIGITS):
        (out,) = Program(f)(to_mp(X))
    want = np.array(f(X))
    assert np.abs(out.astype(float) - want).max() <= 1e-15 * np.abs(want).max()
    g = cs.Function("g", [x], [cs.erfinv(x[0] / 10)])
    with pytest.raises(SpecError, match="does not run CasADi operation"):
        Program(g)


def test_the_precise_regressor_is_the_regressor():
    """The Delta's regressor in 50 digits, its loops closed again to 1e-45, equals the double-precision one to
    1e-12 relative (the double closure's own tolerance)."""
    mech = mechanism("delta")
    states = random_states(mech, 3, seed=4)
    W, constants, unrecognised = precise_regressor(mech, states)
    Y = np.vstack([regressor(mech, *s) for s in states])
    assert W.shape == Y.shape and 0 <= unrecognised < constants
    assert np.abs(W.astype(float) - Y).max() <= 1e-11 * np.abs(Y).max()


#: the counts of the numerical route (tests/core/identification/test_base.py), untied and tied
COUNTS = {"rrr3": (22, 10), "delta": (48, 18), "prs3": (28, 16), "gough_stewart": (106, 46)}


@pytest.mark.parametrize("name", sorted(COUNTS))
def test_both_routes_count_the_same_on_the_shipped_mechanisms(name):
    """Untied and tied, the 50-digit route finds the numerical route's count, with a gap over 1e30 (rounding at
    1e-45 and below, or the model's own rounding under 1e-15) where the numerical one has 1e11. (The hexapod's
    agreement, whose random states alone cost 8 s: the report's ``hexapod.ident`` rows, computed once per run.)"""
    mech = mechanism(name)
    for tie, count in zip((False, True), COUNTS[name]):
        base = base_parameters(mech, tie_legs=tie)
        assert len(base) == count and base.routes_agree is True
        assert base.precise is not None and base.precise.decision.gap > 1e25


def test_the_precise_route_catches_a_rank_trap():
    """Gravity tilted by 1e-12 rad makes the 3-RRR's three proximal links' first moments (mx, my: six parameters
    that a horizontal mechanism never shows) identifiable at 1e-12 of the largest pivot: under double precision's
    rounding floor (1e-10), so the numerical route says 22 with a gap that looks clear (1e9); the 50-digit route
    says 28, with its rounding 1e-45 away, and the result says the routes disagree."""
    mech = pkm.load("rrr3")
    tilt = 1e-12
    mech.model.gravity = pin.Motion(np.array([9.81 * math.sin(tilt), 0.0, -9.81 * math.cos(tilt), 0.0, 0.0, 0.0]))
    base = base_parameters(mech)
    assert len(base) == 22 and not base.decision.ambiguous and base.decision.gap > 1e8
    assert base.precise is not None and base.precise.decision.rank == 28 and base.routes_agree is False
    assert base.precise.floor == MODEL_FLOOR and base.precise.decision.gap > 1e30  # (9.81 sin 1e-12: unrecognised)


#: the report's rows (the papers' mechanisms), untied and tied
REPORTED = {"rrr3": (22, 10), "delta": (48, 18), "prs3": (28, 16), "hexapod": (109, 30)}


@pytest.mark.parametrize("paper", sorted(REPORTED))
def test_the_report_rows_count_the_base_parameters_by_both_routes(paper):
    """``<paper>.ident.n_base`` and ``.n_base_tied`` give the counts (the hexapod's 248 parameters: 109, tied 30),
    ``.routes_agree`` that the 50-digit route found them too (the rows are computed once per run, on disk)."""
    from pkm import papers

    rows = {r.id: r for r in papers.module(paper).reproduce() if ".ident." in r.id}
    assert (rows[f"{paper}.ident.n_base"].computed, rows[f"{paper}.ident.n_base_tied"].computed) == REPORTED[paper]
    assert rows[f"{paper}.ident.routes_agree"].computed is True
    assert "agree" in rows[f"{paper}.ident.n_base"].note


def test_the_qr_fixed_point_rounds_as_mpmath_nint():
    """The QR's fixed point (``_fixed``, on the raw ``mpf``) is ``int(mpmath.nint(x * 2**BITS))`` to the last bit:
    on random numbers of every scale, on exact ties (half-integers after the shift: to even), zero and one."""
    rng = np.random.default_rng(3)
    with mpmath.workdps(DIGITS):
        xs = [mpmath.mpf(float(v)) / 3 * mpmath.mpf(10) ** -int(e)
              for v, e in zip(rng.uniform(-1.0, 1.0, 300), rng.integers(0, 75, 300))]
        xs += [mpmath.mpf(k) / 2 ** (BITS + 1) for k in range(-9, 10)] + [mpmath.mpf(0), mpmath.mpf(1), mpmath.mpf(-1)]
        assert [_fixed(x) for x in xs] == [int(mpmath.nint(x * (1 << BITS))) for x in xs]
        assert _fixed(mpmath.mpf(3) / 2 ** (BITS + 1)) == 2 and _fixed(mpmath.mpf(5) / 2 ** (BITS + 1)) == 2
