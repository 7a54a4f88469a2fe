"""pkm.core.formats.mjcf on MJCF as public collections and MuJoCo's own test models write it: euler sequences,
joint equalities (mimic and locked joints), tendon actuators, unnamed joints and bodies, several top-level
``<default>`` elements, ``<frame>`` and class positions; each checked against MuJoCo's compiled model (the
``bench`` extra) or an independent computation. Every model here is written for these tests."""

from __future__ import annotations

import re

import numpy as np
import pinocchio as pin
import pytest

from pkm.core.formats.mjcf import euler_matrix, read_mjcf
from pkm.core.model.joints import retype_joints
from pkm.core.model.urdf import load_model
from pkm.errors import SpecError

TOL = 1e-12  # [m] or [-] (rotation-matrix entries): both routes compose the same few rotations


def _mujoco_model(text: str):
    mujoco = pytest.importorskip("mujoco")  # the bench extra: MuJoCo is the reference, not a dependency
    return mujoco, mujoco.MjModel.from_xml_string(text)


def _model(text: str) -> tuple[pin.Model, tuple[str, ...]]:
    imp = read_mjcf(text, "t.xml")
    return retype_joints(load_model(imp.urdf), imp.joint_types), imp.notes


#: Bodies, a site and an inertial stating their orientation by euler angles; a default class's site too.
EULER = """<mujoco model="euler">
  <compiler angle="{angle}" eulerseq="{seq}"/>
  <default><default class="tilted"><site euler="{e3}"/></default></default>
  <worldbody>
    <body name="a" pos="0.1 0.2 0.3" euler="{e1}">
      <joint name="ja" axis="0 0 1"/><geom type="sphere" size="0.05" mass="1"/>
      <body name="b" pos="0.4 0 0" euler="{e2}">
        <joint name="jb" axis="0 1 0"/>
        <inertial pos="0.1 0 0" euler="{e2}" mass="1" diaginertia="0.1 0.2 0.3"/>
        <site name="s" pos="0.1 0.2 0.3" euler="{e3}"/><site name="t" pos="0 0.1 0" class="tilted"/>
      </body>
    </body>
  </worldbody>
</mujoco>"""


@pytest.mark.parametrize("seq", ["xyz", "zyx", "XYZ", "ZYX", "xYz", "Zxy", "zxz", "XyX"])
def test_every_euler_sequence_is_read_as_mujoco_reads_it(seq):
    """Lower case about the moving axes, upper case about the fixed ones (Pinocchio 4.1 reads upper case as lower):
    bodies' and sites' world poses equal MuJoCo's at q = 0 and at q = (0.3, -0.7), to 1e-12; in degrees and
    radians."""
    for angle, scale in (("degree", 1.0), ("radian", np.pi / 180)):
        e = [" ".join(repr(v * scale) for v in row) for row in ([30, -50, 70], [-20, 110, 45], [15, 25, -160])]
        text = EULER.format(angle=angle, seq=seq, e1=e[0], e2=e[1], e3=e[2])
        mujoco, mm = _mujoco_model(text)
        md = mujoco.MjData(mm)
        model, _ = _model(text)
        d = model.createData()
        for q in (np.zeros(2), np.array([0.3, -0.7])):
            md.qpos[:] = q
            mujoco.mj_kinematics(mm, md)
            pin.framesForwardKinematics(model, d, q)
            for b in ("a", "b"):
                M = d.oMf[model.getFrameId(b, pin.FrameType.BODY)]
                assert np.abs(M.translation - md.body(b).xpos).max() <= TOL
                assert np.abs(M.rotation - md.body(b).xmat.reshape(3, 3)).max() <= TOL
            for s in ("s", "t"):
                M = d.oMf[model.getFrameId(s)]
                assert np.abs(M.translation - md.site(s).xpos).max() <= TOL
                assert np.abs(M.rotation - md.site(s).xmat.reshape(3, 3)).max() <= TOL
        w, x, y, z = mm.body_iquat[2]
        R = pin.Quaternion(w, x, y, z).matrix()
        inertia = model.inertias[model.getJointId("jb")]
        assert np.abs(inertia.inertia - R @ np.diag(mm.body_inertia[2]) @ R.T).max() <= TOL
        assert np.abs(inertia.lever - mm.body_ipos[2]).max() <= TOL


