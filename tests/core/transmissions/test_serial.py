"""The serial-equivalent model and its files: the exported URDF loads in Pinocchio and the MJCF in MuJoCo, each
giving back the serial model's mass matrix in the outputs (the massless-rod tree of the transmission, an independent
route: the files are read by the two libraries' own parsers); the box limits' corners are feasible by inverse
kinematics and the box lies inside the feasible region; the data file describes each transmission."""

from __future__ import annotations

import json
import pickle

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.analysis.region import Region, _feasible
from pkm.core.transmissions.serial import serial_equivalent, write_serial_equivalent
from tests.core.transmissions.robots import robot, transmissions


@pytest.fixture(scope="module")
def ankle_files(tmp_path_factory):
    se = serial_equivalent(robot("humanoid_ankle"), transmissions("humanoid_ankle"), directions=8)
    return se, write_serial_equivalent(se, tmp_path_factory.mktemp("serial"))


def test_the_urdf_loads_in_pinocchio_with_the_serial_models_inertia(ankle_files):
    se, (urdf, *_) = ankle_files
    (t,) = se.transmissions
    model = pin.buildModelFromUrdf(str(urdf))
    assert [model.names[j] for j in range(1, model.njoints)] == list(t.outputs)  # (the rods are gone)
    M = pin.crba(model, model.createData(), se.q_reference)
    M = np.triu(M) + np.triu(M, 1).T
    M_s = t.serial_model(t.q_reference, np.zeros(2))[0]
    np.testing.assert_allclose(M, M_s, rtol=0, atol=1e-12 * np.abs(M_s).max())
    np.testing.assert_allclose(model.lowerPositionLimit, [se.limits[o][0] for o in t.outputs], rtol=0, atol=1e-12)


def test_the_mjcf_loads_in_mujoco_with_the_constant_armature(ankle_files):
    mujoco = pytest.importorskip("mujoco")  # the bench extra: MuJoCo reads the file, not a dependency
    se, (_, xml, *_) = ankle_files
    (t,) = se.transmissions
    m = mujoco.MjModel.from_xml_path(str(xml))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    M = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, M)
    dM = t.delta_mass(t.q_reference)
    M_s = t.serial_model(t.q_reference, np.zeros(2))[0]
    np.testing.assert_allclose(M, M_s + np.diag(np.diag(dM)), rtol=0, atol=1e-12 * np.abs(M_s).max())
    np.testing.assert_allclose(m.jnt_range, [se.limits[o] for o in t.outputs], rtol=0, atol=1e-12)
    assert m.nu == 2


def test_the_box_lies_inside_the_feasible_region_every_corner_checked(ankle_files):
    se, (*_, data) = ankle_files
    (t,) = se.transmissions
    region = se.regions[t.name]
    assert region.corners_checked == 4
    lo, hi = region.lower, region.upper
    sub = t.mechanism
    bounds = np.array(sub.model.lowerPositionLimit), np.array(sub.model.upperPositionLimit)
    for corner in ((lo[0], lo[1]), (lo[0], hi[1]), (hi[0], lo[1]), (hi[0], hi[1])):
        assert _feasible(sub, dict(zip(t.outputs, corner)), t.q_reference, *bounds, 1e-2)[0] is not None
    polygon = Region(t.outputs, {}, t.q_reference[t.out_q], region.polygon, region.binding, np.zeros(0), 1e-2)
    assert all(polygon.contains(c) for c in (lo, hi, (lo[0], hi[1]), (hi[0], lo[1])))
    content = json.loads(data.read_text())
    assert content["transmissions"][0]["motors"] == ["motor_left", "motor_right"]
    assert content["transmissions"][0]["armature"] == pytest.approx(np.diag(t.delta_mass(t.q_reference)), abs=0)
    assert content["files"]["mjcf"].endswith("_serial.xml")


def test_each_sub_mechanism_is_written_loads_back_the_same_and_pickles(ankle_files):
    se, (*_, sub_urdf, sub_spec, data) = ankle_files
    (t,) = se.transmissions
    assert json.loads(data.read_text())["transmissions"][0]["files"] == {"urdf": sub_urdf.name, "spec": sub_spec.name}
    (back,) = pkm.transmissions(pkm.load(sub_spec))
    assert (back.motors, back.outputs) == (t.motors, t.outputs)
    np.testing.assert_allclose(back.delta_mass(back.q_reference), t.delta_mass(t.q_reference), rtol=1e-12)
    again = pickle.loads(pickle.dumps(t))
    np.testing.assert_allclose(again.velocity_map(t.q_reference), t.velocity_map(t.q_reference), rtol=1e-14)
