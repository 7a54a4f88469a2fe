"""pkm.core.twin.dynamics through pkm.Kernels: the actuator-space model's kernels (M_a, h_a, g_a, M_a and h_a fused,
the forward dynamics with and without friction), compiled and as numpy, equal pkm.actuator_model and
pkm.forward_dynamics on random closed states of the Delta, the 3-PRS, the acceptance set's ankle (two idle rod spins)
and a Delta with geared, rubbing motors (pkm.with_actuators); the twin's RNEA carries the armature as Pinocchio's."""

from __future__ import annotations

import shutil

import casadi as cs
import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.twin import Twin
from pkm.core.twin import kernels as kmod
from pkm.core.twin.kernels import Kernels
from pkm.errors import InvalidInputError
from tests.fd import rel

HAS_CC = bool(shutil.which("cc") or shutil.which("gcc") or shutil.which("clang"))
ANKLE = "examples/ankle/ankle.closures.toml"
_CACHE: dict = {}


def _mechanism(name: str) -> pkm.Mechanism:
    if name not in _CACHE:
        if name == "geared":
            delta = pkm.load("delta")
            _CACHE[name] = pkm.with_actuators(delta, {j: {"rotor_inertia": 2e-5, "gear_ratio": 40.0, "viscous": 0.05,
                                                          "coulomb": 0.02} for j in delta.actuated_names})
        else:
            _CACHE[name] = pkm.load(ANKLE if name == "ankle" else name)
    return _CACHE[name]


def _kernels(name: str, compiled: bool = True) -> Kernels:
    key = (name, compiled)
    if key not in _CACHE:
        _CACHE[key] = Kernels(_mechanism(name), compiled=compiled)
    return _CACHE[key]


def _states(mech: pkm.Mechanism, n: int, seed: int = 0):
    """``n`` closed configurations near the reference with random actuated rates and efforts."""
    rng = np.random.default_rng(seed)
    qa = mech.actuated_q(mech.q_reference)
    Q = np.array([pkm.close_loops(mech, qa + 0.02 * rng.standard_normal(mech.na)).q for _ in range(n)])
    return Q, rng.standard_normal((n, mech.na)), rng.standard_normal((n, mech.na))


def _check(K: Kernels, Q, QD, TAU, single: bool = True) -> None:
    """The fused kernel, gravity and the forward dynamics; with ``single``, the kernels of M_a and h_a alone too
    (each kernel is compiled apart: the tests keep to what they need)."""
    mech = K.mech
    M, h = K.mass_and_bias(Q, QD)
    Ms, hs = (K.mass_matrix(Q), K.bias(Q, QD)) if single else (M, h)
    gs = K.gravity(Q)
    free, rubbing = K.forward_dynamics(Q, QD, TAU), K.forward_dynamics(Q, QD, TAU, friction=True)
    assert M.shape == Ms.shape == (len(Q), mech.na, mech.na) and h.shape == hs.shape == gs.shape == free.shape
    for k in range(len(Q)):
        model = pkm.actuator_model(mech, Q[k], QD[k])
        for got, ref in ((M[k], model.M), (Ms[k], model.M), (h[k], model.h), (hs[k], model.h), (gs[k], model.g),
                         (free[k], pkm.forward_dynamics(mech, Q[k], QD[k], TAU[k])[mech.act_v]),
                         (rubbing[k], model.accelerations(TAU[k], friction=True))):
            assert rel(got, ref) <= 1e-10
        assert np.array_equal(M[k], M[k].T)
        one_M, one_h = K.mass_and_bias(Q[k], QD[k])
        assert rel(one_M, model.M) <= 1e-10 and rel(one_h, model.h) <= 1e-10
        assert rel(K.forward_dynamics(Q[k], QD[k], TAU[k], friction=True), rubbing[k]) <= 1e-14


@pytest.mark.parametrize("name", ["delta", "prs3", "ankle", "geared"])
def test_the_model_kernels_equal_the_python_model(name):
    """M_a and h_a (the fused kernel; the single ones on the Delta), g_a, the forward dynamics without friction
    (pkm.forward_dynamics' actuated entries) and with it (ActuatorSpaceModel.accelerations), a batch of 4 and one
    sample: 1e-10 relative; M_a exactly symmetric. The ankle's two idle spins get coordinates of their own."""
    K = _kernels(name)
    _check(K, *_states(K.mech, 4), single=name == "delta")
    if name == "ankle":
        assert len(K.dynamics.idle) == 2
    if name == "geared":
        model = K.mech.model
        assert min(np.asarray(model.armature)[K.mech.act_v]) == 2e-5 * 40.0 ** 2 and max(model.damping) == 0.05
    assert all(h.startswith("C (" if HAS_CC else "numpy") for h in K.how.values())


@pytest.mark.parametrize("name", ["prs3", "ankle"])
def test_without_a_compiler_numpy_gives_the_same_model(name):
    K = _kernels(name, compiled=False)
    _check(K, *_states(K.mech, 3, seed=1))
    assert all(h.startswith("numpy") for h in K.how.values())


def test_samples_under_the_pivot_floor_come_from_the_python_model(monkeypatch):
    """With the floor above every pivot, every sample of every model kernel is pkm.actuator_model's."""
    K = _kernels("geared")
    Q, QD, TAU = _states(K.mech, 3, seed=2)
    expected = (*K.mass_and_bias(Q, QD), K.gravity(Q), K.forward_dynamics(Q, QD, TAU, friction=True))
    monkeypatch.setattr(kmod, "PIVOT_FLOOR", 2.0)
    got = (*K.mass_and_bias(Q, QD), K.gravity(Q), K.forward_dynamics(Q, QD, TAU, friction=True))
    for a, b in zip(got, expected):
        assert rel(a, b) <= 1e-10


def test_the_twin_rnea_carries_the_armature_as_pinocchio():
    """A reflected inertia on a motor and an armature on a passive joint: the twin's RNEA is Pinocchio's (1e-12)."""
    mech = _mechanism("geared")
    model = mech.model.copy()
    model.armature[int(mech.passive_v[0])] = 0.3
    twin = Twin(pkm.Mechanism(model, mech.spec, source="armature on a passive joint"))
    f = cs.Function("rnea", [twin.q, twin.v, twin.a], [twin.rnea])
    rng = np.random.default_rng(4)
    q, v, a = mech.q_reference, rng.standard_normal(mech.nv), rng.standard_normal(mech.nv)
    assert rel(np.array(f(q, v, a)).ravel(), pin.rnea(model, model.createData(), q, v, a)) <= 1e-12


def test_bad_input_is_refused_clearly():
    K = _kernels("prs3", compiled=False)
    q, z = K.mech.q_reference, np.zeros(3)
    with pytest.raises(InvalidInputError, match="friction"):
        K.forward_dynamics(q, z, z, friction="yes")
    with pytest.raises(InvalidInputError, match="coulomb_velocity"):
        K.forward_dynamics(q, z, z, coulomb_velocity=0.0)
    with pytest.raises(InvalidInputError, match="tau"):
        K.forward_dynamics(q, z, np.zeros(4))
    with pytest.raises(InvalidInputError, match="qd"):
        K.bias(q, np.zeros(2))
    with pytest.raises(InvalidInputError, match="non-finite"):
        K.mass_matrix(np.full_like(q, np.nan))
