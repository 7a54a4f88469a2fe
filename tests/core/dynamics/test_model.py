"""The actuated-coordinate dynamic model against independent routes, on every shipped mechanism and the acceptance
set (and two Gepetto robots whose closures are redundant).

* ``M_a qdd + h_a`` against :func:`pkm.inverse_dynamics` (Khalil's projection or virtual work) at the rates and
  accelerations of :func:`pkm.velocities` and :func:`pkm.accelerations` (the model's own, 1e-12): 1e-10 relative;
  inverse then forward dynamics, every route, gives ``qdd`` back (1e-10 relative);
* ``½ qdᵀ M_a qd`` against the bodies' kinetic energy (Pinocchio): 1e-12 relative;
* the forward dynamics against Pinocchio's ``constraintDynamics`` (proximal where closures are redundant): 1e-9,
  idle accelerations left out (the model reports the convention's, no idle acceleration in the mass metric;
  ``constraintDynamics`` the unforced spin's);
* ``Ṁ_a - 2 C_a`` skew-symmetric, ``Ṁ_a`` from Richardson differences of ``M_a`` along the closed motion: 1e-8
  relative to ``|G|² |M| |qd|`` (the scale of the joint-space terms that ``Gᵀ M G`` cancels, whose rounding the
  differences amplify; ``C_a`` itself holds central differences);
* ``C_a qd = h_a - g_a`` where no idle motion is coupled: 1e-7 relative;
* ``M_a`` symmetric positive definite; the operational-space model gives back the efforts.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.dynamics import model as dm
from pkm.core.dynamics.projection import constraint_dynamics, energy
from pkm.errors import InvalidInputError, NonFiniteError, SingularityError, SpecError, StructureError
from tests.fd import richardson
from tests.test_acceptance import ACCEPTANCE, check_every_route_gives_back

SHIPPED = ("delta", "prs3", "rrr3", "hexapod", "gough_stewart")
SETS = {**{n: n for n in SHIPPED}, **{f"acceptance/{n}": p for n, (p, _) in ACCEPTANCE.items()},
        "gepetto/5bar_linkage": "gepetto:5bar_linkage", "gepetto/robot_delta": "gepetto:robot_delta"}
_CACHE: dict[str, pkm.Mechanism] = {}


def mechanism(name: str) -> pkm.Mechanism:
    if name not in _CACHE:
        where = SETS[name]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            _CACHE[name] = pkm.load(where)
    return _CACHE[name]


@pytest.fixture(scope="module", params=list(SETS))
def state(request):
    """A closed configuration away from the reference, random actuated rates and accelerations."""
    mech = mechanism(request.param)
    rng = np.random.default_rng(7)
    qa = mech.actuated_q(mech.q_reference) + 0.02 * rng.uniform(-1, 1, mech.na)
    q = pkm.close_loops(mech, qa, mech.q_reference).q
    return mech, q, rng.normal(size=mech.na), rng.normal(size=mech.na)


def rel(a, b) -> float:
    return float(np.abs(np.asarray(a) - np.asarray(b)).max() / max(np.abs(b).max(), 1e-300))


def test_model_gives_the_inverse_dynamics_and_the_kinetic_energy(state):
    mech, q, qd, qdd = state
    model = pkm.actuator_model(mech, q, qd)
    v = pkm.velocities(mech, q, qd)
    a = pkm.accelerations(mech, q, v, qdd)
    assert rel(model.v, v) <= 1e-12 and rel(model.joint_accelerations(qdd), a) <= 1e-12  # (one idle convention)
    assert rel(model.efforts(qdd), pkm.inverse_dynamics(mech, q, v, a)) <= 1e-10
    check_every_route_gives_back(mech, q, v, a, qdd)
    kinetic, _ = energy(mech, q, model.v)
    assert abs(model.kinetic_energy - kinetic) <= 1e-12 * kinetic
    assert np.abs(model.M - model.M.T).max() == 0.0
    assert np.linalg.eigvalsh(model.M).min() > 0.0
    assert rel(model.g, pkm.actuator_model(mech, q).h) <= 1e-12  # at rest, h_a is gravity alone


def test_forward_dynamics_equals_constraint_dynamics(state):
    mech, q, qd, _ = state
    model = pkm.actuator_model(mech, q, qd)
    tau = np.random.default_rng(1).normal(size=mech.na) + model.g
    a = pkm.forward_dynamics(mech, q, model.v, tau)
    assert rel(a[mech.act_v], model.accelerations(tau)) <= 1e-12
    if any(j.shortname() == "JointModelMimic" for j in mech.model.joints):
        return  # (constraintDynamics refuses mimic joints on Pinocchio 4.1)
    a_cd = constraint_dynamics(mech, q, model.v, tau)
    N = model.idle  # (the idle accelerations: the convention's here, the unforced spin's there)
    assert rel(a - N @ (N.T @ a), a_cd - N @ (N.T @ a_cd)) <= 1e-9


def test_coriolis_matrix_makes_mdot_minus_2c_skew(state):
    mech, q, qd, _ = state
    C = pkm.coriolis_matrix(mech, q, qd)
    model = pkm.actuator_model(mech, q, qd)
    qa = mech.actuated_q(q)

    def diff(h):
        ends = [pkm.mass_matrix(mech, pkm.close_loops(mech, qa + s * h * qd, pin.integrate(mech.model, q, s * h * model.v)).q)
                for s in (1.0, -1.0)]
        return (ends[0] - ends[1]) / (2.0 * h)

    M_dot = richardson(diff, 2e-5)
    S = M_dot - 2.0 * C
    # relative to the joint-space terms the reduction G^T M G cancels (their rounding, over the steps)
    scale = np.linalg.norm(model.G, 2) ** 2 * np.linalg.norm(model._M_joint, 2) * np.linalg.norm(qd)
    assert np.abs(S + S.T).max() <= 1e-8 * scale
    if not model.idle.shape[1]:
        assert rel(C @ qd, model.h - model.g) <= 1e-7


def test_operational_space_gives_back_the_efforts():
    for name in ("delta", "prs3", "acceptance/ankle"):
        mech = mechanism(name)
        q = mech.q_reference
        qd = np.linspace(0.3, -0.2, mech.na)
        ops = pkm.operational_space(mech, q, qd)
        model = pkm.actuator_model(mech, q, qd)
        qdd = np.linspace(-1.0, 1.0, mech.na)
        ydd = ops.jacobian @ qdd + ops.drift
        tau = model.efforts(qdd)
        assert rel(ops.jacobian.T @ (ops.inertia @ ydd + ops.bias), tau) <= 1e-10
        # and the task acceleration agrees with the kinematics'
        assert rel(ydd, pkm.task_acceleration(mech, q, model.v, model.joint_accelerations(qdd))) <= 1e-10


def test_gepetto_cases_right_with_the_default_arguments():
    """The five-bar (a planar loop closed with a 6-D frame) and the Delta (redundant closures): before 0.2.0 the
    first was 1.33 rad/s^2 off without a word and the second asked for ``mu``."""
    for name in ("gepetto/5bar_linkage", "gepetto/robot_delta"):
        mech = mechanism(name)
        q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + 0.05, mech.q_reference).q
        qd, qdd = np.full(mech.na, 0.5), np.full(mech.na, -0.7)
        v = pkm.velocities(mech, q, qd)
        tau = pkm.inverse_dynamics(mech, q, v, pkm.accelerations(mech, q, v, qdd))
        assert np.abs(pkm.forward_dynamics(mech, q, v, tau)[mech.act_v] - qdd).max() <= 1e-9


def test_reflected_inertia_adds_to_the_diagonal():
    mech = mechanism("delta")
    geared = pkm.with_actuators(mech, {"motor_2": {"rotor_inertia": 2e-5, "gear_ratio": 50.0}})
    q = mech.q_reference
    dM = pkm.mass_matrix(geared, q) - pkm.mass_matrix(mech, q)
    assert np.abs(dM - np.diag([0.0, 0.05, 0.0])).max() <= 1e-12


def test_friction_opposes_the_motion():
    mech = pkm.with_actuators(mechanism("delta"), {j: {"viscous": 0.3, "coulomb": 0.2} for j in
                                                   ("motor_1", "motor_2", "motor_3")})
    qd = np.array([1.0, -0.5, 0.0])
    f = pkm.actuator_model(mech, mech.q_reference, qd).friction
    assert np.allclose(f, -0.3 * qd - 0.2 * np.tanh(qd / dm.COULOMB_VELOCITY), rtol=0, atol=1e-12)


def test_bad_states_are_refused():
    mech = mechanism("delta")
    q = mech.q_reference
    with pytest.raises(InvalidInputError):
        pkm.actuator_model(mech, q, [1.0, np.nan, 0.0])
    with pytest.raises(InvalidInputError):
        pkm.actuator_model(mech, q[:-1])
    planar_task = dataclasses.replace(mech.spec, task=pkm.TaskSpec(("x", "y"), (), {}))
    with pytest.raises(InvalidInputError, match="as many"):
        pkm.operational_space(pkm.from_strings(mech.urdf, planar_task), q)
    with pytest.raises(InvalidInputError):
        pkm.actuator_model(mech, q, coulomb_velocity=0.0)


def test_rates_that_are_not_numbers_and_efforts_that_overflow_are_refused():
    """Fuzz findings: rates numpy cannot read as floats (a dict, a ragged list, an int beyond the floats, strings)
    raise InvalidInputError naming ``qd`` (they raised TypeError, ValueError, OverflowError); efforts whose
    accelerations overflow raise NonFiniteError (they gave NaN)."""
    mech = mechanism("delta")
    q = mech.q_reference
    for qd in ({"value": np.zeros(3)}, [0.0, [1.0], 0.0], 10**400, np.array(["a", "b"])):
        with pytest.raises(InvalidInputError, match="qd"):
            pkm.actuator_model(mech, q, qd)
    with pytest.raises(NonFiniteError):
        pkm.actuator_model(mech, q).accelerations([0.0, -1e308, 1e308])
    with pytest.raises(NonFiniteError):
        pkm.forward_dynamics(mech, q, np.zeros(3), [0.0, -1e308, 1e308])


def test_an_actuated_motion_without_mass_is_refused():
    with pytest.raises(SingularityError, match="moves no mass"):
        dm._solve_inertia(np.diag([1.0, 0.0]), np.ones(2), np.ones(2))


def test_the_inertia_test_does_not_depend_on_the_size():
    """A revolute and a prismatic actuator moving 1 kg at arm L (``M_a = diag(L^2, 1)``, kg m^2 and kg): the raw
    Cholesky diagonal spans L, which a robot of 10 um put under sqrt(RTOL) = 3.2e-5; homogenised by L (the prismatic
    column times L, :class:`~pkm.core.model.scale.JacobianScales`) it spans 1 at every size."""
    for L in (1e-5, 1.0, 1e3):
        qdd = dm._solve_inertia(np.diag([L * L, 1.0]), np.array([L * L, 1.0]), np.array([1.0, L]))
        assert np.allclose(qdd, 1.0, rtol=1e-14)
    with pytest.raises(SingularityError):
        dm._solve_inertia(np.diag([1e-10, 1.0]), np.ones(2), np.ones(2))


# ---------------------------------------------------------------------- a floating base (issue 51)
def _floating_state(name: str, seed: int = 5):
    """A floating robot closed away from its reference with its base turned and moved, random actuated rates and a
    random base twist (all joint rates, nv)."""
    from tests.core.dynamics.floating import floating

    mech = floating(name)
    rng = np.random.default_rng(seed)
    q0 = mech.q_reference.copy()
    at = mech.base.idx_q
    q0[at:at + 7] = np.r_[rng.uniform(-0.5, 0.5, 3), pin.Quaternion(pin.rpy.rpyToMatrix(*rng.uniform(-1, 1, 3))).coeffs()]
    q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + 0.1 * rng.uniform(-1, 1, mech.na), q0).q
    rates = np.zeros(mech.nv)
    rates[mech.base_v], rates[mech.act_v] = rng.normal(size=6), rng.normal(size=mech.na)
    return mech, q, rates, rng


def _without_idle(N, a):
    return a - N @ (N.T @ a)


@pytest.mark.parametrize("name", ["ankle", "delta", "fourbar"])
def test_a_free_base_moves_as_constraint_dynamics_and_newton_say(name):
    """A floating robot's base is free by default: the forward dynamics (base twist and an applied base wrench
    included) equals Pinocchio's constraintDynamics of the same model to 1e-8 relative (idle accelerations left out,
    as above; 1e-14 measured), its centre of mass falls at g exactly under any motor effort (no wrench on a free
    body but gravity), inverse then forward dynamics gives the efforts back with no base wrench asked; held
    (base="fixed"), it equals constraintDynamics with the base welded, and its base does not move. Before issue 51
    the base was held without a word: the floating ankle's motors were 35 to 105 rad/s^2 off constraintDynamics."""
    mech, q, rates, rng = _floating_state(name)
    model = pkm.actuator_model(mech, q, rates)
    assert model.base == "free" and np.array_equal(model.base_velocity, rates[mech.base_v])
    assert rel(model.kinetic_energy, energy(mech, q, model.v)[0]) <= 1e-12
    N = model.idle
    tau, wrench = rng.normal(size=mech.na), rng.normal(size=6)
    for w in (None, wrench):
        a = pkm.forward_dynamics(mech, q, model.v, tau, base_wrench=w)
        a_cd = constraint_dynamics(mech, q, model.v, tau, base_wrench=w)
        assert rel(_without_idle(N, a), _without_idle(N, a_cd)) <= 1e-8
    a = pkm.forward_dynamics(mech, q, model.v, tau)
    pin.centerOfMass(mech.model, mech.data, q, model.v, a)
    assert np.abs(mech.data.acom[0] - mech.model.gravity.linear).max() <= 1e-8 * 9.81
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # (a motion of the free robot asks nothing of the base: no warning)
        out = pkm.base_inverse_dynamics(mech, q, model.v, a)
        assert rel(pkm.inverse_dynamics(mech, q, model.v, a), tau) <= 1e-8
    assert rel(out.efforts, tau) <= 1e-8 and not out.needs_base_wrench and out.base == "free"
    out = pkm.base_inverse_dynamics(mech, q, model.v, pkm.forward_dynamics(mech, q, model.v, tau, base_wrench=wrench))
    assert rel(out.efforts, tau) <= 1e-8 and rel(out.base_wrench, wrench) <= 1e-8 and out.needs_base_wrench
    held = pkm.actuator_model(mech, q, rates, base="fixed")
    assert held.base == "fixed" and held.base_velocity.size == 0 and not np.any(held.v[mech.base_v])
    a = pkm.forward_dynamics(mech, q, held.v, tau, base="fixed")
    assert not np.any(a[mech.base_v])
    assert rel(_without_idle(N, a), _without_idle(N, constraint_dynamics(mech, q, held.v, tau, base="fixed"))) <= 1e-8
    assert rel(pkm.inverse_dynamics(mech, q, held.v, a, base="fixed"), tau) <= 1e-8


