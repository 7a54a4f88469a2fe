"""pkm.core.formats.mjcf: MuJoCo files read through Pinocchio's parser into pkm's one representation, with the
parser's gaps worked around, each checked here against Pinocchio's own model or the file's numbers."""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.formats.mjcf import read_mjcf
from pkm.core.model.compare import mechanism_differences
from pkm.core.model.joints import retype_joints
from pkm.core.model.urdf import load_model
from pkm.errors import SpecError

FOURBAR = Path(__file__).resolve().parents[3] / "examples" / "mjcf_fourbar" / "fourbar.xml"

#: A body with two hinges (Pinocchio's composite joint), a ball and a slide in one body, ranges in degrees,
#: a site on the body without joints, a second body under <worldbody>, a connect to the world and a weld.
PROBE = """<mujoco model="probe">
  <compiler angle="degree"/>
  <default><default class="stiff"><joint range="-30 30"/></default></default>
  <worldbody>
    <body name="stand" pos="0 0 0.2"><site name="stand_tip" pos="0 1 0" euler="0 0 90"/></body>
    <body name="a" pos="0 0 0.5" euler="0 0 90">
      <joint name="ja" type="hinge" axis="1 0 0" range="-90 45"/>
      <joint name="jb" type="hinge" axis="0 1 0" pos="0 0 0.1" class="stiff"/>
      <geom type="sphere" size="0.1" mass="1"/>
      <body name="b" pos="0.2 0 0">
        <joint name="jball" type="ball"/>
        <joint name="jslide" type="slide" axis="0 0 1" range="-0.1 0.1"/>
        <geom type="box" size="0.1 0.05 0.02" mass="2"/>
        <site name="bs" pos="0.1 0 0"/>
      </body>
    </body>
    <body name="c" pos="1 0 0"><joint name="jc" type="slide" axis="1 0 0"/><geom type="sphere" size="0.05" mass="0.5"/></body>
  </worldbody>
  <equality>
    <connect name="tie" body1="b" anchor="0.1 0 0"/>
    <weld body1="a" body2="b"/>
  </equality>
  <actuator><motor joint="ja"/><position joint="jc"/></actuator>
</mujoco>"""


@pytest.fixture(scope="module")
def probe():
    return read_mjcf(PROBE, "probe.xml")


def _pinocchio_model(tmp_path: Path, text: str) -> pin.Model:
    """Pinocchio's own reading of ``text`` with every worldbody child wrapped in one body (what it reads)."""
    wrapped = text.replace("<worldbody>", "<worldbody><body name='w'>").replace("</worldbody>", "</body></worldbody>")
    (tmp_path / "m.xml").write_text(wrapped)
    return pin.buildModelAndConstraintsFromMJCF(str(tmp_path / "m.xml"))[0]


def test_the_urdf_gives_pinocchios_tree_back(probe, tmp_path):
    """Same q layout; every body and site frame and RNEA agree with Pinocchio's model at random states (1e-12)."""
    ours = retype_joints(load_model(probe.urdf), probe.joint_types)
    ref = _pinocchio_model(tmp_path, PROBE)
    assert (ours.nq, ours.nv) == (ref.nq, ref.nv)
    d1, d2 = ref.createData(), ours.createData()
    rng = np.random.default_rng(0)
    names = [f.name for f in ref.frames if f.type in (pin.FrameType.BODY, pin.FrameType.OP_FRAME) and f.name != "w"]
    assert {"a", "b", "c", "bs", "stand"} <= set(names)
    for _ in range(5):
        q = pin.randomConfiguration(ref, -np.ones(ref.nq), np.ones(ref.nq))
        v, a = rng.normal(size=ref.nv), rng.normal(size=ref.nv)
        pin.framesForwardKinematics(ref, d1, q)
        pin.framesForwardKinematics(ours, d2, q)
        for n in names:
            M1, M2 = d1.oMf[ref.getFrameId(n)], d2.oMf[ours.getFrameId(n, pin.FrameType.BODY)]
            assert np.abs(M1.homogeneous - M2.homogeneous).max() <= 1e-12, n
        assert np.abs(pin.rnea(ref, d1, q, v, a) - pin.rnea(ours, d2, q, v, a)).max() <= 1e-12


