"""The idle-motion convention (:mod:`pkm.core.differential.idle`) on every Gepetto robot and acceptance-set mechanism
with idle motions, at one regular configuration away from the reference:

* :func:`pkm.velocities` and :func:`pkm.accelerations` equal the rates and accelerations of least ``½ xᵀ M x``
  under the closures and the actuated values, by the null-space method on the closures and the actuators together
  (an independent route: no idle basis, no split into passive and actuated): 1e-10 relative in the mass metric; and
  they are the model's (``model.v``, ``model.joint_accelerations``): 1e-12;
* ``M_a qdd + h_a`` equals :func:`pkm.inverse_dynamics` at those rates, and ``½ qdᵀ M_a qd`` Pinocchio's kinetic
  energy: 1e-12 relative (before the convention was shared: 2e-5 and 1e-4 on ``cassie_like``);
* an idle acceleration added to ``a`` changes no effort (1e-12);
* inverse then forward dynamics, every route, gives ``qdd`` back: 1e-10 relative (0.86 off on ``wl16_like`` through
  the model before; :func:`tests.test_acceptance.check_every_route_gives_back`).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import pkm
from pkm.core.differential.idle import MASSLESS, idle_inertia_inverse, joint_inertia, without_idle
from pkm.core.dynamics import projection
from pkm.core.kinematics import constraints
from tests.test_acceptance import ACCEPTANCE, check_every_route_gives_back, moved
from tests.test_acceptance import load as acceptance
from tests.test_gepetto_robots import ROBOTS, gepetto

#: The mechanisms with idle motions (a test checks that the others have none).
IDLE = ("gepetto/5bar_linkage", "gepetto/cassie_like", "gepetto/digit_like", "gepetto/disney_like",
        "gepetto/robot_delta", "gepetto/talos_like", "gepetto/wl16_like", "acceptance/rssr", "acceptance/ankle")


def mechanism(name: str) -> pkm.Mechanism:
    where, robot = name.split("/")
    return gepetto(robot) if where == "gepetto" else acceptance(robot)


def rel(a, b) -> float:
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / max(np.abs(b).max(), 1e-300))


def energy_rel(M: np.ndarray, x: np.ndarray, ref: np.ndarray) -> float:
    """``|x - ref|_M / |ref|_M``: the difference in the mass metric (where the convention lives; the Euclidean
    difference of an idle part is the reference route's rounding over the idle inertia, 1e-6 of ``M`` on
    ``robot_delta``, 2e-9 there)."""
    return float(np.sqrt((x - ref) @ M @ (x - ref) / (ref @ M @ ref)))


def least_inertia(mech: pkm.Mechanism, q: np.ndarray, M: np.ndarray, rhs: np.ndarray, actuated: np.ndarray):
    """``argmin ½ xᵀ M x`` with ``J_c x = rhs`` and ``x[act] = actuated``, by the null-space method on
    ``A = [J_c; S_act]`` (its own SVD, rank 1e-9 relative: redundant closures)."""
    A = np.vstack([constraints.jacobian(mech, q), np.eye(mech.nv)[mech.act_v]])
    U, s, Vt = np.linalg.svd(A)
    r = int(np.sum(s > 1e-9 * s[0]))
    x0 = Vt[:r].T @ ((U[:, :r].T @ np.concatenate([rhs, actuated])) / s[:r])
    Z = Vt[r:].T
    return x0 - Z @ np.linalg.solve(Z.T @ M @ Z, Z.T @ M @ x0)


def test_the_set_lists_every_mechanism_with_idle_motions():
    names = [f"gepetto/{n}" for n in ROBOTS] + [f"acceptance/{n}" for n in ACCEPTANCE]
    with_idle = [n for n in names if pkm.diagnose(mechanism(n), mechanism(n).q_reference).idle_motions]
    assert with_idle == list(IDLE)


@pytest.mark.parametrize("name", IDLE)
def test_one_convention_from_the_rates_to_the_efforts(name):
    mech = mechanism(name)
    q = moved(mech)
    diagnosis = pkm.diagnose(mech, q)
    assert diagnosis.classification == "regular" and diagnosis.idle_motions > 0
    rng = np.random.default_rng(5)
    qd, qdd = rng.normal(size=mech.na), rng.normal(size=mech.na)
    v = pkm.velocities(mech, q, qd)
    a = pkm.accelerations(mech, q, v, qdd)
    M = joint_inertia(mech, q)
    assert energy_rel(M, v, least_inertia(mech, q, M, np.zeros(mech.n_constraints), qd)) <= 1e-10
    drift = constraints.drift(mech, q, v)
    assert energy_rel(M, a, least_inertia(mech, q, M, -drift, qdd)) <= 1e-10

    model = pkm.actuator_model(mech, q, qd)
    # (two routes through a J_p made rank deficient by the idle motions, each with its own pseudo-inverse: they agree
    # to round-off, 3e-12 on robot_delta's near-zero components; the identities below hold to 1e-12)
    assert rel(model.v, v) <= 1e-11 and rel(model.joint_accelerations(qdd), a) <= 1e-11
    tau = pkm.inverse_dynamics(mech, q, v, a)
    assert rel(model.efforts(qdd), tau) <= 1e-12
    kinetic, _ = projection.energy(mech, q, v)
    assert abs(model.kinetic_energy - kinetic) <= 1e-12 * kinetic
    N = pkm.idle_motions(mech, q)
    assert rel(pkm.inverse_dynamics(mech, q, v, a + N @ rng.normal(size=N.shape[1])), tau) <= 1e-12

    check_every_route_gives_back(mech, q, v, a, qdd)


def test_a_massless_idle_direction_keeps_the_minimum_norm():
    """An idle direction whose inertia is rounding (under MASSLESS of M's diagonal) is left as given; one with inertia
    is made mass-orthogonal."""
    M = np.diag([2.0, 1.0, 3.0])
    M[0, 2] = M[2, 0] = 0.5
    N = np.array([[0.0], [0.0], [1.0]])
    X = np.array([[1.0], [0.5], [0.0]])
    assert np.abs(N.T @ M @ without_idle(M, N, X)).max() <= 1e-15
    light = M.copy()
    light[2, 2], light[0, 2], light[2, 0] = 0.5 * MASSLESS, 0.0, 0.0
    assert idle_inertia_inverse(light, N).shape == (1, 1) and not idle_inertia_inverse(light, N).any()
    assert np.array_equal(without_idle(light, N, X), X)


@pytest.mark.parametrize("method", ["rk4", "radau"])
def test_a_simulation_keeps_the_energy_of_a_spin_that_moves_mass(method):
    """``talos_like``'s idle rod is not symmetric about its axis (its energy depends on its spin angle), released
    with a push, no friction, no effort: the total energy stays within 1e-8 of the largest kinetic energy over 10 ms,
    with either integrator (Radau closed every evaluation from the last one's configuration, so that the spin angle
    stayed put: 1e-4 off, and a hundred times slower)."""
    mech = mechanism("gepetto/talos_like")
    run = pkm.simulate(mech, moved(mech), np.full(mech.na, 0.5), duration=0.01, dt=1e-3, method=method,
                       friction=False, limits=False, singular_tol=0.0, backend="python")
    assert run.event is None and len(run) == 11
    assert np.abs(run.energy - run.energy[0]).max() <= 1e-8 * run.kinetic.max()


def test_a_configuration_whose_inertia_overflows_is_refused_by_pkm():
    """The fuzz's repro (issue 47): the Gough-Stewart (idle rod spins) at a configuration with a coordinate of
    -1e308 gave numpy's LinAlgError ("Eigenvalues did not converge") from the idle motions' inertia: the mass matrix
    there is not finite, which pkm now says."""
    from pkm.errors import PkmError

    mech = pkm.load("gough_stewart")
    q = mech.q_reference.copy()
    q[-4] = -1e308
    with pytest.raises(PkmError):
        pkm.inverse_velocities(mech, q, np.ones(mech.n_task))


def test_the_joint_inertia_of_a_mimic_tree_is_the_bodies_call_after_call():
    """A mimic joint with a child, sharing an ancestor with the joint it follows (UFACTORY's xArm7 gripper on its
    arm): Pinocchio 4.1's ``crba`` on a reused ``Data`` drifts there, call after call (here by 0.016 kg m^2 a call).
    :func:`joint_inertia` called three times on the same mechanism equals ``Σ V_bᵀ I_b V_b`` over the bodies, their
    twists ``V_b`` per unit joint rate from forward kinematics (an independent route: no crba, no RNEA), to 1e-12
    relative each time."""
    import pinocchio as pin

    model = pin.Model()
    ids: dict[str, int] = {}
    for k, (name, parent) in enumerate((("arm", ""), ("lead", "arm"), ("follow", "arm"), ("child", "follow"))):
        placement = pin.SE3(pin.utils.rotate("x", 0.3 * k) @ pin.utils.rotate("y", 0.2),
                            np.array([0.01 * k, 0.1 - 0.03 * k, 0.2]))
        ids[name] = model.addJoint(ids.get(parent, 0), pin.JointModelRZ() if k % 2 == 0 else pin.JointModelRX(),
                                   placement, name)
        body = pin.Inertia(1.0 + k, np.array([0.0, 0.05, 0.1]), np.diag([1.0, 2.0, 3.0]) * 1e-2)
        model.appendBodyToJoint(ids[name], body, pin.SE3.Identity())
    model = pin.transformJointIntoMimic(model, ids["lead"], ids["follow"], 1.0, 0.0)
    mech = SimpleNamespace(model=model, data=model.createData())  # (what joint_inertia reads of a Mechanism)
    q, data = np.array([0.1, 0.5, 0.9]), model.createData()
    twists = []
    for e in np.eye(model.nv):
        pin.forwardKinematics(model, data, q, e)
        twists.append(np.array([data.v[j].vector for j in range(1, model.njoints)]))
    inertias = [model.inertias[j].matrix() for j in range(1, model.njoints)]
    M = np.array([[sum(a @ Y @ b for a, b, Y in zip(Va, Vb, inertias)) for Vb in twists] for Va in twists])
    for _ in range(3):
        assert rel(joint_inertia(mech, q), M) <= 1e-12
