"""The Gough-Stewart platform: built from the user's points, its inverse kinematics in closed form, its forward
kinematics complete (40 complex solutions for generic data)."""

from __future__ import annotations

import numpy as np
import pytest

import pkm
from pkm.errors import InvalidParameterError, UnreachableError
from pkm.mechanisms import gough_stewart as gs


def _generic(seed: int) -> pkm.Mechanism:
    rng = np.random.default_rng(seed)
    base = rng.uniform(-0.6, 0.6, (6, 3)) * [1.0, 1.0, 0.2]
    platform = rng.uniform(-0.4, 0.4, (6, 3)) * [1.0, 1.0, 0.2]
    return pkm.build("gough_stewart", base=base.tolist(), platform=platform.tolist(), leg_min="30cm", leg_max=1.6)


def test_build_takes_the_users_points_and_the_leg_lengths_are_the_actuated_coordinates():
    mech = _generic(1)
    assert mech.params.base[2] == pytest.approx(tuple(mech.params.base_points[2]))
    assert mech.params.leg_min == pytest.approx(0.3)
    y = pkm.TaskMap.of(mech).value(mech.q_reference)
    rho = gs.inverse_kinematics(mech.params, y)
    assert np.allclose(mech.actuated_q(mech.q_reference), rho, atol=1e-12)
    # the universal joints are Pinocchio's, the ball joints point closures
    assert {mech.joints[f"u{i}"].kind for i in range(1, 7)} == {"JointModelUniversal"}
    assert all(c.type == "point" for c in mech.spec.closures)


def test_the_closed_form_inverse_is_the_cores():
    """The leg lengths of a pose equal those of the generic core's inverse kinematics (1e-10 m)."""
    mech = pkm.load("gough_stewart")
    R = pkm.core.zyx_matrix(0.05, -0.08, 0.1)
    y = gs.task_vector(R, np.array([0.02, -0.03, pkm.TaskMap.of(mech).value(mech.q_reference)[2] + 0.04]))
    q = pkm.solve_ik(mech, y).q
    assert np.abs(mech.actuated_q(q) - gs.closed_form_ik(mech.params, y)).max() < 1e-10
    with pytest.raises(UnreachableError, match="leg"):
        gs.inverse_kinematics(mech.params, gs.task_vector(np.eye(3), np.array([0.0, 0.0, 2.0])))


def _general(seed: int) -> pkm.Mechanism:
    """A design of general geometry, given by its points alone: base and platform points up to 1.4 m off their
    planes (as in Dietmaier's 40-real-solution examples), the stroke left at its default."""
    rng = np.random.default_rng(seed)
    base, platform = rng.uniform(-0.6, 0.6, (6, 3)), rng.uniform(-0.4, 0.4, (6, 3))
    base[:, 2], platform[:, 2] = rng.uniform(-1.4, 1.4, 6), rng.uniform(-1.4, 1.4, 6)
    return pkm.build("gough_stewart", base=base.tolist(), platform=platform.tolist())


@pytest.mark.parametrize("seed", range(8))
def test_a_design_of_general_geometry_builds_from_its_points_alone(seed):
    """Issue 27: the level platform above the base centre cannot hold such legs mid-stroke; the reference is a
    pose with every leg inside the stroke where one is found (else the legs outside are named), away from a
    singularity (a least-squares fit over the whole pose would end on one)."""
    mech = _general(seed)
    rho = gs.inverse_kinematics(mech.params, pkm.TaskMap.of(mech).value(mech.q_reference), check_limits=False)
    outside = {f"leg{i + 1}" for i, r in enumerate(rho) if not mech.params.leg_min <= r <= mech.params.leg_max}
    assert set(mech.outside_limits(mech.q_reference)) == outside
    assert pkm.diagnose(mech, mech.q_reference).classification == "regular"
    if seed < 3:  # (these three designs have such a pose: found)
        assert not outside


def test_generic_data_have_forty_complex_assembly_modes():
    """Raghavan 1993, Husty 1996: 40 complex solutions for generic data; every path of the parameter homotopy
    ends at one of them (none at infinity or on Study's exceptional set), the real ones verified by the core.
    The design is of general geometry (:func:`_general`), built from its points alone."""
    pytest.importorskip("bertini")
    mech = _general(3)
    modes = pkm.assembly_modes(mech, mech.actuated_q(mech.q_reference))
    assert modes.complete and modes.n_paths == 40
    assert len(modes) + modes.n_complex == 40 and modes.n_infinite == modes.n_exceptional == 0
    assert len(modes) >= 2 and len(modes) % 2 == 0  # complex solutions come in conjugate pairs
    ref = pkm.TaskMap.of(mech).value(mech.q_reference)
    assert min(np.abs(pkm.TaskMap.of(mech).value(m.q) - ref).max() for m in modes) < 1e-9  # the reference is one


@pytest.mark.parametrize("bad", [dict(base=[[0.0, 0.0, 0.0]] * 5), dict(platform=[[0.1, 0.0, 0.0]] * 6),
                                 dict(leg_min=1.2, leg_max=1.0), dict(base="points")])
def test_bad_designs_are_refused(bad):
    with pytest.raises(InvalidParameterError):
        pkm.build("gough_stewart", **bad)
