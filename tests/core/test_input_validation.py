"""Input validation of the generic core: wrong types, shapes, magnitudes and settings end in a PkmError
that names the argument, solvers stay bounded, and no routine returns NaN or infinity silently."""

from __future__ import annotations

import time

import numpy as np
import pytest

import pkm
from pkm.core.analysis import redundant_parameter
from pkm.core.differential import indices, screws
from pkm.core.dynamics.projection import KhalilProjection, constraint_dynamics, forward_dynamics
from pkm.core.kinematics.solve import MAX_TOTAL_ITER
from pkm.errors import (
    ConvergenceError,
    InvalidInputError,
    NonFiniteError,
    PkmError,
    SingularityError,
    SpecError,
    SpecNameError,
    UnknownNameError,
    UnreachableError,
)
from pkm.validation import as_count, as_scalar, as_vector, finite_result


@pytest.fixture(scope="module")
def delta():
    return pkm.load("delta")


@pytest.fixture(scope="module")
def rrr3():
    return pkm.load("rrr3")


# ---------------------------------------------------------------------- the shared converters
@pytest.mark.parametrize("bad", ["1.5", b"1", None, True, [True, False, True], 1 + 2j, [[1.0, 2.0], [3.0]],
                                 {"a": 1}, object(), [1.0, "x", 2.0], [None, 1.0, 2.0], 10**400,
                                 [1.0, 2.0, 10**400], np.array(["1", "2", "3"])])
def test_as_vector_refuses_what_is_not_numbers(bad):
    """Strings, booleans, None, complex, ragged nests, objects and ints beyond float range: InvalidInputError."""
    with pytest.raises(InvalidInputError) as info:
        as_vector(bad, 3, "q")
    assert info.value.name == "q" and "\n" not in str(info.value)


def test_as_vector_accepts_numbers_of_any_real_dtype():
    """Lists, tuples, int and float32 arrays of the right length become float64 copies."""
    for good in ([1, 2, 3], (1.0, 2.0, 3.0), np.arange(3), np.ones(3, dtype=np.float32)):
        out = as_vector(good, 3, "q")
        assert out.dtype == np.float64 and out.shape == (3,)


def test_scalar_count_and_finite_result_helpers():
    """as_scalar checks bounds, as_count refuses floats and bools, finite_result raises NonFiniteError."""
    assert as_scalar(np.array([2.0]), "x", low=0.0) == 2.0
    for bad in (float("nan"), "2", -1.0, np.ones(2)):
        with pytest.raises(InvalidInputError):
            as_scalar(bad, "x", low=0.0)
    for bad in (2.5, True, 0, "3", 10**9):
        with pytest.raises(InvalidInputError):
            as_count(bad, "n", low=1, high=1000)
    with pytest.raises(NonFiniteError) as info:
        finite_result((np.ones(2), [1.0, np.inf]), "thing")
    assert info.value.what == "thing"


# ---------------------------------------------------------------------- generic core
@pytest.mark.parametrize("fn", [pkm.forward_jacobian, pkm.inverse_jacobian, pkm.passive_map, pkm.twist_jacobian,
                                pkm.diagnose])
@pytest.mark.parametrize("mech", [None, "delta", 3])
def test_core_functions_refuse_what_is_not_a_mechanism(fn, mech, delta):
    """Passing a name, None or a number where a Mechanism belongs says how to get one (not AttributeError)."""
    with pytest.raises(InvalidInputError, match=r"pkm\.load"):
        fn(mech, delta.q_reference)


