"""pkm.core.differential.velocity: the passive map, the Jacobians, velocities and accelerations, and the diagnosis.

Finite differences of every map on 200 poses per mechanism are in ``tests/test_mechanisms_generic.py``; here each
function is checked against an identity it must satisfy, and against the five-bar's singularities, placed
analytically (distal links collinear: direct; a leg stretched: inverse).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core import Configuration
from pkm.core.kinematics import constraints
from pkm.core.model.builder import from_strings
from pkm.errors import InvalidInputError, SingularityError
from pkm.mechanisms import names
from tests.fivebar import inverse_kinematics as fivebar_ik


def _near_reference(mech, seed: int) -> np.ndarray:
    """An assembled configuration near the reference (actuators moved by up to 0.02 rad or m)."""
    rng = np.random.default_rng(seed)
    qa = mech.actuated_q(mech.q_reference) + 0.02 * rng.uniform(-1, 1, mech.na)
    return pkm.close_loops(mech, qa).q


@pytest.mark.parametrize("name", names())
def test_the_passive_map_spans_the_closure_null_space_and_keeps_the_actuators(name, built):
    """J_c G = 0 (1e-12 of |J_c| |G|) and the actuated rows of G are the identity: closure-keeping rates."""
    mech = built(name)
    q = _near_reference(mech, 1)
    G = pkm.passive_map(mech, q)
    Jc = constraints.jacobian(mech, q)
    assert np.abs(Jc @ G).max() <= 1e-12 * np.abs(Jc).max() * max(np.abs(G).max(), 1.0)
    np.testing.assert_array_equal(G[mech.act_v], np.eye(mech.na))


@pytest.mark.parametrize("name", names())
def test_velocities_and_accelerations_round_trip_through_the_task(name, built):
    """inverse_velocities(task_velocity(v)) = v and inverse_accelerations(task_acceleration(a)) = a for the
    closure-keeping v = G qd and a = accelerations(qdd); forward and twist Jacobians agree with them."""
    mech = built(name)
    q = _near_reference(mech, 2)
    rng = np.random.default_rng(2)
    qd, qdd = rng.uniform(-1, 1, mech.na), rng.uniform(-1, 1, mech.na)
    v = pkm.velocities(mech, q, qd)
    yd = pkm.task_velocity(mech, q, v)
    np.testing.assert_allclose(yd, pkm.forward_jacobian(mech, q) @ qd, rtol=0, atol=1e-12 * max(1, abs(yd).max()))
    np.testing.assert_allclose(pkm.inverse_velocities(mech, q, yd), v, rtol=0, atol=1e-10 * max(1, abs(v).max()))
    a = pkm.accelerations(mech, q, v, qdd)
    gamma = constraints.drift(mech, q, v)
    assert np.abs(constraints.jacobian(mech, q) @ a + gamma).max() <= 1e-10 * max(1.0, np.abs(gamma).max())
    ydd = pkm.task_acceleration(mech, q, v, a)
    np.testing.assert_allclose(pkm.inverse_accelerations(mech, q, v, ydd), a, rtol=0,
                               atol=1e-9 * max(1, abs(a).max()))
    twist = pkm.twist_jacobian(mech, q) @ qd  # [v; w] of the end-effector origin, world axes
    pin.computeJointJacobians(mech.model, mech.data, q)
    pin.updateFramePlacements(mech.model, mech.data)
    Jee = pin.getFrameJacobian(mech.model, mech.data, mech.ee_frame, pin.LOCAL_WORLD_ALIGNED)
    np.testing.assert_allclose(twist, Jee @ v, rtol=0, atol=1e-12 * max(1, abs(twist).max()))


@pytest.mark.parametrize("name", names())
def test_the_inverse_jacobian_inverts_the_forward_one(name, built):
    """J_inv J_fwd = I on the actuated rates (square and regular at the reference neighbourhood)."""
    mech = built(name)
    q = _near_reference(mech, 3)
    Jf, Ji = pkm.forward_jacobian(mech, q), pkm.inverse_jacobian(mech, q)
    np.testing.assert_allclose(Ji @ Jf, np.eye(mech.na), rtol=0, atol=1e-10)


@pytest.mark.parametrize("name", names())
def test_the_analyses_equal_one_configuration_snapshot(name, built):
    """The Jacobians the analyses use are those of Configuration.at (one kinematics pass), whatever ran before."""
    mech = built(name)
    q1, q2 = _near_reference(mech, 4), _near_reference(mech, 5)
    c1 = Configuration.at(mech, q1)
    c2 = Configuration.at(mech, q2)  # a second snapshot leaves the first as it was
    np.testing.assert_array_equal(c1.constraint_jacobian, constraints.jacobian(mech, q1))
    np.testing.assert_array_equal(c1.residual, constraints.residual(mech, q1))
    np.testing.assert_array_equal(c1.task_value, pkm.TaskMap.of(mech).value(q1))
    np.testing.assert_array_equal(c1.task_jacobian, pkm.TaskMap.of(mech).jacobian(q1))
    np.testing.assert_array_equal(c2.task_jacobian, pkm.TaskMap.of(mech).jacobian(q2))
    G = pkm.passive_map(mech, q1)
    np.testing.assert_allclose(pkm.forward_jacobian(mech, q1), c1.task_jacobian @ G, rtol=0, atol=1e-13)
    with pytest.raises(InvalidInputError):
        Configuration.at(mech, q1[:-1])


# ---------------------------------------------------------------------- singularities of the five-bar
def _fivebar_at(mech, tip, branch=None) -> np.ndarray:
    return mech.q_from_dict(fivebar_ik(mech.params, tip, branch))


def test_collinear_distal_links_are_a_direct_singularity(built):
    """Tip (0, 0.15) m on the elbows_out mode: motors at pi - acos(0.8) and acos(0.8), both distal links horizontal.
    The passive map, forward Jacobian and velocities raise SingularityError('direct'); diagnose says so."""
    mech = built("fivebar")
    p = mech.params
    assert (p.d, p.l1, p.l2) == (0.20, 0.25, 0.30)  # the construction below assumes them
    q = _fivebar_at(mech, (0.0, 0.15), "elbows_out")
    motors = [float(np.ravel(mech.q_to_dict(q)[f"motor_{n}"])[0]) for n in (1, 2)]
    elbows = [np.array([s * p.d / 2, 0.0]) + p.l1 * np.array([math.cos(t), math.sin(t)])
              for s, t in zip((-1, 1), motors)]
    assert abs(abs(elbows[1][0] - elbows[0][0]) - 2 * p.l2) < 1e-12 and abs(elbows[0][1] - 0.15) < 1e-12
    for fn, args in ((pkm.passive_map, ()), (pkm.forward_jacobian, ()), (pkm.velocities, (np.ones(2),))):
        with pytest.raises(SingularityError) as exc:
            fn(mech, q, *args)
        assert exc.value.kind == "direct"
    d = pkm.diagnose(mech, q)
    assert d.classification == "direct" and d.sigma_direct < 1e-12 < d.sigma_inverse
    assert pkm.inverse_jacobian(mech, q).shape == (2, 2)  # the inverse problem stays regular


def test_a_stretched_leg_is_an_inverse_singularity(built):
    """Tip at l1 + l2 from motor 1 (leg 1 stretched): inverse_jacobian raises SingularityError('inverse'), the passive
    map exists, diagnose says 'inverse'."""
    mech = built("fivebar")
    p = mech.params
    tip = np.array([-p.d / 2, 0.0]) + (p.l1 + p.l2) * np.array([math.cos(math.pi / 3), math.sin(math.pi / 3)])
    q = _fivebar_at(mech, tip)
    with pytest.raises(SingularityError) as exc:
        pkm.inverse_jacobian(mech, q)
    assert exc.value.kind == "inverse"
    pkm.passive_map(mech, q)
    d = pkm.diagnose(mech, q)
    assert d.classification == "inverse" and d.sigma_inverse < 1e-7 and d.mobility == 2


def test_the_planar_loop_has_one_redundant_point_equation(built):
    """A point closure in the plane gives three equations, one redundant (z): rank 2, mobility nv - 2 = 2."""
    d = pkm.diagnose(built("fivebar"), built("fivebar").q_reference)
    assert (d.constraint_rank, d.redundant_constraints, d.mobility, d.classification) == (2, 1, 2, "regular")


@pytest.mark.parametrize("rtol", [0.0, -1e-3, float("nan"), 2.0, "1e-9"])
def test_a_bad_rank_tolerance_is_refused(rtol, built):
    mech = built("fivebar")
    for fn in (pkm.passive_map, pkm.inverse_jacobian, pkm.diagnose):
        with pytest.raises(InvalidInputError):
            fn(mech, mech.q_reference, rtol=rtol)


# ---------------------------------------------------------------------- idle motions
def _fivebar_with_spinning_rod():
    """The toy five-bar with distal link 1 free to spin about its own axis: the spin moves neither the closure
    point nor the tip, an idle motion, as a rod between two ball joints. Returns it and the plain five-bar."""
    import dataclasses

    from tests import fivebar

    p = fivebar.Params()
    spec = fivebar.closure_spec(p)
    spec = dataclasses.replace(spec, reference={**spec.reference, "spin_1": (0.0,)})
    return from_strings(fivebar.urdf_xml(p, spinning_rod=True), spec), fivebar.build(p)


def test_an_idle_rod_spin_is_reported_and_is_not_a_singularity():
    """The spinning rod gives one idle motion (spin_1): diagnose says regular with idle_motions 1; the passive map,
    forward and inverse Jacobians, velocities and accelerations exist and equal those of the five-bar without the
    spin (1e-12), with no spin rate or acceleration."""
    spin, plain = _fivebar_with_spinning_rod()
    rng = np.random.default_rng(7)
    for _ in range(5):
        y = pkm.TaskMap.of(plain).value(plain.q_reference) + 0.03 * rng.uniform(-1, 1, 2)
        q0 = plain.q_from_dict(fivebar_ik(plain.params, y))
        q1 = spin.q_from_dict({**fivebar_ik(plain.params, y), "spin_1": [float(rng.uniform(-3, 3))]})
        d = pkm.diagnose(spin, q1)
        assert (d.classification, d.idle_motions, d.idle_joints, d.near) == ("regular", 1, ("spin_1",), ())
        assert d.mobility == pkm.diagnose(plain, q0).mobility + 1
        np.testing.assert_allclose(pkm.forward_jacobian(spin, q1), pkm.forward_jacobian(plain, q0), rtol=0, atol=1e-12)
        np.testing.assert_allclose(pkm.inverse_jacobian(spin, q1), pkm.inverse_jacobian(plain, q0), rtol=0, atol=1e-11)
        qd, qdd = rng.uniform(-1, 1, 2), rng.uniform(-1, 1, 2)
        v1, v0 = pkm.velocities(spin, q1, qd), pkm.velocities(plain, q0, qd)
        s = spin.joints["spin_1"].idx_v
        assert v1[s] == 0.0
        np.testing.assert_allclose(np.delete(v1, s), v0, rtol=0, atol=1e-12)
        a1, a0 = pkm.accelerations(spin, q1, v1, qdd), pkm.accelerations(plain, q0, v0, qdd)
        assert abs(a1[s]) < 1e-12
        np.testing.assert_allclose(np.delete(a1, s), a0, rtol=0, atol=1e-11)
        yd = pkm.task_velocity(plain, q0, v0)
        np.testing.assert_allclose(pkm.inverse_velocities(spin, q1, yd), v1, rtol=0, atol=1e-11)


def test_rank_decisions_are_relative_to_the_largest_singular_value():
    """Scaling the whole five-bar by 1e-4 (a 20 um mechanism) leaves its distances to singularity unchanged
    (the old absolute floor max(smax, 1) made every small mechanism singular)."""
    from tests import fivebar

    big = fivebar.build()
    small = fivebar.build(fivebar.Params(d=0.2e-4, l1=0.25e-4, l2=0.3e-4))
    q_big = big.q_reference
    d_big = pkm.diagnose(big, q_big)
    q_small = small.q_from_dict(fivebar_ik(small.params, 1e-4 * pkm.TaskMap.of(big).value(q_big)))
    d_small = pkm.diagnose(small, q_small)
    assert d_small.classification == d_big.classification == "regular"
    assert math.isclose(d_small.direct_distance, d_big.direct_distance, rel_tol=1e-9)
    assert math.isclose(d_small.inverse_distance, d_big.inverse_distance, rel_tol=1e-9)
    pkm.passive_map(small, q_small)
    pkm.inverse_jacobian(small, q_small)


def test_diagnose_grades_the_approach_to_a_direct_singularity(built):
    """Along the five-bar's approach to collinear distal links, the direct distance falls linearly; below 1e-3 it
    is reported as near; the weakest direction tends to the tip moving across the links (along y)."""
    mech = built("fivebar")
    dists = []
    for eps in (1e-1, 1e-2, 1e-3, 1e-4):
        d = pkm.diagnose(mech, _fivebar_at(mech, (0.0, 0.15 + eps), "elbows_out"))
        dists.append(d.direct_distance)
        assert d.classification == "regular" and d.near == (("direct",) if d.direct_distance < 1e-3 else ())
        assert str(d).startswith("regular, but near a direct singularity (distance " if d.near else "regular: ")
        assert f"mobility {d.mobility} (constraint rank {d.constraint_rank} of " in str(d)
        assert f"distance to a direct singularity {d.direct_distance:.3g}, to an inverse one " in str(d)
        if eps <= 1e-3:
            assert abs(abs(d.direct_direction[1]) - 1.0) < 1e-3
    ratios = np.array(dists[:-1]) / np.array(dists[1:])
    assert np.all(ratios > 5) and np.all(ratios < 20)


def _fivebar_driven_by(actuated, task):
    import dataclasses

    from pkm.core.model.spec import TaskSpec
    from tests import fivebar

    plain = fivebar.build()
    spec = dataclasses.replace(plain.spec, actuated=actuated, task=TaskSpec(task), branches={}, default_branch=None)
    return from_strings(plain.urdf, spec)


def test_actuators_beyond_the_mobility_are_named_when_the_model_loads_and_by_diagnose():
    """Issue 27: a five-bar (mobility 2) driven by three joints loads with a PkmWarning naming the dependent one
    (kept in mech.notes); diagnose names it; loop closure from values that disagree says so instead of only 'did
    not converge'."""
    from pkm.core.differential.velocity import actuation
    from pkm.errors import ConvergenceError, PkmWarning

    with pytest.warns(PkmWarning, match=r"actuator\(s\) \['elbow_1'\] depend on the others \(mobility 2, 2 "):
        mech = _fivebar_driven_by(("motor_1", "motor_2", "elbow_1"), ("x", "y"))
    assert mech.dependent_actuators == ("elbow_1",) and "elbow_1" in mech.notes[-1]
    fit = actuation(mech)
    assert (fit.mobility, fit.independent, fit.unactuated) == (2, 2, 0)
    d = pkm.diagnose(mech, mech.q_reference)
    assert d.dependent_actuators == ("elbow_1",) and "['elbow_1'] depend on the others" in str(d)
    qa = mech.actuated_q(mech.q_reference) + [0.01, -0.01, 0.3]  # elbow_1 disagrees with the motors
    with pytest.raises(ConvergenceError, match=r"\['elbow_1'\] depend on the others"):
        pkm.close_loops(mech, qa)


