"""pkm.learn.mjwarp: the humanoid ankle's example environment (examples/mjwarp/ankle_env.py) steps 4,096 worlds in
MuJoCo Warp on Warp's CPU device with its transmission exact inside the step (issue 56's acceptance), checked against
pkm's own Python route at the state it reached: MuJoCo Warp's smooth acceleration is ``M_o⁻¹(J⁻ᵀ τ_m - h_o)`` of the
closed loop (ΔM in the mass matrix, Δh applied, no lag) to float32's rounding, the motors' positions are pkm's
motors_from_outputs, and the passive joints close the loop to the kernels' tolerance.

One environment for the module (one compile of MuJoCo Warp's kernels and pkm's fused kernel: about 40 s the first
time on a CPU, a few seconds once Warp's kernel cache holds them)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

from pkm.core.kinematics.constraints import residual
from pkm.errors import MissingDependencyError

ENV = Path(__file__).resolve().parents[2] / "examples" / "mjwarp" / "ankle_env.py"
N = 4096


@pytest.fixture(scope="module")
def stepped():
    """The environment with 4,096 worlds after three actions (15 Euler steps of 2 ms) of random commands."""
    pytest.importorskip("mujoco_warp")  # (the mjwarp extra)
    spec = importlib.util.spec_from_file_location("pkm_example_ankle_env", ENV)
    assert spec is not None and spec.loader is not None
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    env = example.AnkleEnv(N, seed=3)
    env.reset()
    rng = np.random.default_rng(0)
    for _ in range(3):
        action = rng.uniform(-1.0, 1.0, (N, 2))
        obs, reward, _, info = env.step(action)
    return env, env.hold + env.scale * action, obs, reward, info


def test_4096_worlds_step_with_the_loops_closed(stepped):
    env, _, obs, reward, info = stepped
    w = env.worlds
    t = w.units[0].t
    assert obs.shape == (N, 10) and np.isfinite(obs).all() and reward.shape == (N,)
    assert (w.status == 0).all()
    moved = np.abs(w.output_q - env.reference).max(axis=1)
    assert np.median(moved) > 1e-3  # (the feet moved: the commands act)
    tol = 1e-11 * t.mechanism.characteristic_length  # (the kernels' closure tolerance, RTOL)
    assert info["residual"].max() <= tol
    q = w.sub_q(0)
    for k in (0, 1, N - 1):  # (pkm's closure residual at the kernel's configuration: the loop is closed)
        assert np.abs(residual(t.mechanism, q[k])).max() <= tol
        qm, _ = t.motors_from_outputs(w.output_q[k], q[k])
        assert np.abs(qm - w.motor_q[k]).max() <= 1e-12


def test_the_acceleration_is_the_closed_loops(stepped):
    """ΔM in MuJoCo Warp's mass matrix and Δh applied at the state being evaluated: ``qacc_smooth`` is the closed
    loop's output acceleration (pkm's Python output model) to float32 (MuJoCo Warp's precision: 1e-5 relative)."""
    import mujoco_warp as mjw
    import warp as wp

    env, tau_m, *_ = stepped
    w = env.worlds
    t = w.units[0].t
    with wp.ScopedDevice(w.device):
        mjw.forward(w.model, w.data)
    acc = w.data.qacc_smooth.numpy()
    q, od = w.sub_q(0), w.qvel.astype(float)
    for k in (0, 7, N - 1):
        M_o, h_o = t.output_model(q[k], od[k])
        expected = np.linalg.solve(M_o, t.inverse_effort_map(q[k]) @ tau_m[k] - h_o)
        assert np.abs(acc[k] - expected).max() <= 1e-5 * np.abs(expected).max(), (k, acc[k], expected)
        M_s, _ = t.serial_model(q[k], od[k])  # (without ΔM the acceleration would be far off: the check can fail)
        assert np.abs(np.linalg.solve(M_s, M_o @ expected) - expected).max() > 1.0 * np.abs(expected).max()


def test_without_mujoco_warp_the_extra_is_named(monkeypatch):
    from pkm.learn.mjwarp import TransmissionWorlds

    monkeypatch.setitem(sys.modules, "mujoco_warp", None)
    with pytest.raises(MissingDependencyError) as e:
        TransmissionWorlds(None, 1)  # type: ignore[arg-type]  (the extra is checked first)
    assert e.value.extra == "mjwarp" and 'pip install "pkm-robotics[mjwarp]"' in str(e.value)


def test_outputs_on_two_branches_have_no_place_in_mujocos_sparse_mass_matrix():
    """ΔM's off-diagonal entry of two outputs goes where MuJoCo's sparse M has the entry of the later dof and its
    ancestor; outputs hanging from one body side by side have none: refused, not dropped."""
    mujoco = pytest.importorskip("mujoco")
    from pkm.errors import TransmissionError
    from pkm.learn.mjwarp import _mass_addresses

    chain = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body><joint name='a'/><geom size='.1'/><body><joint name='b'/><geom size='.1'/>"
        "</body></body></worldbody></mujoco>")
    assert _mass_addresses(chain, [0, 1]).tolist() == [0, 1, -1, 2]  # (M's CSR: row 0 [0,0]; row 1 [1,0], [1,1])
    siblings = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body><joint name='a'/><geom size='.1'/></body><body><joint name='b'/><geom size='.1'/>"
        "</body></worldbody></mujoco>")
    with pytest.raises(TransmissionError, match="different branches"):
        _mass_addresses(siblings, [0, 1])


def test_attached_to_a_model_built_elsewhere(stepped):
    """TransmissionWorlds.attach (how Newton's SolverMuJoCo gets the transmissions: tools/mjwarp_newton.py) puts the
    same kernels on another MuJoCo Warp model's control callback: at that model's state it gives the motors the
    owning worlds give; stepping and setting the state are its owner's, refused; an output joint the model lacks or an
    armature counting ΔM's diagonal twice (or not at all) is refused, not run."""
    import pkm
    from pkm.errors import InvalidInputError, UnknownNameError
    from pkm.learn.mjwarp import TransmissionWorlds

    env, *_ = stepped
    w = env.worlds
    t = w.units[0].t
    robot = pkm.load(ENV.parents[1] / "humanoid_ankle" / "ankle.closures.toml")
    try:
        attached = TransmissionWorlds.attach(robot, w.mj_model, w.model, w.data, transmissions=[t])
        assert w.model.callback.control == attached._control and attached.nworld == N
        assert np.abs(attached.motor_q - w.motor_q).max() <= 1e-12
        with pytest.raises(InvalidInputError, match="stepped by their owner"):
            attached.step()
        with pytest.raises(InvalidInputError, match="owner"):
            attached.reset(outputs=[0.0, 0.0])
    finally:
        w.model.callback.control = w._control
    with pytest.raises(InvalidInputError, match="armature") as e:  # (the exact model's outputs carry none)
        TransmissionWorlds.attach(robot, w.mj_model, w.model, w.data, transmissions=[t], exact=False)
    assert e.value.value == 0.0
    with pytest.raises(UnknownNameError):
        TransmissionWorlds.attach(robot, w.mj_model, w.model, w.data, transmissions=[t],
                                  joints={t.outputs[0]: "_robot_joints_" + t.outputs[0]})