#: A configuration (or the mechanism) passed where another kind of object belongs: ``(call, the argument named)``.
WRONG_TYPES = [
    (lambda m, q: pkm.calibration_parameters(m, q), "kind"),
    (lambda m, q: pkm.CalibrationModel(m, q), "kind"),
    (lambda m, q: pkm.track_assembly_mode(m, q, [m.actuated_q(q)]), "mode"),
    (lambda m, q: pkm.track_working_mode(m, q, [[0.0, 0.0, -0.36]]), "mode"),
    (lambda m, q: pkm.serial_equivalent(m, q), "transmissions[0]"),
    (lambda m, q: pkm.serial_equivalent(m, 3), "transmissions"),
    (lambda m, q: pkm.serial_equivalent(m, (), around=q), "around"),
    (lambda m, q: pkm.tolerance_table(m, q), "model"),
    (lambda m, q: pkm.base_geometry(m, q), "model"),
    (lambda m, q: pkm.calibrate(m, q, q), "model"),
    (lambda m, q: pkm.calibration_poses(m, 5), "model"),
    (lambda m, q: pkm.write_calibrated(m, q), "cal"),
    (lambda m, q: pkm.write_serial_equivalent(m, q), "se"),
    (lambda m, q: pkm.export_c(m, q), "directory"),
    (lambda m, q: pkm.validate(m, q, q), "predict"),
    (lambda m, q: pkm.capability(m, q, q), "kind"),
    (lambda m, q: pkm.inverse_dynamics(m, q, 0 * q[:m.nv], 0 * q[:m.nv], method=q), "method"),
    (lambda m, q: pkm.quantity(1.0, q), "kind"),
    (lambda m, q: pkm.zyx_matrix(m, 0.0, 0.0), "roll"),
]


@pytest.mark.parametrize("call, name", WRONG_TYPES, ids=[f"{k}-{n}" for k, (_, n) in enumerate(WRONG_TYPES)])
def test_wrong_kinds_of_object_are_refused_naming_the_argument(call, name, delta):
    """A configuration array (or the mechanism) passed where a measurement model's name, a mode, a calibration model,
    transmissions, a folder or a method belongs: an InvalidInputError naming that argument and carrying what came,
    before any work (numpy's ValueError of an array's truth value, or an AttributeError, before)."""
    with pytest.raises(InvalidInputError) as info:
        call(delta, delta.q_reference)
    assert info.value.name == name and str(info.value).startswith(f"{name}: ")
    assert info.value.value is not None


def test_task_rates_are_checked_like_every_other_vector(delta):
    """inverse_velocities/inverse_accelerations check yd, ydd (shape, finiteness) instead of failing in lstsq."""
    q, v = delta.q_reference, np.zeros(delta.nv)
    with pytest.raises(InvalidInputError, match="yd"):
        pkm.inverse_velocities(delta, q, [0.1, 0.0])
    with pytest.raises(InvalidInputError, match="yd"):
        pkm.inverse_velocities(delta, q, [0.1, np.nan, 0.0])
    with pytest.raises(InvalidInputError, match="ydd"):
        pkm.inverse_accelerations(delta, q, v, np.zeros((3, 1)))
    assert np.all(np.isfinite(pkm.inverse_velocities(delta, q, [0.1, 0.0, 0.0])))


@pytest.mark.parametrize("kwargs", [{"tol": 0.0}, {"tol": -1e-9}, {"tol": np.nan}, {"max_iter": 0},
                                    {"max_iter": 2.5}, {"max_iter": True}, {"max_step": 0.0}, {"max_step": np.inf},
                                    {"tol": "1e-9"}])
def test_solver_settings_are_validated(delta, kwargs):
    """Zero, negative, non-finite or mistyped tolerances, iteration limits and step sizes are InvalidInputError."""
    with pytest.raises(InvalidInputError):
        pkm.close_loops(delta, delta.actuated_q(delta.q_reference), **kwargs)
    with pytest.raises(InvalidInputError):
        pkm.solve_ik(delta, [0.0, 0.0, -0.36], **kwargs)


def test_unknown_branch_is_refused_before_any_work(delta):
    """solve_ik(branch=...) with an unknown branch lists the valid ones."""
    with pytest.raises(UnknownNameError, match="knee_out"):
        pkm.solve_ik(delta, [0.0, 0.0, -0.36], branch="knee_sideways")


