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
from pkm.core.model.joints import stated_limits
from pkm.core.transmissions.limits import output_limits
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
    assert region.points_checked == 4 + 4 * 4
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


def test_the_welded_bodies_keep_the_whole_robots_mass_and_each_output_its_transmissions_inertia():
    """battobot: the rods, cranks and motor bodies welded to their parents at the reference, not deleted (0.76 kg,
    4.4 % of the robot, were): the serial model's mass and centre of mass at the reference are the closed robot's
    to 1e-12; and each transmission's outputs carry in it what its ``M_s`` says (its diagonal plus the constant
    armature: Pinocchio's CRBA adds the armature), the convention ``ΔM`` completes."""
    bot = robot("battobot_6d")
    se = serial_equivalent(bot, transmissions("battobot_6d"), limits=False)
    mass = pin.computeTotalMass(bot.model)
    assert abs(pin.computeTotalMass(se.model) - mass) <= 1e-12 * mass
    com = pin.centerOfMass(bot.model, bot.model.createData(), bot.q_reference)
    com_serial = pin.centerOfMass(se.model, se.model.createData(), se.q_reference)
    assert np.abs(com_serial - com).max() <= 1e-12 * bot.characteristic_length
    M = pin.crba(se.model, se.model.createData(), se.q_reference)
    M = np.triu(M) + np.triu(M, 1).T
    for t in se.transmissions:
        idx = [se.model.joints[se.model.getJointId(o)].idx_v for o in t.outputs]
        M_s = t.serial_model(t.q_reference, np.zeros(t.k))[0]
        expected = M_s + np.diag([se.armature[o] for o in t.outputs])
        np.testing.assert_allclose(M[np.ix_(idx, idx)], expected, rtol=0, atol=1e-12 * np.abs(M_s).max())


def _largest_raster_box(polygon: np.ndarray, point: np.ndarray, n: int = 81) -> float:
    """The largest area of an axis-aligned box of grid cells inside ``polygon`` (every cell centre in it, even-odd
    rule) that holds the cell of ``point``: a brute force over the pairs of columns about the point, the rows
    grown from its row while every cell of the span is inside (an independent route to the largest box)."""
    lo, hi = polygon.min(axis=0), polygon.max(axis=0)
    xs, ys = (np.linspace(lo[i], hi[i], n) for i in (0, 1))
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    inside = np.zeros(X.shape, dtype=bool)
    for (x1, y1), (x2, y2) in zip(polygon, np.roll(polygon, -1, axis=0)):
        crosses = (y1 > Y) != (y2 > Y)
        with np.errstate(divide="ignore", invalid="ignore"):
            inside ^= crosses & (X < x1 + (Y - y1) * (x2 - x1) / (y2 - y1))
    i0, j0 = int(np.argmin(np.abs(xs - point[0]))), int(np.argmin(np.abs(ys - point[1])))
    cell = (xs[1] - xs[0]) * (ys[1] - ys[0])
    best = 0.0
    for a in range(i0 + 1):
        for b in range(i0, n):
            rows = inside[a:b + 1].all(axis=0)
            if not rows[j0]:
                continue
            down = j0 - next((j for j in range(j0, -1, -1) if not rows[j]), -1)
            up = next((j for j in range(j0, n) if not rows[j]), n) - j0
            best = max(best, (b - a) * (up + down - 2) * cell)
    return best


