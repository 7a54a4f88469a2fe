"""Input validation of the mechanism modules: parameter sets, params objects, branches, grids and
iterative solvers end in a PkmError naming what was wrong, in bounded time, never with NaN."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest

import pkm
from pkm.errors import (
    ConvergenceError,
    InvalidInputError,
    InvalidParameterError,
    NonFiniteError,
    PkmError,
    UnknownNameError,
)
from pkm.mechanisms import delta, hexapod, prs3, rrr3
from pkm.mechanisms.delta import design as delta_design
from pkm.mechanisms.delta import workspace as delta_workspace
from pkm.mechanisms.hexapod import indices as hexapod_indices
from pkm.mechanisms.hexapod import reconfiguration as hexapod_reconfigure
from pkm.mechanisms.hexapod import singularities as hexapod_singularities
from pkm.mechanisms.prs3.dynamics import Prs3Dynamics
from pkm.mechanisms.rrr3 import workspace as rrr3_maps
from pkm.papers.hexapod import pose_T_placement


def test_build_refuses_unknown_parameters_with_the_valid_names():
    """pkm.build("delta", Rr=...) is an UnknownNameError listing the Delta's parameters (not a TypeError)."""
    with pytest.raises(UnknownNameError, match="'La'") as info:
        pkm.build("delta", Rr=0.1)
    assert info.value.kind == "parameter" and "R" in info.value.valid
    with pytest.raises(UnknownNameError):
        pkm.build(["delta"])


@pytest.mark.parametrize("name, kwargs", [
    ("delta", {"La": 10**400}), ("delta", {"La": "0.11deg"}), ("delta", {"La": True}), ("delta", {"La": 2e6}),
    ("delta", {"home": "abc"}), ("delta", {"home": (0.0, 0.0)}), ("delta", {"home": (0.0, None, -0.3)}),
    ("rrr3", {"home": (0.0, 10**400, 0.0)}), ("rrr3", {"branch": 2.0}), ("rrr3", {"a": -0.4}),
    ("hexapod", {"layout": ["sector"]}), ("hexapod", {"theta": (1.0,) * 5}), ("hexapod", {"H0": np.nan}),
    ("prs3", {"actuation": ["P"]}), ("prs3", {"reference": {"z": 0.8}}), ("prs3", {"Ixz3": 10**400}),
])
def test_bad_parameter_values_are_invalid_parameter_errors(name, kwargs):
    """Huge ints, strings, booleans, absurd magnitudes, wrong tuple lengths and unhashable names are refused
    by the parameter dataclass with the field's name."""
    with pytest.raises(InvalidParameterError) as info:
        pkm.build(name, **kwargs)
    assert info.value.name == next(iter(kwargs)) or info.value.name in ("home", "reference", "Ixx3")


def test_tuple_parameters_given_as_arrays_are_stored_as_tuples():
    """home, theta, reference... passed as numpy arrays are normalised to tuples of floats (the spec can be written)."""
    mech = pkm.build("hexapod", theta=np.radians([35.0, 155.0, 275.0, 25.0, 145.0, 265.0]))
    assert isinstance(mech.params.theta, tuple) and all(isinstance(v, float) for v in mech.params.theta)
    mech = pkm.build("prs3", reference=np.array([0.81, 0.0, 0.0]))
    assert mech.params.reference == (0.81, 0.0, 0.0) and mech.spec.parameters["reference_1"] == 0.81


@pytest.mark.parametrize("fn, args", [
    (delta.closed_form_ik, ([0.0, 0.0, -0.36],)), (delta.forward_kinematics, ([-0.9, -0.85, -1.0],)),
    (rrr3.closed_form_ik, ([0.5, 0.29, 0.0],)), (rrr3.forward_kinematics, ([0.1, 1.5, 3.0],)),
    (prs3.closed_form_ik, ([0.81, 0.0, 0.0],)), (hexapod.closed_form_fk, (np.zeros(7),)),
    (delta_design.reachable_radii, ([0.0, 0.0, -0.36],)), (delta_workspace.condition_numbers, (np.zeros((1, 3)),)),
])
@pytest.mark.parametrize("params", [None, "delta", 3])
def test_closed_forms_refuse_a_wrong_params_object(fn, args, params):
    """A name, None or a number where the design belongs is an InvalidParameterError naming the class to pass."""
    with pytest.raises(InvalidParameterError, match="Params"):
        fn(params, *args)


