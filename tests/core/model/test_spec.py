"""The closure-spec format: round trip, and a clear SpecError or UnknownNameError for every defect."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

from pkm.core import ClosureSpec
from pkm.core.kinematics import constraints
from pkm.core.model.builder import from_strings
from pkm.data import spec_path
from pkm.errors import SpecError, UnknownNameError
from pkm.mechanisms import names


@pytest.fixture(scope="module")
def delta_text():
    return spec_path("delta").read_text()


@pytest.mark.parametrize("name", names(with_files=True))
def test_shipped_specs_round_trip_byte_for_byte(name):
    """Parsing then writing a shipped spec reproduces the file exactly."""
    text = spec_path(name).read_text()
    assert ClosureSpec.from_toml(text).to_toml() == text


@pytest.mark.parametrize("edit, message", [
    (lambda t: t.replace('format = "pkm.closures/1"', 'format = "pkm.closures/9"'), "unsupported format"),
    (lambda t: t.replace('type = "point"', 'type = "hinge"', 1), "type 'hinge' unknown"),
    (lambda t: t.replace('end_effector = "platform"\n', ''), "need an end_effector"),
    (lambda t: t.replace('components = ["x", "y", "z"]', 'components = ["x", "w"]'), "task.components"),
    (lambda t: t.replace('default_branch = "knee_out"', 'default_branch = "knee_sideways"'), "default_branch"),
    (lambda t: t.replace("signs = { knee_1 = -1,", "signs = { knee_1 = 2,", 1), r"\+1 or -1"),
    (lambda t: re.sub(r"platform_z = \[[^\]]*\]", "platform_z = [nan]", t), "non-finite"),
    (lambda t: "surprise = 1\n" + t, "unknown keys"),
    (lambda t: t.replace("[task]", "[task"), "not valid TOML"),
    (lambda t: t.replace('actuated = ["motor_1", "motor_2", "motor_3"]', 'actuated = ["motor_1", "motor_1"]'),
     "twice"),
    (lambda t: t + "\n[links.upper_1]\ncompliance = [[1e-8]]\n", "6 rows of 6"),
    (lambda t: t + "\n[links.upper_1]\ncompliance = " + str((np.eye(6) + np.eye(6, k=1) * 1e-3).tolist()) + "\n",
     "symmetric positive definite"),
    (lambda t: t + "\n[links.upper_1]\nradius = 0.01\n", "one key, compliance"),
])
def test_malformed_spec_raises_spec_error_saying_what(delta_text, edit, message):
    """Each defect of a spec file is reported as a SpecError naming the problem."""
    with pytest.raises(SpecError, match=message):
        ClosureSpec.from_toml(edit(delta_text))


def test_missing_spec_file_is_a_spec_error(tmp_path):
    """A spec path that does not exist gives a SpecError with the path."""
    with pytest.raises(SpecError, match="cannot read"):
        ClosureSpec.load(tmp_path / "nope.closures.toml")


def test_spec_names_are_checked_against_the_urdf(built):
    """Unknown frames and joints are refused with the list of valid names; so are multi-DOF actuators."""
    mech = built("delta")
    spec = mech.spec
    bad_frame = dataclasses.replace(spec, end_effector="platfrom")
    with pytest.raises(UnknownNameError, match=r"frame 'platfrom' does not exist.*'platform'"):
        from_strings(mech.urdf, bad_frame)
    bad_joint = dataclasses.replace(spec, actuated=("motor_1", "motor_2", "motr_3"))
    with pytest.raises(UnknownNameError, match=r"joint 'motr_3'.*'motor_3'"):
        from_strings(mech.urdf, bad_joint)
    partial = dataclasses.replace(spec, reference={k: v for k, v in spec.reference.items() if k != "knee_2"})
    assembled = from_strings(mech.urdf, partial)  # the missing joint is found by assembly
    assert np.abs(constraints.residual(assembled, assembled.q_reference)).max() <= 1e-10
    bad_closure = dataclasses.replace(spec, closures=(dataclasses.replace(spec.closures[0], frame_b="nowhere"),))
    with pytest.raises(UnknownNameError, match="closure 'ball_1'"):
        from_strings(mech.urdf, bad_closure)


@pytest.mark.parametrize("odd", ["a/b", "knee 1", 'say "hi"', "dot.ted", "élan", "tab\there", "new\nline", "back\\slash"])
def test_any_names_round_trip_through_toml(odd, delta_text):
    """Joint, branch and parameter names TOML cannot write bare are quoted (and escaped): the text parses back to
    the same spec."""
    spec = ClosureSpec.from_toml(delta_text)
    ref = dict(spec.reference)
    ref[odd] = ref.pop("knee_1")
    branches = {odd: dataclasses.replace(next(iter(spec.branches.values())), name=odd, signs={odd: 1})}
    odd_spec = dataclasses.replace(spec, reference=ref, branches=branches, default_branch=odd,
                                   parameters={**spec.parameters, odd: 1.5}, description=odd)
    assert ClosureSpec.from_toml(odd_spec.to_toml()) == odd_spec


MINIMAL = """format = "pkm.closures/1"
mechanism = "five"
urdf = "five.urdf"
actuated = ["motor_1", "motor_2"]

