"""The ``case`` fixture of the tests of pkm.viz: every registered mechanism, its scene and two configurations."""

from __future__ import annotations

import pytest

import pkm
from pkm import viz
from tests.viz.helpers import assembled


@pytest.fixture(scope="module", params=pkm.MECHANISMS)
def case(request):
    """(mechanism, its scene, the reference and a second assembled configuration)."""
    mech = pkm.load(request.param)
    return mech, viz.Scene.from_mechanism(mech), [mech.q_reference, assembled(mech)]
