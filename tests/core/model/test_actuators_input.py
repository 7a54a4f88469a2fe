"""Bad drives are refused with pkm's errors, never an OverflowError or an infinite inertia (findings of the fuzz
report's ``Actuator``, ``pkm.with_actuators`` and ``spec.actuators`` entries)."""

from __future__ import annotations

import math

import pytest

import pkm
from pkm.errors import InvalidInputError, SpecError


def test_a_reflected_inertia_that_overflows_is_refused():
    """``rotor_inertia * gear_ratio**2`` beyond the floats is refused (it was inf, or Python's OverflowError from
    ``**``); a tiny rotor behind a huge ratio is still computed, without overflow on the way."""
    with pytest.raises(InvalidInputError, match="overflows") as info:
        pkm.Actuator("m", rotor_inertia=1e200, gear_ratio=1e200)
    assert info.value.name == "rotor_inertia"
    assert pkm.Actuator("m", rotor_inertia=1e-300, gear_ratio=1e200).reflected_inertia == pytest.approx(1e100)


def test_integers_beyond_the_floats_and_names_that_are_not_names():
    """An int too large for a float is an infinity: refused where a field must be finite, "none" for a limit (it
    raised OverflowError); a joint that is not a name is refused."""
    with pytest.raises(InvalidInputError, match="armature"):
        pkm.Actuator("m", armature=10**400)
    with pytest.raises(InvalidInputError, match="effort_limit"):
        pkm.Actuator("m", effort_limit=-(10**400))
    assert pkm.Actuator("m", effort_limit=10**400).effort_limit == math.inf
    with pytest.raises(InvalidInputError, match="joint"):
        pkm.Actuator(None)  # type: ignore[arg-type]


def test_with_actuators_and_the_spec_refuse_them_too():
    delta = pkm.load("delta")
    free = pkm.with_actuators(delta, {"motor_1": {"effort_limit": 10**400, "gear_ratio": 10}})
    assert free.actuators[0].effort_limit == math.inf and free.actuators[0].gear_ratio == 10.0
    with pytest.raises(InvalidInputError, match="overflows"):
        pkm.with_actuators(delta, {"motor_1": {"rotor_inertia": 1e200, "gear_ratio": 1e200}})
    text = delta.spec.to_toml() + "\n[actuators.motor_1]\nrotor_inertia = 1e300\ngear_ratio = 1e300\n"
    with pytest.raises(SpecError, match="overflows"):
        pkm.ClosureSpec.from_toml(text)
