"""Shared fixtures: mechanisms built once per session; the test-only toy mechanism registered.

``tests/fivebar`` is a fifth mechanism that exists only here: registering it (one line) puts it
through every test that iterates the registry (generic core, property tests, fuzzing, scenes),
which proves that a mechanism is one folder plus one registry entry.
"""

from __future__ import annotations

import pytest

from pkm.mechanisms import MechanismDefinition, module, register

register(MechanismDefinition("fivebar", "toy planar five-bar (tests only)", "tests.fivebar", task_scale=(0.03, 0.0, 0.0)))


@pytest.fixture(scope="session")
def built():
    """``built(name)``: the reference design of a mechanism, generated from its parameters, cached."""
    cache = {}

    def get(name: str):
        if name not in cache:
            cache[name] = module(name).build()
        return cache[name]

    return get