@pytest.mark.parametrize("ankle", ["foot_assembly", "foot_assembly_2"])
def test_each_battobot_ankles_box_is_the_largest_its_region_holds_about_the_reference(ankle):
    """The box was centred on the reference in the polygon's proportions (left ankle 1.7° x 3.0°, the reference
    1.9° from the region's edge): it is now the largest box that holds the reference, at least 90 % of the largest
    one a brute force over grid cells finds in the same traced region, its area stated against the region's; a grid
    of points over it (edges and inside) solved by inverse kinematics lies within every joint's limits."""
    t = next(x for x in transmissions("battobot_6d") if x.name == ankle)
    reg = output_limits(t, directions=8, steps=5, tol=1e-4)
    ref = t.q_reference[t.out_q]
    area = float(np.prod(reg.upper - reg.lower))
    assert np.all(reg.lower <= ref) and np.all(ref <= reg.upper) and np.array_equal(reg.around, ref)
    assert area >= 0.9 * _largest_raster_box(reg.polygon, ref)
    region = Region(t.outputs, {}, ref, reg.polygon, reg.binding, np.zeros(0), 1e-2)
    assert reg.area_fraction == pytest.approx(area / region.area, rel=1e-12)
    assert area >= (np.radians(15.0) * np.radians(23.0))  # (the issue's boxes: 1.7° x 3.0°, 5.8° x 7.6°)
    lo, hi = (np.array(x) for x in stated_limits(t.mechanism.model))
    q = t.q_reference
    for a in np.linspace(0.0, 1.0, 4):
        for b in np.linspace(0.0, 1.0, 4):
            _, q = t.motors_from_outputs(reg.lower + np.array([a, b]) * (reg.upper - reg.lower), q)
            assert np.all(q >= lo - 1e-9) and np.all(q <= hi + 1e-9)


def test_a_small_box_is_said_and_a_point_outside_the_region_or_no_output_refused(monkeypatch):
    """The humanoid knee's interval (the whole traced one: its share 1): under a bound of SMALL_BOX above 1 the
    warning names the share; ``around`` outside the interval, or naming no output, is refused."""
    t = transmissions("humanoid_knee")[0]
    monkeypatch.setattr("pkm.core.transmissions.limits.SMALL_BOX", 1.5)
    with pytest.warns(pkm.errors.PkmWarning, match=r"'shank': its box limits hold 100 % of the length"):
        reg = output_limits(t, steps=4, tol=1e-4)
    assert reg.area_fraction == pytest.approx(1.0, abs=1e-5) and reg.points_checked == 3
    with pytest.raises(pkm.errors.InvalidInputError, match="outside its feasible interval"):
        output_limits(t, around=[reg.upper[0] + 0.1], steps=4, tol=1e-4)
    with pytest.raises(pkm.errors.InvalidInputError, match=r"\['nope'\] are no outputs"):
        serial_equivalent(robot("humanoid_knee"), [t], around={"nope": 0.1})


def test_a_kept_joint_s_spring_is_written_and_a_locked_one_s_said():
    """Springs (``[springs]``) on an output (kept: its MJCF ``stiffness``, ``springref``, ``damping``, as MuJoCo
    compiles them, 1e-15) and on a motor (locked in the serial model: a warning names it, its effort is the kernels'
    Δh, not the files')."""
    import dataclasses

    bot = robot("humanoid_ankle")
    springs = {"ankle_pitch": {"stiffness": 11.0, "rest": -0.05, "damping": 0.3}, "motor_left": {"stiffness": 2.0}}
    sprung = pkm.from_strings(bot.urdf, dataclasses.replace(bot.spec, springs=springs))
    with pytest.warns(pkm.errors.PkmWarning, match=r"springs of \['motor_left'\] \(locked"):
        se = serial_equivalent(sprung, transmissions("humanoid_ankle"), limits=False)
    text = se.mjcf()
    assert text.count("stiffness=") == 1 and 'springref="-0.05"' in text and 'damping="0.3"' in text
    mujoco = pytest.importorskip("mujoco")
    m = mujoco.MjModel.from_xml_string(text)
    j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "ankle_pitch")
    assert (m.jnt_stiffness[j], m.qpos_spring[m.jnt_qposadr[j]], m.dof_damping[m.jnt_dofadr[j]]) == (11.0, -0.05, 0.3)
    from pkm.core.formats.imported import read_urdf

    urdf = se.urdf()  # (Gazebo's URDF extension: pkm's URDF reader gives it back, Pinocchio the damping)
    assert read_urdf(urdf, "serial.urdf").springs == {"ankle_pitch": {"stiffness": 11.0, "rest": -0.05}}
    model = pin.buildModelFromXML(urdf)
    assert model.damping[model.joints[model.getJointId("ankle_pitch")].idx_v] == 0.3
