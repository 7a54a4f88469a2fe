"""pkm.core.formats.sdf: SDFormat models with loops, read by pkm itself (the PyPI Pinocchio has no SDFormat), with
SDFormat's pose semantics; each cut joint becomes closures that are exactly that joint."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from lxml import etree

import pkm
from pkm.core.formats.sdf import read_sdf
from pkm.core.model.spec import TaskSpec
from pkm.errors import SpecError

INERTIA = ("<inertial><mass>0.2</mass><inertia><ixx>1e-4</ixx><iyy>1e-4</iyy><izz>1e-4</izz><ixy>0</ixy><ixz>0</ixz>"
           "<iyz>0</iyz></inertia></inertial>")


def fourbar(cut: str = "revolute", extra: str = "", version: str = "1.7") -> str:
    """A spatial four-bar about y: crank at the origin, rocker at x = 0.3 (posed in degrees, relative to the
    crank's pose), the loop cut at the coupler-rocker joint, of type ``cut``."""
    axis = "" if cut in ("ball", "fixed") else "<axis><xyz expressed_in='__model__'>0 1 0</xyz></axis>"
    return f"""<sdf version="{version}"><model name="fb">
      <link name="crank">{INERTIA}</link>
      <link name="coupler"><pose relative_to="crank">0 0 0.1 0 0 0</pose>{INERTIA}</link>
      <link name="rocker"><pose degrees="true">0.3 0 0 0 0 0</pose>{INERTIA}</link>
      <frame name="tip" attached_to="coupler"><pose relative_to="coupler">0.15 0 0.07 0 0 0</pose></frame>
      <joint name="crank_joint" type="revolute"><parent>world</parent><child>crank</child>
        <axis><xyz>0 1 0</xyz><limit><lower>-2</lower><upper>2</upper></limit></axis></joint>
      <joint name="coupler_joint" type="revolute"><parent>crank</parent><child>coupler</child>
        <axis><xyz>0 1 0</xyz><use_parent_model_frame>true</use_parent_model_frame></axis></joint>
      <joint name="rocker_joint" type="revolute"><parent>world</parent><child>rocker</child>
        <axis><xyz>0 1 0</xyz></axis></joint>
      <joint name="cut" type="{cut}"><parent>coupler</parent><child>rocker</child>
        <pose>0 0 0.15 0 0 0</pose>{axis}</joint>
      {extra}
    </model></sdf>"""


def mechanism(text: str, actuated=("crank_joint",)) -> pkm.Mechanism:
    imp = read_sdf(text, "fb.sdf")
    spec = pkm.ClosureSpec(mechanism="fb", urdf="fb.sdf", end_effector=None, actuated=tuple(actuated),
                           closures=imp.closures, task=TaskSpec((), tuple(actuated)), reference={},
                           joint_types=imp.joint_types)
    return pkm.from_strings(imp.urdf, spec, source="fb.sdf")


def placements(mech, q, *names):
    pin.framesForwardKinematics(mech.model, mech.data, q)
    return [mech.data.oMf[mech.frame_id(n)] for n in names]


def test_poses_follow_sdformat():
    """relative_to, degrees, a <frame>; the joint pose in the child's frame; axes in the joint or the model frame."""
    mech = mechanism(fourbar())
    coupler, rocker, tip, cut = placements(mech, mech.q_reference, "coupler", "rocker", "tip", "cut_child")
    assert np.allclose(coupler.translation, [0, 0, 0.1]) and np.allclose(rocker.translation, [0.3, 0, 0])
    assert np.allclose(tip.translation, [0.15, 0, 0.17]) and np.allclose(cut.translation, [0.3, 0, 0.15])
    assert mech.limits == {"crank_joint": (-2.0, 2.0)}


@pytest.mark.parametrize("cut, closures", [("revolute", [("cut", "point"), ("cut_axis", "point")]),
                                           ("ball", [("cut", "point")])])
def test_a_cut_joint_becomes_closures_that_are_exactly_that_joint(cut, closures):
    """Moved by the crank: the two halves of the cut keep their origin and, for a revolute, its axis."""
    mech = mechanism(fourbar(cut))
    assert [(c.name, c.type) for c in mech.spec.closures] == closures
    q = pkm.close_loops(mech, [0.4], mech.q_reference).q
    child, parent = placements(mech, q, "cut_child", "cut_parent")
    assert np.allclose(child.translation, parent.translation, atol=1e-12)
    if cut == "revolute":
        assert np.allclose(child.rotation[:, 1], parent.rotation[:, 1], atol=1e-12)  # the y axis, the joint's
        assert np.allclose(child.rotation[:, 1], [0, 1, 0], atol=1e-12)
    assert pkm.diagnose(mech, q).mobility == 1  # (the rocker's revolute to the world keeps a ball cut planar)


def test_a_cut_prismatic_joint_stays_in_the_tree():
    text = fourbar("revolute").replace('name="cut" type="revolute"', 'name="cut" type="prismatic"')
    imp = read_sdf(text, "fb.sdf")
    assert [(c.name, c.type, c.frame_a) for c in imp.closures] == [("cut", "frame", "cut_cut")]
    assert "<joint name=\"cut\" type=\"prismatic\">" in imp.urdf


def test_a_fixed_cut_is_a_frame_closure():
    imp = read_sdf(fourbar("fixed"), "fb.sdf")
    assert [(c.name, c.type) for c in imp.closures] == [("cut", "frame")]


def test_a_base_link_without_a_parent_is_fixed_where_it_is_posed():
    text = fourbar().replace("<parent>world</parent><child>rocker</child>", "<parent>ground</parent><child>rocker</child>")
    text = text.replace("<parent>world</parent><child>crank</child>", "<parent>ground</parent><child>crank</child>")
    text = text.replace('<link name="crank">', '<link name="ground"><pose>0 0 1 0 0 0</pose></link><link name="crank">')
    mech = mechanism(text)
    (ground,) = placements(mech, mech.q_reference, "ground")
    assert np.allclose(ground.translation, [0, 0, 1])


@pytest.mark.parametrize("edit, message", [
    (lambda s: s.replace('type="revolute"><parent>crank', 'type="universal"><parent>crank'), "'universal' is not"),
    (lambda s: s.replace("<parent>crank</parent>", "<parent>nope</parent>"), "parent 'nope' is not a link"),
    (lambda s: s.replace('relative_to="crank"', 'relative_to="nowhere"'), "relative_to 'nowhere'"),
    (lambda s: s.replace("</model>", "<link name='s1'/><link name='s2'/></model>"), "have no parent joint"),
    (lambda s: s.replace("</model>", "<model name='inner'/></model>"), "nested models"),
    (lambda s: s.replace("<axis><xyz>0 1 0</xyz></axis></joint>\n      <joint name=\"cut\"", "</joint>\n      "
                         "<joint name=\"cut\""), "needs <axis><xyz>"),
    (lambda s: s.replace("<sdf", "<robot").replace("</sdf>", "</robot>"), "expected <sdf>"),
    (lambda s: s.replace('<link name="coupler">', '<link name="coupler_">'), "not a link"),
    (lambda s: s.replace('<frame name="tip"', '<frame'), "every <frame> needs a distinct name"),
])
def test_what_it_refuses_it_says(edit, message):
    with pytest.raises(SpecError, match=message):
        read_sdf(edit(fourbar()), "fb.sdf")


def test_an_sdf_file_alone_says_that_a_spec_must_name_the_actuators(tmp_path):
    path = tmp_path / "fb.sdf"
    path.write_text(fourbar())
    with pytest.raises(SpecError, match="names no actuated joint"):
        pkm.load(path)


def test_a_ball_joint_in_the_tree_and_link_frames_at_their_sdf_poses():
    """A ball joint of the tree is a Pinocchio spherical joint; a link whose joint is posed away from it keeps a
    frame of its name at its SDF pose (the URDF link, at the joint, is <link>__joint)."""
    text = fourbar().replace('<joint name="coupler_joint" type="revolute">', '<joint name="coupler_joint" type="ball">')
    text = text.replace("<axis><xyz>0 1 0</xyz><use_parent_model_frame>true</use_parent_model_frame></axis>", "")
    text = text.replace('<parent>crank</parent><child>coupler</child>',
                        '<parent>crank</parent><child>coupler</child><pose>0 0 -0.02 0 0 0</pose>')
    mech = mechanism(text)
    assert mech.joints["coupler_joint"].kind == "JointModelSpherical"
    (coupler,) = placements(mech, mech.q_reference, "coupler")
    assert np.allclose(coupler.translation, [0, 0, 0.1])  # the SDF pose, not the joint's (0, 0, 0.08)
    assert mech.model.existFrame("coupler__joint")


def test_a_chain_deeper_than_the_recursion_limit_is_a_spec_error():
    links = "".join(f"<link name='l{k}'/>" for k in range(1499, -1, -1))  # children first
    joints = "".join(f"<joint name='j{k}' type='fixed'><parent>l{k - 1}</parent><child>l{k}</child></joint>"
                     for k in range(1499, 0, -1))
    with pytest.raises(SpecError, match="nested deeper"):
        read_sdf(f"<sdf version='1.7'><model name='deep'>{links}{joints}</model></sdf>", "deep.sdf")


@pytest.mark.parametrize("flag", ["1", "true", "True"])
def test_use_parent_model_frame_is_an_sdformat_boolean(flag):
    """SDFormat booleans are ``true`` or ``1`` (Cassie's files write ``1``): the axis is then in the model frame,
    here the model's x, i.e. -y of the rocker turned 90 degrees about z."""
    text = fourbar().replace('<link name="rocker"><pose degrees="true">0.3 0 0 0 0 0</pose>',
                             '<link name="rocker"><pose degrees="true">0.3 0 0 0 0 90</pose>')
    text = text.replace("<parent>world</parent><child>rocker</child>\n        <axis><xyz>0 1 0</xyz></axis>",
                        "<parent>world</parent><child>rocker</child>\n        <axis><xyz>1 0 0</xyz>"
                        f"<use_parent_model_frame>{flag}</use_parent_model_frame></axis>")
    imp = read_sdf(text, "fb.sdf")
    (axis,) = [j.find("axis").get("xyz") for j in etree.fromstring(imp.urdf.encode()).findall("joint")
               if j.get("name") == "rocker_joint"]
    assert np.allclose([float(x) for x in axis.split()], [0, -1, 0], atol=1e-12)


def test_links_that_are_each_others_parents_are_refused():
    """A cycle of parents above a link that reaches the world through it (the walk is linear: each link once)."""
    text = fourbar().replace("</model>", """<link name="a"/><link name="b"/><link name="c"/>
      <joint name="ab" type="fixed"><parent>b</parent><child>a</child></joint>
      <joint name="bc" type="fixed"><parent>c</parent><child>b</child></joint>
      <joint name="ca" type="fixed"><parent>a</parent><child>c</child></joint></model>""")
    with pytest.raises(SpecError, match=r"links \['a', 'b', 'c'\] are each other's parents"):
        read_sdf(text, "fb.sdf")


def test_the_drive_of_an_actuated_joint_is_read_and_sdf_defaults_mean_none():
    """SDFormat's ``<limit><effort>``, ``<velocity>`` and ``<dynamics><damping>``, ``<friction>`` become the
    actuator's continuous effort and speed limits and its viscous and Coulomb friction; SDFormat's default -1 (no
    limit) reads as none, and a negative damping is refused with the joint named."""
    drive = ("<axis><xyz>0 1 0</xyz><limit><lower>-2</lower><upper>2</upper><effort>12.5</effort>"
             "<velocity>4</velocity></limit><dynamics><damping>0.03</damping><friction>0.2</friction></dynamics>"
             "</axis></joint>")
    text = fourbar().replace("<axis><xyz>0 1 0</xyz><limit><lower>-2</lower><upper>2</upper></limit></axis></joint>",
                             drive, 1)
    (act,) = mechanism(text).actuators
    assert (act.effort_limit, act.velocity_limit, act.viscous, act.coulomb) == (12.5, 4.0, 0.03, 0.2)
    (free,) = mechanism(text.replace("<effort>12.5</effort>", "<effort>-1</effort>")).actuators
    assert free.effort_limit == np.inf and free.velocity_limit == 4.0
    (bare,) = mechanism(fourbar()).actuators
    assert (bare.effort_limit, bare.velocity_limit, bare.viscous) == (np.inf, np.inf, 0.0)
    with pytest.raises(SpecError, match="joint 'crank_joint': a negative dynamics value"):
        read_sdf(text.replace("<damping>0.03</damping>", "<damping>-0.03</damping>"), "fb.sdf")
