"""Position solvers and differential kinematics of the core: results, bounds, and errors on bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

import pkm
from pkm.core import close_loops, diagnose, solve_ik
from pkm.core.kinematics import constraints
from pkm.core.model.builder import from_strings
from pkm.errors import (
    AssemblyError,
    ConvergenceError,
    InvalidInputError,
    SingularityError,
    SpecError,
    UnknownNameError,
)
from pkm.mechanisms import delta as D
from pkm.mechanisms import names, rrr3


@pytest.fixture(scope="module")
def delta(built):
    return built("delta")


def test_solve_result_reports_convergence_residual_and_iterations(delta):
    """A loop closure from a neighbouring configuration converges in a few iterations to 1e-12."""
    qa = delta.actuated_q(delta.q_reference) + 0.01
    res = close_loops(delta, qa, delta.q_reference)
    assert res.converged and res.residual <= 1e-12 and 1 <= res.iterations <= 10 and res.steps == 1
    assert res.branch_signs == {"knee_1": -1, "knee_2": -1, "knee_3": -1}


@pytest.mark.parametrize("bad", [[0.1, 0.2], [0.1, math.nan, 0.2], [[0.1, 0.2, 0.3]], "abc", None])
def test_bad_actuated_input_is_refused(delta, bad):
    """Wrong shapes, NaN and non-numbers are InvalidInputErrors naming the argument."""
    with pytest.raises(InvalidInputError, match="q_actuated"):
        close_loops(delta, bad)


def test_bad_configuration_and_target_are_refused(delta):
    """A configuration of the wrong size or with inf, and a target of the wrong size, are refused."""
    with pytest.raises(InvalidInputError, match="q0"):
        close_loops(delta, [0.0, 0.0, 0.0], np.zeros(5))
    with pytest.raises(InvalidInputError, match="target"):
        solve_ik(delta, [0.0, 0.0])
    with pytest.raises(InvalidInputError, match="target"):
        solve_ik(delta, [0.0, math.inf, -0.3])
    q = delta.q_reference.copy()
    q[0] = math.inf
    with pytest.raises(InvalidInputError):
        pkm.forward_jacobian(delta, q)


def test_unassemblable_motor_angles_raise_convergence_error_with_the_open_loop():
    """Motor angles with no assembly: the solver stops, bounded, and says which loop stays open."""
    short = D.build(D.DeltaParams(Lb=0.2, home=(0.0, 0.0, -0.2)))
    theta = [-0.7, -0.4, 0.2]
    with pytest.raises(AssemblyError):  # the paper's sphere intersection agrees: no assembly
        D.forward_kinematics(short.params, theta)
    with pytest.raises(ConvergenceError) as info:
        close_loops(short, theta, max_iter=15)
    err = info.value
    assert err.residual > 1e-3 and err.worst_closure in {"ball_1", "ball_2", "ball_3"} and err.worst_gap > 1e-3
    assert "stays open" in str(err)


def test_a_coarser_min_step_gives_up_sooner_and_closes_the_same():
    """min_step (the random states' draws take 0.05): a hexapod target its path cannot reach fails after fewer Newton
    iterations than with the default 1e-3; one it reaches closes to the same configuration, bit for bit; a min_step
    outside (0, 1] is refused."""
    hexapod = pkm.load("hexapod")
    qa0 = hexapod.actuated_q(hexapod.q_reference)
    far, near = qa0 + np.random.default_rng(0).uniform(-0.1, 0.1, hexapod.na), qa0 + 0.02  # (the first draw: out)
    fine = close_loops(hexapod, far, raise_on_failure=False)
    coarse = close_loops(hexapod, far, raise_on_failure=False, min_step=0.05)
    assert not fine.converged and not coarse.converged and coarse.iterations < fine.iterations
    assert np.array_equal(close_loops(hexapod, near).q, close_loops(hexapod, near, min_step=0.05).q)
    for bad in (0.0, 1.5, math.nan):
        with pytest.raises(InvalidInputError, match="min_step"):
            close_loops(hexapod, near, min_step=bad)


def test_a_target_outside_the_workspace_is_unreachable_not_a_convergence_failure(delta, built):
    """A platform position far outside the workspace, and the five-bar's tip beyond its reach (0.7 m up, links
    0.55 m), give UnreachableError naming the closure left open at the least-squares minimum, never NaN nor
    "did not converge"."""
    from pkm.errors import UnreachableError

    with pytest.raises(UnreachableError, match=r"out of the workspace.*closure 'ball_\d' stays open"):
        solve_ik(delta, [0.0, 0.0, -2.0], max_iter=10)
    with pytest.raises(UnreachableError, match=r"closure 'tip' stays open by .* the task misses by 0\.1"):
        solve_ik(built("fivebar"), [0.0, 0.7])
    import dataclasses
    from pathlib import Path

    from pkm.core.model.spec import TaskSpec

    files = pkm.load(Path(__file__).resolve().parents[3] / "examples" / "gepetto_fivebar")
    gepetto = from_strings(files.urdf, dataclasses.replace(files.spec, end_effector="closedloop1_A",
                                                                     task=TaskSpec(("x", "y"))))
    with pytest.raises(UnreachableError, match=r"the task misses by 4\.\d+ m or rad .*the loops close") as exc:
        solve_ik(gepetto, {"x": 5.0})  # so far that the least-squares minimum has the loop (all but) closed
    assert exc.value.leg == 0


def test_a_reachable_target_the_solver_cannot_reach_is_a_convergence_failure(delta):
    """One Newton iteration per step to a reachable target: "did not converge", with the residual."""
    with pytest.raises(ConvergenceError) as exc:
        solve_ik(delta, [0.05, 0.0, -0.3], max_iter=1, max_step=1.0)
    assert not isinstance(exc.value, UnknownNameError) and exc.value.residual > 1e-12


def test_unknown_branch_and_frame_names_list_the_valid_ones(delta):
    """Unknown names raise UnknownNameError with the valid names in the message."""
    with pytest.raises(UnknownNameError, match="knee_out"):
        solve_ik(delta, [0.0, 0.0, -0.35], branch="knees_out")
    with pytest.raises(UnknownNameError, match="platform_ball_1"):
        delta.frame_id("platform_bal_1")


def test_other_branch_is_reached_from_a_branch_seed(delta):
    """The generic IK on 'knee_in' equals the closed form on that branch."""
    y = [0.01, 0.02, -0.36]
    res = solve_ik(delta, y, branch="knee_in")
    assert delta.on_branch(res.q, "knee_in")
    assert np.abs(delta.actuated_q(res.q) - D.inverse_kinematics(delta.params, y, "knee_in")).max() < 1e-9


def test_diagnose_classifies_a_folded_leg_as_inverse_singularity(delta):
    """With forearm 1 folded back onto arm 1's plane direction (double root of its IK), the configuration
    is an inverse singularity, and the inverse measure falls to zero on the way there."""
    p = delta.params
    th, eta = -3.1, -0.8
    B1 = np.array([0.0, p.R - p.r + p.La * math.cos(th), p.La * math.sin(th)])
    f = np.array([math.sin(eta), math.cos(eta) * math.cos(th), math.cos(eta) * math.sin(th)])
    E = B1 - p.Lb * f  # forearm 1's projection on arm 1's plane lies along the arm
    d = diagnose(delta, D.configuration(delta, E))
    assert d.classification == "inverse" and d.sigma_inverse < 1e-7
    with pytest.raises(SingularityError) as info:
        pkm.inverse_jacobian(delta, D.configuration(delta, E))
    assert info.value.kind == "inverse"
    sig = [diagnose(delta, D.configuration(delta, B1 - (p.Lb + s) * f)).sigma_inverse for s in (1e-4, 1e-5, 1e-6)]
    assert sig[0] > sig[1] > sig[2] > 0


def test_a_path_that_leaves_the_workspace_is_reported_as_such_when_the_target_itself_closes():
    """When continuation from the seed fails but a direct correction at the target closes, the error says the path
    left the workspace and asks for a nearer seed, instead of reporting a tiny residual as too large."""
    m = rrr3.build()
    qa = rrr3.closed_form_ik(m.params, [0.501, 0.025, 0.750])
    seed = rrr3.closed_form_configuration(m, [0.716, 0.203, 0.793])
    with pytest.raises(ConvergenceError, match="left the workspace") as info:
        close_loops(m, qa, seed)
    assert info.value.residual > info.value.tolerance
    assert info.value.result.residual <= info.value.tolerance


# ---------------------------------------------------------------------- assembly and the reference
def _without_reference(mech):
    import dataclasses

    return dataclasses.replace(mech.spec, reference={})


@pytest.mark.parametrize("name", names())
def test_a_spec_without_reference_is_assembled(name, built):
    """With no [reference], every registered mechanism is assembled from its neutral configuration (Levenberg-
    Marquardt with restarts) to 1e-10, and that configuration is accepted as its reference."""
    mech = built(name)
    again = from_strings(mech.urdf, _without_reference(mech))
    assert np.abs(constraints.residual(again, again.q_reference)).max() <= 1e-10


def test_assemble_closes_from_far_seeds_and_says_which_closure_stays_open_when_nothing_can():
    """pkm.assemble closes the Delta from seeds 1 rad away; a five-bar whose motors are 2 m apart (links 1.1 m
    in all) cannot close: the SpecError names the closure and its gap (about 0.9 m)."""
    import pinocchio as pin

    import pkm
    from tests import fivebar

    delta = pkm.load("delta")
    rng = np.random.default_rng(5)
    for _ in range(3):
        q0 = pin.integrate(delta.model, delta.q_reference, rng.uniform(-1, 1, delta.nv))
        res = pkm.assemble(delta, q0)
        assert res.converged and np.abs(constraints.residual(delta, res.q)).max() <= 1e-10
    plain = fivebar.build()
    with pytest.raises(SpecError, match=r"loops cannot be closed: .*'tip' \('tip_1'/'tip_2'\) open by 0\.[89]"):
        from_strings(fivebar.urdf_xml(fivebar.Params(d=2.0)), _without_reference(plain))


def test_a_frame_closure_that_cannot_close_is_named_with_its_gap_and_what_would_close_it():
    """Issue 27 (Gepetto's kangaroo_like: 6-D loops whose frames no joint can align): a planar five-bar closed by a
    frame closure whose second frame is tilted 0.3 rad about x cannot close, even alone; the error names the
    closure, its frames, the gap left at best (0 m, 0.3 rad: the tilt no joint can take) and that a point closure
    closes it, and carries the closures with their gaps (its cause, an AssemblyError). As a point closure it
    assembles, its frames then 0.3 rad apart about x at least."""
    import dataclasses

    import pinocchio as pin

    from pkm.core.model.spec import Closure
    from tests import fivebar

    tilted = ('<link name="tilted"/><joint name="tilted_fixed" type="fixed"><parent link="distal_2"/>'
              '<child link="tilted"/><origin xyz="0.3 0 0" rpy="0.3 0 0"/></joint></robot>')
    urdf = fivebar.urdf_xml(fivebar.Params()).replace("</robot>", tilted)
    spec = dataclasses.replace(fivebar.build().spec, reference={},
                               closures=(Closure("tips", "frame", "tip_1", "tilted"),))
    with pytest.raises(SpecError, match=r"cannot be closed: .*'tips' \('tip_1'/'tilted'\) open by 0 m and 0\.3 rad "
                                        r"at best \(its origins can meet\); each closes alone as a point closure") as info:
        from_strings(urdf, spec)
    (name, gap), = info.value.__cause__.closures
    assert name == "tips" and gap > 0.01
    mech = from_strings(urdf, dataclasses.replace(spec, closures=(Closure("tips", "point", "tip_1",
                                                                                      "tilted"),)))
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() <= 1e-10
    pin.framesForwardKinematics(mech.model, mech.data, mech.q_reference)
    tilt = mech.data.oMf[mech.frame_id("tilted")].rotation.T @ mech.data.oMf[mech.frame_id("tip_1")].rotation
    assert np.linalg.norm(pin.log3(tilt)) >= 0.3 - 1e-9  # (no joint turns about x)


def test_assemble_holds_the_joints_it_is_told_to_and_a_partial_reference_holds_what_it_states(built):
    """pkm.assemble(hold=...) keeps the held coordinates exactly; a [reference] that states only the actuators is
    assembled at those actuators (the 3-RPR of the acceptance set: its leg lengths)."""
    import pinocchio as pin

    delta = built("delta")
    rng = np.random.default_rng(2)
    q0 = pin.integrate(delta.model, delta.q_reference, 0.2 * rng.uniform(-1, 1, delta.nv))
    res = pkm.assemble(delta, q0, hold=delta.actuated_names)
    assert np.abs(delta.actuated_q(res.q) - delta.actuated_q(q0)).max() <= 1e-15
    assert np.abs(constraints.residual(delta, res.q)).max() <= 1e-10
    with pytest.raises(InvalidInputError, match="joint names"):
        pkm.assemble(delta, q0, hold="motor_1")
    from pathlib import Path

    rpr = pkm.load(Path(__file__).resolve().parents[3] / "examples" / "rpr3" / "rpr3.closures.toml")
    assert np.abs(rpr.actuated_q(rpr.q_reference) - 0.45).max() <= 1e-15


def test_a_spec_without_any_loop_is_refused(built):
    import dataclasses

    mech = built("delta")
    with pytest.raises(SpecError, match="no loop closure"):
        from_strings(mech.urdf, dataclasses.replace(mech.spec, closures=()))


def test_an_open_reference_is_refused_with_the_closure_and_the_gap(built):
    """A [reference] 8 cm off its closure (the Delta's platform moved down) is refused, naming the open closure."""
    import dataclasses

    mech = built("delta")
    ref = dict(mech.spec.reference)
    ref["platform_z"] = (ref["platform_z"][0] - 0.08,)
    with pytest.raises(SpecError, match=r"leaves closure 'ball_\d' open by 0\.0[78]"):
        from_strings(mech.urdf, dataclasses.replace(mech.spec, reference=ref))


def test_a_reference_in_degrees_or_without_values_is_refused(built):
    import dataclasses

    mech = built("delta")
    ref = {**mech.spec.reference, "motor_1": (45.0,)}
    with pytest.raises(SpecError, match=r"motor_1 = 45, beyond 2 pi: angles are in rad"):
        from_strings(mech.urdf, dataclasses.replace(mech.spec, reference=ref))
    ref = {**mech.spec.reference, "motor_1": ()}  # (found by the fuzzing: an IndexError before)
    with pytest.raises(SpecError, match=r"joint 'motor_1' takes 1 coordinate\(s\), got \(0,\)"):
        from_strings(mech.urdf, dataclasses.replace(mech.spec, reference=ref))


def test_a_result_checks_itself_again_and_assemble_follows_the_solvers_failure_rule(delta):
    """SolveResult.check(mech) re-verifies a result from its q alone (qpsolvers' Solution.is_optimal): true for
    what a solver returned, false once q is moved off the loops, for another mechanism, or for a NaN; assemble, like
    close_loops and solve_ik, returns a failed result instead of raising with raise_on_failure=False."""
    import dataclasses

    res = close_loops(delta, [-0.9, -0.85, -1.0])
    assert res.check(delta)
    moved = dataclasses.replace(res, q=res.q + 1e-3)
    assert not moved.check(delta)
    assert not dataclasses.replace(res, q=np.full_like(res.q, np.nan)).check(delta)
    assert not res.check(pkm.load("rrr3"))
    from tests import fivebar

    far = from_strings(fivebar.urdf_xml(fivebar.Params()), fivebar.build().spec)
    plain = dataclasses.replace(far.spec, reference={})
    tight = from_strings(fivebar.urdf_xml(fivebar.Params()), plain)
    q_open = tight.q_reference.copy()
    q_open[tight.joint("elbow_1").idx_q] += 2.0
    failed = pkm.assemble(tight, q_open, hold=("motor_1", "motor_2", "elbow_1"), restarts=0, raise_on_failure=False)
    assert not failed.converged and failed.residual > 1e-3 and failed.check(tight)


@pytest.mark.filterwarnings("ignore::pkm.errors.ImplausibleModelWarning")  # (the 0.1 copy's masses are the original's)
def test_a_result_checks_itself_alike_on_copies_scaled_in_size(delta):
    """SolveResult.check's tol counts a closure's gap in the characteristic length L (issue 52): the Delta and its
    copies scaled by 0.1 and 10, a solution moved off the loops by 1e-8 rad at a passive joint (a gap g of about 1.6e-8
    L, computed here from the point closures' residual over L): it holds to 2 g and not to g / 2 at every size, and
    its own solution holds to the default. (Before, in m: to tol = 1e-9 the copy 10 times smaller held, the others not.)"""
    import dataclasses

    from pkm.core.kinematics import constraints
    from pkm.core.model.builder import scaled_mechanism
    from pkm.core.model.scale import scale_configuration

    qa = np.array([-0.9, -0.85, -1.0])
    res = close_loops(delta, qa)
    moved = res.q.copy()
    moved[delta.passive_v[0]] += 1e-8
    verdicts = []
    for s in (1.0, 0.1, 10.0):
        m = delta if s == 1.0 else scaled_mechanism(delta, s)
        q = scale_configuration(delta, moved, s)
        r = constraints.residual(m, q)
        assert len(r) == 3 * len(m.spec.closures)  # (point closures: every row a length)
        gap = max(np.linalg.norm(r[k:k + 3]) for k in range(0, len(r), 3)) / m.characteristic_length
        assert 1e-9 < gap < 1e-7, (s, gap)
        mine = close_loops(m, qa)
        assert mine.check(m)
        off = dataclasses.replace(mine, q=q)
        verdicts.append((off.check(m, tol=2.0 * gap), off.check(m, tol=0.5 * gap), off.check(m, tol=1e-9)))
    assert verdicts == [(True, False, False)] * 3, verdicts


def test_a_failure_carries_its_problem_whose_jacobian_is_the_derivative_of_its_residual(delta):
    """ConvergenceError.problem (ClosureProblem, IKProblem): residual(q) is zero at a solution and equals the
    failure's residual at its last iterate; jacobian(q) equals central differences of residual along random
    tangent directions (1e-6 relative)."""
    import pinocchio as pin

    from pkm.core import ClosureProblem, IKProblem

    sol = close_loops(delta, [-0.9, -0.85, -1.0])
    closure = ClosureProblem(delta, delta.actuated_q(sol.q))
    ik = IKProblem(delta, pkm.TaskMap.of(delta).value(sol.q))
    rng = np.random.default_rng(0)
    for problem in (closure, ik):
        assert np.abs(problem.residual(sol.q)).max() <= 1e-10
        q = pin.integrate(delta.model, sol.q, 0.05 * rng.standard_normal(delta.nv))
        J = problem.jacobian(q)
        for _ in range(3):
            d = rng.standard_normal(delta.nv)
            h = 1e-6
            fd = (problem.residual(pin.integrate(delta.model, q, h * d))
                  - problem.residual(pin.integrate(delta.model, q, -h * d))) / (2 * h)
            assert np.abs(J @ d - fd).max() <= 1e-6 * max(1.0, np.abs(fd).max())
    short = D.build(D.DeltaParams(Lb=0.2, home=(0.0, 0.0, -0.2)))  # (these motor angles admit no assembly)
    with pytest.raises(ConvergenceError) as info:
        close_loops(short, [-0.7, -0.4, 0.2], max_iter=15)
    err = info.value
    assert isinstance(err.problem, ClosureProblem) and np.allclose(err.problem.q_actuated, [-0.7, -0.4, 0.2])
    closure_part = err.problem.residual(err.result.q)[:short.n_constraints]
    assert np.abs(closure_part).max() == pytest.approx(err.result.residual, rel=1e-9)


def test_a_solve_reports_interference_only_when_asked(delta):
    """collisions=True: the Gough-Stewart with 9.5 cm legs turned 1.2 rad interferes (its legs cross by 0.8 mm), at
    the reference it does not; the clearance is pkm.clearance's minimum; not asked, None; a mechanism without
    collision geometry (the Delta's URDF without its collision elements) refuses the question."""
    from pkm.errors import NoCollisionGeometryError

    thick = pkm.build("gough_stewart", cylinder_radius=0.095, rod_radius=0.095)
    turned = solve_ik(thick, {"yaw": 1.2}, collisions=True)
    home = close_loops(thick, thick.actuated_q(thick.q_reference), collisions=True)
    assert turned.interferes and -1e-3 < turned.clearance < 0.0 and not home.interferes and home.clearance > 0.0
    for res in (turned, home):
        assert res.clearance == pkm.clearance(thick, res.q).minimum
    assert solve_ik(thick, {"yaw": 1.2}).clearance is None
    from tests.core.collision.test_clearance import _without_collisions

    bare = pkm.from_strings(_without_collisions(delta.urdf), delta.spec)
    with pytest.raises(NoCollisionGeometryError):
        close_loops(bare, bare.actuated_q(bare.q_reference), collisions=True)


def test_redundant_actuation_closes_along_the_independent_actuators_and_names_the_dependent_one(built, redundant):
    """The five-bar with one elbow actuated too (3 actuators, mobility 2): the straight path from the reference's
    actuated values to a target's crosses values where the elbow disagrees with the motors (no assembly: a
    ConvergenceError at 0 % of the way before); now the elbow is released along the way and held at the target only.
    The result equals the five-bar's inverse kinematics (an independent route) to 1e-12; an elbow that disagrees
    with the motors is refused naming the open closure and the dependent actuator."""
    five, mech = built("fivebar"), redundant
    assert mech.dependent_actuators == ("elbow_1",) and len(mech.passive_v)
    y0 = pkm.TaskMap.of(five).value(five.q_reference)
    for dy in ([0.02, -0.03], [0.05, 0.04]):
        q = solve_ik(five, y0 + dy).q
        res = close_loops(mech, mech.actuated_q(q))
        assert res.converged and res.steps >= 2 and np.abs(mech.difference(q, res.q)).max() < 1e-12
    with pytest.raises(ConvergenceError, match=r"actuators \['elbow_1'\] depend on the others") as info:
        close_loops(mech, mech.actuated_q(q) + [0.0, 0.0, 1e-3])
    assert info.value.worst_closure == "tip" and info.value.worst_gap > 1e-5
