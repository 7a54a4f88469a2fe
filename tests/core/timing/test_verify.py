"""A plan checked by pkm.inverse_dynamics at 10x its resolution and by a tracking simulation."""

from __future__ import annotations

import numpy as np
import pytest

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


def test_labels_equal_the_plans_with_viscous_friction(ankle, delta):
    """The ankle (viscous friction at its motors) on a short path within its limits: the rows the planner solved
    are active on every segment, recomputed from verify's own efforts to 1e-9; the true limits are used under 1 on
    some (the friction that helps braking is not counted by the planner), which the old definition called inactive.
    The Delta with a motor line: the one switch, the same in both."""
    plan = pkm.time_optimal(ankle, [[0.0, 0.0], [0.2, 0.05], [0.4, 0.1]], points=12)
    check = pkm.verify_time_optimal(plan, factor=1, simulate=False)
    assert check.holds and check.inactive == plan.inactive == ()
    np.testing.assert_allclose(check.planned_usage, plan.planned_usage, rtol=0, atol=1e-9)
    C, idx = plan.coefficients, np.column_stack([np.arange(11), np.arange(1, 12)]).ravel()  # (the segments' ends)
    sd, u = plan.sd[idx, None], np.repeat(plan.sdd, 2)[:, None]
    planned = C.a[idx] * u + C.b[idx] * sd ** 2 + C.c[idx] + C.d[idx] * sd  # (the friction the model's, by G)
    np.testing.assert_allclose(check.efforts, planned, rtol=0, atol=1e-9 * np.abs(planned).max())
    assert plan.usage.min() < 1.0 - 1e-3 and np.all(plan.usage <= plan.planned_usage + 1e-9)
    tracked = pkm.verify_time_optimal(plan, factor=1, dt=plan.cycle_time / 40)  # (pitch and roll: no position)
    assert tracked.task_error is None and tracked.tracking_error.shape == (2,)
    line = pkm.time_optimal(delta, ARC[1:3], points=16, limits={"omega0": 8.0, "speed": 20.0})
    check = pkm.verify_time_optimal(line, factor=1, simulate=False)
    assert len(line.inactive) == 1 and check.inactive == line.inactive


def _same(a, b) -> None:
    """Two verifications of one plan equal: efforts to 1e-10 relative, usages, labels, verdicts."""
    np.testing.assert_allclose(a.efforts, b.efforts, rtol=0, atol=1e-10 * np.abs(b.efforts).max())
    for key in ("effort_usage", "speed_usage", "acceleration_usage"):
        assert abs(getattr(a, key) - getattr(b, key)) <= 1e-10, key
    np.testing.assert_allclose(a.planned_usage, b.planned_usage, rtol=0, atol=1e-10)
    assert (a.holds, a.inactive, a.outside_limits, a.reason) == (b.holds, b.inactive, b.outside_limits, b.reason)


