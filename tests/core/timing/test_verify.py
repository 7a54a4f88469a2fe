"""A plan checked by pkm.inverse_dynamics at 10x its resolution and by a tracking simulation."""

from __future__ import annotations

import pkm

from .conftest import ARC, PITCH


def test_plan_with_payload_and_motor_line_holds_when_recomputed(delta):
    plan = pkm.time_optimal(delta, ARC, points=24, payload=1.0, limits={"omega0": 8.0, "speed": 20.0})
    check = pkm.verify_time_optimal(plan, dt=plan.cycle_time / 300)
    assert check.holds and 0.99 < check.effort_usage <= 1.0 + 1e-6
    assert len(check.inactive) <= 1  # (the switch from accelerating to braking)
    assert check.event is None and check.simulated_duration >= plan.cycle_time * (1 - 1e-9)
    assert check.task_error < 1e-3  # [m]: the PD tracks the plan


def test_a_plan_across_position_limits_does_not_hold(ankle):
    """A plan made on the ankle without its limits (pitch to 0.8 rad, range +-0.6; the motors to 1.047 rad, range
    +-1), checked on the ankle with them: holds is False, the joints outside named with the reason; the same plan
    checked where no limit is stated holds (its efforts and speeds are within their limits)."""
    import copy
    import dataclasses

    free = copy.copy(ankle)
    free.limits = {}
    plan = pkm.time_optimal(free, PITCH, points=8)
    check = pkm.verify_time_optimal(plan, factor=1, simulate=False)
    assert check.holds and check.reason is None and check.outside_limits == ()
    check = pkm.verify_time_optimal(dataclasses.replace(plan, mech=ankle), factor=1, simulate=False)
    assert not check.holds and set(check.outside_limits) == {"ankle_pitch", "motor_left", "motor_right"}
    assert check.reason.startswith("position limits crossed: ankle_pitch = 0.685714 at s = 0.857143, outside its "
                                   "limits [-0.6, 0.6]")  # (the first check point outside: s = 6/7, pitch 0.8 s)
