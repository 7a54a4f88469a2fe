"""Transmission kernels (:mod:`pkm.core.transmissions.kernels`) on the humanoid ankle (two motors, two rods between
balls: idle motions, rotor armature), compiled C, against independent routes: pkm's closure and Jacobian,
Pinocchio's CRBA and RNEA of the serial bodies, pkm's actuator-space model; and the refusals."""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.transmissions.kernels import TransmissionKernels
from pkm.errors import InvalidInputError, TransmissionError
from tests.core.transmissions.robots import transmissions


@functools.cache
def ankle() -> TransmissionKernels:
    """The humanoid ankle's transmission ("foot": motors left and right -> ankle pitch and roll)."""
    return TransmissionKernels.of(transmissions("humanoid_ankle")[0])


@functools.cache
def knee() -> TransmissionKernels:
    """The humanoid knee's ("shank": the knee motor -> the knee)."""
    return TransmissionKernels.of(transmissions("humanoid_knee")[0])


def states(tk: TransmissionKernels, n: int, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """``n`` motor positions within ±0.2 rad of the reference and their closed configurations (the kernel's FK from
    the reference: checked below against pkm.close_loops)."""
    qm = tk.mech.actuated_q(tk.mech.q_reference) + np.random.default_rng(seed).uniform(-0.2, 0.2, (n, tk.k))
    q, _, status, _ = tk.run("fk", np.tile(tk.mech.q_reference, (n, 1)), qm)
    assert (status == 0).all()
    return qm, q


def serial_model(tk: TransmissionKernels) -> pin.Model:
    """Pinocchio's model with the inertias of every body but the serial ones zeroed (the independent route)."""
    model = pin.Model(tk.mech.model)
    keep = {tk.mech.joints[n].id for n in tk.outputs}
    for j in range(1, model.njoints):
        if j not in keep:
            model.inertias[j] = pin.Inertia.Zero()
    return model


def test_fk_ik_round_trip_and_maps_match_pkm():
    """Motors -> outputs -> motors to 1e-12 from a cold start (the reference, 0.2 rad away), the outputs equal to
    pkm.close_loops'; J = pkm.forward_jacobian (the task is the outputs) and J J_inv = I to 1e-12."""
    tk = ankle()
    mech = tk.mech
    qm, q = states(tk, 40)
    qo = q[:, tk.output_q]
    for k in (0, 17, 39):
        closed = pkm.close_loops(mech, qm[k], mech.q_reference, tol=1e-13).q
        assert np.abs(closed[tk.output_q] - qo[k]).max() <= 1e-12
    _, qm_back, status, residual = tk.run("ik", np.tile(mech.q_reference, (40, 1)), qo)
    assert (status == 0).all() and residual.max() <= 1e-12
    assert np.abs(qm_back - qm).max() <= 1e-12
    J, J_inv, pivot = tk.run("maps", q)
    J, J_inv = (x.reshape(-1, 2, 2).transpose(0, 2, 1) for x in (J, J_inv))  # (column-major)
    assert np.abs(J @ J_inv - np.eye(2)).max() <= 1e-12 and pivot.min() > 1e-3
    for k in (0, 39):
        assert np.abs(J[k] - pkm.forward_jacobian(mech, q[k])).max() <= 1e-12


def test_serial_plus_delta_is_the_closed_loop_model():
    """``Jᵀ (M_s + ΔM) J = pkm.mass_matrix`` and ``Jᵀ (h_s + Δh + (M_s + ΔM) J̇ q̇_m) = pkm.bias_efforts`` to 1e-10
    relative, with ``M_s``, ``h_s`` from Pinocchio's CRBA and RNEA of the serial bodies (the foot; rods, cranks and
    rotors dropped) and ``J̇ q̇_m`` the outputs' accelerations at ``q̈_m = 0`` (pkm.accelerations); ΔM is symmetric
    and carries the rotors' armature (0.0825 kg m² each, reflected)."""
    tk = ankle()
    mech = tk.mech
    _, q = states(tk, 6, seed=2)
    qdm = np.random.default_rng(3).uniform(-2.0, 2.0, (6, 2))
    J = tk.run("maps", q)[0].reshape(-1, 2, 2).transpose(0, 2, 1)
    qdo = np.einsum("nij,nj->ni", J, qdm)
    dM, dh, pivot = tk.run("delta", q, qdo)
    dM = dM.reshape(-1, 2, 2).transpose(0, 2, 1)
    assert np.abs(dM - dM.transpose(0, 2, 1)).max() == 0.0 and pivot.min() > 1e-3
    model = serial_model(tk)
    data = model.createData()
    o = tk.output_v
    for k in range(6):
        M_s = pin.crba(model, data, q[k])
        M_s = np.triu(M_s) + np.triu(M_s, 1).T
        v = np.zeros(mech.nv)
        v[o] = qdo[k]
        h_s = pin.rnea(model, data, q[k], v, np.zeros(mech.nv))[o]
        M_o = M_s[np.ix_(o, o)] + dM[k]
        M_a = pkm.mass_matrix(mech, q[k])
        assert np.abs(J[k].T @ M_o @ J[k] - M_a).max() <= 1e-10 * np.abs(M_a).max()
        jdot_qd = pkm.accelerations(mech, q[k], pkm.velocities(mech, q[k], qdm[k]), np.zeros(2))[o]
        h_a = pkm.bias_efforts(mech, q[k], qdm[k])
        assert np.abs(J[k].T @ (h_s + dh[k] + M_o @ jdot_qd) - h_a).max() <= 1e-10 * np.abs(h_a).max()
    assert dM[0].diagonal().min() > 0.0825 * np.abs(np.linalg.inv(J[0])).min() ** 2  # (the rotors are in ΔM)


def test_the_kernels_equal_the_python_reference():
    """The C kernels equal :class:`pkm.Transmission`'s maps (pkm's solvers, its output-coordinate model and serial
    tree: another route to every number) at random states: FK to 1e-12, the velocity and effort maps to 1e-12,
    ΔM and Δh to 1e-10 relative."""
    t = transmissions("humanoid_ankle")[0]
    tk = ankle()
    assert (tk.name, tk.motors, tk.outputs) == (t.name, t.motors, t.outputs)
    qm, q = states(tk, 4, seed=6)
    qdo = np.random.default_rng(7).uniform(-2.0, 2.0, (4, 2))
    J, J_inv, _ = (x.reshape(-1, 2, 2).transpose(0, 2, 1) for x in tk.run("maps", q))
    dM, dh, _ = tk.run("delta", q, qdo)
    dM = dM.reshape(-1, 2, 2).transpose(0, 2, 1)
    for k in range(4):
        assert np.abs(t.outputs_from_motors(qm[k])[0] - q[k, tk.output_q]).max() <= 1e-12
        assert np.abs(t.effort_map(q[k]) - J[k].T).max() <= 1e-12
        assert np.abs(t.inverse_effort_map(q[k]) - J_inv[k].T).max() <= 1e-12
        M_o, h_o = t.output_model(q[k], qdo[k])
        assert np.abs(t.delta_mass(q[k]) - dM[k]).max() <= 1e-10 * np.abs(M_o).max()
        assert np.abs(t.delta_bias(q[k], qdo[k]) - dh[k]).max() <= 1e-10 * np.abs(h_o).max()


def test_fk_reports_its_status_and_holds_the_warm_start():
    """An unreachable motor target is ``NOT_CONVERGED`` (1) with its residual, not a wrong answer; a warm start a
    tick away converges in the kernel's iterations."""
    tk = knee()
    qm, q = states(tk, 3)
    _, _, status, residual = tk.run("fk", q, qm + 0.01)
    assert (status == 0).all() and residual.max() <= 1e-12
    _, qo, status, _ = tk.run("fk", tk.mech.q_reference, qm)  # (one warm start for every sample)
    assert qo.shape == (3, 1) and (status == 0).all()
    _, _, status, residual = tk.run("fk", q[0], np.array([qm[0, 0] + 3.0]))
    assert status[0] in (1.0, 2.0) and not residual[0] <= 1e-12
    with pytest.raises(InvalidInputError, match=r"qm.*non-finite"):
        tk.run("fk", q[0], np.array([np.nan]))


def test_bad_outputs_are_refused_naming_the_transmission():
    mech = knee().mech
    with pytest.raises(TransmissionError, match=r"transmission 'left_knee': output 'knee_motor' is a motor"):
        TransmissionKernels(mech, ("knee_motor",), name="left_knee")
    with pytest.raises(TransmissionError, match=r"'left_knee': output 'nope' is not a one-coordinate joint"):
        TransmissionKernels(mech, ("nope",), name="left_knee")
    with pytest.raises(TransmissionError, match="2 distinct outputs for 1 motors"):
        TransmissionKernels(mech, tuple(n for n in mech.joints if n != "knee_motor")[:2])
