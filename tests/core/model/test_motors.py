"""The motors' map onto the actuated joints (:mod:`pkm.core.model.motors`): the ``[motors]`` tables read, written and
checked (a differential of as many motors as joints, invertible), and the efforts mapped both ways."""

from __future__ import annotations

import numpy as np
import pytest

from pkm.core.model.motors import motor_map
from pkm.core.model.spec import ClosureSpec
from pkm.errors import SpecError

ACTUATED = ("a", "b", "c")
SPEC = '''
format = "pkm.closures/1"
mechanism = "m"
urdf = "m.urdf"
actuated = ["a", "b", "c"]
[[closure]]
name = "loop"
type = "point"
frame_a = "fa"
frame_b = "fb"
'''


def test_a_differential_and_a_direct_joint_make_one_square_map():
    """Rows ordered by the first joint each motor names; ``C^T`` maps motor efforts to joint efforts (the inverse
    transpose back: 1e-15)."""
    mm = motor_map(ACTUATED, {"m2": {"b": 2.0, "c": -1.0}, "m1": {"b": 1.0, "c": 1.0}})
    assert mm.names == ("a", "m2", "m1") and not mm.identity
    np.testing.assert_array_equal(mm.matrix, [[1, 0, 0], [0, 2, -1], [0, 1, 1]])
    f = np.array([0.3, -1.2, 2.5])
    tau = mm.matrix.T @ f
    np.testing.assert_allclose(np.linalg.solve(mm.matrix.T, tau), f, rtol=0, atol=1e-15)
    assert motor_map(ACTUATED, {}).identity


@pytest.mark.parametrize("motors, message", [
    ({"m": {"b": 1.0, "c": 1.0}}, r"motors \['m'\] drive the joints \['b', 'c'\]: .* as many motors as joints"),
    ({"m": {"b": 1.0, "c": 1.0}, "n": {"b": 2.0, "c": 2.0}}, r"do not determine the joints \['b', 'c'\]"),
    ({"m": {"b": 1.0, "z": 1.0}}, r"\[motors.m\]: 'z' is not an actuated joint"),
    ({"a": {"b": 1.0, "c": 1.0}, "n": {"b": 1.0, "c": -1.0}}, r"\[motors.a\] has the name of the actuated joint"),
])
def test_a_map_that_does_not_determine_its_joints_is_refused_by_name(motors, message):
    with pytest.raises(SpecError, match=message):
        motor_map(ACTUATED, motors, "t")


def test_the_spec_reads_and_writes_motors_and_refuses_bad_tables():
    spec = ClosureSpec.from_toml(SPEC + "[motors.left]\nb = 1.0\nc = 1.0\n[motors.right]\nb = 1.0\nc = -1.0\n")
    assert spec.motors == {"left": {"b": 1.0, "c": 1.0}, "right": {"b": 1.0, "c": -1.0}}
    assert ClosureSpec.from_toml(spec.to_toml()).motors == spec.motors
    with pytest.raises(SpecError, match=r"\[motors.left\] must be a table of actuated joint = finite coefficient"):
        ClosureSpec.from_toml(SPEC + '[motors.left]\nb = "one"\n')
    with pytest.raises(SpecError, match=r"\[motors.left\]: 'q' is not an actuated joint"):
        ClosureSpec.from_toml(SPEC + "[motors.left]\nq = 1.0\n")
