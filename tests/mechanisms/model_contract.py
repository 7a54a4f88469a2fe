"""Checks shared by ``tests/mechanisms/<name>/test_model.py``: the generated URDF is a tree holding every name its
closure spec uses, the spec survives its TOML, and ``build`` of a design that is not the default gives the mechanism
of that design, closed at its reference; the collision primitives span the links' joint and closure points there.
(The default design against the shipped files is ``tests/test_reference_files.py``.)"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pkm.core.kinematics import constraints
from pkm.core.model.spec import ClosureSpec
from pkm.core.model.urdf import parse_xml
from pkm.errors import InvalidParameterError
from pkm.mechanisms._common import ROD_SHAPE, spec_parameters


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


def collision_elements(text: str) -> list[tuple[str, str, pin.SE3, dict[str, float]]]:
    """``(link, shape, placement in the link's frame, sizes [m])`` of every ``<collision>`` of a URDF, read from its
    text (not from the generator's arithmetic)."""
    out = []
    for link in parse_xml(text).iter("link"):
        for col in link.iter("collision"):
            org = col.find("origin")
            xyz = [float(v) for v in org.get("xyz").split()]
            rpy = [float(v) for v in org.get("rpy").split()]
            (shape,) = list(col.find("geometry"))
            if shape.tag == "box":
                size = dict(zip("xyz", (float(v) for v in shape.get("size").split())))
            else:
                size = {k: float(v) for k, v in shape.attrib.items()}
            out.append((link.get("name"), shape.tag, pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz)), size))
    return out


def check_collision_primitives(mech, text: str, rods: dict, plates: dict, boxes: dict | None = None) -> None:
    """The URDF's collision primitives against the model's forward kinematics at its reference (a closed
    configuration): every link with mass carries exactly one, and each is listed:

    * ``rods = {link: (frame_start, frame_end, radius)}``: a :data:`~pkm.mechanisms._common.ROD_SHAPE` of ``radius``
      whose axis' end centres (a capsule's hemispheres' centres) are the world positions of the two frames (1e-12 m);
    * ``plates = {link: (radius, thickness, [(frame, axial), ...])}``: a cylinder of that radius and thickness, each
      frame's point (or a world point given as an array) at ``radius`` from its axis and ``axial`` [m] from its
      mid-plane along its axis (1e-12 m);
    * ``boxes = {link: (frame, edge)}``: a cube of that edge centred at the frame's point (1e-12 m).
    """
    boxes = boxes or {}
    model, data, q = mech.model, mech.model.createData(), mech.q_reference
    pin.framesForwardKinematics(model, data, q)
    assert np.abs(constraints.residual(mech, q)).max() < 1e-12  # (closed: closure frames coincide)

    def at(frame) -> np.ndarray:
        return frame if isinstance(frame, np.ndarray) else data.oMf[model.getFrameId(frame)].translation

    prims = collision_elements(text)
    by_link = {link: (shape, M, size) for link, shape, M, size in prims}
    assert len(by_link) == len(prims), "one primitive a link"
    massive = {el.get("name") for el in parse_xml(text).iter("link")
               if el.find("inertial") is not None and float(el.find("inertial/mass").get("value")) > 0.0}
    assert massive <= set(by_link), sorted(massive - set(by_link))
    assert set(by_link) == set(rods) | set(plates) | set(boxes)
    for link, (shape, M, size) in by_link.items():
        oM = data.oMf[model.getFrameId(link)] * M  # the primitive in the world
        if link in rods:
            a, b, radius = rods[link]
            assert shape == ROD_SHAPE and size["radius"] == pytest.approx(radius, abs=1e-15), (link, size)
            half = np.array([0.0, 0.0, size["length"] / 2.0])
            np.testing.assert_allclose(oM.act(-half), at(a), rtol=0, atol=1e-12, err_msg=link)
            np.testing.assert_allclose(oM.act(half), at(b), rtol=0, atol=1e-12, err_msg=link)
        elif link in plates:
            radius, thickness, rim = plates[link]
            assert shape == "cylinder" and (size["radius"], size["length"]) == pytest.approx((radius, thickness),
                                                                                            abs=1e-15), (link, size)
            axis = oM.rotation[:, 2]
            for frame, axial in rim:
                d = at(frame) - oM.translation
                assert d @ axis == pytest.approx(axial, abs=1e-12), (link, frame)
                assert np.linalg.norm(d - (d @ axis) * axis) == pytest.approx(radius, abs=1e-12), (link, frame)
        else:
            frame, edge = boxes[link]
            assert shape == "box" and list(size.values()) == pytest.approx([edge] * 3, abs=1e-15), (link, size)
            np.testing.assert_allclose(oM.translation, at(frame), rtol=0, atol=1e-12, err_msg=link)
