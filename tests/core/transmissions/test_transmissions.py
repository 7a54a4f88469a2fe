"""pkm.transmissions: the decomposition's rules on whole robots of every format, the maps of each transmission
against independent routes, and the refusals.

Checked on every transmission of :data:`tests.core.transmissions.robots.ROBOTS`, at the reference and at a state
moved from it:

* motors -> outputs -> motors to 1e-12 [rad or m] (the loop closure, then the inverse kinematics seeded at the
  reference);
* the velocity map against Richardson differences of the forward position map (1e-7 relative), and the effort map,
  computed with the outputs independent, equal to the velocity map's transpose, computed with the motors
  independent (1e-12 relative; ``1e-14 ‖Ĝ‖`` where the joints move more than 100 times faster than the outputs,
  the round-off of either route growing with ``‖Ĝ‖``: talos_like's rods, each three revolutes, sit 4e-4 rad from
  their gimbal lock at its reference, ``‖Ĝ‖`` = 3890, the error 3.6e-12, as between pkm's own forward and inverse
  Jacobians there, 2.6e-12);
* serial model + ΔM + Δh = the closed-loop model in output coordinates, and that model, mapped by the velocity map,
  equal to pkm's actuator-space model (``pkm.mass_matrix = Jᵀ M_o J``, ``pkm.bias_efforts = Jᵀ (h_o + M_o J̇ ṁ)``):
  1e-10 relative;
* ``Ġ ȯ`` against Richardson differences of ``Ĝ ȯ`` along the motion, on the mechanisms without idle motions.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.transmissions.coordinates import drift_acceleration, output_rates, output_split
from pkm.core.transmissions.serial import serial_equivalent
from pkm.errors import TransmissionError, UnknownNameError
from tests.core.transmissions.robots import FILES, ROBOTS, robot, transmissions
from tests.fd import rel, richardson

#: What the rules choose, written from each file's structure: (name, root, motors, outputs) per transmission.
EXPECTED = {
    "humanoid_ankle": [("foot", "world", ("motor_left", "motor_right"), ("ankle_pitch", "ankle_roll"))],
    "humanoid_knee": [("shank", "thigh", ("knee_motor",), ("knee",))],
    "slider_crank": [("slider", "frame", ("crank_joint",), ("rail",))],
    "ankle": [("foot", "shank", ("motor_left", "motor_right"), ("ankle_pitch", "ankle_roll"))],
    "knee": [("back_link", "shank", ("knee_front",), ("knee_back",))],
    "battobot_6d": [  # (two legs, each a knee four-bar and a two-motor ankle; the knee carries the rest of the leg)
        ("shin_assembly_sym", "tigh_assembly_sym", ("motor_knee_left",), ("knee_left",)),
        ("shin_assembly", "tigh_assembly", ("motor_knee_right",), ("knee_right",)),
        ("foot_assembly", "shin_assembly", ("motor_ankle1_right", "motor_ankle2_right"),
         ("ankley_right", "anklex_right")),
        ("foot_assembly_2", "shin_assembly_sym", ("motor_ankle1_left", "motor_ankle2_left"),
         ("ankley_left", "anklex_left"))],
    "talos_like": [("ankle", "knee", ("motor_shin",), ("free_ankle",))],
    "cassie_like": [("foot_2", "tarsus", ("motor_ankle",), ("free_ankle",))],
    "digit_like": [("foot_part", "tarsus", ("motor_shin1", "motor_shin2"), ("free_foot1", "free_foot2"))],
}


@pytest.mark.parametrize("name", ROBOTS)
def test_the_rules_find_each_robots_transmissions(name):
    found = transmissions(name)
    assert [(t.name, t.root, t.motors, t.outputs) for t in found] == EXPECTED[name]
    mech = robot(name)
    for t in found:  # motors, outputs and passive joints partition the sub-mechanism's joints
        assert set(t.mechanism.joints) == {*t.motors, *t.outputs, *t.passive}
        assert set(t.motors) <= set(mech.actuated_names)
        assert list(t.mechanism.actuators) == [a for a in mech.actuators if a.joint in t.motors]  # (rotors kept)
        sub = t.mechanism  # (written as URDF and read back: every closure frame where the robot has it)
        pin.framesForwardKinematics(mech.model, mech.data, mech.q_reference)
        pin.framesForwardKinematics(sub.model, sub.data, t.q_reference)
        for fa, fb in sub.closure_frames:
            for f in (fa, fb):
                here, there = sub.data.oMf[f], mech.data.oMf[mech.frame_id(sub.model.frames[f].name)]
                assert np.abs(here.homogeneous - there.homogeneous).max() <= 1e-12
        np.testing.assert_array_equal(  # the sub-mechanism sits where the robot's reference puts it
            [t.q_reference[t.mechanism.joints[n].idx_q] for n in t.outputs],
            [mech.q_reference[mech.joints[n].idx_q] for n in t.outputs])


def _moved(t: pkm.Transmission, rng: np.random.Generator) -> np.ndarray:
    qm = t.mechanism.actuated_q(t.q_reference) + rng.uniform(-0.02, 0.02, t.k)
    return t.outputs_from_motors(qm)[1]


def _forward_differences(t: pkm.Transmission, q: np.ndarray) -> np.ndarray:
    """``∂o/∂m`` by Richardson differences of the forward position map."""
    qm = t.mechanism.actuated_q(q)

    def column(e: np.ndarray) -> np.ndarray:
        return richardson(lambda h: (t.outputs_from_motors(qm + h * e, q)[0]
                                     - t.outputs_from_motors(qm - h * e, q)[0]) / (2 * h), 1e-5)

    return np.column_stack([column(e) for e in np.eye(t.k)])


@pytest.mark.parametrize("name", ROBOTS)
def test_the_maps_agree_with_independent_routes(name):
    rng = np.random.default_rng(7)
    for t in transmissions(name):
        sub = t.mechanism
        mass = pin.computeTotalMass(sub.model)  # (the other joints welded: the sub-mechanism's mass kept, the root's
        com = pin.centerOfMass(sub.model, sub.model.createData(), t.q_reference)  # share on the universe, index 0)
        data = t.serial.createData()
        pin.forwardKinematics(t.serial, data, t.q_reference)
        welded = [(I.mass, data.oMi[j].act(I.lever)) for j, I in enumerate(t.serial.inertias)]
        assert abs(sum(m for m, _ in welded) - mass) <= 1e-12 * mass
        assert np.abs(sum(m * c for m, c in welded) / mass - com).max() <= 1e-12 * sub.characteristic_length
        for q in (t.q_reference, _moved(t, rng)):
            qm = sub.actuated_q(q)
            qo, q1 = t.outputs_from_motors(qm, q)
            qm_back, _ = t.motors_from_outputs(qo)
            assert np.abs(qm_back - qm).max() <= 1e-12, t.name
            J = t.velocity_map(q1)
            amplification = np.linalg.norm(output_split(sub, q1, t.out_v, sub.act_v).G, 2)  # (joint per output rate)
            assert rel(t.effort_map(q1), J.T) <= max(1e-12, 1e-14 * amplification), t.name
            assert rel(t.inverse_effort_map(q1) @ t.effort_map(q1), np.eye(t.k)) <= 1e-12
            assert rel(J, _forward_differences(t, q1)) <= 1e-7, t.name
            qd_m = rng.normal(size=t.k)
            qd_o = J @ qd_m
            M_o, h_o = t.output_model(q1, qd_o)
            M_s, h_s = t.serial_model(q1, qd_o)
            dM, dh = t.delta_mass(q1), t.delta_bias(q1, qd_o)
            np.testing.assert_allclose(M_s + dM, M_o, rtol=0, atol=1e-14 * np.abs(M_o).max())
            np.testing.assert_allclose(h_s + dh, h_o, rtol=0, atol=1e-14 * np.abs(h_o).max())
            M_a = pkm.mass_matrix(sub, q1)
            assert rel(J.T @ (M_s + dM) @ J, M_a) <= 1e-10, t.name
            v = pkm.velocities(sub, q1, qd_m)
            od_b = pkm.accelerations(sub, q1, v, np.zeros(t.k))[t.out_v]  # (J̇ ṁ: the outputs at no motor acceleration)
            assert rel(J.T @ (h_s + dh + (M_s + dM) @ od_b), pkm.bias_efforts(sub, q1, qd_m)) <= 1e-10, t.name


@pytest.mark.parametrize("name", ["humanoid_knee", "slider_crank"])
def test_the_drift_acceleration_is_the_derivative_of_the_joint_rates_along_the_motion(name):
    t = transmissions(name)[0]
    sub = t.mechanism
    q = _moved(t, np.random.default_rng(3))
    qd_o = np.array([0.7])
    qo = q[t.out_q]

    def rates(s: float) -> np.ndarray:
        qs = t.motors_from_outputs(qo + s * qd_o, q)[1]
        return output_split(sub, qs, t.out_v, sub.act_v).G @ qd_o

    fd = richardson(lambda h: (rates(h) - rates(-h)) / (2 * h), 1e-4)
    sp = output_split(sub, q, t.out_v, sub.act_v)
    assert sp.idle.shape[1] == 0
    assert rel(drift_acceleration(sub, q, sp.G @ qd_o, sp, t.out_v), fd) <= 1e-7


@pytest.mark.parametrize("name", ["humanoid_ankle", "humanoid_knee"])
def test_output_rates_are_the_splits_rates_to_the_last_bit(name):
    """``Ĝ`` alone (the fidelity runs' effort map) is the full split's, bitwise: with idle motions removed in the mass
    metric (the ankle's rods spin between their balls) and without (the knee)."""
    t = transmissions(name)[0]
    sub = t.mechanism
    q = _moved(t, np.random.default_rng(4))
    sp = output_split(sub, q, t.out_v, sub.act_v)
    assert sp.idle.shape[1] == (2 if name == "humanoid_ankle" else 0)
    assert np.array_equal(output_rates(sub, q, t.out_v), sp.G)


def test_named_outputs_name_the_transmission_and_bad_ones_are_refused():
    knee = robot("humanoid_knee")
    (t,) = pkm.transmissions(knee, {"left_knee": ["knee"]})
    assert (t.name, t.outputs) == ("left_knee", ("knee",))
    ankle = robot("humanoid_ankle")
    with pytest.raises(TransmissionError, match="2 motors") as err:  # (wrong count)
        pkm.transmissions(ankle, {"left_ankle": ["ankle_pitch"]})
    assert (err.value.transmission, err.value.reason, err.value.joints) == ("left_ankle", "outputs", ("ankle_pitch",))
    with pytest.raises(TransmissionError, match="hangs below 'knee_motor'"):  # (not a serial chain)
        pkm.transmissions(knee, {"k": ["rod_top"]})
    with pytest.raises(UnknownNameError, match="did you mean 'knee'"):
        pkm.transmissions(knee, {"k": ["kne"]})
    five = pkm.load(FILES["ankle"].parents[1] / "gepetto_fivebar")
    with pytest.raises(TransmissionError, match="no one-coordinate serial joint") as err:  # (a frame's output)
        pkm.transmissions(five)
    assert err.value.reason == "outputs" and set(err.value.joints) == set(five.actuated_names)


def test_outputs_singular_at_the_reference_are_refused():
    crank = pkm.load(FILES["slider_crank"])
    crank.q_reference = pkm.close_loops(crank, [0.0]).q  # (the dead centre: the slider's travel has zero slope)
    with pytest.raises(TransmissionError, match="singular at the reference") as err:
        pkm.transmissions(crank)
    assert (err.value.transmission, err.value.reason, err.value.joints) == ("slider", "singular", ("rail",))
    assert err.value.value > 1e-3


def test_a_sub_mechanism_whose_chain_outnumbers_its_motors_is_refused_or_left_out():
    cassie = robot("cassie_like")  # (the knee motor and the passive tarsus joint both carry the foot)
    with pytest.raises(TransmissionError, match=r"\['motor_knee', 'free_knee'\] carry the rest of the robot.*1 "
                       r"motor.*no choice of outputs.*skip_unfit=True \(pkm transmission --skip-unfit\)"):
        pkm.transmissions(cassie)
    with pytest.raises(TransmissionError, match="no choice of outputs"):  # (naming outputs changes nothing)
        pkm.transmissions(cassie, {"tarsus": ["motor_knee"]})
    with pytest.warns(pkm.errors.PkmWarning, match="'tarsus'.*left out"):
        (ankle,) = pkm.transmissions(cassie, skip_unfit=True)
    assert (ankle.name, ankle.motors, ankle.outputs) == ("foot_2", ("motor_ankle",), ("free_ankle",))
    with pytest.raises(pkm.errors.InvalidInputError, match=r"closures \['loop2'\] belong to no transmission"):
        serial_equivalent(cassie, [ankle], limits=False)


def test_the_spec_names_a_transmission_and_its_outputs(tmp_path):
    folder = FILES["humanoid_knee"].parent
    (tmp_path / "knee.urdf").write_text((folder / "knee.urdf").read_text())
    spec = FILES["humanoid_knee"].read_text() + '\n[transmission.left_knee]\noutputs = ["knee"]\n'
    (tmp_path / "knee.closures.toml").write_text(spec)
    knee = pkm.load(tmp_path / "knee.closures.toml")
    assert knee.spec.transmissions == {"left_knee": ("knee",)}
    assert pkm.ClosureSpec.from_toml(knee.spec.to_toml()).transmissions == {"left_knee": ("knee",)}
    assert [(t.name, t.outputs) for t in pkm.transmissions(knee)] == [("left_knee", ("knee",))]
    with pytest.raises(pkm.errors.SpecError, match=r"\[transmission.k\] must hold one key"):
        pkm.ClosureSpec.from_toml(spec.replace("left_knee]\noutputs", "k]\nout"))


def test_a_floating_base_is_held_at_the_reference_in_the_sub_mechanism(tmp_path):
    folder = FILES["humanoid_knee"].parent
    tilt = [0.1, 0.2, 1.0, 0.0, float(np.sin(np.pi / 8)), 0.0, float(np.cos(np.pi / 8))]  # (pitched 45 degrees)
    (tmp_path / "knee.urdf").write_text((folder / "knee.urdf").read_text().replace(
        '<robot name="humanoid_knee">', '<robot name="humanoid_knee">\n  <link name="world"/>\n  <joint name="pelvis" '
        'type="floating"><parent link="world"/><child link="thigh"/></joint>'))
    (tmp_path / "knee.closures.toml").write_text(FILES["humanoid_knee"].read_text().replace(
        'urdf = "knee.urdf"', 'urdf = "knee.urdf"\nfloating_base = "pelvis"').replace(
        "knee = [0.8]", f"knee = [0.8]\npelvis = {tilt}"))
    (t,) = pkm.transmissions(pkm.load(tmp_path / "knee.closures.toml"))
    (fixed,) = transmissions("humanoid_knee")
    assert (t.name, t.root, t.outputs) == (fixed.name, fixed.root, fixed.outputs) and "pelvis" not in t.mechanism.joints
    np.testing.assert_allclose(t.delta_mass(t.q_reference), fixed.delta_mass(fixed.q_reference), rtol=1e-12)
    g_tilted, g_upright = t.delta_bias(t.q_reference, [0.0]), fixed.delta_bias(fixed.q_reference, [0.0])
    assert abs(g_tilted[0] - g_upright[0]) > 1e-3 * abs(g_upright[0])  # (gravity as the tilted pelvis sees it)


def test_a_robot_with_no_transmission_is_refused():
    disney = pkm.load("gepetto:disney_like")  # (one sub-mechanism of five motors, its outputs singular)
    with pytest.warns(pkm.errors.PkmWarning, match="singular at the reference.*left out"):
        with pytest.raises(TransmissionError, match="no closed sub-mechanism that is a transmission") as err:
            pkm.transmissions(disney, skip_unfit=True)
    assert (err.value.transmission, err.value.reason) == ("disney_like", "no_loop")


def test_maps_in_output_coordinates_refuse_a_state_where_the_outputs_are_singular():
    """Away from the reference too: at the slider-crank's dead centre the slider held leaves the crank free, so no
    map or model in output coordinates exists there; each raises (before: a least-squares answer, no word)."""
    crank = pkm.load(FILES["slider_crank"])
    (t,) = pkm.transmissions(crank)
    dead = t.outputs_from_motors([0.0])[1]
    for call in (t.inverse_effort_map, t.effort_map, t.delta_mass, lambda q: t.delta_bias(q, [0.1])):
        with pytest.raises(pkm.errors.SingularityError, match="do not determine the sub-mechanism") as err:
            call(dead)
        assert err.value.kind == "outputs" and err.value.distance > 1e-3
    t.inverse_effort_map(t.q_reference)  # (the same transmission at its reference: a map)