def test_what_pinocchio_drops_is_read_from_the_file(probe):
    """The second body under <worldbody>, the site of a body without joints, the composite's joint names, the
    equalities' names, ranges (hinges in degrees, a slide's as a length, a default class's), the actuators."""
    model = load_model(probe.urdf)
    assert {"ja", "jb", "jball", "jslide", "jc"} <= set(model.names)
    assert probe.actuated == ("ja", "jc")
    assert probe.joint_types == {"jball": "spherical"}
    assert [(c.name, c.type) for c in probe.closures] == [("tie", "point"), ("weld1", "frame")]
    mech = pkm.from_strings(probe.urdf, pkm.ClosureSpec(
        mechanism="probe", urdf="probe.urdf", end_effector=None, actuated=probe.actuated, closures=probe.closures,
        task=pkm.core.model.spec.TaskSpec((), probe.actuated), reference={}, joint_types=probe.joint_types))
    assert mech.limits["ja"] == pytest.approx((-np.pi / 2, np.pi / 4), abs=1e-15)
    assert mech.limits["jb"] == pytest.approx((-np.pi / 6, np.pi / 6), abs=1e-15)
    assert mech.limits["jslide"] == (-0.1, 0.1)
    pin.framesForwardKinematics(mech.model, mech.data, pin.neutral(mech.model))
    tip = mech.data.oMf[mech.frame_id("stand_tip")]
    assert np.allclose(tip.translation, [0, 1, 0.2], atol=1e-15)
    assert np.allclose(tip.rotation, pin.AngleAxis(np.pi / 2, np.array([0, 0, 1.0])).matrix(), atol=1e-15)


def test_a_file_loads_pickles_and_saves_as_a_spec_that_round_trips(tmp_path):
    mech = pkm.load(FOURBAR)
    assert mech.actuated_names == ("crank_joint",) and mech.spec.closures[0].name == "pin_c"
    assert mechanism_differences(mech, pickle.loads(pickle.dumps(mech))) == []
    again = pkm.load(pkm.save(mech, tmp_path / "fourbar.closures.toml"))
    assert mechanism_differences(mech, again) == []


def test_a_spec_may_name_an_mjcf_file_and_add_a_task(tmp_path):
    (tmp_path / "fourbar.xml").write_text(FOURBAR.read_text())
    spec = tmp_path / "fourbar.closures.toml"
    spec.write_text('format = "pkm.closures/1"\nmechanism = "fb"\nurdf = "fourbar.xml"\nend_effector = "coupler_point"\n'
                    'actuated = ["crank_joint"]\n[task]\ncomponents = ["x"]\n')
    mech = pkm.load(spec)
    assert [c.name for c in mech.spec.closures] == ["pin_c"] and pkm.TaskMap.of(mech).names == ("x",)
    clash = spec.read_text() + '[[closure]]\nname = "pin_c"\ntype = "point"\nframe_a = "crank"\nframe_b = "rocker"\n'
    spec.write_text(clash)
    with pytest.raises(SpecError, match="'pin_c' is both in the spec"):
        pkm.load(spec)


@pytest.mark.parametrize("edit, message", [
    (lambda s: s.replace("<worldbody>", "<include file='x.xml'/><worldbody>"), "<include> is refused"),
    (lambda s: s.replace("</equality>", "<tendon tendon1='t'/></equality>"), "<tendon> is not a constraint"),
    (lambda s: s.replace("</equality>", "<joint joint1='jb' joint2='jball'/></equality>"), "'jball' is a ball joint"),
    (lambda s: s.replace('<joint name="jb" type="hinge"', '<joint name="jb" type="screw"'), "type 'screw'"),
    (lambda s: s.replace('<position joint="jc"/>', '<position joint="nope"/>'), "joint 'nope'"),
    (lambda s: s.replace("<mujoco", "<robot").replace("</mujoco>", "</robot>"), "expected <mujoco>"),
    (lambda s: s.replace("<compiler", "<compiler eulerseq='zyxz'"), "eulerseq"),
    (lambda s: s[:200], "not well-formed"),
    (lambda s: s.replace("<worldbody>", "<worldbody><joint type='hinge'/>", 1), "is in <worldbody>, not in a <body>"),
])
def test_what_it_refuses_it_says(edit, message):
    with pytest.raises(SpecError, match=message):
        read_mjcf(edit(PROBE), "probe.xml")


