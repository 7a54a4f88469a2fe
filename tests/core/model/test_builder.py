"""The builder (:mod:`pkm.core.model.builder`): a partial ``[reference]`` is assembled holding the joints it states, a
complete one must close its loops, loops that cannot close are named with their gap (checked against the five-bar's
closed form), and a mechanism survives the pickling round trip through :func:`rebuild`."""

from __future__ import annotations

import dataclasses
import math
import pickle
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm.core.kinematics import constraints
from pkm.core.model import builder
from pkm.core.model.compare import mechanism_differences
from pkm.errors import AssemblyError, InvalidInputError, SpecError
from tests import fivebar

KNEE = Path(__file__).resolve().parents[3] / "examples" / "knee" / "knee.closures.toml"


def _with_reference(mech, reference):
    return dataclasses.replace(mech.spec, reference=reference)


@pytest.fixture
def partial(built):
    """The five-bar built from a [reference] that states only its motors, at a tip 3 cm right and 2 cm up of its
    reference (the motors from the closed-form inverse kinematics)."""
    mech = built("fivebar")
    p = mech.params
    qa = fivebar.closed_form_ik(p, fivebar.reference_pose(p) + np.array([0.03, 0.02]))
    spec = _with_reference(mech, {"motor_1": (qa[0],), "motor_2": (qa[1],)})
    return builder.from_strings(mech.urdf, spec, p), qa


def test_a_partial_reference_is_assembled_holding_the_joints_it_states(partial):
    """The stated motors are kept exactly, the loop is closed (1e-12, the builder's assembly tolerance) and the tip is
    one of the two closed-form circle intersections of those motor angles (1e-9)."""
    mech, qa = partial
    np.testing.assert_array_equal(mech.actuated_q(mech.q_reference), qa)
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() <= 1e-12
    tip = pkm.TaskMap.of(mech).value(mech.q_reference)
    assert np.abs(fivebar.closed_form_fk(mech.params, qa, seed=tip) - tip).max() <= 1e-9
    assert set(mech.spec.reference) == {"motor_1", "motor_2"}  # (the spec keeps what it stated)


def test_pickling_goes_through_rebuild_and_gives_the_same_mechanism(partial):
    """__reduce__ names builder.rebuild with the URDF and spec texts; calling it, or pickle.loads, gives no
    difference (pkm.core.model.compare, its default tolerances) and the same source and parameters: the partial
    reference is assembled again to the same configuration."""
    mech, _ = partial
    function, args = mech.__reduce__()
    assert function is builder.rebuild
    for again in (function(*args), pickle.loads(pickle.dumps(mech))):
        assert mechanism_differences(mech, again) == []
        assert again.source == mech.source and again.params == mech.params
        assert np.abs(again.q_reference - mech.q_reference).max() <= 1e-12


def test_a_complete_reference_that_leaves_a_loop_open_is_refused_naming_it(built):
    """Every joint stated, elbow_1 moved by 0.01 rad: a SpecError naming closure 'tip', its gap and the tolerance,
    and saying how to have pkm assemble it instead."""
    mech = built("fivebar")
    reference = dict(mech.spec.reference)
    reference["elbow_1"] = (reference["elbow_1"][0] + 0.01,)
    with pytest.raises(SpecError, match=r"leaves closure 'tip' open by 0\.003 .*closed means <= 1e-09.*leave joints "
                                        r"out of \[reference\]"):
        builder.from_strings(mech.urdf, _with_reference(mech, reference))