def test_euler_matrix_composes_moving_and_fixed_axes():
    """Independent of MuJoCo: "xyz" is Rx Ry Rz (moving axes), "XYZ" is Rz Ry Rx (fixed axes)."""
    R = {k: pin.AngleAxis(a, np.eye(3)["xyz".index(k)]).matrix() for k, a in zip("xyz", (0.1, 0.2, 0.3))}
    assert np.abs(euler_matrix([0.1, 0.2, 0.3], "xyz") - R["x"] @ R["y"] @ R["z"]).max() <= 1e-15
    assert np.abs(euler_matrix([0.1, 0.2, 0.3], "XYZ") - R["z"] @ R["y"] @ R["x"]).max() <= 1e-15
    assert np.abs(euler_matrix([0.1, 0.2, 0.3], "xYz") - R["y"] @ R["x"] @ R["z"]).max() <= 1e-15
    with pytest.raises(SpecError, match="eulerseq='xyw'"):
        read_mjcf(EULER.format(angle="degree", seq="xyw", e1="0 0 0", e2="0 0 0", e3="0 0 0"), "t.xml")


#: Two hinges and a slide; j2 follows j1 (with refs), j3 is locked, a tendon on j1 and j2 drives them.
COUPLED = """<mujoco model="coupled">
  <compiler angle="degree"/>
  <worldbody>
    <body name="a"><joint name="j1" axis="0 0 1" ref="20" range="-90 90"/><geom type="sphere" size="0.05" mass="1"/>
      <site name="sa" pos="0.2 0 0"/></body>
    <body name="b" pos="0.5 0 0"><joint name="j2" axis="0 0 1" ref="-10" range="-30 60"/>
      <geom type="sphere" size="0.05" mass="1"/><site name="sb" pos="0.2 0 0"/>
      <body name="c" pos="0.2 0 0"><joint name="j3" type="slide" axis="1 0 0" ref="0.05"/>
        <geom type="sphere" size="0.05" mass="1"/><site name="sc" pos="0 0.1 0"/></body>
    </body>
  </worldbody>
  <tendon><fixed name="pair"><joint joint="j1" coef="0.5"/><joint joint="j2" coef="0.75"/></fixed></tendon>
  <equality>
    <joint name="follow" joint1="j2" joint2="j1" polycoef="0.1 -2 0 0 0"/>
    <joint name="hold" joint1="j3" polycoef="0.02 0 0 0 0"/>
  </equality>
  <actuator><motor tendon="pair"/></actuator>
</mujoco>"""


def test_a_linear_joint_equality_is_a_mimic_joint_and_locks_a_joint_alone():
    """MuJoCo: j2 - ref2 = 0.1 - 2 (j1 - ref1); j3 - ref3 = 0.02. pkm's tree, at j1 = x, puts every site where
    MuJoCo puts them with qpos = (x, 0.1 - 2 (x - ref1) + ref2, 0.07), to 1e-12; q is MuJoCo's qpos."""
    mujoco, mm = _mujoco_model(COUPLED)
    md = mujoco.MjData(mm)
    model, notes = _model(COUPLED)
    assert model.nq == 1 and model.joints[model.getJointId("j2")].shortname() == "JointModelMimic"
    assert any("follow" in n and "mimic" in n for n in notes) and any("j3 locked at 0.07" in n for n in notes)
    d = model.createData()
    ref1, ref2 = np.radians(20), np.radians(-10)
    for x in (0.0, 0.4, -1.1):
        md.qpos[:] = [x, 0.1 - 2 * (x - ref1) + ref2, 0.07]
        mujoco.mj_kinematics(mm, md)
        pin.framesForwardKinematics(model, d, np.array([x]))
        for s in ("sa", "sb", "sc"):
            assert np.abs(d.oMf[model.getFrameId(s)].translation - md.site(s).xpos).max() <= TOL