def test_the_base_choice_is_checked_and_named():
    """Every mechanism shipped has a fixed base (its model says so and is what it was); "free" there, an unknown
    choice, a wrench on a held base, and the Christoffel symbols of a free base are refused by name."""
    from tests.core.dynamics.floating import floating

    delta = mechanism("delta")
    model = pkm.actuator_model(delta, delta.q_reference, [0.3, 0.0, -0.2])
    assert model.base == "fixed" and np.array_equal(model.M, pkm.actuator_model(delta, delta.q_reference,
                                                                                 [0.3, 0.0, -0.2], base="fixed").M)
    for kw, match in (({"base": "free"}, "no floating base"), ({"base": "floating"}, "use one of")):
        with pytest.raises(InvalidInputError, match=match):
            pkm.actuator_model(delta, delta.q_reference, **kw)
    with pytest.raises(InvalidInputError, match="base_wrench"):
        pkm.forward_dynamics(delta, delta.q_reference, np.zeros(3), np.zeros(3), base_wrench=np.zeros(6))
    mech = floating("fourbar")
    q = pkm.close_loops(mech, [0.4], mech.q_reference).q
    with pytest.raises(InvalidInputError, match="base='fixed'"):
        pkm.coriolis_matrix(mech, q, [0.1])
    assert pkm.coriolis_matrix(mech, q, [0.1], base="fixed").shape == (1, 1)
    with pytest.raises(InvalidInputError, match="base_wrench"):
        pkm.forward_dynamics(mech, q, np.zeros(mech.nv), [0.0], base="fixed", base_wrench=np.zeros(6))
    with pytest.raises(InvalidInputError, match="no twist"):
        constraint_dynamics(mech, q, np.r_[np.ones(6), np.zeros(mech.nv - 6)], [0.0], base="fixed")
    delta = floating("delta")  # (its base tied to the ground by a closure: not a free body)
    anchored = dataclasses.replace(delta.spec, closures=(*delta.spec.closures,
                                                         pkm.Closure("anchor", "point", "ground", "base")))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (the builder's: the actuators fall short of the mobility)
        mech = pkm.from_strings(delta.urdf, anchored)
    q = pkm.close_loops(mech, mech.actuated_q(delta.q_reference) + 0.05, mech.q_reference).q
    with pytest.raises(SpecError, match="the closures hold the floating base 'pelvis'"):
        pkm.actuator_model(mech, q)
    assert pkm.actuator_model(mech, q, base="fixed").base == "fixed"


def test_an_undeclared_free_flyer_root_is_said_to_follow_the_idle_rule():
    """The ankle on a free pelvis that the spec does not declare its floating base: the pelvis is a passive joint
    whose motion is idle (the task is the ankle's joints), so the idle-motion rule, not gravity, sets its
    acceleration; the model says so (a PkmWarning naming it)."""
    from pkm.errors import PkmWarning
    from tests.core.dynamics.floating import floating

    declared = floating("ankle")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (the builder's: the actuators fall short of the mobility)
        mech = pkm.from_strings(declared.urdf, dataclasses.replace(declared.spec, floating_base=None))
    q = pkm.close_loops(mech, [0.1, -0.1], mech.q_reference).q
    with pytest.warns(PkmWarning, match="free-flyer 'pelvis' on the world is a passive joint"):
        pkm.actuator_model(mech, q)


def test_friction_on_a_free_base_enters_its_rows():
    """The Delta on a free pelvis with viscous friction on its motors and a drag on the pelvis's joint: the forward
    dynamics with friction balances every row of the equations of motion, ``[Ĝ Ĝ_b]ᵀ (rnea(q, v, a) - f) = [τ; 0]``
    (f the joints' friction at v; 1e-10 relative): the inverse dynamics' base wrench is the drag's share, its
    efforts ``τ + Ĝᵀ f``."""
    from pkm.core.differential.velocity import passive_map
    from tests.core.dynamics.floating import floating

    base = floating("delta")
    mech = pkm.with_actuators(base, {j: {"viscous": 0.05} for j in base.actuated_names})
    mech.model.damping[mech.base_v] = 0.2  # (this mechanism's own model: with_actuators builds a new one)
    q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + 0.05, mech.q_reference).q
    rates = np.zeros(mech.nv)
    rates[mech.base_v], rates[mech.act_v] = [0.3, -0.2, 0.5, 1.0, -0.5, 2.0], 0.4
    model = pkm.actuator_model(mech, q, rates)
    tau = np.array([0.1, -0.2, 0.3])
    a = dm.forward_dynamics(mech, q, model.v, tau, friction=True)
    f = -np.asarray(mech.model.damping) * model.v
    out = pkm.base_inverse_dynamics(mech, q, model.v, a)
    assert rel(out.base_wrench, model.base_friction) <= 1e-10 and rel(model.base_friction, f[mech.base_v]) <= 1e-10
    assert rel(out.efforts, tau + passive_map(mech, q).T @ f) <= 1e-10


def test_the_coriolis_matrix_of_a_redundantly_actuated_mechanism_is_refused_naming_the_dependent_actuator(redundant):
    """The five-bar with one elbow actuated too: M_a's derivative along one actuated coordinate alone opens the loops
    (a ConvergenceError from the nudged loop closure before); refused up front, the elbow named with the actuators
    to load instead, before any loop closure (the mass matrix itself stays defined on the rates that agree)."""
    q = redundant.q_reference
    with pytest.raises(StructureError, match=r"\['elbow_1'\] depend on the others.*\['motor_1', 'motor_2'\]") as info:
        pkm.coriolis_matrix(redundant, q, [0.1, 0.2, 0.0])
    assert info.value.part == "actuated"
    assert pkm.mass_matrix(redundant, q).shape == (3, 3)