def test_with_every_joint_actuated_no_direct_singularity_is_told(all_actuated):
    """No passive coordinate: nothing the actuators leave free, so no direct singularity (sigma inf, distance 1:
    the empty passive Jacobian was graded 0, a 'direct' singularity); the passive map is the identity on the
    actuated rows."""
    mech = all_actuated
    d = pkm.diagnose(mech, mech.q_reference)
    assert d.classification == "regular" and d.sigma_direct == math.inf and d.direct_distance == 1.0
    assert d.near == () and d.dependent_actuators == ("elbow_1", "elbow_2") and d.mobility == 2
    assert np.array_equal(pkm.passive_map(mech, mech.q_reference)[mech.act_v], np.eye(mech.nv))


def test_actuators_short_of_the_mobility_are_reported():
    """A five-bar driven by one motor keeps one degree of freedom with it locked, which moves the tip: reported
    (not an idle motion); the registered mechanisms and the toy five-bar fit theirs exactly."""
    from pkm.core.differential.velocity import actuation
    from pkm.errors import PkmWarning

    with pytest.warns(PkmWarning, match=r"1 degree\(s\) of freedom move the task with every actuator locked"):
        mech = _fivebar_driven_by(("motor_1",), ("x",))
    fit = actuation(mech)
    assert (fit.mobility, fit.independent, fit.dependent, fit.unactuated, fit.idle_motions) == (2, 1, (), 1, 0)
    assert pkm.diagnose(mech, mech.q_reference).unactuated == 1
    from tests import fivebar

    assert actuation(fivebar.build()).problem == ""
    from pkm.errors import SpecError

    with pytest.raises(SpecError, match="no actuated joint"):  # (an IndexError before)
        _fivebar_driven_by((), ())


