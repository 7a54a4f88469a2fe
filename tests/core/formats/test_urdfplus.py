"""pkm.core.formats.urdfplus: a URDF with URDF+ ``<loop>`` or urdfdom ``<constraint>`` elements loads as a closed
mechanism; the same four-bar written as pkm's spec (cut elsewhere) gives the same FK."""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.formats.urdfplus import read_urdf
from pkm.errors import SpecError, SpecNameError

INERTIA = ('<inertial><mass value="0.2"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/>'
           '</inertial>')
#: A planar four-bar about y: crank 0.1 m at the origin, rocker 0.12 m at x = 0.35, a coupler between their tips,
#: closed at q = 0; a tip frame on the coupler.
TREE = f"""<robot name="fourbar">
  <link name="base"/>
  <link name="crank">{INERTIA}</link>
  <link name="coupler">{INERTIA}</link>
  <link name="rocker">{INERTIA}</link>
  <link name="tip"/>
  <joint name="crank_joint" type="revolute"><parent link="base"/><child link="crank"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="5" velocity="3"/></joint>
  <joint name="coupler_joint" type="continuous"><parent link="crank"/><child link="coupler"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/></joint>
  <joint name="rocker_joint" type="continuous"><parent link="base"/><child link="rocker"/>
    <origin xyz="0.35 0 0"/><axis xyz="0 1 0"/></joint>
  <joint name="tip_joint" type="fixed"><parent link="coupler"/><child link="tip"/><origin xyz="0.2 0 0.05"/></joint>
  {{extra}}
</robot>"""
#: URDF+ (arXiv 2411.19753): the loop frame at the coupler's end and the rocker's tip, revolute about y.
LOOP = """<loop name="cut" type="revolute">
    <predecessor link="coupler"><origin xyz="0.35 0 0.02" rpy="0 0 0"/></predecessor>
    <successor link="rocker"><origin xyz="0 0 0.12" rpy="0 0 0"/></successor>
    <axis xyz="0 1 0"/>
  </loop>
  <transmission name="crank_tr"><type>transmission_interface/SimpleTransmission</type>
    <joint name="crank_joint"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>
    <actuator name="crank_motor"><mechanicalReduction>1</mechanicalReduction></actuator></transmission>"""
#: urdfdom PR #108: the same cut, its frames rotated differently on each side (the axes given in each).
CONSTRAINT = """<constraint name="cut" type="revolute">
    <parent link="coupler"/><parent_origin xyz="0.35 0 0.02" rpy="1.5707963267948966 0 0"/>
    <parent_axis xyz="0 0 -1"/>
    <child link="rocker"/><child_origin xyz="0 0 0.12" rpy="0 0 0.3"/>
    <child_axis xyz="0.29552020666133955 0.955336489125606 0"/>
  </constraint>"""
