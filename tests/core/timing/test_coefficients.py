"""The effort coefficients a, b, c along a path against pkm.inverse_dynamics, finite differences, the compiled
route, and the payload against an external wrench."""

from __future__ import annotations

import numpy as np

import pkm
from pkm.core.timing import path_coefficients, with_payload


def _id_efforts(mech, C, k, sd, sdd, wrench=None):
    q = C.q[k]
    v = pkm.inverse_velocities(mech, q, C.dy[k] * sd)
    a = pkm.inverse_accelerations(mech, q, v, C.ddy[k] * sd * sd + C.dy[k] * sdd)
    return pkm.inverse_dynamics(mech, q, v, a, wrench)


def test_coefficients_equal_inverse_dynamics_at_random_speeds(delta, arc):
    _, C = arc
    rng = np.random.default_rng(3)
    for k in rng.integers(0, len(C.s), 6):
        sd, sdd = rng.uniform(0.1, 4.0), rng.uniform(-30.0, 30.0)
        tau = _id_efforts(delta, C, k, sd, sdd)
        mine = C.a[k] * sdd + C.b[k] * sd * sd + C.c[k]
        assert np.abs(mine - tau).max() <= 1e-9 * np.abs(tau).max()


def test_path_derivatives_against_finite_differences(delta, arc):
    path, C = arc
    h = 1e-5
    s = C.s[5:8]
    up, down = path_coefficients(delta, path, s + h), path_coefficients(delta, path, s - h)
    assert np.abs((up.qa - down.qa) / (2 * h) - C.dqa[5:8]).max() <= 1e-8 * np.abs(C.dqa).max()
    assert np.abs((up.dqa - down.dqa) / (2 * h) - C.ddqa[5:8]).max() <= 1e-7 * np.abs(C.ddqa).max()


def test_compiled_route_equals_core(delta, arc):
    path, C = arc
    K = path_coefficients(delta, path, C.s, kernels=pkm.Kernels(delta))
    for f in ("qa", "dqa", "a", "c"):
        assert np.abs(getattr(K, f) - getattr(C, f)).max() <= 1e-9 * np.abs(getattr(C, f)).max(), f
    inner = slice(1, -1)  # (b: Richardson differences of q_a')
    assert np.abs(K.b[inner] - C.b[inner]).max() <= 1e-9 * np.abs(C.b).max()


def test_payload_equals_its_weight_and_inertia_as_a_wrench(delta, arc):
    path, C = arc
    m = 1.5
    Cp = path_coefficients(with_payload(delta, m), path, C.s[9:11])
    sd, sdd = 1.3, -7.0
    acc = C.ddy[10] * sd * sd + C.dy[10] * sdd  # the end effector's acceleration (a point: the task is x y z)
    wrench = np.concatenate([m * (np.array([0.0, 0.0, -9.81]) - acc), np.zeros(3)])
    tau = _id_efforts(delta, C, 10, sd, sdd, wrench)
    mine = Cp.a[1] * sdd + Cp.b[1] * sd * sd + Cp.c[1]
    assert np.abs(mine - tau).max() <= 1e-9 * np.abs(tau).max()