def test_a_configuration_is_accepted_wherever_q_is_and_computed_once(monkeypatch):
    """forward_jacobian, inverse_jacobian, diagnose... at one Configuration: equal results, one kinematics pass
    (Configuration.compute is not called again); a Configuration of another mechanism is refused."""
    from pkm.core.kinematics.configuration import Configuration

    delta = pkm.load("delta")
    q = _near_reference(delta, 4)
    c = Configuration.at(delta, q)
    expected = (pkm.forward_jacobian(delta, q), pkm.inverse_jacobian(delta, q), pkm.diagnose(delta, q).sigma_direct)
    calls = []
    real = Configuration.compute.__func__
    monkeypatch.setattr(Configuration, "compute", classmethod(lambda cls, m, qq: calls.append(1) or real(cls, m, qq)))
    got = (pkm.forward_jacobian(delta, c), pkm.inverse_jacobian(delta, c), pkm.diagnose(delta, c).sigma_direct)
    assert not calls
    np.testing.assert_array_equal(got[0], expected[0])
    np.testing.assert_array_equal(got[1], expected[1])
    assert got[2] == expected[2]
    np.testing.assert_array_equal(pkm.velocities(delta, c, [0.1, 0.2, 0.3]), pkm.velocities(delta, q, [0.1, 0.2, 0.3]))
    with pytest.raises(InvalidInputError, match="Configuration of 'delta'"):
        pkm.forward_jacobian(pkm.load("rrr3"), c)


