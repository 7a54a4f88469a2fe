"""Shared, expensive rows of the identification tests: an optimised excitation per mechanism, built once a run."""

from __future__ import annotations

import functools

from pkm.core.identification.excitation import Excitation, excite
from tests.core.dynamics.test_model import mechanism


@functools.cache
def excitation(name: str) -> Excitation:
    """The excitation the tests share (10 s period, 5 harmonics, 60 samples; at most 30 SLSQP iterations, 8 for
    the Gough-Stewart's 66 coefficients: each iteration differentiates the condition number by 66 evaluations)."""
    return excite(mechanism(name), period=10.0, max_iter=8 if mechanism(name).na > 3 else 30)