def test_a_file_without_actuators_says_how_to_name_them(tmp_path):
    path = tmp_path / "passive.xml"
    path.write_text(FOURBAR.read_text().replace('<motor name="drive" joint="crank_joint" gear="1"/>', ""))
    with pytest.raises(SpecError, match=r"names no actuated joint.*pkm spec init"):
        pkm.load(path)


def test_equalities_on_sites_close_the_sites_frames():
    """(Pinocchio 4.1 crashes the process on site-based equalities: pkm takes them out of Pinocchio's copy.) A weld
    between two sites is a frame closure between those sites, a connect a point closure; one site alone, or no body
    and no site, is refused."""
    text = PROBE.replace('<weld body1="a" body2="b"/>', '<weld name="w" site1="bs" site2="stand_tip"/>')
    imported = read_mjcf(text, "probe.xml")
    assert [(c.name, c.type, c.frame_a, c.frame_b) for c in imported.closures] == [
        ("tie", "point", "tie_a", "tie_b"), ("w", "frame", "bs", "stand_tip")]
    with pytest.raises(SpecError, match="give both site1 and site2"):
        read_mjcf(PROBE.replace('<weld body1="a" body2="b"/>', '<weld site1="bs"/>'), "probe.xml")
    with pytest.raises(SpecError, match=r"site 'nope' does not exist in probe.xml \(<equality><connect "
                                        r"name='connect2'> \(line \d+\) site2\)"):
        read_mjcf(PROBE.replace('<weld body1="a" body2="b"/>', '<connect site1="bs" site2="nope"/>'), "probe.xml")
    with pytest.raises(SpecError, match="no body1 and no sites"):
        read_mjcf(PROBE.replace('<weld body1="a" body2="b"/>', '<connect anchor="0 0 0"/>'), "probe.xml")


def test_the_world_body_and_free_bodies_are_where_mujoco_puts_them(tmp_path):
    """body2="world" names the world; a free body keeps its pose at qpos0 (Pinocchio 4.1 applies it twice), its
    loop closed there, its sites where MuJoCo puts them."""
    text = """<mujoco model="free"><compiler angle="degree"/><worldbody>
      <body name="plat" pos="0.1 0.2 0.5" euler="0 0 30"><freejoint name="pf"/>
        <geom type="sphere" size="0.05" mass="1"/><site name="s" pos="0.1 0 0"/></body>
      <body name="arm"><joint name="j" type="hinge" axis="0 0 1"/>
        <geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.01" mass="0.1"/></body>
    </worldbody><equality><connect body1="plat" body2="arm" anchor="0 0 0"/>
      <connect body1="arm" body2="world" anchor="0 0 0"/></equality>
    <actuator><motor joint="j"/></actuator></mujoco>"""
    (tmp_path / "free.xml").write_text(text)
    mech = pkm.load(tmp_path / "free.xml")
    at = mech.joint("pf").idx_q
    R = pin.AngleAxis(np.radians(30), np.array([0, 0, 1.0])).matrix()
    assert np.allclose(mech.q_reference[at:at + 7], pin.SE3ToXYZQUAT(pin.SE3(R, np.array([0.1, 0.2, 0.5]))))
    from pkm.core.kinematics import constraints

    assert np.abs(constraints.residual(mech, mech.q_reference)).max() <= 1e-12
    pin.framesForwardKinematics(mech.model, mech.data, mech.q_reference)
    assert np.allclose(mech.data.oMf[mech.frame_id("s")].translation, [0.1, 0.2, 0.5] + R @ [0.1, 0, 0])


def test_a_urdf_named_xml_is_read_as_a_urdf(tmp_path):
    knee = Path(__file__).resolve().parents[3] / "examples" / "knee"
    (tmp_path / "knee.xml").write_text((knee / "knee.urdf").read_text())
    (tmp_path / "knee.closures.toml").write_text((knee / "knee.closures.toml").read_text().replace("knee.urdf",
                                                                                                     "knee.xml"))
    assert pkm.load(tmp_path / "knee.closures.toml").actuated_names == ("knee_front",)