def test_the_split_is_kept_for_the_same_jacobians_and_given_out_as_copies():
    """The split a path step asks for four times is made once per configuration: the same object for the same
    Jacobians, bit for bit the one made afresh, another where they change; an idle basis written to by a caller does
    not change the next answer (the humanoid ankle: its rods' spins are idle)."""
    from pkm.core.differential import velocity

    ankle = pkm.load(Path(__file__).resolve().parents[3] / "examples" / "humanoid_ankle" / "ankle.closures.toml")
    q = _near_reference(ankle, 3)
    c = Configuration.at(ankle, q)
    kept = velocity._split(ankle, c, 1e-9)
    assert velocity._split(ankle, Configuration.at(ankle, q), 1e-9) is kept
    fresh = velocity._Split.of(ankle, c.constraint_jacobian, c.task_jacobian, 1e-9)
    assert np.array_equal(kept.idle, fresh.idle) and np.array_equal(kept.Vat, fresh.Vat)
    assert velocity._split(ankle, Configuration.at(ankle, _near_reference(ankle, 4)), 1e-9) is not kept
    N = pkm.idle_motions(ankle, q)
    assert N.shape[1] == 2
    N[:] = 0.0
    assert np.array_equal(pkm.idle_motions(ankle, q), fresh.idle)


def test_singularity_distances_are_diagnoses(built):
    """``singularity_distances`` (the searches' shortcut) gives diagnose's two distances bit for bit, far from and near
    a direct singularity of the five-bar, at a non-default rtol too."""
    from pkm.core.differential.velocity import singularity_distances

    mech = built("fivebar")
    for eps, rtol in ((1e-1, 1e-7), (1e-3, 1e-7), (1e-3, 1e-2)):
        q = _fivebar_at(mech, (0.0, 0.15 + eps), "elbows_out")
        d = pkm.diagnose(mech, q, rtol=rtol)
        assert singularity_distances(mech, q, rtol=rtol) == (d.direct_distance, d.inverse_distance)
