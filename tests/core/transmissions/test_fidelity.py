"""Fidelity, the short version (0.2 s of the chirp on the humanoid ankle; the 2 s table on the ankle and the knee is
``tools/transmission_fidelity.py``'s): the serial-equivalent model in MuJoCo with pkm's ΔM and Δh applied follows the
closed loop simulated by pkm.simulate to 1e-9 rad (measured 1e-12), where the constant-armature model is off by
millimetre-radians."""

from __future__ import annotations

import pytest

from pkm.core.transmissions import fidelity as F
from pkm.core.transmissions.fidelity import fidelity, table
from pkm.core.transmissions.serial import serial_equivalent
from tests.core.transmissions.robots import transmissions


def test_serial_plus_delta_follows_the_closed_loop_and_constant_armature_does_not(monkeypatch):
    """(The serial-equivalent and MuJoCo models built once for the table's runs, (b) and (c).)"""
    pytest.importorskip("mujoco")  # the bench extra: MuJoCo runs the serial model, not a dependency
    built = []
    monkeypatch.setattr(F, "serial_equivalent", lambda *a, **k: built.append(a) or serial_equivalent(*a, **k))
    t = transmissions("humanoid_ankle")[0]
    t.__dict__.pop("_fidelity_serial", None)
    (row,) = fidelity(t, duration=0.2, dt=2e-3, which=("chirp",), integrators=False)
    assert len(built) == 1
    assert row.motion > 0.01  # (the foot moves: a degree or more)
    assert row.exact <= 1e-9
    assert row.constant_armature > 1e-4  # (the constant armature misses ΔM's change and Δh: visible in 0.2 s)
    assert "| foot | chirp |" in table([row])