#: The drives' values in every form the reader takes: a default class's (joint and actuator), a motor's ctrlrange
#: times gear under a joint's actuatorfrcrange, an asymmetric forcerange of a position servo, a fixed tendon's
#: coefficient, a passive joint's damping (not read).
DRIVES = """<mujoco model="drives">
  <default>
    <geom type="sphere" size="0.05" mass="1"/>
    <default class="geared"><joint armature="0.02" damping="0.5" frictionloss="0.3"/><motor gear="20"/>
      <position forcerange="-1.5 1.5"/></default>
  </default>
  <worldbody>
    <body name="a"><joint name="ja" class="geared" axis="0 0 1"/><geom/>
      <body name="b" pos="0.3 0 0"><joint name="jb" axis="0 0 1" damping="0.1" actuatorfrcrange="-4 4"/><geom/>
        <body name="c" pos="0.3 0 0"><joint name="jc" type="slide" axis="1 0 0" armature="1.5"/><geom/>
          <body name="d" pos="0.3 0 0"><joint name="jd" axis="0 0 1" damping="7"/><geom/></body>
        </body>
      </body>
    </body>
    <body name="e" pos="1 0 0"><joint name="je" axis="0 0 1"/><geom/></body>
  </worldbody>
  <tendon><fixed name="t"><joint joint="je" coef="0.5"/></fixed></tendon>
  <actuator>
    <motor name="ma" joint="ja" class="geared"/>
    <motor name="mb" joint="jb" ctrlrange="-10 10" gear="2"/>
    <position name="pc" joint="jc" kp="100" forcerange="-30 50"/>
    <motor name="me" tendon="t" forcerange="-8 8" gear="3"/>
  </actuator>
</mujoco>"""


def test_the_drives_are_read_in_joint_units_as_mujoco_applies_them():
    """armature, damping, frictionloss as stated (classes included); the effort limit is the force MuJoCo's
    actuators apply at full control, in the joint's units (gear, tendon coefficient, ctrlrange of a motor,
    actuatorfrcrange), the smaller of the two directions; checked against MuJoCo's qfrc_actuator when installed."""
    imp = read_mjcf(DRIVES, "drives.xml")
    assert imp.actuators == {
        "ja": {"armature": 0.02, "viscous": 0.5, "coulomb": 0.3, "effort_limit": 30.0},  # class: 1.5 x gear 20
        "jb": {"viscous": 0.1, "effort_limit": 4.0},  # ctrlrange 10 x gear 2, held to actuatorfrcrange 4
        "jc": {"armature": 1.5, "effort_limit": 30.0},  # [-30, 50]: the smaller magnitude
        "je": {"effort_limit": 12.0}}  # 8 x gear 3 x coef 0.5
    assert any("'pc'" in n and "[-30, 50] is not symmetric" in n for n in imp.notes)
    assert any("'mb'" in n and "ctrlrange bounds joint jb" in n for n in imp.notes)
    assert any("gains of <position name='pc'>" in n for n in imp.notes)
    assert imp.springs["jd"] == {"damping": 7.0} and any("jd (damping 7)" in n for n in imp.notes)  # (passive)
    try:
        import mujoco
    except ImportError:
        return
    m = mujoco.MjModel.from_xml_string(DRIVES)
    d = mujoco.MjData(m)
    reach = {}
    for sign in (1.0, -1.0):
        d.ctrl[:] = sign * 1e3
        mujoco.mj_forward(m, d)
        for joint in imp.actuators:
            dof = m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, joint)]
            reach[joint] = min(reach.get(joint, np.inf), abs(d.qfrc_actuator[dof]))
    for joint, values in imp.actuators.items():
        dof = m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, joint)]
        assert reach[joint] == pytest.approx(values["effort_limit"], rel=1e-12), joint
        assert (m.dof_armature[dof], m.dof_damping[dof], m.dof_frictionloss[dof]) == \
            (values.get("armature", 0.0), values.get("viscous", 0.0), values.get("coulomb", 0.0))


@pytest.mark.parametrize("edit, message", [
    (lambda s: s.replace('damping="0.1"', 'damping="-0.1"'), r"joint 'jb': viscous: .*-0\.1"),
    (lambda s: s.replace('armature="1.5"', 'armature="heavy"'), r"joint 'jc' armature: 'heavy' is not"),
    (lambda s: s.replace('gear="3"', 'gear="0"'), r"<motor name='me'> on joint 'je': gear 0"),
    (lambda s: s.replace('forcerange="-8 8"', 'forcelimited="true"'), r"<motor name='me'> forcerange not given: "
                                                                       r"a limited range needs lower < upper"),
    (lambda s: s.replace('forcerange="-8 8"', 'forcerange="-8 nan"'), r"'me'> forcerange: .*not finite"),
])
def test_a_bad_drive_value_is_a_spec_error_naming_it(edit, message):
    with pytest.raises(SpecError, match=message):
        read_mjcf(edit(DRIVES), "drives.xml")