def test_a_tendon_on_coupled_joints_drives_their_leader_and_the_ranges_bound_it():
    """0.5 j1 + 0.75 j2 with j2 = -2 j1 + c is -j1 + c': the actuated joint is j1 (noted); with 0.25 for 0.75 no
    joint moves the tendon: refused. j2's range [-30, 60] deg bounds j1 through the coupling."""
    with pytest.raises(SpecError, match=r"tendon 'pair' \(0.5 j1 \+ 0.25 j2\), whose length no joint moves"):
        read_mjcf(COUPLED.replace('coef="0.75"', 'coef="0.25"'), "t.xml")
    imp = read_mjcf(COUPLED, "t.xml")
    assert imp.actuated == ("j1",)
    assert any("tendon 'pair'" in n and "actuated joint j1 (length = -1 j1" in n for n in imp.notes)
    j2 = np.radians([-30, 60])
    bound = sorted((j2 - 0.1 - np.radians(-10)) / -2 + np.radians(20))
    lo, hi = max(bound[0], np.radians(-90)), min(bound[1], np.radians(90))
    from pkm.core.model.urdf import position_limits

    assert position_limits(imp.urdf)["j1"] == pytest.approx((lo, hi), abs=1e-15) and "j2" not in position_limits(
        imp.urdf)


def test_the_mimic_leader_is_the_joint_pinocchio_visits_first():
    """MuJoCo's j1 may come after j2 in Pinocchio's traversal (name order): the coupling is inverted, j2 leads."""
    text = COUPLED.replace('joint1="j2" joint2="j1"', 'joint1="j1" joint2="j2"')
    model, _ = _model(text)
    assert model.joints[model.getJointId("j2")].shortname() == "JointModelMimic"  # j1 visited first: j1 leads
    mim = model.joints[model.getJointId("j2")].extract()
    # MuJoCo: j1 - ref1 = 0.1 - 2 (j2 - ref2), so j2 = -(j1 - ref1 - 0.1) / 2 + ref2
    assert (mim.scaling, mim.offset) == pytest.approx((-0.5, (np.radians(20) + 0.1) / 2 + np.radians(-10)), abs=1e-15)


@pytest.mark.parametrize("edit, message", [
    (lambda s: s.replace('polycoef="0.1 -2 0 0 0"', 'polycoef="0.1 -2 0.3 0 0"'),
     r"<equality><joint name='follow'>: polycoef .* degree 2 .* only the linear coupling"),
    (lambda s: s.replace('joint2="j1"', 'joint2="nope"'), "joint 'nope' does not exist"),
    (lambda s: s.replace('<motor tendon="pair"/>', '<motor tendon="j1"/>'), "tendon 'j1' does not exist"),
    (lambda s: s.replace('<motor tendon="pair"/>', '<motor joint="j3"/>'), "which an <equality><joint> locks"),
    (lambda s: s.replace('</tendon>', '<spatial name="rope"><site site="sa"/><site site="sb"/></spatial></tendon>')
     .replace('tendon="pair"', 'tendon="rope"'), "spatial tendon 'rope'"),
    (lambda s: s.replace('<joint name="follow"', '<joint name="follow" active="false"').replace('coef="0.75"', ''),
     r"motors \['pair'\] drive the joints \['j1', 'j2'\]: pkm reads a differential of as many motors as joints"),
])
def test_what_cannot_be_one_joint_input_is_refused_by_name(edit, message):
    with pytest.raises(SpecError, match=message):
        read_mjcf(edit(COUPLED), "t.xml")


def test_unnamed_joints_and_bodies_get_names_from_their_body():
    """A free joint, two hinges and a slide without names, unnamed bodies, a site already called 'beam1_child_hinge':
    derived names that clash with nothing (Pinocchio loses unnamed bodies)."""
    text = """<mujoco model="unnamed"><worldbody>
      <body name="beam1" pos="0 0 1"><freejoint/><geom type="sphere" size="0.05" mass="1"/>
        <site name="beam1_child_hinge"/>
        <body pos="0.1 0 0"><joint/><joint axis="0 1 0"/><geom type="sphere" size="0.05" mass="1"/></body>
        <body pos="0.2 0 0"><joint type="slide"/><geom type="sphere" size="0.05" mass="1"/></body>
      </body></worldbody><actuator><motor joint="nope"/></actuator></mujoco>"""
    with pytest.raises(SpecError, match="valid joints: 'beam1_free', 'beam1_child_hinge_2', 'beam1_child_hinge_3', "
                                        "'beam1_child_2_slide'"):
        read_mjcf(text, "t.xml")
    model, notes = _model(text.replace('<actuator><motor joint="nope"/></actuator>', ""))
    assert set(model.names[1:]) == {"beam1_free", "beam1_child_hinge_2", "beam1_child_hinge_3", "beam1_child_2_slide"}
    assert model.existFrame("beam1_child", pin.FrameType.BODY) and model.existFrame("beam1_child_2", pin.FrameType.BODY)
    assert model.existFrame("beam1_child_hinge")
    assert "hinge joint beam1_child_hinge_2" in notes[0]