def test_a_complete_reference_is_judged_relative_to_the_size_the_same_in_millimetres_and_in_metres(built):
    """elbow_1 moved so that the loop stays open by 0.5e-9, then 2e-9, of the characteristic length: the five-bar
    and its files scaled by 100 (an open gap of 1.1e-8 m there, refused before by the absolute 1e-9 m) both accept
    the first and both refuse the second."""
    from pkm.core.model.scale import scale_urdf

    mech = built("fivebar")
    L = mech.characteristic_length

    def moved(by):
        reference = dict(mech.spec.reference)
        reference["elbow_1"] = (reference["elbow_1"][0] + by,)
        return reference

    q = mech.q_reference.copy()
    q[mech.joints["elbow_1"].idx_q] += 1e-6
    per_rad = constraints.worst_closure(mech, constraints.residual(mech, q))[0] / 1e-6 / L  # (the gap's slope)
    for rel, accepted in ((0.5e-9, True), (2e-9, False)):
        for s in (1.0, 100.0):
            spec = _with_reference(mech, moved(rel / per_rad))
            if accepted:
                copy = builder.from_strings(scale_urdf(mech.urdf, s), spec)
                gap = constraints.worst_closure(copy, constraints.residual(copy, copy.q_reference))[0]
                assert 0.3e-9 * s * L < gap < 0.7e-9 * s * L, (s, gap)
            else:
                with pytest.raises(SpecError, match=r"relative to the mechanism's size"):
                    builder.from_strings(scale_urdf(mech.urdf, s), spec)


def test_a_partial_reference_that_cannot_be_held_names_the_missing_joints_and_the_gap(built):
    """Motors at pi and 0 put the elbows 2 (l1 + d/2) = 0.7 m apart, beyond 2 l2 = 0.6 m: the message names the
    joints left out and the 0.1 m the loop is short by (the closed form)."""
    mech = built("fivebar")
    assert (mech.params.l1, mech.params.d, mech.params.l2) == (0.25, 0.2, 0.3)
    with pytest.raises(SpecError, match=r"\[reference\] lacks joints \['elbow_1', 'elbow_2'\].*short by 0\.1 m"):
        builder.from_strings(mech.urdf, _with_reference(mech, {"motor_1": (math.pi,), "motor_2": (0.0,)}))


def test_loops_that_cannot_close_at_all_are_refused_with_the_assembly_error_as_cause(built):
    """Motors 2 m apart and links of 0.55 m: with no [reference] the loop cannot close; the SpecError says so with the
    gap of the closed form (2 - 2 x 0.55 = 0.9 m) and chains the AssemblyError."""
    mech = built("fivebar")
    far = fivebar.urdf_xml(fivebar.FiveBarParams(d=2.0))
    with pytest.raises(SpecError, match=r"the loops cannot be closed: .*'tip'.*open by 0\.9 m") as info:
        builder.from_strings(far, _with_reference(mech, {}))
    assert isinstance(info.value.__cause__, AssemblyError)


def test_from_strings_refuses_arguments_of_the_wrong_type(built):
    """The URDF must be text and the spec a ClosureSpec or its TOML text: InvalidInputError naming the argument."""
    mech = built("fivebar")
    with pytest.raises(InvalidInputError, match="urdf: expected the URDF text as a str, got bytes"):
        builder.from_strings(mech.urdf.encode(), mech.spec)
    with pytest.raises(InvalidInputError, match="spec: expected a ClosureSpec or its TOML text, got dict"):
        builder.from_strings(mech.urdf, {"mechanism": "x"})
    again = builder.from_strings(mech.urdf, mech.spec.to_toml())  # (the TOML text is read as the spec)
    assert mechanism_differences(mech, again) == []


def test_from_files_reads_the_spec_and_its_model_as_from_strings_does(tmp_path):
    """A spec and its URDF (the knee example) from a str or a Path: the same mechanism as from_strings of the two
    texts, its source the spec's path; a model path caught in a symbolic-link loop is a SpecError saying so."""
    mech = builder.from_files(str(KNEE))
    assert mech.source == str(KNEE)
    same = builder.from_strings(KNEE.with_name("knee.urdf").read_text(), KNEE.read_text())
    assert mechanism_differences(mech, same) == [] and mechanism_differences(mech, builder.from_files(KNEE)) == []
    (tmp_path / "knee.closures.toml").write_text(KNEE.read_text().replace('urdf = "knee.urdf"', 'urdf = "loop.urdf"'))
    (tmp_path / "loop.urdf").symlink_to("loop.urdf")
    with pytest.raises(SpecError, match=r"cannot resolve urdf = 'loop.urdf'"):
        builder.from_files(tmp_path / "knee.closures.toml")
