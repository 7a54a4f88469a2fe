"""pkm.follow_task and pkm.follow_actuators: motions of any mechanism, sample by sample, on one branch, with the
samples where the path would leave it reported."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm.errors import InvalidInputError

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"


@pytest.fixture(scope="module")
def knee():
    return pkm.load(EXAMPLES / "knee" / "knee.closures.toml")


def _motion(t):
    """A smooth actuator motion of the knee's front link [rad] and its two derivatives."""
    return -0.6 + 0.5 * np.sin(2.0 * t), 1.0 * np.cos(2.0 * t), -2.0 * np.sin(2.0 * t)


def test_following_the_actuators_equals_the_generic_calls_sample_by_sample(knee):
    t = np.linspace(0.0, 1.5, 16)
    qa, qd, qdd = _motion(t)
    traj = pkm.follow_actuators(knee, qa, qd, qdd)
    assert traj.jumps == () and len(traj) == 16 and np.all(traj.residual <= 1e-10)
    for k in (0, 7, 15):
        q = pkm.close_loops(knee, [qa[k]], traj.q[k - 1] if k else knee.q_reference).q
        assert np.abs(traj.q[k] - q).max() <= 1e-9
        v = pkm.velocities(knee, q, [qd[k]])
        a = pkm.accelerations(knee, q, v, [qdd[k]])
        assert np.abs(traj.v[k] - v).max() <= 1e-9 and np.abs(traj.a[k] - a).max() <= 1e-9
        assert np.abs(traj.efforts[k] - pkm.inverse_dynamics(knee, q, v, a)).max() <= 1e-9
        assert np.abs(traj.task_velocity[k] - pkm.task_velocity(knee, q, v)).max() <= 1e-9
    assert traj.units == {"actuated": {"knee_front": "rad"}, "task": {"pitch": "rad"}}


def test_the_rates_are_the_time_derivatives_of_the_path(knee):
    """Central differences of the sampled configurations over time give the velocities (1e-6 relative)."""
    dt = 1e-5
    for t0 in (0.2, 1.1):
        traj = pkm.follow_actuators(knee, *_motion(np.array([t0 - dt, t0, t0 + dt])))
        v_fd = (traj.q[2] - traj.q[0]) / (2 * dt)  # (revolute joints only: q is the tangent coordinate)
        assert np.linalg.norm(traj.v[1] - v_fd) <= 1e-6 * np.linalg.norm(v_fd)
        y_fd = (traj.task[2] - traj.task[0]) / (2 * dt)
        assert np.abs(traj.task_velocity[1] - y_fd).max() <= 1e-6 * np.abs(y_fd).max()


def test_following_the_task_inverts_the_forward_path(knee):
    t = np.linspace(0.0, 1.5, 12)
    fwd = pkm.follow_actuators(knee, *_motion(t))
    back = pkm.follow_task(knee, fwd.task, fwd.task_velocity, fwd.task_acceleration)
    assert back.jumps == ()
    assert np.abs(back.actuated - fwd.actuated).max() <= 1e-9
    assert np.abs(back.actuated_velocity - fwd.actuated_velocity).max() <= 1e-8
    assert np.abs(back.efforts - fwd.efforts).max() <= 1e-8 * max(1.0, np.abs(fwd.efforts).max())


def test_where_the_path_leaves_its_branch_it_says_so():
    """The slider-crank driven by its slider: past the dead centre (the slider's farthest travel) the samples do not
    converge; a four-bar driven in one 2.5 rad step lands too far from the first-order prediction (a fold, or a
    path too coarse to vouch for its branch)."""
    crank = pkm.load(EXAMPLES / "sdf_slider_crank" / "slider_crank.closures.toml")
    traj = pkm.follow_task(crank, np.concatenate([np.linspace(-0.05, -0.002, 9), [0.003]]), efforts=False)
    assert [(j.index, j.reason) for j in traj.jumps] == [(9, "did not converge")]
    assert traj.efforts is None
    four = pkm.load(EXAMPLES / "mjcf_fourbar" / "fourbar.xml")
    traj = pkm.follow_actuators(four, [0.0, 0.05, 2.5])
    assert [(j.index, j.reason) for j in traj.jumps] == [(2, "fold")]
    turn = pkm.follow_actuators(four, np.linspace(-np.pi, np.pi, 73), efforts=False)
    assert turn.jumps == ()  # (the crank's angle wraps at pi: a small step, not a jump of 2 pi)