#: pkm's spec of the same four-bar, cut at the rocker's ground pivot instead (the rocker hangs on the coupler).
SPEC_URDF = f"""<robot name="fourbar">
  <link name="base"/><link name="crank">{INERTIA}</link><link name="coupler">{INERTIA}</link>
  <link name="rocker">{INERTIA}</link><link name="tip"/><link name="pivot"/><link name="foot"/>
  <link name="pivot_y"/><link name="foot_y"/>
  <joint name="crank_joint" type="revolute"><parent link="base"/><child link="crank"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="5" velocity="3"/></joint>
  <joint name="coupler_joint" type="continuous"><parent link="crank"/><child link="coupler"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/></joint>
  <joint name="rocker_joint" type="continuous"><parent link="coupler"/><child link="rocker"/>
    <origin xyz="0.35 0 0.02"/><axis xyz="0 1 0"/></joint>
  <joint name="tip_joint" type="fixed"><parent link="coupler"/><child link="tip"/><origin xyz="0.2 0 0.05"/></joint>
  <joint name="pivot_j" type="fixed"><parent link="base"/><child link="pivot"/><origin xyz="0.35 0 0"/></joint>
  <joint name="pivot_yj" type="fixed"><parent link="base"/><child link="pivot_y"/><origin xyz="0.35 0.2 0"/></joint>
  <joint name="foot_j" type="fixed"><parent link="rocker"/><child link="foot"/><origin xyz="0 0 -0.12"/></joint>
  <joint name="foot_yj" type="fixed"><parent link="rocker"/><child link="foot_y"/><origin xyz="0 0.2 -0.12"/>
  </joint>
</robot>"""
SPEC = """format = "pkm.closures/1"
mechanism = "fourbar"
urdf = "fourbar.urdf"
actuated = ["crank_joint"]
[[closure]]
name = "pivot"
type = "point"
frame_a = "pivot"
frame_b = "foot"
[[closure]]
name = "pivot_axis"
type = "point"
frame_a = "pivot_y"
frame_b = "foot_y"
"""
ANGLES = (-0.6, 0.3, 0.9)  # crank angles [rad]
#: The cut's axis in its two frames, by format.
AXES = {"urdfplus": ([0, 1, 0], [0, 1, 0]), "urdfdom": ([0, 0, -1], [np.sin(0.3), np.cos(0.3), 0])}


@functools.cache
def loaded(kind: str) -> pkm.Mechanism:
    import tempfile

    folder = Path(tempfile.mkdtemp())
    if kind == "spec":
        (folder / "fourbar.urdf").write_text(SPEC_URDF)
        (folder / "fourbar.closures.toml").write_text(SPEC)
        return pkm.load(folder / "fourbar.closures.toml")
    return pkm.load(_file(kind)) if kind == "urdfplus" else pkm.load(_file(kind), actuated=["crank_joint"])


def tip(mech: pkm.Mechanism, q: np.ndarray) -> pin.SE3:
    pin.framesForwardKinematics(mech.model, mech.data, q)
    return mech.data.oMf[mech.frame_id("tip")]


def test_both_formats_read_as_the_closures_of_their_cut_joint():
    """A revolute cut: two point closures (at the joint, and along its axis); actuators from <transmission>."""
    for kind in ("urdfplus", "urdfdom"):
        mech = loaded(kind)
        assert [(c.name, c.type) for c in mech.spec.closures] == [("cut", "point"), ("cut_axis", "point")]
        assert mech.spec.actuated == ("crank_joint",) and mech.limits["crank_joint"] == (-2.0, 2.0)
    assert read_urdf(TREE.format(extra=LOOP), "f.urdf").format == "urdfplus"
    assert read_urdf(TREE.format(extra=CONSTRAINT), "f.urdf").format == "urdfdom"
    plain = read_urdf(TREE.format(extra=""), "f.urdf")  # a plain URDF reads as before: no loops, no actuators
    assert plain.format == "urdf" and plain.closures == () and plain.actuated == ()


@pytest.mark.parametrize("typ, closures", [("fixed", [("c", "frame")]), ("spherical", [("c", "point")])])
def test_fixed_and_spherical_cuts(typ, closures):
    text = TREE.format(extra=CONSTRAINT.replace('name="cut" type="revolute"', f'name="c" type="{typ}"'))
    imp = read_urdf(text, "f.urdf")
    assert [(c.name, c.type) for c in imp.closures] == closures
    assert (imp.closures[0].frame_a, imp.closures[0].frame_b) == ("c_parent", "c_child")