def test_absurd_targets_are_refused(delta):
    """A target beyond 1e6 (SI: a unit error) is an InvalidInputError before any iteration."""
    with pytest.raises(InvalidInputError, match="beyond 1e\\+06"):
        pkm.solve_ik(delta, [1e300, 0.0, -0.36])


@pytest.mark.parametrize("target", [[0.0, 0.0, 6e5], [3.0, -2.0, 50.0]])
def test_far_targets_fail_fast_with_a_finite_residual(delta, target):
    """Targets far outside the workspace end in an UnreachableError with a finite miss (a least-squares minimum
    that is not a solution), or a ConvergenceError with a finite residual and a bounded iteration count; in well
    under three seconds (continuation capped at MAX_STEPS, stalls detected)."""
    t0 = time.perf_counter()
    with pytest.raises((ConvergenceError, UnreachableError)) as info:
        pkm.solve_ik(delta, target)
    assert time.perf_counter() - t0 < 3.0
    err = info.value
    if isinstance(err, UnreachableError):
        assert np.isfinite(err.excess) and err.excess > 0 and "out of the workspace" in str(err)
        return
    assert np.isfinite(err.residual) and err.residual > err.tolerance
    assert 0 < err.iterations <= MAX_TOTAL_ITER + 100 and err.what == "inverse kinematics"
    assert np.all(np.isfinite(err.result.q))


def test_far_actuated_coordinates_fail_fast():
    """Loop closure for 3-PRS sliders 10^5 m away is refused quickly, the open closure and its gap attached."""
    prs3 = pkm.load("prs3")
    t0 = time.perf_counter()
    with pytest.raises(ConvergenceError) as info:
        pkm.close_loops(prs3, [1e5, -3e4, 2.0])
    assert time.perf_counter() - t0 < 3.0 and np.isfinite(info.value.residual)
    assert info.value.worst_closure.startswith("ball_") and info.value.worst_gap > 1.0


def test_forward_dynamics_with_redundant_closures_names_the_fix(rrr3):
    """The planar 3-RRR's 3-D point closures are redundant: the default (model) route needs no mu and agrees with
    Pinocchio's proximal constraintDynamics; that route with mu = 0 is a SingularityError saying to pass mu > 0."""
    q, v, tau = rrr3.q_reference, np.zeros(rrr3.nv), np.ones(3)
    a = forward_dynamics(rrr3, q, v, tau)
    assert np.abs(constraint_dynamics(rrr3, q, v, tau) - a).max() <= 1e-9 * np.abs(a).max()
    with pytest.raises(SingularityError, match="mu > 0"):
        constraint_dynamics(rrr3, q, v, tau, mu=0.0)
    with pytest.raises(InvalidInputError):
        constraint_dynamics(rrr3, q, v, tau, mu=-1.0)
    with pytest.raises(InvalidInputError, match="method='constraint_dynamics'"):
        forward_dynamics(rrr3, q, v, tau, mu=1e-8)
    for max_iter in (-1.0, 2.5, 0, "10", None, 10**400):  # (a fuzz finding: Boost.Python's ArgumentError)
        with pytest.raises(InvalidInputError, match="max_iter"):
            constraint_dynamics(rrr3, q, v, tau, max_iter=max_iter)


def test_khalil_projection_checks_its_mechanism_and_wrench(delta):
    """KhalilProjection refuses non-mechanisms; its wrench must be 6 finite numbers."""
    with pytest.raises(InvalidInputError):
        KhalilProjection("delta")
    kp = KhalilProjection(delta)
    z = np.zeros(delta.nv)
    with pytest.raises(InvalidInputError, match="wrench"):
        kp.inverse_dynamics(delta.q_reference, z, z, wrench=[1.0, np.nan, 0, 0, 0, 0])


