"""Shared fixtures: mechanisms built once per session."""

from __future__ import annotations

import pytest

from pkm.mechanisms import module


@pytest.fixture(scope="session")
def built():
    """``built(name)``: the reference design of a mechanism, generated from its parameters, cached."""
    cache = {}

    def get(name: str):
        if name not in cache:
            cache[name] = module(name).build()
        return cache[name]

    return get