def test_fk_holds_the_loop_matches_the_spec_and_inverts():
    """At each crank angle: the loop closes to 1e-12 (the cut's two frames coincide in position and the joint's
    axis); the tip's placement is the spec's (cut at another joint) to 1e-12; IK of the tip's x gives the angle."""
    spec = loaded("spec")
    for kind in ("urdfplus", "urdfdom"):
        mech = loaded(kind)
        role = ("predecessor", "successor") if kind == "urdfplus" else ("parent", "child")
        for angle in ANGLES:
            q = pkm.close_loops(mech, [angle], tol=1e-13).q
            pin.framesForwardKinematics(mech.model, mech.data, q)
            a, b = (mech.data.oMf[mech.frame_id(f"cut_{r}")] for r in role)
            assert np.linalg.norm(a.translation - b.translation) < 1e-12
            axis_a, axis_b = AXES[kind]
            assert np.linalg.norm(a.rotation @ axis_a - b.rotation @ axis_b) < 1e-12
            q_spec = pkm.close_loops(spec, [angle], tol=1e-13).q
            X, Y = tip(mech, q), tip(spec, q_spec)
            assert np.linalg.norm(X.translation - Y.translation) < 1e-12
            assert np.linalg.norm(X.rotation - Y.rotation) < 1e-12
    mech = pkm.load(_file("urdfplus"), task={"end_effector": "tip", "components": ["x"]})
    for angle in ANGLES:
        x = tip(mech, pkm.close_loops(mech, [angle], tol=1e-13).q).translation[0]
        ik = pkm.solve_ik(mech, [x], tol=1e-13)
        assert abs(mech.actuated_q(ik.q)[0] - angle) < 1e-9


def _file(kind: str) -> Path:
    import tempfile

    path = Path(tempfile.mkdtemp()) / "fourbar.urdf"
    path.write_text(TREE.format(extra=LOOP if kind == "urdfplus" else CONSTRAINT))
    return path


def test_bad_input_names_the_file_the_element_and_its_line():
    missing = TREE.format(extra=LOOP.replace('successor link="rocker"', 'successor link="rockr"'))
    with pytest.raises(SpecNameError, match=r"f\.urdf.*<loop name='cut'> at line 14") as err:
        read_urdf(missing, "f.urdf")
    assert err.value.name == "rockr" and "rocker" in err.value.valid
    with pytest.raises(SpecNameError, match=r"<constraint name='cut'> at line 14"):
        read_urdf(TREE.format(extra=CONSTRAINT.replace('<child link="rocker"/>', '<child link="x"/>')), "f.urdf")
    for bad, match in ((LOOP.replace('type="revolute"', 'type="prismatic"'), "prismatic joint is not read"),
                       (LOOP.replace('xyz="0 1 0"/>\n  </loop>', 'xyz="0 0 0"/>\n  </loop>'), "a zero axis"),
                       ('<coupling name="g" ratio="2"><predecessor link="crank"/><successor link="rocker"/>'
                        '</coupling>', "couplings"),
                       (CONSTRAINT.replace('type="revolute"', 'type="universal"'), "universal cut"),
                       (LOOP.replace("0.35 0 0.02", "0.35 0 nan"), "three finite numbers"),
                       (LOOP + CONSTRAINT, "one kind")):
        with pytest.raises(SpecError, match=match):
            read_urdf(TREE.format(extra=bad), "f.urdf")
    with pytest.raises(SpecNameError, match="crank_tr"):
        read_urdf(TREE.format(extra=LOOP.replace('joint name="crank_joint"', 'joint name="nope"')), "f.urdf")



def test_a_urdf_plus_file_alone_uploads_and_a_plain_urdf_alone_is_refused():
    """An upload (:func:`pkm.core.formats.load.load_texts`, the service's) of one URDF+ file is a mechanism, the
    same as ``pkm.load`` of the file; a plain URDF alone still needs a spec, and the refusal says why."""
    from pkm.core.formats.load import load_texts
    from pkm.errors import SpecError

    mech = load_texts({"fourbar.urdf": TREE.format(extra=LOOP)})
    assert [c.name for c in mech.spec.closures] == ["cut", "cut_axis"] and mech.spec.actuated == ("crank_joint",)
    q, q_file = (pkm.close_loops(m, [0.3], tol=1e-13).q for m in (mech, loaded("urdfplus")))
    assert np.linalg.norm(q - q_file) < 1e-12
    with pytest.raises(SpecError, match="a plain URDF cannot hold one"):
        load_texts({"fourbar.urdf": TREE.format(extra="")})
