"""pkm.core.twin.kernels: the generated kernels (compiled C; numpy and CasADi's virtual machine) equal the generic core on
closed states of shipped and user mechanisms; the derivatives equal finite differences; paths warm-start and fall
back to the core where the fixed pivots fail."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

import pkm
from pkm.core.kinematics.task import TaskMap
from pkm.core.twin import kernels as kmod
from pkm.core.twin.kernels import Kernels
from pkm.errors import InvalidInputError, SpecError
from tests.core.twin.test_tree import FILES
from tests.fd import rel, richardson

NAMES = ["prs3", "delta", "rrr3", "hexapod", "gough_stewart", "mjcf_fourbar"]
HAS_CC = bool(shutil.which("cc") or shutil.which("gcc") or shutil.which("clang"))



def _mechanism(name: str) -> pkm.Mechanism:
    return pkm.load(FILES[name]) if name in FILES else pkm.load(name)


def _states(mech: pkm.Mechanism, n: int, seed: int = 0):
    """``n`` closed configurations near the reference, with random actuated rates and accelerations."""
    rng = np.random.default_rng(seed)
    qa = mech.actuated_q(mech.q_reference)
    Q = np.array([pkm.close_loops(mech, qa + 0.01 * rng.standard_normal(mech.na)).q for _ in range(n)])
    return Q, rng.standard_normal((n, mech.na)), rng.standard_normal((n, mech.na))


@pytest.mark.parametrize(("name", "compiled"), [(n, True) for n in NAMES]
                         + [(n, False) for n in ("prs3", "rrr3", "mjcf_fourbar")],
                         ids=[f"{n}-C" for n in NAMES] + [f"{n}-numpy" for n in ("prs3", "rrr3", "mjcf_fourbar")])
def test_the_kernels_equal_the_generic_core(name, compiled):
    """Efforts, joint rates and accelerations, forward and inverse Jacobians from the kernels (compiled for every
    mechanism; numpy and the virtual machine, the same expressions, for three), one sample and a batch
    of 6: the generic core's (pkm.inverse_dynamics, pkm.velocities, pkm.accelerations, pkm.forward_jacobian) to
    1e-10 relative."""
    mech = _mechanism(name)
    K = Kernels(mech, compiled=compiled)
    Q, QD, QDD = _states(mech, 6)
    tau = K.inverse_dynamics(Q, QD, QDD)
    V = K.velocities(Q, QD)
    for k in range(len(Q)):
        v = pkm.velocities(mech, Q[k], QD[k])
        a = pkm.accelerations(mech, Q[k], v, QDD[k])
        assert rel(V[k], v) <= 1e-10
        assert rel(K.accelerations(Q[k], v, QDD[k]), a) <= 1e-10
        assert rel(tau[k], pkm.inverse_dynamics(mech, Q[k], v, a)) <= 1e-10
        assert rel(K.inverse_dynamics(Q[k], QD[k], QDD[k]), tau[k]) <= 1e-14
        J = pkm.forward_jacobian(mech, Q[k])
        assert rel(K.forward_jacobian(Q[k]), J) <= 1e-10
        if J.shape[0] == J.shape[1]:
            assert rel(K.inverse_jacobian(Q[k]) @ J, np.eye(mech.na)) <= 1e-10
    assert len(K.how) == 5 and all(h.startswith("C (" if compiled and HAS_CC else "numpy") for h in K.how.values())


@pytest.mark.parametrize("name", ["prs3", "delta", "gough_stewart"])
def test_the_derivatives_of_the_efforts_equal_finite_differences(name):
    """dtau/dqa along the closure (the configuration re-solved by pkm.close_loops), dtau/dqd and dtau/dqdd: central
    differences, Richardson-extrapolated, to 1e-6 relative."""
    mech = _mechanism(name)
    K = Kernels(mech)
    Q, QD, QDD = _states(mech, 2, seed=3)
    for q, qd, qdd in zip(Q, QD, QDD):
        d = K.inverse_dynamics_derivatives(q, qd, qdd)
        assert rel(d["tau"], K.inverse_dynamics(q, qd, qdd)) <= 1e-14
        for key, arg in (("dtau_dqa", "dqa"), ("dtau_dqd", "dqd"), ("dtau_dqdd", "dqdd")):
            assert rel(d[key], _differences(K, q, qd, qdd, arg)) <= 1e-6, key


def _differences(K: Kernels, q, qd, qdd, arg: str) -> np.ndarray:
    """Central differences of the efforts in one of their inputs (``dqa``: the configuration re-solved)."""
    qa = K.mech.actuated_q(q)

    def at(dqa=0.0, dqd=0.0, dqdd=0.0):
        qq = q if np.isscalar(dqa) else pkm.close_loops(K.mech, qa + dqa, q, tol=1e-14).q
        return K.inverse_dynamics(qq, qd + dqd, qdd + dqdd)

    return richardson(lambda h: np.column_stack([(at(**{arg: e}) - at(**{arg: -e})) / (2 * h)
                                                 for e in h * np.eye(K.mech.na)]), 1e-4)


@pytest.mark.parametrize("name", ["prs3", "delta", "rrr3", "gough_stewart"])
def test_paths_warm_start_and_equal_the_core(name):
    """The loop closure along 60 samples of a smooth actuated path equals pkm.close_loops per sample (1e-9) with at
    most 3 kernel iterations per sample; the IK along the task values of every 6th sample comes back to the same
    configurations."""
    mech = _mechanism(name)
    K = Kernels(mech)
    qa = mech.actuated_q(mech.q_reference)
    s = np.sin(np.linspace(0.0, 3.0, 60))[:, None]
    path = qa + 0.02 * s * np.linspace(1.0, -1.0, mech.na)
    r = K.close_loops_path(path)
    assert r.fallback == () and r.residual.max() <= 1e-12 and r.iterations.max() <= 3
    q = mech.q_reference
    for k in range(0, 60, 7):
        q = pkm.close_loops(mech, path[k], q).q
        assert np.abs(mech.difference(r.q[k], q)).max() <= 1e-9
    task = TaskMap(mech)
    Y = np.array([task.value(x) for x in r.q[::6]])
    ik = K.ik_path(Y)
    assert ik.fallback == () and ik.residual.max() <= 1e-12
    assert max(np.abs(mech.difference(a, b)).max() for a, b in zip(ik.q, r.q[::6])) <= 1e-9


def test_every_joint_actuated_the_kernels_equal_the_core(built, all_actuated):
    """No passive coordinate (the passive solve's factorisation of the empty matrix raised numpy's ValueError):
    CasADi's kernels give the rates, the forward Jacobian and the efforts of pkm's core at the five-bar's closed
    configurations, and close the loop along its actuated path in place."""
    five, mech = built("fivebar"), all_actuated
    y0 = TaskMap(five).value(five.q_reference)
    Q = np.array([pkm.solve_ik(five, y0 + [0.01 * k, -0.01 * k]).q for k in range(3)])
    K = Kernels(mech, compiled=False)
    r = K.close_loops_path(Q[:, mech.act_q])
    assert r.fallback == () and r.residual.max() <= 1e-12 and np.abs(r.q - Q).max() <= 1e-12
    for q in Q:
        v = pkm.velocities(five, q, [0.3, -0.2])  # (closure-consistent rates of every joint)
        a = pkm.accelerations(five, q, v, [1.0, 0.5])
        qd, qdd = v[mech.act_v], a[mech.act_v]
        assert np.abs(K.velocities(q, qd) - v).max() <= 1e-12 and np.abs(pkm.velocities(mech, q, qd) - v).max() <= 1e-12
        assert np.abs(K.forward_jacobian(q) - pkm.forward_jacobian(mech, q)).max() <= 1e-12
        tau = pkm.inverse_dynamics(mech, q, v, a)
        assert np.abs(K.inverse_dynamics(q, qd, qdd) - tau).max() <= 1e-10 * max(1.0, np.abs(tau).max())


def test_paths_on_copies_scaled_in_size_take_the_same_iterations():
    """The 3-RRR and its copies scaled by 0.1 and 10 (CasADi's virtual machine: no compiler), the loop closure along
    4 samples 0.2 rad apart and the IK back along their task values: the same iterations per sample, no fallback, the
    same residuals (lengths counted in the characteristic length, 1e-14) (issue 52: before, the tolerance was 1e-12 m,
    and the copy 10 times larger took 5 IK iterations where the original took 4)."""
    from pkm.core.model.scale import scale_configuration

    mech = _mechanism("rrr3")
    qa = mech.actuated_q(mech.q_reference) + np.linspace(0.0, 0.6, 4)[:, None] * np.array([1.0, -0.5, 1.0])
    runs = {}
    for s in (1.0, 0.1, 10.0):
        m = mech if s == 1.0 else pkm.scaled_mechanism(mech, s)
        K = Kernels(m, compiled=False)
        fk = K.close_loops_path(qa)
        ik = K.ik_path(np.array([TaskMap.of(m).value(q) for q in fk.q[::-1]]), fk.q[-1])
        runs[s] = (m, fk, ik)
    _, fk1, ik1 = runs[1.0]
    assert fk1.iterations.max() >= 4 and ik1.iterations.max() >= 4  # (several Newton iterations per sample)
    for s in (0.1, 10.0):
        m, fk, ik = runs[s]
        for mine, theirs in ((fk1, fk), (ik1, ik)):
            assert theirs.fallback == () == mine.fallback and theirs.iterations.tolist() == mine.iterations.tolist(), s
            assert np.abs(theirs.residual - mine.residual).max() <= 1e-14 and theirs.residual.max() <= 1e-12, s
        assert max(np.abs(m.difference(scale_configuration(mech, a, s), b)).max() for a, b in zip(fk1.q, fk.q)) <= 1e-9


def test_redundant_actuation_the_kernels_equal_the_core(built, redundant):
    """One elbow actuated too (3 actuators, mobility 2): the efforts are not unique; the kernels' passive solve kept
    the closure rows with a pivot (another distribution than the core's, 9 % off; its mass matrix 22 %, and the
    samples under the pivot floor got the core's), now the core's homogenised pseudo-inverse: the efforts, the
    actuator-space model, the regressor and the rates of an actuator alone equal the core's to 1e-12, and the
    efforts do the five-bar's work (its own efforts through the elbow's rate map: an independent route)."""
    five, mech = built("fivebar"), redundant
    y0 = TaskMap(five).value(five.q_reference)
    K = Kernels(mech, compiled=False)
    for k in range(2):
        q = pkm.solve_ik(five, y0 + [0.02 * k, -0.03 * k]).q
        v = pkm.velocities(five, q, [0.7, -0.4])  # (closure-consistent rates of every joint)
        a = pkm.accelerations(five, q, v, [1.0, 2.0])
        qd, qdd = v[mech.act_v], a[mech.act_v]
        tau, model = pkm.inverse_dynamics(mech, q, v, a), pkm.actuator_model(mech, q, qd)
        scale = np.abs(tau).max()
        assert np.abs(K.inverse_dynamics(q, qd, qdd) - tau).max() <= 1e-12 * scale
        assert np.abs(K.mass_matrix(q) - model.M).max() <= 1e-12 * np.abs(model.M).max()
        assert np.abs(K.bias(q, qd) - model.h).max() <= 1e-12 * np.abs(model.h).max()
        assert np.abs(K.regressor(q, qd, qdd) - pkm.regressor(mech, q, qd, qdd)).max() <= 1e-12
        assert np.abs(K.velocities(q, [1.0, 0.0, 0.0]) - pkm.passive_map(mech, q)[:, 0]).max() <= 1e-12
        T = np.column_stack([pkm.velocities(five, q, e) for e in np.eye(2)])[mech.act_v]  # (3 rates of 2 motors')
        assert np.abs(T.T @ tau - pkm.inverse_dynamics(five, q, v, a)).max() <= 1e-12 * scale


def test_samples_under_the_pivot_floor_fall_back_to_the_core(monkeypatch):
    """With the floor above every pivot, each path sample and each effort comes from the core, listed as such, and
    the answers are the same."""
    mech = _mechanism("delta")
    K = Kernels(mech)
    qa = mech.actuated_q(mech.q_reference)
    path = qa + np.linspace(0.0, 0.05, 8)[:, None]
    Q, QD, QDD = _states(mech, 3)
    expected_q, expected_tau = K.close_loops_path(path).q, K.inverse_dynamics(Q, QD, QDD)
    monkeypatch.setattr(kmod, "PIVOT_FLOOR", 2.0)
    r = K.close_loops_path(path)
    assert r.fallback == tuple(range(8))
    assert max(np.abs(mech.difference(a, b)).max() for a, b in zip(r.q, expected_q)) <= 1e-10
    assert rel(K.inverse_dynamics(Q, QD, QDD), expected_tau) <= 1e-10


def test_without_a_compiler_the_virtual_machine_runs_and_says_so(monkeypatch):
    monkeypatch.setattr(shutil, "which", lambda name: None)
    K = Kernels(_mechanism("prs3"))
    Q, QD, QDD = _states(K.mech, 2)
    K.inverse_dynamics(Q, QD, QDD)
    assert "no C compiler" in K.how["inverse_dynamics"]


def test_bad_input_is_refused_clearly():
    K = Kernels(_mechanism("delta"), compiled=False)
    q = K.mech.q_reference
    with pytest.raises(InvalidInputError, match="qd"):
        K.inverse_dynamics(q, np.zeros(4), np.zeros(3))
    with pytest.raises(InvalidInputError, match="one sample"):
        K.inverse_dynamics(q, np.zeros((2, 3)), np.zeros(3))
    with pytest.raises(InvalidInputError, match="different lengths"):
        K.inverse_dynamics(np.array([q, q]), np.zeros((3, 3)), np.zeros((3, 3)))
    with pytest.raises(InvalidInputError, match="non-finite"):
        K.inverse_dynamics(np.full_like(q, np.nan), np.zeros(3), np.zeros(3))
    with pytest.raises(InvalidInputError, match="kernel"):
        K.function("nope")
    with pytest.raises(InvalidInputError, match="targets"):
        K.close_loops_path(np.full((2, 3), np.nan))


def test_a_mechanism_with_idle_motions_is_refused():
    mech = pkm.load(FILES["rssr"])
    with pytest.raises(SpecError, match="idle motions"):
        Kernels(mech).inverse_dynamics(mech.q_reference, np.zeros(mech.na), np.zeros(mech.na))


@pytest.mark.parametrize("name", ["ankle", "rssr"])
def test_idle_motions_are_held_by_the_task_kernels(name, monkeypatch):
    """On mechanisms with idle motions (rods spinning between two balls) the inverse kinematics along a path, the
    inverse Jacobian and the inverse rates (numpy over the samples: the expressions the C compiles) hold one
    coordinate per idle motion: the configurations close the loops and reach the task (1e-12), the actuated rates
    and accelerations are pkm.inverse_velocities' and pkm.inverse_accelerations' (1e-10 relative), the held
    coordinates' rates are zero; under the pivot floor the core's come back, equal."""
    mech = _mechanism(name)
    K = Kernels(mech, compiled=False)
    held = K.dynamics.idle
    assert held
    task = TaskMap(mech)
    y0 = task.value(mech.q_reference)
    rng = np.random.default_rng(2)
    step = 0.03 * rng.standard_normal(task.size)
    Y = np.array([task.retract(y0, t * step) for t in np.linspace(0.0, 1.0, 5)])
    YD, YDD = rng.standard_normal((5, task.size)), rng.standard_normal((5, task.size))
    ik = K.ik_path(Y, tol=1e-14)
    assert ik.fallback == () and ik.residual.max() <= 1e-12
    v, qdd = K.inverse_rates(ik.q, YD, YDD)
    assert np.abs(v[:, held]).max() == 0.0
    for k, q in enumerate(ik.q):
        assert np.abs(pkm.solve_ik(mech, Y[k], q).q - q).max() <= 1e-12  # (the core's solve stays: solved)
        vk = pkm.inverse_velocities(mech, q, YD[k])
        assert rel(v[k, mech.act_v], vk[mech.act_v]) <= 1e-10
        assert rel(qdd[k], pkm.inverse_accelerations(mech, q, vk, YDD[k])[mech.act_v]) <= 1e-10
        assert rel(K.inverse_jacobian(q).reshape(mech.na, -1), pkm.inverse_jacobian(mech, q)) <= 1e-10
    monkeypatch.setattr(kmod, "PIVOT_FLOOR", 2.0)
    v_core, qdd_core = K.inverse_rates(ik.q, YD, YDD)
    assert rel(v_core[:, mech.act_v], v[:, mech.act_v]) <= 1e-10 and rel(qdd_core, qdd) <= 1e-10
