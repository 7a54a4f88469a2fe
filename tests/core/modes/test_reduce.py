"""The reduction of a mechanism to its platform and legs (:mod:`pkm.core.modes.reduce`): the legs of the Delta and the
3-RRR named after their closures with their joints and actuators, each leg's sphere of the design's own link length,
and the invariance the reduction rests on (``|B - A|`` does not depend on the passive joints)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from pkm.core.formats.load import load_model_file
from pkm.core.modes.reduce import reduce_mechanism
from pkm.errors import StructureError


def _data(mech, q):
    d = mech.model.createData()
    pin.forwardKinematics(mech.model, d, q)
    return d


def test_the_delta_is_a_translating_platform_on_three_spheres(built):
    """T3 (the platform's x, y, z slides carry it), one sphere per ball closure with its two knee joints and its
    motor; the sphere's radius is the forearm length Lb (1e-12); describe() says so in one line."""
    mech = built("delta")
    red = reduce_mechanism(mech)
    assert (red.group, red.normal, red.chain) == ("T3", None, ("platform_x", "platform_y", "platform_z"))
    assert [(leg.name, leg.kind, leg.joints, leg.actuated) for leg in red.legs] == [
        (f"ball_{i}", "sphere", (f"knee_{i}", f"knee_{i}_b"), (f"motor_{i}",)) for i in (1, 2, 3)]
    d = _data(mech, mech.q_reference)
    for leg in red.legs:
        assert abs(np.linalg.norm(leg.geometry(d)[1]) - mech.params.Lb) <= 1e-12 and leg.n_equations == 1
    assert red.describe() == "platform in T3; legs ball_1: sphere, ball_2: sphere, ball_3: sphere"


def test_the_3rrr_is_a_planar_platform_carried_by_its_first_leg(built):
    """SE2 about the z axis; the first leg carries the platform ("platform chain": elbow_1 then wrist_1, the
    platform's own rotation), the other two are the wrist closures; every sphere's radius is the distal length b."""
    mech = built("rrr3")
    red = reduce_mechanism(mech)
    assert red.group == "SE2" and np.array_equal(np.abs(red.normal), [0.0, 0.0, 1.0])
    assert red.chain == ("elbow_1", "wrist_1")
    assert [(leg.name, leg.kind, leg.joints, leg.actuated) for leg in red.legs] == [
        ("platform chain", "sphere", ("elbow_1", "wrist_1"), ("motor_1",)),
        ("wrist_2", "sphere", ("elbow_2",), ("motor_2",)), ("wrist_3", "sphere", ("elbow_3",), ("motor_3",))]
    assert [c.name for c in mech.spec.closures] == [leg.name for leg in red.legs[1:]]
    d = _data(mech, mech.q_reference)
    assert all(abs(np.linalg.norm(leg.geometry(d)[1]) - mech.params.b) <= 1e-12 for leg in red.legs)
    assert red.platform_joint == mech.model.frames[mech.ee_frame].parentJoint


@pytest.mark.parametrize("name", ["delta", "rrr3", "prs3"])
def test_a_legs_sphere_and_plane_do_not_depend_on_its_passive_joints(built, name):
    """At a random configuration with the actuators held at the reference (the loops open), |B - A| and, for a circle,
    n . (B - A) are those of the reference (1e-12): what lets the passive joints be eliminated."""
    mech = built(name)
    red = reduce_mechanism(mech)
    pin.seed(11)
    q = pin.randomConfiguration(mech.model, -np.ones(mech.nq), np.ones(mech.nq))
    for j in mech.actuated:
        q[j.idx_q:j.idx_q + j.nq] = mech.q_reference[j.idx_q:j.idx_q + j.nq]
    ref, moved = _data(mech, mech.q_reference), _data(mech, q)
    assert np.abs(q - mech.q_reference).max() > 0.1
    for leg in red.legs:
        (_, r0, n0), (_, r1, n1) = leg.geometry(ref), leg.geometry(moved)
        assert abs(np.linalg.norm(r1) - np.linalg.norm(r0)) <= 1e-12, leg.name
        if leg.kind == "circle":
            assert abs(n1 @ r1 - n0 @ r0) <= 1e-12 and leg.n_equations == 2
    n_eq = sum(1 if red.group == "SE2" else leg.n_equations for leg in red.legs)
    assert n_eq == {"SE3": 6, "SE2": 3, "T3": 3}[red.group]  # as many equations as the platform's freedoms


def test_a_mechanism_without_an_end_effector_is_refused():
    """The MJCF four-bar loaded alone has no end-effector frame: StructureError saying the platform is unknown."""
    fourbar = Path(__file__).resolve().parents[3] / "examples" / "mjcf_fourbar" / "fourbar.xml"
    with pytest.raises(StructureError, match="mjcf_fourbar: no end-effector frame: the platform is unknown"):
        reduce_mechanism(load_model_file(fourbar))