def test_closed_forms_refuse_another_mechanisms_params():
    """Passing the Delta's parameters to the 3-RRR's closed forms is refused, not an AttributeError."""
    with pytest.raises(InvalidParameterError, match="Rrr3Params"):
        rrr3.jacobians(delta.DeltaParams(), [0.5, 0.29, 0.0])
    with pytest.raises(InvalidInputError, match=r"pkm\.Mechanism"):
        delta.closed_form_configuration(pkm.load("delta").model, [0.0, 0.0, -0.36])


@pytest.mark.parametrize("branch", [3, ["knee_out"] * 2, ("knee_out", ["x"], "knee_in"), None, "knee_sideways"])
def test_unhashable_or_unknown_branches_are_invalid_input(branch):
    """Branches that are not names (numbers, lists, nested lists) are InvalidInputError, not a TypeError."""
    with pytest.raises(InvalidInputError, match="branch"):
        delta.inverse_kinematics(delta.DeltaParams(), [0.0, 0.0, -0.36], branch)


def test_branch_of_the_wrong_type_is_invalid_input():
    """A 3-RRR working mode given as a list or a float is refused with the valid forms."""
    for branch in (["mode1"], 2.0, "mode9"):
        with pytest.raises(InvalidInputError, match="branch"):
            rrr3.branch_signs(branch)


def test_hexapod_forward_kinematics_settings_and_bounded_failure():
    """Bad tol/max_iter/seed are InvalidInputError; actuated angles without assembly fail in bounded time with
    a finite residual; assembly_modes refuses a non-hexapod mechanism."""
    p = hexapod.HexapodParams()
    alphas = hexapod.paper_alphas(np.zeros(7))
    for kwargs in ({"tol": 0.0}, {"max_iter": 0}, {"seed": np.zeros(5)}, {"seed": "C"}):
        with pytest.raises(InvalidInputError):
            hexapod.forward_kinematics(p, alphas, 0.0, **kwargs)
    t0 = time.perf_counter()
    with pytest.raises(ConvergenceError) as info:
        hexapod.forward_kinematics(p, alphas, 0.0)
    assert time.perf_counter() - t0 < 1.0 and np.isfinite(info.value.residual) and 3 <= info.value.iterations < 50  # stops on stall
    with pytest.raises(InvalidParameterError):
        hexapod.assembly_modes(pkm.load("delta"), np.zeros(7), n_starts=1)
    with pytest.raises(InvalidInputError):
        hexapod.assembly_modes(pkm.load("hexapod"), np.zeros(7), n_starts=0)


def test_hexapod_indices_and_reconfiguration_check_their_arguments():
    """Lengths, tolerances, index names, limits and pose lists are validated with the argument named."""
    p = hexapod.HexapodParams()
    R, P = pose_T_placement()
    with pytest.raises(InvalidInputError, match="length"):
        hexapod_indices.indices(p, R, P, 0.0, length="0.2")
    with pytest.raises(InvalidInputError, match="tol"):
        hexapod_singularities.classify(p, R, P, 0.0, tol=None)
    with pytest.raises(InvalidInputError, match="index"):
        hexapod_reconfigure.optimal_beta(p, R, P, index=["w_rot"])
    with pytest.raises(InvalidInputError, match="limits"):
        hexapod_reconfigure.optimal_beta(p, R, P, limits=(10**400, 1.0))
    for poses in (None, "poses", [(R, P), 3], [([[1.0, 0.0], [0.0]], P)]):
        with pytest.raises(InvalidInputError):
            hexapod_reconfigure.beta_profile(p, poses)