def test_a_drive_one_way_or_unlimited_reads_as_the_range_allows():
    """A one-sided range is read as its magnitude (a note says so); forcelimited="false", a range MuJoCo does not
    apply (lower >= upper under "auto") and 1e6 or more read as no limit."""
    one_sided = read_mjcf(DRIVES.replace('forcerange="-8 8"', 'forcerange="0 8"'), "d.xml")
    assert one_sided.actuators["je"] == {"effort_limit": 12.0}
    assert any("[0, 8] is one-sided" in n for n in one_sided.notes)
    for edit in ('forcerange="-8 8" forcelimited="false"', 'forcerange="8 8"', 'forcerange="-1e30 1e30"'):
        assert "je" not in read_mjcf(DRIVES.replace('forcerange="-8 8"', edit), "d.xml").actuators, edit


def test_the_fourbars_drive_loads_saves_and_pickles(tmp_path):
    """An MJCF file's drive values reach mech.actuators and the model's fields, and ride in the saved spec's
    [actuators] tables (the URDF cannot carry an armature); a spec naming the file overrides them field by field."""
    text = FOURBAR.read_text().replace('<joint name="crank_joint" range="-180 180"/>',
                                       '<joint name="crank_joint" range="-180 180" armature="0.003" damping="0.05" '
                                       'frictionloss="0.1"/>').replace('gear="1"/>', 'gear="2" forcerange="-1.5 1.5"/>')
    (tmp_path / "fourbar.xml").write_text(text)
    mech = pkm.load(tmp_path / "fourbar.xml")
    assert mech.actuators == (pkm.Actuator("crank_joint", armature=0.003, viscous=0.05, coulomb=0.1, effort_limit=3.0),)
    iv = mech.act_v[0]
    assert (mech.model.armature[iv], mech.model.damping[iv], mech.model.effortLimit[iv]) == (0.003, 0.05, 3.0)
    assert pkm.load(pkm.save(mech, tmp_path / "saved.closures.toml")).actuators == mech.actuators
    assert pickle.loads(pickle.dumps(mech)).actuators == mech.actuators
    spec = tmp_path / "fb.closures.toml"
    spec.write_text('format = "pkm.closures/1"\nmechanism = "fb"\nurdf = "fourbar.xml"\nactuated = ["crank_joint"]\n'
                    '[actuators.crank_joint]\nviscous = 0.2\n')
    assert pkm.load(spec).actuators[0] == pkm.Actuator("crank_joint", armature=0.003, viscous=0.2, coulomb=0.1,
                                                       effort_limit=3.0)


_FOURBAR = Path(__file__).resolve().parents[3] / "examples" / "mjcf_fourbar" / "fourbar.xml"


def test_the_reference_is_mujocos_qpos0_the_joints_at_their_ref(tmp_path):
    """A hinge's ``ref`` is where its body has the file's pose (MuJoCo's ``qpos0``, where a connect's second anchor
    is taken): the four-bar with the coupler's ``ref`` at 30 degrees is assembled there (it was assembled from 0
    before), and with the rocker a free body (the connect re-anchored by pkm) it is closed there too (it was anchored
    at the coupler's 0, which left MuJoCo's qpos0 open by 0.52 rad of coupler). MuJoCo's own qpos0 agrees
    (test_mjcf_mujoco.py checks the written files in MuJoCo)."""
    from pkm.core.kinematics import constraints

    text = _FOURBAR.read_text().replace('<joint name="coupler_joint"/>', '<joint name="coupler_joint" ref="30"/>')
    free = text.replace('<body name="rocker" pos="0.3 0 0">\n      <joint name="rocker_joint"/>',
                        '<body name="rocker" pos="0.3 0 0">\n      <freejoint name="rocker_free"/>')
    assert free != text
    for name, body, expected in (("hinged.xml", text, [0.0, np.pi / 6, 0.0]),
                                 ("free.xml", free, [0.0, np.pi / 6, 0.3, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])):
        (tmp_path / name).write_text(body)
        mech = pkm.load(tmp_path / name)
        assert np.abs(mech.q_reference - expected).max() <= 1e-12, name
        assert np.abs(constraints.residual(mech, np.array(expected))).max() <= 1e-12, name
        assert any("assembled from the joints' ref" in n for n in mech.notes), name