def test_several_top_level_defaults_frames_and_class_positions_are_read_as_mujoco_does():
    """Pinocchio 4.1 reads the first top-level <default> only (a class of the second: "unordered_map::at", as
    on Reachy Mini's head), loses a <frame>'s bodies and a class's joint pos (Robotiq 2F-85's followers): pkm's
    tree puts every body and site where MuJoCo does, at q = 0 and elsewhere."""
    text = """<mujoco model="heads"><compiler angle="radian"/>
      <default><default class="a"><joint axis="1 0 0"/></default></default>
      <default><default class="b"><joint axis="0 1 0" pos="0 0 0.1"/><site pos="0.05 0 0"/></default></default>
      <worldbody><body name="base">
        <frame pos="0.1 0 0.2" quat="0.9 0 0.3 0.1">
          <body name="l" pos="0.3 0 0"><joint name="j" class="b"/><geom type="sphere" size="0.05" mass="1"/>
            <site name="s" class="b"/>
            <body name="m" pos="0.2 0 0"><joint name="k" class="a"/><geom type="sphere" size="0.05" mass="1"/>
            </body></body>
        </frame></body></worldbody></mujoco>"""
    with pytest.raises(IndexError, match="unordered_map::at"):  # the upstream bug this works around
        import tempfile
        from pathlib import Path

        with tempfile.TemporaryDirectory() as tmp:
            (Path(tmp) / "m.xml").write_text(re.sub(r"</?frame[^>]*>", "", text))
            pin.buildModelAndConstraintsFromMJCF(str(Path(tmp) / "m.xml"))
    mujoco, mm = _mujoco_model(text)
    md = mujoco.MjData(mm)
    model, notes = _model(text)
    assert any("<default>" in n for n in notes) and any("<frame>" in n for n in notes)
    for q in (np.zeros(2), np.array([0.5, -0.8])):
        _bodies_and_site_where_mujoco_puts_them(mujoco, mm, md, model, q)


def _bodies_and_site_where_mujoco_puts_them(mujoco, mm, md, model, q):
    """Bodies ``l``, ``m`` and site ``s`` at ``q``: Pinocchio's frames where MuJoCo's kinematics puts them (TOL)."""
    d = model.createData()
    md.qpos[:] = q
    mujoco.mj_kinematics(mm, md)
    pin.framesForwardKinematics(model, d, q)
    for b in ("l", "m"):
        assert np.abs(d.oMf[model.getFrameId(b, pin.FrameType.BODY)].translation - md.body(b).xpos).max() <= TOL
    assert np.abs(d.oMf[model.getFrameId("s")].translation - md.site("s").xpos).max() <= TOL


def test_a_default_stated_after_the_worldbody_is_read_as_mujoco_does():
    """MuJoCo reads the <default> classes wherever they stand (ToddlerBot's files state them last); Pinocchio 4.1 in
    document order ("unordered_map::at" before): pkm moves them before the <worldbody>, and a class's joint axis and
    pos and site pos put every body and site where MuJoCo does."""
    text = """<mujoco model="late"><compiler angle="radian"/>
      <worldbody><body name="l" pos="0.3 0 0"><joint name="j" class="b"/><geom type="sphere" size="0.05" mass="1"/>
        <site name="s" class="b"/><body name="m" pos="0.2 0 0"><joint name="k" axis="0 0 1"/>
        <geom type="sphere" size="0.05" mass="1"/></body></body></worldbody>
      <default><default class="b"><joint axis="0 1 0" pos="0 0 0.1"/><site pos="0.05 0 0"/></default></default>
      </mujoco>"""
    mujoco, mm = _mujoco_model(text)
    md = mujoco.MjData(mm)
    model, _ = _model(text)
    _bodies_and_site_where_mujoco_puts_them(mujoco, mm, md, model, np.array([0.5, -0.8]))