[[closure]]
name = "tip"
type = "point"
frame_a = "tip_1"
frame_b = "tip_2"
"""


def test_a_minimal_spec_names_only_closures_and_actuators():
    """Closures and actuated joints suffice: no end effector, no task (the outputs are then the actuated joints),
    no reference (assembled); the generic answers follow (IK, FK, Jacobians, dynamics by virtual work)."""
    import pkm
    from tests import fivebar

    mech = from_strings(fivebar.urdf_xml(fivebar.Params()), MINIMAL)
    assert mech.spec.end_effector is None and mech.spec.task.joints == ("motor_1", "motor_2")
    q = mech.q_reference
    assert np.abs(constraints.residual(mech, q)).max() <= 1e-10
    qa = mech.actuated_q(q) + [0.05, -0.03]
    ik = pkm.solve_ik(mech, qa)
    np.testing.assert_allclose(mech.actuated_q(ik.q), qa, atol=1e-10)
    np.testing.assert_allclose(pkm.forward_jacobian(mech, ik.q), np.eye(2), atol=1e-12)
    v = pkm.velocities(mech, ik.q, [0.1, 0.2])
    a = pkm.accelerations(mech, ik.q, v, [0.0, 0.0])
    assert np.all(np.isfinite(pkm.inverse_dynamics(mech, ik.q, v, a)))
    assert ClosureSpec.from_toml(mech.spec.to_toml()) == mech.spec


@pytest.mark.parametrize("edit, message", [
    (lambda t: t + '\n[task]\ncomponents = ["x", "y"]\n', r"need an end_effector"),
    (lambda t: t.replace('actuated =', 'end_effector = "tip_1"\nactuated ='), r"missing key 'task'"),
    (lambda t: t.replace('actuated =', 'end_effector = ""\nactuated ='), r"non-empty string"),
])
def test_a_minimal_spec_says_what_it_misses(edit, message):
    with pytest.raises(SpecError, match=message):
        ClosureSpec.from_toml(edit(MINIMAL))


def test_more_task_coordinates_than_actuators_are_refused():
    from tests import fivebar

    text = MINIMAL.replace('actuated =', 'end_effector = "tip_1"\nactuated =') + '\n[task]\ncomponents = ["x", "y", "z"]\n'
    with pytest.raises(SpecError, match=r"the task has 3 coordinates but only 2 joints are actuated"):
        from_strings(fivebar.urdf_xml(fivebar.Params()), text)


def test_task_is_actuated_says_whether_a_format_without_a_task_gives_it_back():
    """A spec whose task is its actuated joints (no end effector, components or frames) is what Gepetto's, MJCF's and
    URDF+'s readers give back; the Delta's (an end effector's x y z) is not, nor the same joints in another order."""
    delta = ClosureSpec.load(spec_path("delta"))
    assert not delta.task_is_actuated
    joints = dataclasses.replace(delta, end_effector=None, task=dataclasses.replace(delta.task, components=(),
                                                                                     frames={}, joints=delta.actuated))
    assert joints.task_is_actuated
    swapped = dataclasses.replace(joints, task=dataclasses.replace(joints.task, joints=delta.actuated[::-1]))
    assert not swapped.task_is_actuated