def test_maps_and_grids_refuse_mismatched_shapes_and_unbounded_sizes():
    """Node arrays that do not broadcast, non-numeric nodes, a grid step of 1e-9 m and a workspace spacing of
    1 um are refused at once (no allocation of 10^17 nodes)."""
    design = rrr3_maps.Design(0.4, 0.4, 0.1, 1.0)
    with pytest.raises(InvalidInputError, match="broadcast"):
        rrr3_maps.condition_index(design, np.zeros(23), np.zeros(24))
    with pytest.raises(InvalidInputError):
        rrr3_maps.condition_index(design, {"x": 1}, np.zeros(2))
    t0 = time.perf_counter()
    with pytest.raises(InvalidInputError, match="step"):
        rrr3_maps.Grid.square((0.5, 0.3), 0.3, 1e-9)
    with pytest.raises(InvalidInputError, match="nodes"):
        rrr3_maps.Grid((0.5, 0.3), 5000, 0.001)
    with pytest.raises(InvalidInputError, match="spacing"):
        delta_workspace.workspace(delta.DeltaParams(), spacing=1e-6)
    assert time.perf_counter() - t0 < 1.0
    with pytest.raises(InvalidInputError, match="n_scan"):
        delta_design.radius_minimising_condition(delta.DeltaParams(), [0.0, 0.0, -0.36], n_scan=0)
    with pytest.raises(InvalidInputError, match="kinds"):
        delta_workspace.condition_numbers(delta.DeltaParams(), np.zeros((1, 3)), kinds=None)


def test_prs3_overflow_is_an_error_not_nan():
    """Inputs that overflow the closed forms (z = -8e299 m, rates of 1e300) raise NonFiniteError; a NaN
    wrench given once for all samples is refused."""
    with pytest.raises(NonFiniteError):
        prs3.closed_form_ik(prs3.Prs3Params(), [-8.1e299, 0.0, 0.0])
    dyn = Prs3Dynamics()
    Y = np.tile([0.81, 0.0, 0.0], (4, 1))
    with pytest.raises(NonFiniteError, match="sample"):
        dyn.batch(Y, np.full((4, 3), 1e300), np.zeros((4, 3)))
    with pytest.raises(InvalidInputError, match="wrench"):
        dyn.batch(Y, np.zeros((4, 3)), np.zeros((4, 3)), wrench=[np.nan] * 6)
    with pytest.raises(NonFiniteError):
        dyn.forces([0.81, 0.0, 0.0], [0.0, 1e300, 0.0], [0.0, 0.0, 0.0])
    with pytest.raises(InvalidInputError):
        dyn.forces([0.81, 0.0, 0.0], [0.0, 0.0, 0.0], {"a": 1})
    with pytest.raises(InvalidInputError, match="chunk"):
        dyn.batch(Y, np.zeros((4, 3)), np.zeros((4, 3)), chunk=0)


@pytest.mark.parametrize("name", pkm.MECHANISMS)
def test_every_closed_form_result_is_finite_or_an_error(name):
    """Closed-form IK over targets from valid to absurd returns finite coordinates or raises a PkmError."""
    mech = pkm.load(name)
    mod = pkm.mechanism_module(name)
    task = pkm.TaskMap(mech)
    y0 = task.value(mech.q_reference)
    rng = np.random.default_rng(1)
    for scale in (1e-3, 0.1, 1.0, 1e3, 1e100, 1e300):
        y = task.retract(y0, scale * rng.standard_normal(task.size))
        try:
            out = mod.closed_form_ik(mech.params, y)
        except PkmError:
            continue
        assert np.all(np.isfinite(out)), (scale, out)


def test_params_dataclasses_stay_frozen_and_comparable():
    """Normalising tuple fields does not break equality or replace()."""
    a = delta.DeltaParams(home=np.array([0.0, 0.0, -0.375]))
    assert a == delta.DeltaParams(home=(0.0, 0.0, -0.375)) and dataclasses.replace(a, R=0.12).R == 0.12


def test_subnormal_characteristic_lengths_are_errors_not_infinities():
    """A characteristic length of 5e-324 m passes the > 0 check but overflows the moments: NonFiniteError."""
    p = rrr3.Rrr3Params()
    with pytest.raises(NonFiniteError, match="length"):
        rrr3.homogenized_jacobians(p, rrr3.reference_pose(p), length=5e-324)
    h = hexapod.HexapodParams()
    with pytest.raises(NonFiniteError, match="length"):
        hexapod_singularities.classify(h, *pose_T_placement(), 0.0, length=5e-324)
