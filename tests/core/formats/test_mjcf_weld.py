"""Every form of MJCF's ``<weld>`` (:func:`pkm.core.formats.mjcf._welds`): ``relpose`` (body2's pose in body1's
frame, position then quaternion ``w x y z``) between free bodies, ``anchor`` (the point of body2 where body1's
relpose frame sits), ``torquescale="0"`` (position only: a point closure). MuJoCo's weld holds
``X1 relpose = X2 T(anchor)``; checked against an independent composition of those poses and, where MuJoCo is
installed, against MuJoCo's own constraint residual (``efc_pos``) at pkm's closed configuration. Every model here is
written for these tests."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.formats.mjcf import read_mjcf
from pkm.core.kinematics.constraints import residual
from pkm.errors import SpecError, SpecNameError

TOL = 1e-10  # [m], [rad]: pkm's loop closure converges to 1e-12; the poses compose a few rotations

#: A crank on the world, and a lid (a free body, put anywhere by the file) welded to it by ``WELD``.
WELDED = """<mujoco model="welded">
  <worldbody>
    <body name="crank" pos="0 0 0.5">
      <joint name="crank_joint" type="hinge" axis="0 0 1"/>
      <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01" mass="0.3"/>
    </body>
    <body name="lid" pos="0.7 -0.3 0.1" quat="0.9 0.1 0.3 0.2">
      <freejoint name="lid_free"/>
      <geom type="box" size="0.05 0.04 0.03" mass="0.2"/>
    </body>
  </worldbody>
  <equality>WELD</equality>
  <actuator><motor joint="crank_joint"/></actuator>
</mujoco>"""
RELPOSE = '<weld name="w" body1="crank" body2="lid" relpose="0.2 0.05 0.1 0.8 0.2 -0.4 0.3" anchor="0.03 -0.02 0.01"/>'


def _relpose_world(q_crank: float) -> pin.SE3:
    """Where the weld puts the lid, composed independently: X_lid = X_crank relpose T(anchor)^-1."""
    crank = pin.SE3(pin.AngleAxis(q_crank, np.array([0.0, 0.0, 1.0])).matrix(), np.array([0.0, 0.0, 0.5]))
    w, x, y, z = np.array([0.8, 0.2, -0.4, 0.3]) / np.linalg.norm([0.8, 0.2, -0.4, 0.3])
    rel = pin.SE3(pin.Quaternion(w, x, y, z).matrix(), np.array([0.2, 0.05, 0.1]))
    return crank * rel * pin.SE3(np.eye(3), np.array([0.03, -0.02, 0.01])).inverse()


def _lid(mech: pkm.Mechanism, q: np.ndarray) -> pin.SE3:
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    return data.oMf[mech.model.getFrameId("lid", pin.FrameType.BODY)]


@pytest.fixture(scope="module")
def relpose(tmp_path_factory):
    path = tmp_path_factory.mktemp("weld") / "welded.xml"
    path.write_text(WELDED.replace("WELD", RELPOSE))
    return path, pkm.load(path)


def test_relpose_and_anchor_between_a_body_and_a_free_body(relpose):
    """A frame closure; assembled, and at a crank angle closed, the lid where relpose and anchor put it (1e-10)."""
    _, mech = relpose
    assert [(c.name, c.type) for c in mech.spec.closures] == [("w", "frame")] and mech.nv == 7
    for qa in (None, [0.4]):
        q = mech.q_reference if qa is None else pkm.close_loops(mech, qa).q
        crank = q[mech.joints["crank_joint"].idx_q]
        got, want = _lid(mech, q), _relpose_world(crank)
        assert np.allclose(got.translation, want.translation, atol=TOL)
        assert np.allclose(got.rotation, want.rotation, atol=TOL)


def test_mujoco_holds_pkms_closed_configuration(relpose):
    """MuJoCo's own weld residual (efc_pos of the equality rows, position and orientation) at pkm's closed q: 0."""
    mujoco = pytest.importorskip("mujoco")  # the bench extra: MuJoCo is the reference, not a dependency
    path, mech = relpose
    q = pkm.close_loops(mech, [0.4]).q
    mm = mujoco.MjModel.from_xml_path(str(path))
    md = mujoco.MjData(mm)
    lid = mech.joints["lid_free"].idx_q
    x, y, z, qx, qy, qz, qw = q[lid:lid + 7]
    md.qpos[mm.jnt_qposadr[mm.joint("crank_joint").id]] = q[mech.joints["crank_joint"].idx_q]
    md.qpos[mm.jnt_qposadr[mm.joint("lid_free").id]:][:7] = [x, y, z, qw, qx, qy, qz]  # (MuJoCo: w first)
    mujoco.mj_forward(mm, md)
    rows = md.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    assert rows.sum() == 6 and np.max(np.abs(md.efc_pos[rows])) < TOL


def test_torquescale_zero_is_a_point_closure_at_the_anchor(tmp_path):
    """``torquescale="0"``: the orientation left free, 3 equations; the anchor point meets the relpose point."""
    path = tmp_path / "point.xml"
    path.write_text(WELDED.replace("WELD", RELPOSE.replace("/>", ' torquescale="0"/>')))
    mech = pkm.load(path)
    assert [(c.name, c.type) for c in mech.spec.closures] == [("w", "point")]
    q = pkm.close_loops(mech, [0.4]).q
    crank, lid = _relpose_world(q[mech.joints["crank_joint"].idx_q]), _lid(mech, q)
    anchor = lid * pin.SE3(np.eye(3), np.array([0.03, -0.02, 0.01]))
    assert np.allclose(anchor.translation, (crank * pin.SE3(np.eye(3), np.array([0.03, -0.02, 0.01]))).translation,
                       atol=TOL)


def test_without_relpose_the_pose_at_qpos0_is_kept_with_the_anchor(tmp_path):
    """No relpose: the lid welded where the file puts it (the reference is closed as it stands: 1e-12)."""
    path = tmp_path / "qpos0.xml"
    path.write_text(WELDED.replace("WELD", '<weld body1="crank" body2="lid" anchor="0.1 0 0"/>'))
    imp = read_mjcf(path.read_text(), str(path))
    assert [(c.name, c.type) for c in imp.closures] == [("weld1", "frame")]
    mech = pkm.load(path)
    assert np.max(np.abs(residual(mech, mech.q_reference))) < 1e-12
    lid = _lid(mech, mech.q_reference)
    assert np.allclose(lid.translation, [0.7, -0.3, 0.1], atol=TOL)


def test_bad_welds_name_the_element_and_line(tmp_path):
    """A missing body, a negative torquescale, a relpose of 4 numbers: SpecErrors naming the file and element."""
    with pytest.raises(SpecNameError, match=r"body 'nobody' does not exist in bad.xml \(<equality><weld "
                                            r"name='w'> \(line 13\) body2\); valid bodies: 'crank', 'lid'"):
        read_mjcf(WELDED.replace("WELD", '\n<weld name="w" body1="crank" body2="nobody"/>'), "bad.xml")
    with pytest.raises(SpecError, match=r"bad.xml: <equality><weld name='w'> \(line 12\) torquescale = -1"):
        read_mjcf(WELDED.replace("WELD", '<weld name="w" body1="crank" body2="lid" torquescale="-1"/>'), "bad.xml")
    with pytest.raises(SpecError, match=r"bad.xml: .*<equality><weld name='w'> \(line 12\) relpose"):
        read_mjcf(WELDED.replace("WELD", '<weld name="w" body1="crank" body2="lid" relpose="0 0 0 1"/>'), "bad.xml")