def test_a_connect_on_a_body_whose_joint_has_a_pos_closes_where_mujoco_does():
    """A four-bar whose follower's hinge sits at ``pos`` in its body, closed by a connect at the body's origin
    (Robotiq 2F-85's fingers): Pinocchio 4.1 put the anchor in the joint's frame, 0.1 m off here, and MuJoCo's connect
    stood 8.1 mm open at pkm's closed pose; pkm reads the anchor in the body's frame: with the crank moved by
    0.4 rad MuJoCo's connect holds to 1e-12 m."""
    import pkm
    from pkm.core.formats.load import load_texts
    from pkm.core.formats.to_mjcf import qpos_of

    text = """<mujoco model="offset"><compiler angle="radian"/><worldbody>
      <body name="crank"><joint name="c" axis="0 1 0"/><geom type="sphere" size="0.01" mass="1"/>
        <body name="coupler" pos="0.2 0 0"><joint name="k" axis="0 1 0"/><geom type="sphere" size="0.01" mass="1"/>
        </body></body>
      <body name="rocker" pos="0.5 0 0"><joint name="r" axis="0 1 0"/><geom type="sphere" size="0.01" mass="1"/>
        <body name="follower" pos="0 0 0.4"><joint name="f" axis="0 1 0" pos="0 0 -0.1"/>
          <geom type="sphere" size="0.01" mass="1"/></body></body>
      </worldbody><equality><connect body1="follower" body2="coupler" anchor="0 0 0"/></equality>
      <actuator><motor joint="c"/></actuator></mujoco>"""
    mujoco, mm = _mujoco_model(text)
    md = mujoco.MjData(mm)
    mech = load_texts({"offset.xml": text})
    q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + 0.4, mech.q_reference).q
    for k in range(mm.njnt):
        md.qpos[mm.jnt_qposadr[k]] = qpos_of(mech.model, mech.model.getJointId(mm.joint(k).name), q)[0]
    mujoco.mj_forward(mm, md)
    assert np.abs(md.efc_pos[:md.nefc]).max() <= 1e-12


def test_notes_say_what_is_left_out():
    notes = read_mjcf(COUPLED.replace("<actuator>", "<contact/><sensor/><actuator><motor site='sa'/>"), "t.xml").notes
    assert any("<contact>, <sensor> not read" in n for n in notes)
    assert any("acts on site 'sa'" in n for n in notes)


def test_two_unnamed_connects_between_the_same_bodies_are_both_read():
    """Pinocchio 4.1 keys the equalities by name (``a_b_constraint`` for both here) and keeps one: pkm names them."""
    text = """<mujoco model="dup"><worldbody>
      <body name="a"><joint name="ja" axis="0 1 0"/><geom type="sphere" size="0.01" mass="1"/></body>
      <body name="b" pos="1 0 0"><joint name="jb" axis="0 1 0"/><geom type="sphere" size="0.01" mass="1"/></body>
      </worldbody><equality><connect body1="a" body2="b" anchor="0 0 1"/><connect body1="a" body2="b" anchor="0 0 0.5"/>
      </equality></mujoco>"""
    imp = read_mjcf(text, "t.xml")
    model = load_model(imp.urdf)
    d = model.createData()
    pin.framesForwardKinematics(model, d, np.zeros(model.nq))
    assert [c.name for c in imp.closures] == ["connect1", "connect2"]
    for name, z in (("connect1_a", 1.0), ("connect2_a", 0.5)):
        assert np.abs(d.oMf[model.getFrameId(name)].translation - [0, 0, z]).max() <= TOL


