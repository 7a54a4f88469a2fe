"""Shared fixtures: mechanisms built once per session; the test-only toy mechanism registered; one folder of
compiled twin kernels for the whole session (``PKM_CACHE_DIR``, inherited by the subprocesses the tests start), so
that a kernel is compiled once and nothing is written to the user's cache.

``tests/fivebar`` is a mechanism that exists only here: registering it (one line) puts it
through every test that iterates the registry (generic core, property tests, fuzzing, scenes),
which proves that a mechanism is one folder plus one registry entry.
"""

from __future__ import annotations

import os

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


@pytest.fixture(scope="session", autouse=True)
def _twin_cache(tmp_path_factory):
    previous = os.environ.get("PKM_CACHE_DIR")
    os.environ["PKM_CACHE_DIR"] = str(tmp_path_factory.mktemp("twin-cache"))
    yield
    if previous is None:
        os.environ.pop("PKM_CACHE_DIR", None)
    else:
        os.environ["PKM_CACHE_DIR"] = previous