# ---------------------------------------------------------------------- indices, screws
def test_condition_numbers_do_not_overflow_and_keep_inf_for_singular():
    """Matrices with entries near 1e300 or 1e-300 have the condition number of their scaled copy; a singular
    matrix gives inf, never NaN; manipulability that overflows is a NonFiniteError."""
    rng = np.random.default_rng(0)
    J = rng.normal(size=(4, 3, 3))
    for kind in indices.KINDS:
        ref = indices.condition_number(J, kind)
        for scale in (1e300, 1e-300):
            np.testing.assert_allclose(indices.condition_number(J * scale, kind), ref, rtol=1e-12)
    S = np.array([[1.0, 2.0], [0.0, 0.0]]) * 1e300
    assert indices.condition_number(S) == np.inf
    assert indices.inverse_condition(S) == 0.0
    with pytest.raises(NonFiniteError):
        indices.manipulability(J * 1e300)
    for bad in ({"J": 1}, [[1.0, "x"], [0.0, 1.0]], np.zeros((0, 3))):
        with pytest.raises(InvalidInputError):
            indices.condition_number(bad)
    with pytest.raises(InvalidInputError, match="rotation_rows"):
        indices.homogenize(np.eye(3), 7, 0.1)


def test_screw_stacks_of_incompatible_shapes_are_refused():
    """Stacks that do not broadcast (2 screws against 4 points) are InvalidInputError, not a numpy ValueError."""
    with pytest.raises(InvalidInputError, match="broadcast"):
        screws.shift(np.ones((2, 6)), np.ones((4, 3)))
    with pytest.raises(InvalidInputError):
        screws.transform(np.ones(6), np.eye(3)[:2], np.zeros(3))
    with pytest.raises(InvalidInputError, match="rates"):
        screws.chain_twist(np.ones((3, 6)), np.ones(4))


# ---------------------------------------------------------------------- reconfiguration (proxqp)
@pytest.mark.parametrize("index, match", [
    (3, "callable"),
    (lambda k, x: np.zeros(7), "shape"),
    (lambda k, x: "high", "index"),
    (lambda k, x: np.full(np.shape(x), np.nan), "not finite"),
    (lambda k, x: 1.0 / 0.0, "raised ZeroDivisionError"),
    (lambda k, x: np.exp(1e3 * x), "overflow|not finite"),
])
def test_bad_index_functions_are_reported_quickly(index, match):
    """An index that is not callable, mis-shaped, non-numeric, NaN, raising or overflowing its derivatives is an
    InvalidInputError within a second (proxqp never sees non-finite data)."""
    t0 = time.perf_counter()
    with pytest.raises((InvalidInputError, NonFiniteError), match=match):
        redundant_parameter.maximise(index, [-0.6, -1.9], [0.15, 0.7])
    assert time.perf_counter() - t0 < 1.0


def test_relative_gain_is_nan_where_the_baseline_index_is_zero():
    """Where the baseline's index is 0 the relative gain is NaN (documented), and mean_gain skips it."""
    def index(k, x):
        return np.where(k == 0, np.abs(x), 1.0 + 0.1 * np.cos(x))
    res = redundant_parameter.optimise_profile(index, [-1.0, -1.0], [1.0, 1.0], rate_limit=2.0, smoothness=0.0)
    assert res.baseline_ok.all() and res.baseline_value[0] == 0.0
    assert np.isnan(res.relative_gain[0]) and np.isfinite(res.relative_gain[1])
    assert res.mean_gain() == pytest.approx(res.relative_gain[1])


@pytest.mark.parametrize("kwargs", [{"rate_limit": 0.0}, {"rate_limit": np.nan}, {"rate_limit": 0.1, "smoothness": -1},
                                    {"rate_limit": 0.1, "max_iter": 0}, {"rate_limit": 0.1, "baseline": "0"},
                                    {"rate_limit": 0.1, "tol": np.inf}])