def test_bad_samples_are_refused(knee):
    with pytest.raises(InvalidInputError, match="samples"):
        pkm.follow_actuators(knee, np.zeros((3, 2)))
    with pytest.raises(InvalidInputError, match="non-finite"):
        pkm.follow_actuators(knee, [0.0, np.nan])
    with pytest.raises(InvalidInputError, match="3 x 1"):
        pkm.follow_actuators(knee, [0.0, 0.1, 0.2], qd=[0.0, 0.1])
    with pytest.raises(InvalidInputError, match="True or False"):
        pkm.follow_actuators(knee, [0.0, 0.1], efforts=np.zeros(2))


def test_task_values_are_named():
    hexapod = pkm.load("hexapod")
    values = pkm.task_values(hexapod, hexapod.q_reference)
    assert list(values) == ["x", "y", "z", "roll", "pitch", "yaw", "beta_1"]


def test_a_motion_across_the_position_limits_names_each_joint_where_it_first_leaves_them():
    """The humanoid ankle's pitch 0 -> 0.8 rad in 9 samples (range +-0.6; its motors +-1): per joint, the first
    sample outside with its value there (the trajectory's own coordinate) and limits; the sample before is within
    (Mechanism.outside_limits, sample by sample); a motion within the limits has none."""
    ankle = pkm.load(EXAMPLES / "humanoid_ankle" / "ankle.closures.toml")
    y = np.column_stack([np.linspace(0.0, 0.8, 9), np.zeros(9)])
    traj = pkm.follow_task(ankle, y, efforts=False)
    first = {v.joint: (k, v) for k, v in traj.outside_limits}
    assert traj.outside_limits[0][1].joint == "ankle_pitch" and first["ankle_pitch"][0] == 7  # (0.7)
    assert set(first) == {"ankle_pitch", "motor_left", "motor_right"}
    for joint, (k, v) in first.items():
        assert v.value == traj.q[k, ankle.joints[joint].idx_q] and not v.limit[0] <= v.value <= v.limit[1]
        assert joint in ankle.outside_limits(traj.q[k]) and joint not in ankle.outside_limits(traj.q[k - 1])
    assert pkm.follow_task(ankle, y * 0.5, efforts=False).outside_limits == ()


def test_a_motion_into_interference_names_the_first_sample_and_the_pair(knee):
    """The Gough-Stewart with 9.5 cm legs turning from 0 to 1.2 rad of yaw in 7 samples: each sample's clearance is
    pkm.clearance's minimum, the first negative one is named with its pair and depth; a mechanism without collision
    geometry has none (None)."""
    thick = pkm.build("gough_stewart", cylinder_radius=0.095, rod_radius=0.095)
    task = pkm.TaskMap.of(thick)
    y = np.array([task.value(pkm.solve_ik(thick, {"yaw": yaw}).q) for yaw in np.linspace(0.0, 1.2, 7)])
    traj = pkm.follow_task(thick, y, efforts=False)
    minima = [pkm.clearance(thick, q) for q in traj.q]
    np.testing.assert_allclose(traj.clearance, [c.minimum for c in minima], rtol=0, atol=1e-12)
    k = next(i for i, c in enumerate(minima) if c.interferes)
    assert 0 < k < 7 and traj.interference.at == k and traj.interference.pair == minima[k].closest
    assert traj.interference.distance == pytest.approx(minima[k].minimum, abs=1e-12)
    plain = pkm.follow_actuators(knee, np.array([knee.actuated_q(knee.q_reference)] * 2), efforts=False)
    assert plain.clearance is None and plain.interference is None
