"""pkm.simulate's C backend (pkm.core.twin.simulation) against its Python backend: the same samples and energies over a
1-s regular Delta run, the same events (a direct singularity, a joint limit or none with limits=False, the assembly
mode lost), the steps it hands back to Python, a controller called back from C, friction and saturation; and how
the backend is chosen or refused. Short runs (the 10-s one is pkm bench
simulation_speed)."""

from __future__ import annotations

import math
import shutil

import numpy as np
import pytest

import pkm
from pkm.core.dynamics import simulate as smod
from pkm.core.twin import simulation
from pkm.errors import CompilerError, ControllerError, InvalidInputError

pytestmark = pytest.mark.skipif(not (shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")),
                                reason="the C backend needs a C compiler")
FIELDS = ("q", "v", "a", "actuated", "actuated_velocity", "actuated_acceleration", "task", "task_velocity",
          "task_acceleration", "efforts", "time", "kinetic", "potential", "work", "dissipated")


@pytest.fixture(scope="module")
def delta():
    """The Delta, an object of this module's (its compiled simulation is no other test's), its servos' speed limit
    (2.97 rad/s) lifted: released, it falls faster than they turn, and the events here are others."""
    mech = pkm.load("delta")
    return pkm.with_actuators(mech, {j: {"velocity_limit": math.inf} for j in mech.actuated_names})


def _both(mech, **kwargs):
    return pkm.simulate(mech, backend="c", **kwargs), pkm.simulate(mech, backend="python", **kwargs)


def _agree(c, p, tol: float = 1e-9) -> None:
    assert len(c) == len(p) and c.event == p.event and c.method == p.method
    for f in FIELDS:
        a, b = getattr(c, f), getattr(p, f)
        assert np.abs(a - b).max() <= tol * max(1.0, np.abs(b).max()), f
    assert np.abs(c.energy - p.energy).max() <= tol and c.residual.max() <= 1e-12


def test_a_one_second_delta_run_is_the_python_one(delta):
    """From the pose (0, 0, -0.35) m held by gravity's efforts there plus a 0.02 N m chirp (a stable equilibrium: the
    run stays regular), 1 s at 1 kHz: positions, rates, accelerations, task, efforts and energies of the two
    backends agree to 1e-9 (they do to about 1e-13)."""
    q0 = pkm.solve_ik(delta, [0.0, 0.0, -0.35]).q
    g = pkm.gravity_efforts(delta, q0)
    t = np.linspace(0.0, 1.0, 1001)
    table = g + 0.02 * np.sin(2 * np.pi * (0.5 + 0.5 * t) * t)[:, None] * np.array([1.0, -0.5, 0.3])
    c, p = _both(delta, q0=q0, duration=1.0, dt=1e-3, torques=(t, table))
    _agree(c, p)
    assert c.event is None and len(c) == 1001 and np.abs(c.actuated - c.actuated[0]).max() > 0.1


def test_the_events_are_the_python_ones(delta, monkeypatch):
    """Released without effort the Delta reaches a direct singularity at 0.23 s: the same samples and event, the steps
    near it (to halve, or near the event) handed to Python; held at the reference by constant efforts plus a chirp,
    a knee reaches its limit at the same sample, and with limits=False neither stops there; thrown at 40 rad/s with
    1-s steps unchecked, the loops stop closing (the assembly mode lost) at the same sample."""
    handed = []
    step = smod._rk4_step
    monkeypatch.setattr(smod, "_rk4_step", lambda dyn, t, *a: handed.append(t) or step(dyn, t, *a))
    fall_c = pkm.simulate(delta, duration=1.0, friction=False, backend="c")
    assert handed and fall_c.event.kind == "singularity"
    fall_p = pkm.simulate(delta, duration=1.0, friction=False, backend="python")
    _agree(fall_c, fall_p)
    g = pkm.gravity_efforts(delta, delta.q_reference)
    t = np.linspace(0.0, 1.0, 1001)
    table = (t, g + 0.05 * np.sin(2 * np.pi * (1 + 2 * t) * t)[:, None] * np.array([1.0, -0.5, 0.3]))
    limit_c, limit_p = _both(delta, duration=0.5, torques=table)
    _agree(limit_c, limit_p)
    assert limit_c.event.kind == "joint_limit" and "knee_1" in limit_c.event.detail
    free_c, free_p = _both(delta, duration=0.4, torques=table, limits=False)
    _agree(free_c, free_p)
    assert free_c.event is None and len(free_c) > len(limit_c)
    lost_c, lost_p = _both(delta, v0=[40.0, -40.0, 40.0], duration=0.3, dt=0.02, friction=False, step_tol=10.0,
                           singular_tol=0.0, limits=False)
    assert lost_c.event.kind == lost_p.event.kind == "assembly_mode" and lost_c.event.time == lost_p.event.time
    assert len(lost_c) == len(lost_p) and np.abs(lost_c.q - lost_p.q).max() <= 1e-12


def test_a_controller_is_called_back_from_c(delta):
    """A Python controller runs once per stage from C: a table given as a controller gives the table's run bit for
    bit; a PD controller's run is the Python backend's; a controller that raises stops the run with a
    ControllerError, as in Python."""
    times = np.linspace(0.0, 0.05, 11)
    table = np.column_stack([0.3 * np.sin(40 * times), 0.2 * np.cos(30 * times), 0.1 * times])
    by_table = pkm.simulate(delta, duration=0.08, torques=(times, table), backend="c")
    by_call = pkm.simulate(delta, duration=0.08, backend="c", controller=lambda t, q, v: np.array(
        [np.interp(t, times, table[:, j]) for j in range(3)]))
    assert np.array_equal(by_table.q, by_call.q) and np.array_equal(by_table.efforts, by_call.efforts)
    q0 = pkm.solve_ik(delta, [0.0, 0.0, -0.35]).q
    g, qa0 = pkm.gravity_efforts(delta, q0), delta.actuated_q(q0)
    c, p = _both(delta, q0=q0, v0=[0.5, 0.0, 0.0], duration=0.2,
                 controller=lambda t, q, v: g + 2.0 * (qa0 - q[delta.act_q]) - 0.1 * v[delta.act_v])
    _agree(c, p)

    def fails(t, q, v):
        if t > 0.01:
            raise ZeroDivisionError("boom")
        return np.zeros(3)

    with pytest.raises(ControllerError, match="ZeroDivisionError"):
        pkm.simulate(delta, duration=0.05, controller=fails, backend="c")


def test_friction_and_saturation_agree():
    """A Delta with geared motors (reflected inertia), viscous and Coulomb friction and a saturated drive: the
    Python backend's run. (Other joints' exponentials, as Pinocchio's: ``tests/core/twin/test_simulation.py``.)"""
    base = pkm.load("delta")
    mech = pkm.with_actuators(base, {j: {"rotor_inertia": 2e-5, "gear_ratio": 40.0, "viscous": 0.05, "coulomb": 0.02,
                                         "effort_limit": 1.0, "peak_effort": 1.5} for j in base.actuated_names})
    t = np.linspace(0.0, 0.1, 11)
    c, p = _both(mech, v0=[1.0, -0.5, 0.3], duration=0.1, torques=(t, 3.0 * np.sin(40 * t)[:, None] * np.ones(3)))
    _agree(c, p)
    assert np.abs(c.efforts).max() == 1.5 and c.dissipated[-1] > 0.0


def test_the_backend_is_chosen_or_refused(monkeypatch):
    """'auto' runs Python for a short run of a mechanism not compiled yet, and C once it is; 'c' refuses Radau, a
    mechanism with idle motions (the ankle) and a machine without a C compiler; an unknown backend is refused."""
    mech = pkm.load("delta")
    pkm.simulate(mech, duration=0.01)
    assert mech not in simulation._SIMULATORS
    pkm.simulate(mech, duration=0.01, backend="c")
    assert mech in simulation._SIMULATORS
    with monkeypatch.context() as patch:
        patch.setattr(smod, "_rk4_c", lambda *a: "the C route")
        assert pkm.simulate(mech, duration=0.01) == "the C route"
    with pytest.raises(InvalidInputError, match="backend"):
        pkm.simulate(mech, duration=0.01, backend="fast")
    with pytest.raises(InvalidInputError, match="rk4"):
        pkm.simulate(mech, duration=0.01, method="radau", backend="c")
    with pytest.raises(InvalidInputError, match="idle motions"):
        pkm.simulate(pkm.load("examples/ankle/ankle.closures.toml"), duration=0.01, backend="c")
    monkeypatch.setattr(shutil, "which", lambda name: None)
    fresh = pkm.load("delta")
    with pytest.raises(CompilerError, match="no C compiler"):
        pkm.simulate(fresh, duration=0.01, backend="c")
    monkeypatch.setattr(smod, "AUTO_STEPS", 1)
    assert pkm.simulate(fresh, duration=0.01).event is None  # ('auto': Python)
