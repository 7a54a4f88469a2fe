"""Checks shared by ``tests/mechanisms/<name>/test_model.py``: the generated URDF is a tree holding every name its
closure spec uses, the spec survives its TOML, and ``build`` of a design that is not the default gives the mechanism
of that design, closed at its reference. (The default design against the shipped files is
``tests/test_reference_files.py``.)"""

from __future__ import annotations

import numpy as np
import pytest

from pkm.core.kinematics import constraints
from pkm.core.model.spec import ClosureSpec
from pkm.core.model.urdf import parse_xml
from pkm.errors import InvalidParameterError
from pkm.mechanisms._common import spec_parameters


def urdf_names(text: str) -> tuple[set[str], dict[str, tuple[str, str]]]:
    """The URDF's link names and ``{joint: (parent, child)}``."""
    root = parse_xml(text)
    links = {el.get("name") for el in root.iter("link")}
    joints = {el.get("name"): (el.find("parent").get("link"), el.find("child").get("link")) for el in root.iter("joint")}
    return links, joints


def check_urdf_holds_the_spec_names(mod, params) -> None:
    """The URDF parses, is a tree (one root; every other link the child of exactly one joint, whose parent exists;
    mimic leaders exist) and has every joint and frame the closure spec names: actuated, reference, branch,
    joint-type and task joints, closure frames, the end effector."""
    text = mod.urdf_xml(params)
    links, joints = urdf_names(text)
    children = [c for _, c in joints.values()]
    assert len(children) == len(set(children)) and {p for p, _ in joints.values()} <= links
    assert len(links - set(children)) == 1, "one root link"
    for el in parse_xml(text).iter("mimic"):
        assert el.get("joint") in joints
    spec = mod.closure_spec(params)
    used = set(spec.actuated) | set(spec.reference) | set(spec.joint_types) | set(spec.task.joints)
    used |= {j for b in spec.branches.values() for j in b.signs}
    assert used <= set(joints), sorted(used - set(joints))
    frames = {f for c in spec.closures for f in (c.frame_a, c.frame_b)}
    assert frames <= links, sorted(frames - links)
    assert spec.end_effector in links | set(joints)
    assert spec.urdf == f"{mod.NAME}.urdf" and spec.mechanism == mod.NAME
    assert spec.default_branch in spec.branches


def check_spec_round_trip(mod, params) -> None:
    """closure_spec -> to_toml -> from_toml is the same spec, and writing it again gives the same text."""
    spec = mod.closure_spec(params)
    text = spec.to_toml()
    back = ClosureSpec.from_toml(text, "<round trip>")
    assert back == spec and back.to_toml() == text


def check_build_of_a_design(mod, params) -> object:
    """build(params) is that design's mechanism: its params, its spec (with the design's parameter table), its
    reference configuration closed (1e-12) and its actuated joints those of the spec."""
    mech = mod.build(params)
    assert mech.params == params and mech.spec == mod.closure_spec(params)
    assert dict(mech.spec.parameters) == spec_parameters(params)
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() < 1e-12
    assert mech.actuated_names == mech.spec.actuated
    return mech


def check_other_params_refused(mod, other) -> None:
    """urdf_xml and closure_spec of another mechanism's design (or None) name the class to pass."""
    for fn in (mod.urdf_xml, mod.closure_spec):
        for bad in (other, None):
            with pytest.raises(InvalidParameterError, match=mod.Params.__name__):
                fn(bad)


def joint_offset(mech, joint: str) -> np.ndarray:
    """The translation of ``joint``'s placement in its parent joint's frame [m] (where a link's length lives)."""
    return np.asarray(mech.model.jointPlacements[mech.model.getJointId(joint)].translation)


def frame_offset(mech, frame: str) -> np.ndarray:
    """The translation of ``frame`` in its parent joint's frame [m]."""
    return np.asarray(mech.model.frames[mech.model.getFrameId(frame)].placement.translation)