def test_profile_settings_are_validated(kwargs):
    """Rate limit, smoothness, iteration budget, baseline and tolerance are checked before any QP."""
    with pytest.raises(InvalidInputError):
        redundant_parameter.optimise_profile(lambda k, x: np.cos(x), [-1.0, -1.0], [1.0, 1.0], **kwargs)


# ---------------------------------------------------------------------- errors carry their data
def test_errors_carry_the_data_a_caller_needs(delta):
    """SpecNameError is both a SpecError (source) and an UnknownNameError (kind, name, valid); ConvergenceError
    keeps the solver's name; every one is a PkmError with a one-line message."""
    spec = delta.spec.to_toml().replace('end_effector = "platform"', 'end_effector = "platfrom"')
    with pytest.raises(SpecNameError) as info:
        pkm.from_strings(delta.urdf, spec, source="mine.toml")
    err = info.value
    assert isinstance(err, SpecError) and isinstance(err, UnknownNameError) and isinstance(err, PkmError)
    assert err.source == "mine.toml" and err.kind == "frame" and err.name == "platfrom" and "platform" in err.valid
    assert "\n" not in str(err)
    with pytest.raises(ConvergenceError) as info:
        pkm.close_loops(pkm.load("prs3"), [5.0, 0.0, 0.0])
    assert info.value.what == "loop closure" and info.value.worst_closure is not None


def test_warm_qp_solves_feasible_qps_proxqp_defaults_gave_up_on():
    """Two QPs met while fuzzing, both feasible and bounded: a 3-pose profile QP that proxqp's default
    infeasibility threshold called PRIMAL_INFEASIBLE, and a 4-pose QP with a curvature of 2e10 (a pose at
    the edge of its interval) whose absolute duality gap never reached 1e-10. WarmQP solves both."""
    D3 = np.diff(np.eye(3), axis=0)
    H3 = np.array([[2.956944236288412, -1.0, 0.0], [-1.0, 2.000001, -1.0], [0.0, -1.0, 2.956944236288412]])
    g3 = np.array([-0.30422296823013717, -0.818957539963395, -0.30422296823013717])
    lb3 = np.array([-0.46115120646480606, -0.8637522299428041, -0.46115120646480606])
    ub3 = np.array([-0.301566499769425, -0.704167523247423, -0.301566499769425])
    qp = redundant_parameter.WarmQP(3, D3, np.full(2, -0.40260102347799803), np.full(2, 0.40260102347799803))
    y = qp.solve(H3, g3, lb3, ub3)
    assert qp.statuses == ["PROXQP_SOLVED"] and np.all(lb3 - 1e-9 <= y) and np.all(y <= ub3 + 1e-9)
    D4 = np.diff(np.eye(4), axis=0)
    H4 = np.diag([1.9163e10, 0.2, 1.5, 3.2]) + D4.T @ D4
    g4 = np.array([1.9120e10, 4.3243e-03, 1.4953e-03, 8.5535e-04])
    lb4, ub4 = np.array([-0.9992, -0.9932, -0.9874, -0.9817]), np.array([-0.3553, -0.3353, -0.3153, -0.2953])
    qp = redundant_parameter.WarmQP(4, D4, np.full(3, -0.02), np.full(3, 0.02))
    y = qp.solve(H4, g4, lb4, ub4)
    assert qp.statuses == ["PROXQP_SOLVED"] and np.all(np.abs(np.diff(y)) <= 0.02 + 1e-9)
    assert y[0] == pytest.approx(-g4[0] / H4[0, 0], abs=1e-6)  # the stiff pose sits at its own minimiser


def test_warm_qp_refuses_non_finite_data():
    """NaN or infinite QP data raise NonFiniteError before proxqp runs (it would spin to its iteration limit)."""
    qp = redundant_parameter.WarmQP(2)
    with pytest.raises(NonFiniteError, match="QP data H"):
        qp.solve(np.diag([1.0, np.inf]), np.zeros(2), -np.ones(2), np.ones(2))
