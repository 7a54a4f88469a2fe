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
    y = mech.task_map.value(mech.q_reference)
    rho = gs.inverse_kinematics(mech.params, y)
    assert np.allclose(mech.actuated_q(mech.q_reference), rho, atol=1e-12)
    # the universal joints are Pinocchio's, the ball joints point closures
    assert {mech.joints[f"u{i}"].kind for i in range(1, 7)} == {"JointModelUniversal"}
    assert all(c.type == "point" for c in mech.spec.closures)


def test_the_closed_form_inverse_is_the_cores():
    """The leg lengths of a pose equal those of the generic core's inverse kinematics (1e-10 m)."""
    mech = pkm.load("gough_stewart")
    R = pkm.core.zyx_matrix(0.05, -0.08, 0.1)
    y = gs.task_vector(R, np.array([0.02, -0.03, mech.task_map.value(mech.q_reference)[2] + 0.04]))
    q = pkm.solve_ik(mech, y).q
    assert np.abs(mech.actuated_q(q) - gs.closed_form_ik(mech.params, y)).max() < 1e-10
    with pytest.raises(UnreachableError, match="leg"):
        gs.inverse_kinematics(mech.params, gs.task_vector(np.eye(3), np.array([0.0, 0.0, 2.0])))


def test_generic_data_have_forty_complex_assembly_modes():
    """Raghavan 1993, Husty 1996: 40 complex solutions for generic data; every path of the parameter homotopy
    ends at one of them (none at infinity or on Study's exceptional set), the real ones verified by the core."""
    pytest.importorskip("bertini")
    mech = _generic(3)
    modes = pkm.assembly_modes(mech, mech.actuated_q(mech.q_reference))
    assert modes.complete and modes.n_paths == 40
    assert len(modes) + modes.n_complex == 40 and modes.n_infinite == modes.n_exceptional == 0
    assert len(modes) >= 2 and len(modes) % 2 == 0  # complex solutions come in conjugate pairs
    ref = mech.task_map.value(mech.q_reference)
    assert min(np.abs(mech.task_map.value(m.q) - ref).max() for m in modes) < 1e-9  # the reference is one


@pytest.mark.parametrize("bad", [dict(base=[[0.0, 0.0, 0.0]] * 5), dict(platform=[[0.1, 0.0, 0.0]] * 6),
                                 dict(leg_min=1.2, leg_max=1.0), dict(base="points")])
def test_bad_designs_are_refused(bad):
    with pytest.raises(InvalidParameterError):
        pkm.build("gough_stewart", **bad)
