"""Identification from another simulator's measurements: MuJoCo runs the ``to_mjcf`` model of the Delta and the
3-PRS (its loops soft equality constraints, its own integrator), the base parameters identified from one run predict
MuJoCo's efforts along a second, different run.

The runs: each actuator follows a four-harmonic multi-sine (0.15 rad or m, 4 s period) under a PD law tuned on
pkm's actuated mass matrix (8 Hz, damping 0.8) plus the gravity efforts at the start; MuJoCo's explicit Euler at
1 ms; what is recorded is what a robot's drives and encoders would give, read from MuJoCo's data: the actuated
positions, rates and accelerations (``qpos``, ``qvel``, ``qacc``) and the efforts applied (``ctrl``). One sample in
ten (after the first 0.1 s) enters the estimate: 390 samples.

The bound, explained: MuJoCo's loops close softly (the equality constraints are stiff springs with damping,
``solref`` 0.02 s), so MuJoCo's mechanism is pkm's up to the constraint violation it allows (about ``1e-5``
m here), and its accelerations carry the constraint's own dynamics; what the base parameters cannot explain is of
that order. Measured at this commit: the validation's relative RMS error is 0.42 %, 0.15 %, 0.38 % of the RMS
effort for the Delta (whose efforts are mostly its light arms' gravity: 0.18 N m) and 0.011 % for the 3-PRS (26 N);
the test asks 1 % and 0.1 %. On the identification run itself the Delta's fit is 100 times closer (4e-5): a
multi-sine leaves some of its 48 base parameters poorly excited (relative standard deviations up to 480 %), which
fit the run's own constraint noise; an optimised excitation (:mod:`pkm.core.identification.excitation`) is the
remedy the method prescribes."""

from __future__ import annotations

import numpy as np
import pytest

import pkm
from pkm.core.dynamics.model import gravity_efforts, mass_matrix
from pkm.core.identification.base import base_parameters
from pkm.core.identification.estimate import estimate
from pkm.core.identification.regressor import regressor

mujoco = pytest.importorskip("mujoco")  # (the bench extra: installed by make test's venv, pkm-robotics[all])

PERIOD, DT, AMPLITUDE, HARMONICS, HZ, DAMPING = 4.0, 1e-3, 0.15, 4, 8.0, 0.8
BOUND = {"delta": 0.01, "prs3": 0.001}  # validation relative RMS error, per actuator


def multisine(mech: pkm.Mechanism, seed: int):
    rng = np.random.default_rng(seed)
    qa0 = mech.actuated_q(mech.q_reference)
    A = rng.uniform(-1.0, 1.0, (mech.na, HARMONICS)) / np.arange(1, HARMONICS + 1)
    w = 2.0 * np.pi / PERIOD * np.arange(1, HARMONICS + 1)

    def ref(t: float) -> tuple[np.ndarray, np.ndarray]:
        return qa0 + AMPLITUDE * (A * np.sin(w * t)).sum(1), AMPLITUDE * (A * w * np.cos(w * t)).sum(1)

    return ref


def mujoco_run(mech: pkm.Mechanism, seed: int) -> tuple[np.ndarray, ...]:
    """MuJoCo's measurements along one multi-sine (module doc): actuated positions, rates, accelerations, efforts."""
    from pkm.bench.mujoco_baseline import MujocoRigid

    rigid = MujocoRigid(mech)
    mm, md = rigid.model, rigid.data
    mm.opt.timestep = DT
    mm.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER  # (qacc then belongs to the state the step starts from)
    assert mm.nu == mech.na
    ref = multisine(mech, seed)
    qa0, qd0 = ref(0.0)
    q0 = pkm.close_loops(mech, qa0, mech.q_reference).q
    rigid._state(q0, pkm.velocities(mech, q0, qd0), np.zeros(mech.nv))
    M = mass_matrix(mech, q0)
    wn = 2.0 * np.pi * HZ
    kp, kd, g = M * wn**2, 2.0 * DAMPING * M * wn, gravity_efforts(mech, q0)
    act_q = [int(mm.jnt_qposadr[mujoco.mj_name2id(mm, mujoco.mjtObj.mjOBJ_JOINT, mech.model.names[j.id])])
             for j in mech.actuated]
    act_v = rigid._act
    rows = []
    for k in range(round(PERIOD / DT)):
        qr, qdr = ref(k * DT)
        qa, qd = md.qpos[act_q].copy(), md.qvel[act_v].copy()
        md.ctrl[:] = g + kp @ (qr - qa) + kd @ (qdr - qd)
        mujoco.mj_step(mm, md)
        rows.append(np.concatenate([qa, qd, md.qacc[act_v], md.ctrl]))
    data = np.array(rows)[100::10]
    QA, QD, QDD, TAU = np.split(data, 4, axis=1)
    Q, q = [], mech.q_reference
    for qa in QA:
        q = pkm.close_loops(mech, qa, q).q
        Q.append(q)
    return np.array(Q), QD, QDD, TAU


def relative_rms(mech, est, Q, QD, QDD, TAU) -> np.ndarray:
    pred = np.array([est.predict(regressor(mech, *s)) for s in zip(Q, QD, QDD)])
    return np.sqrt(np.mean((pred - TAU) ** 2, axis=0)) / np.sqrt(np.mean(TAU**2, axis=0))


@pytest.mark.parametrize("name", sorted(BOUND))
def test_the_model_identified_from_mujoco_predicts_mujoco(name):
    mech = pkm.load(name)
    base = base_parameters(mech, precise=False)
    train, check = mujoco_run(mech, 1), mujoco_run(mech, 2)
    est = estimate(mech, *train, base=base)
    fit, validation = relative_rms(mech, est, *train), relative_rms(mech, est, *check)
    assert validation.max() <= BOUND[name], validation
    assert fit.max() <= BOUND[name], fit