def test_the_reference_keyframe_is_the_reference_and_a_wrong_one_is_refused_by_line(tmp_path):
    """``<keyframe><key name="reference" qpos>`` (what pkm.save writes) is the reference, held (a note says so); a
    qpos of the wrong length is a SpecError naming the file, the key and its line."""
    q = [0.1, 0.2, 0.3]
    key = f'<keyframe><key name="reference" qpos="{" ".join(map(str, q))}"/></keyframe>\n</mujoco>'
    text = _FOURBAR.read_text()
    (tmp_path / "keyed.xml").write_text(text.replace("</mujoco>", key))
    with pytest.raises(SpecError, match="leaves closure 'pin_c' open"):  # (an arbitrary qpos is not closed: held)
        pkm.load(tmp_path / "keyed.xml")
    mech = pkm.load(_FOURBAR)
    q = pkm.close_loops(mech, [0.2]).q
    (tmp_path / "keyed.xml").write_text(text.replace("</mujoco>", key.replace("0.1 0.2 0.3", " ".join(repr(float(x)) for x in q))))
    keyed = pkm.load(tmp_path / "keyed.xml")
    assert np.abs(keyed.q_reference - q).max() == 0.0 and any("<keyframe>" in n for n in keyed.notes)
    (tmp_path / "short.xml").write_text(text.replace("</mujoco>", key.replace("0.1 0.2 0.3", "0.1 0.2")))
    with pytest.raises(SpecError, match=r"short\.xml: <keyframe><key name='reference'> \(line \d+\) qpos"):
        pkm.load(tmp_path / "short.xml")


def test_without_the_reference_key_the_first_key_inside_the_limits_is_closed_holding_its_motors(tmp_path):
    """A key of another name (Menagerie's ``home``), its loops open by millimetres as MuJoCo's soft equalities leave
    them: its motor held (the crank at 0.2, 1e-15), the other joints closed from it, the same configuration as
    ``close_loops`` from the crank (1e-10); a key outside a range before it is passed over, both said in the notes."""
    mech = pkm.load(_FOURBAR)
    q = pkm.close_loops(mech, [0.2]).q
    keys = (f'<keyframe><key name="bad" qpos="4 0 0"/><key name="home" qpos="0.2 {float(q[1]) + 0.01!r} '
            f'{float(q[2]) - 0.01!r}"/><key name="later" qpos="0.1 0 0"/></keyframe>\n</mujoco>')
    (tmp_path / "home.xml").write_text(_FOURBAR.read_text().replace("</mujoco>", keys))
    keyed = pkm.load(tmp_path / "home.xml")
    assert abs(keyed.q_reference[0] - 0.2) <= 1e-15 and np.abs(keyed.q_reference - q).max() < 1e-10
    notes = " | ".join(keyed.notes)
    assert "<key name='home'>" in notes and "'bad' (crank_joint)" in notes and "not read" in notes and "'later'" in notes
    assert "loops open by 0.0051" in notes


def test_an_assembled_reference_outside_a_range_is_assembled_again_inside_it_else_said(tmp_path):
    """No key, ``qpos0`` outside the crank's range [10, 60] deg: the crank is restarted at the middle of its range and
    the reference lands inside every limit, closed (1e-12), a note saying so; a rocker range no closure reaches keeps
    the first assembly with a PkmWarning naming the joint (never a reference outside a limit without a word)."""
    from pkm.core.kinematics import constraints
    from pkm.errors import PkmWarning

    text = _FOURBAR.read_text()
    (tmp_path / "crank.xml").write_text(text.replace('range="-180 180"', 'range="10 60"'))
    mech = pkm.load(tmp_path / "crank.xml")
    assert mech.outside_limits(mech.q_reference) == ()
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() <= 1e-12
    assert any("assembled again from ['crank_joint']" in n for n in mech.notes)
    (tmp_path / "rocker.xml").write_text(text.replace('<joint name="rocker_joint"/>',
                                                      '<joint name="rocker_joint" range="150 160"/>'))
    with pytest.warns(PkmWarning, match=r"outside the position limits of \['rocker_joint'\]"):
        rocker = pkm.load(tmp_path / "rocker.xml")
    assert rocker.outside_limits(rocker.q_reference) == ("rocker_joint",)