#: Springs and dampers on a hinge (springref in degrees, a class's stiffness), a slide, an actuated hinge (its damping
#: is its drive's), a ball (not read) and a mimic follower (not read).
SPRINGS = """<mujoco model="springs">
  <compiler angle="{angle}"/>
  <default><default class="soft"><joint stiffness="7"/></default></default>
  <worldbody>
    <body name="a"><joint name="ja" axis="0 0 1" class="soft" springref="{ref}" damping="0.5"/>
      <geom type="sphere" size="0.05" mass="1"/>
      <body name="b" pos="0.2 0 0"><joint name="jb" type="slide" axis="1 0 0" stiffness="300" springref="0.05"/>
        <geom type="sphere" size="0.05" mass="1"/>
        <body name="c" pos="0.2 0 0"><joint name="jc" type="ball" stiffness="2"/><geom type="sphere" size="0.05" mass="1"/>
          <body name="d" pos="0.2 0 0"><joint name="jd" axis="0 1 0" damping="0.3"/><geom type="sphere" size="0.05" mass="1"/>
            <body name="e" pos="0.2 0 0"><joint name="je" axis="0 1 0" stiffness="4"/><geom type="sphere" size="0.05" mass="1"/>
            </body></body></body></body></body>
  </worldbody>
  <equality><joint joint1="je" joint2="jb"/></equality>
  <actuator><motor joint="jd"/></actuator>
</mujoco>"""


@pytest.mark.parametrize(("angle", "ref"), [("degree", "30"), ("radian", "0.5235987755982988")])
def test_joint_springs_are_read_as_mujoco_compiles_them(angle, ref):
    """``stiffness``, ``springref`` (degrees for a hinge unless radians) and a passive joint's ``damping`` are the
    ``[springs]`` entries, equal to MuJoCo's ``jnt_stiffness``, ``qpos_spring`` and ``dof_damping`` (1e-15); the
    actuated joint's damping stays its drive's; a ball's and a mimic follower's spring are named as not read."""
    text = SPRINGS.format(angle=angle, ref=ref)
    imp = read_mjcf(text, "springs.xml")
    assert set(imp.springs) == {"ja", "jb"} and imp.actuators["jd"]["viscous"] == 0.3
    assert any("not read: jc, je" in n for n in imp.notes) and any("[springs]" in n for n in imp.notes)
    mujoco, m = _mujoco_model(text)
    for name, spring in imp.springs.items():
        j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
        expected = {"stiffness": m.jnt_stiffness[j], "rest": m.qpos_spring[m.jnt_qposadr[j]],
                    "damping": m.dof_damping[m.jnt_dofadr[j]]}
        assert all(abs(spring.get(k, 0.0) - v) <= 1e-15 for k, v in expected.items()), name


#: A four-bar closed by a connect between two sites, each named as a body (and a joint) of the file: MJCF allows it.
SHARED_SITES = """<mujoco model="shared_names">
  <worldbody>
    <body name="crank"><joint name="crank" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 0.1" size="0.01"/>
      <body name="coupler" pos="0 0 0.1"><joint name="coupler" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.01"/><site name="rocker" pos="0.3 0 0"/></body></body>
    <body name="rocker" pos="0.3 0 0"><joint name="rocker" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 0.1" size="0.01"/><site name="coupler" pos="0 0 0.1"/></body>
  </worldbody>
  <equality><connect site1="rocker" site2="coupler"/></equality>
  <actuator><motor joint="crank"/></actuator>
</mujoco>"""


def test_a_closure_on_sites_named_as_bodies_closes_the_sites():
    """The closure's frames are the sites (frames of their own, a note says so), not the bodies of the same names
    (before: the bodies, 0.2 m apart: "cannot close"): at pkm's reference, MuJoCo puts the two sites together
    (1e-12) where pkm puts its frames."""
    from pkm.core.formats.load import load_texts

    imp = read_mjcf(SHARED_SITES, "shared.xml")
    assert [(c.frame_a, c.frame_b) for c in imp.closures] == [("rocker_site", "coupler_site")]
    assert any("rocker -> rocker_site" in n for n in imp.notes)
    mujoco, m = _mujoco_model(SHARED_SITES)
    mech = load_texts({"shared.xml": SHARED_SITES})
    d = mujoco.MjData(m)
    d.qpos[:] = [mech.q_reference[mech.joints[mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j)].idx_q]
                 for j in range(m.njnt)]
    mujoco.mj_kinematics(m, d)
    a, b = (d.site(n).xpos for n in ("rocker", "coupler"))
    assert np.abs(a - b).max() <= 1e-12
    pin.framesForwardKinematics(mech.model, mech.data, mech.q_reference)
    assert np.abs(mech.data.oMf[mech.frame_id("rocker_site")].translation - a).max() <= 1e-12
