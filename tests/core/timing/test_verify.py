"""A plan checked by pkm.inverse_dynamics at 10x its resolution and by a tracking simulation."""

from __future__ import annotations

import pkm

from .conftest import ARC


def test_plan_with_payload_and_motor_line_holds_when_recomputed(delta):
    plan = pkm.time_optimal(delta, ARC, points=24, payload=1.0, limits={"omega0": 8.0, "speed": 20.0})
    check = pkm.verify_time_optimal(plan, dt=plan.cycle_time / 300)
    assert check.holds and 0.99 < check.effort_usage <= 1.0 + 1e-6
    assert len(check.inactive) <= 1  # (the switch from accelerating to braking)
    assert check.event is None and check.simulated_duration >= plan.cycle_time * (1 - 1e-9)
    assert check.task_error < 1e-3  # [m]: the PD tracks the plan