def test_the_compiled_route_equals_the_core_on_the_ankle(ankle, monkeypatch):
    """The humanoid ankle (idle motions: its rods spin between their balls) at 2x the resolution of a 12-point plan:
    the kernels' verification (numpy over the samples: the expressions the C compiles) equals the core's (efforts
    1e-10 relative, usages, labels, verdict); a plan across the position limits, the same reason; where every step
    reads as a fold, the compiled route hands the path to the core, which names the jump; the planner's compiled
    route on the ankle equals its core (cycle time 1e-9, labels)."""
    import copy
    import dataclasses

    import pkm.core.kinematics.trajectory as trajectory
    from pkm.errors import InvalidInputError

    K = pkm.Kernels(ankle, compiled=False)
    plan = pkm.time_optimal(ankle, [[0.0, 0.0], [0.2, 0.05], [0.4, 0.1]], points=12)
    core = pkm.verify_time_optimal(plan, factor=2, simulate=False)
    compiled = pkm.verify_time_optimal(plan, factor=2, simulate=False, kernels=K)
    _same(compiled, core)
    assert core.holds and core.inactive == plan.inactive
    assert compiled.route.startswith("kernels (numpy") and core.route == "core"
    free = copy.copy(ankle)
    free.limits = {}
    across = dataclasses.replace(pkm.time_optimal(free, PITCH, points=6), mech=ankle)
    outside = pkm.verify_time_optimal(across, factor=1, simulate=False, kernels=K)
    _same(outside, pkm.verify_time_optimal(across, factor=1, simulate=False))
    assert outside.route.startswith("kernels") and not outside.holds
    monkeypatch.setattr(trajectory, "JUMP_RATIO", -1.0)
    folded = pkm.verify_time_optimal(plan, factor=1, simulate=False, kernels=K)
    assert not folded.holds and "jumps" in folded.reason and folded.route == "core"
    monkeypatch.undo()
    compiled = pkm.time_optimal(ankle, [[0.0, 0.0], [0.2, 0.05], [0.4, 0.1]], points=12, kernels=K)
    assert compiled.coefficients.route.startswith("kernels")
    assert abs(compiled.cycle_time / plan.cycle_time - 1.0) <= 1e-9 and compiled.inactive == plan.inactive
    with pytest.raises(InvalidInputError, match="kernels"):
        pkm.verify_time_optimal(plan, simulate=False, kernels=pkm.Kernels(free, compiled=False))


def test_the_compiled_route_equals_the_core_on_the_delta(delta):
    """The Delta (no idle motions: the efforts by the twin's projection; its knees' branch signs followed) with a
    motor line, numpy over the samples: the core's verification (efforts 1e-10 relative, the one switch)."""
    line = pkm.time_optimal(delta, ARC[1:3], points=8, limits={"omega0": 8.0, "speed": 20.0})
    core = pkm.verify_time_optimal(line, factor=1, simulate=False)
    compiled = pkm.verify_time_optimal(line, factor=1, simulate=False, kernels=pkm.Kernels(delta, compiled=False))
    _same(compiled, core)
    assert len(core.inactive) == 1 and compiled.route.startswith("kernels")


def test_a_plan_through_interference_does_not_hold(ankle):
    """The ankle as shipped: its plan to 0.8 rad of pitch (limits lifted) keeps 7.5 mm between the rods and the
    shank, the smallest distance over the check points reported; with the shank's capsule 12 mm thicker (37 mm) the
    rods cut into it on the way: holds is False, the first check point and the pair named, the depth pkm.clearance's
    there."""
    import copy

    from pkm.core.collision import CollisionModel

    free = copy.copy(ankle)
    free.limits = {}
    check = pkm.verify_time_optimal(pkm.time_optimal(free, PITCH, points=8), factor=1, simulate=False)
    assert check.holds and check.clearance == pytest.approx(0.00747690, abs=1e-7)
    urdf = ankle.urdf.replace('<capsule radius="0.025"', '<capsule radius="0.037"')
    thick = pkm.from_strings(urdf, ankle.spec)
    thick.limits = {}
    assert ("rod_left", "shank") in CollisionModel.of(thick).pairs  # (6 mm apart at the reference: checked)
    check = pkm.verify_time_optimal(pkm.time_optimal(thick, PITCH, points=8), factor=1, simulate=False)
    assert not check.holds and check.clearance < -1e-3
    k = int(np.argmax(np.isclose(check.s, float(check.reason.split("at s = ")[1]))))
    q = pkm.solve_ik(thick, [PITCH[-1, 0] * check.s[k], 0.0]).q
    c = pkm.clearance(thick, q)
    assert check.reason.startswith(f"bodies interpenetrate: {c.closest[0]} and {c.closest[1]} by "
                                   f"{-c.minimum:.6g} m at s = ")
    assert c.interferes and not pkm.clearance(thick, pkm.solve_ik(thick, [PITCH[-1, 0] * check.s[k - 1], 0.0]).q) \
        .interferes
