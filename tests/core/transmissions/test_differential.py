"""A differential (issue 51: motors on fixed tendons, ``[motors]``: ``u = C q_a``) as a transmission with constant
maps, through the same outputs as a closed loop's: on ``data/coupled.xml``'s waist (two tendon motors, ``yaw + roll``
and ``yaw - roll``) against the whole robot's motor map (:func:`pkm.motor_values`, :func:`pkm.motor_efforts`, read
from MuJoCo's tendons: tests/core/formats/test_mjcf_couplings.py) and finite differences, its kernels in process and
as the exported C; a differential on a closed ankle's two motors (the maps composed with ``C``) against finite
differences of its own position map; a differential across a loop and a serial joint refused."""

from __future__ import annotations

import dataclasses
import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm import cli
from pkm.core.transmissions.kernels import TransmissionKernels
from pkm.core.transmissions.targets import write_transmission
from pkm.errors import PkmWarning, TransmissionError
from tests.core.transmissions.robots import robot

XML = Path(__file__).parents[1] / "formats" / "data" / "coupled.xml"
GEAR = '<joint name="neck_gear" joint1="right_neck" joint2="left_neck" polycoef="0 1 0 0 0"/>'


@pytest.fixture(scope="module")
def coupled(tmp_path_factory) -> pkm.Mechanism:
    """``coupled.xml`` without its neck gear (a mimic joint the sub-mechanism's URDF cannot hold): a neck loop of one
    motor and the waist differential."""
    path = tmp_path_factory.mktemp("coupled") / "coupled.xml"
    path.write_text(XML.read_text().replace(GEAR, ""), encoding="utf-8")
    return pkm.load(path)


@pytest.fixture(scope="module")
def waist(coupled) -> pkm.Transmission:
    head, waist = pkm.transmissions(coupled)
    assert (head.name, head.motors, head.outputs, head.constant) == ("head", ("left_neck",), ("neck_pitch",), False)
    return waist


def _whole(mech: pkm.Mechanism, t: pkm.Transmission, q_sub: np.ndarray) -> np.ndarray:
    """The whole robot at its reference with the differential's joints as in ``q_sub``."""
    values = dict(zip(t.drives, q_sub[[t.mechanism.joints[d].idx_q for d in t.drives]]))
    return mech.with_actuated(mech.q_reference, [values.get(n, v) for n, v in
                                                 zip(mech.actuated_names, mech.actuated_q(mech.q_reference))])


def test_a_differential_is_a_transmission_with_constant_maps(coupled, waist):
    """Its motors are the tendons' (names and map, not joints); motors -> outputs -> motors to 1e-15; the motors'
    coordinates at ``fk``'s outputs are the whole robot's :func:`pkm.motor_values` (MuJoCo's tendon lengths) to 1e-15;
    ``J`` central differences of ``fk`` (1e-9) and ``C⁻¹``, the same at two configurations; the effort maps ``Jᵀ`` and
    ``J⁻ᵀ`` the whole robot's :func:`pkm.motor_efforts` and :func:`pkm.joint_efforts` (1e-14); ``ΔM = 0``,
    ``Δh = 0`` (nothing welded)."""
    t, C = waist, np.array([[1.0, 1.0], [1.0, -1.0]])
    assert (t.name, t.root, t.motors, t.drives, t.outputs, t.passive, t.constant) == (
        "torso", "pelvis", ("waist_left_motor", "waist_right_motor"), ("waist_yaw", "waist_roll"),
        ("waist_yaw", "waist_roll"), (), True)
    np.testing.assert_array_equal(t.motor_matrix, C)
    rng = np.random.default_rng(3)
    Js = []
    for u in rng.uniform(-0.4, 0.4, (2, 2)):
        qo, q = t.outputs_from_motors(u)
        assert np.abs(t.motors_from_outputs(qo, q)[0] - u).max() <= 1e-15
        assert np.abs(pkm.motor_values(coupled, _whole(coupled, t, q))[:2] - u).max() <= 1e-15
        h = 1e-6
        fd = np.array([(t.outputs_from_motors(u + h * e)[0] - t.outputs_from_motors(u - h * e)[0]) / (2 * h)
                       for e in np.eye(2)]).T
        J = t.velocity_map(q)
        assert np.abs(J - fd).max() <= 1e-9 and np.abs(J - np.linalg.inv(C)).max() <= 1e-15
        assert np.abs(t.inverse_velocity_map(q) @ J - np.eye(2)).max() <= 1e-15
        tau_o = rng.uniform(-5.0, 5.0, 2)
        tau_a = np.zeros(coupled.na)
        tau_a[:2] = tau_o  # (the drives are the whole robot's first actuated joints)
        assert np.abs(t.effort_map(q) - J.T).max() <= 1e-15
        assert np.abs(t.effort_map(q) @ tau_o - pkm.motor_efforts(coupled, tau_a)[:2]).max() <= 1e-14
        tau_m = t.effort_map(q) @ tau_o
        assert np.abs(t.inverse_effort_map(q) @ tau_m - tau_o).max() <= 1e-14
        assert np.abs(pkm.joint_efforts(coupled, np.r_[tau_m, 0.0, 0.0])[:2] - tau_o).max() <= 1e-14
        assert not t.delta_mass(q).any() and not t.delta_bias(q, rng.uniform(-2, 2, 2)).any()
        Js.append(J)
    assert np.array_equal(Js[0], Js[1])


def test_its_kernels_are_the_python_route_in_process_and_in_the_exported_c(waist, tmp_path):
    """The kernels (compiled in process) equal the Python route to 1e-15 (``fk``, ``ik`` in the motors' coordinates,
    ``maps`` ``C⁻¹`` and ``C``, ``delta`` zero); the exported C (gcc -std=c99 -Wall -Werror) names the motors and
    their map (``motor_names``, ``drive_names``, ``motor_map``), and its ``fk`` and ``ik`` are the kernels'."""
    t = waist
    tk = TransmissionKernels.of(t)
    u = np.array([0.3, -0.1])
    qo, q = t.outputs_from_motors(u)
    q_out, y, status, _ = tk.run("fk", t.q_reference, u)
    assert status[0] == 0 and np.abs(y - qo).max() <= 1e-15 and np.abs(q_out - q).max() <= 1e-15
    _, m, status, _ = tk.run("ik", t.q_reference, qo)
    assert status[0] == 0 and np.abs(m - u).max() <= 1e-15
    J, J_inv, _ = tk.run("maps", q)
    assert np.abs(J.reshape(2, 2, order="F") - t.velocity_map(q)).max() <= 1e-15
    assert np.abs(J_inv.reshape(2, 2, order="F") - t.inverse_velocity_map(q)).max() <= 1e-15
    dM, dh, _ = tk.run("delta", q, [1.0, -2.0])
    assert not dM.any() and not dh.any()
    files = write_transmission(tk, tmp_path, ["c"])
    data = json.loads(files["transmission.json"].read_text())
    assert data["motors"] == ["waist_left_motor", "waist_right_motor"] and data["passive"] == []
    assert data["motor_map"] == {"waist_left_motor": {"waist_yaw": 1.0, "waist_roll": 1.0},
                                 "waist_right_motor": {"waist_yaw": 1.0, "waist_roll": -1.0}}
    assert "waist_right_motor = 1 waist_yaw - 1 waist_roll" in files["torso.h"].read_text()
    if not shutil.which("gcc"):
        return
    (tmp_path / "main.c").write_text("""#include <stdio.h>
#include "torso.h"
int main(void) {
  double q[TORSO_NQ], qo[TORSO_K], qm[TORSO_K] = {0.3, -0.1}, back[TORSO_K];
  int i, s;
  for (i = 0; i < TORSO_NQ; ++i) q[i] = torso_q_reference[i];
  s = torso_fk(qm, q, qo, NULL);
  s += 10 * torso_ik(qo, q, back, NULL);
  printf("%d %s %s %s %s\\n", s, torso_motor_names[0], torso_motor_names[1], torso_drive_names[0],
         torso_drive_names[1]);
  for (i = 0; i < TORSO_K * TORSO_K; ++i) printf("%.17g ", torso_motor_map[i]);
  printf("\\n%.17g %.17g %.17g %.17g\\n", qo[0], qo[1], back[0], back[1]);
  return 0;
}
""")
    subprocess.run(["gcc", "-std=c99", "-O0", "-Wall", "-Werror", "-o", "main", "main.c", "torso.c", "-lm"],
                   cwd=tmp_path, check=True, capture_output=True)
    lines = subprocess.run([str(tmp_path / "main")], capture_output=True, text=True, check=True).stdout.splitlines()
    assert lines[0].split() == ["0", "waist_left_motor", "waist_right_motor", "waist_yaw", "waist_roll"]
    assert np.array(lines[1].split(), dtype=float).tolist() == [1.0, 1.0, 1.0, -1.0]  # (C, column-major)
    out = np.array(lines[2].split(), dtype=float)
    assert np.abs(out[:2] - qo).max() <= 1e-15 and np.abs(out[2:] - u).max() <= 1e-15


def test_a_differential_on_a_closed_ankles_motors_composes_its_maps():
    """The humanoid ankle's two crank motors driven by ``sum = left + right`` and ``diff = left/2 - 2 right``: the
    transmission's motors are those two, its position map round-trips (1e-12), ``J`` is central differences of it
    in the motors' coordinates (1e-7 relative), the effort map ``Jᵀ`` by its other route (1e-10); the kernels' ``J``
    and ``J⁻¹`` the Python route's (1e-12)."""
    ankle = robot("humanoid_ankle")
    left, right = ankle.actuated_names
    spec = dataclasses.replace(ankle.spec, motors={"sum": {left: 1.0, right: 1.0}, "diff": {left: 0.5, right: -2.0}})
    geared = pkm.Mechanism(ankle.model, spec, urdf=ankle.urdf, source=ankle.source)
    geared.q_reference = ankle.q_reference.copy()
    [t] = pkm.transmissions(geared)
    assert (t.motors, t.drives, t.constant) == (("sum", "diff"), (left, right), False)
    C = np.array([[1.0, 1.0], [0.5, -2.0]])
    u = C @ ankle.actuated_q(ankle.q_reference) + np.array([0.05, -0.08])
    qo, q = t.outputs_from_motors(u)
    assert np.abs(t.motors_from_outputs(qo, q)[0] - u).max() <= 1e-12
    assert np.abs(C @ t.mechanism.actuated_q(q) - u).max() <= 1e-12  # (the motors' coordinates, not the cranks')
    h = 1e-6
    fd = np.array([(t.outputs_from_motors(u + h * e, q)[0] - t.outputs_from_motors(u - h * e, q)[0]) / (2 * h)
                   for e in np.eye(2)]).T
    J = t.velocity_map(q)
    assert np.abs(J - fd).max() <= 1e-7 * np.abs(J).max()
    assert np.abs(t.effort_map(q) - J.T).max() <= 1e-10 * np.abs(J).max()
    assert np.abs(t.inverse_effort_map(q) - np.linalg.inv(J).T).max() <= 1e-10 * np.abs(np.linalg.inv(J)).max()
    kJ, kJ_inv, _ = TransmissionKernels.of(t).run("maps", q)
    assert np.abs(kJ.reshape(2, 2, order="F") - J).max() <= 1e-12
    assert np.abs(kJ_inv.reshape(2, 2, order="F") - t.inverse_velocity_map(q)).max() <= 1e-12


def test_a_differential_across_a_loop_and_a_serial_joint_is_refused(coupled):
    """Motors that drive the neck loop's crank and the shoulder (a serial joint) together: no transmission, a
    TransmissionError naming the motor; with ``skip_unfit`` the waist alone, a warning saying why."""
    spec = dataclasses.replace(coupled.spec, motors={
        **coupled.spec.motors, "m1": {"left_neck": 1.0, "left_shoulder_pitch": 1.0},
        "m2": {"left_neck": 1.0, "left_shoulder_pitch": -1.0}})
    mech = pkm.Mechanism(coupled.model, spec, urdf=coupled.urdf, source=coupled.source)
    mech.q_reference = coupled.q_reference.copy()
    with pytest.raises(TransmissionError, match=r"its motor 'm1'.*also drives \['left_shoulder_pitch'\]"):
        pkm.transmissions(mech)
    with pytest.warns(PkmWarning, match="m1"):
        assert [t.name for t in pkm.transmissions(mech, skip_unfit=True)] == ["torso"]


def test_pkm_transmission_shows_a_tendon_motor_with_its_map(tmp_path, capsys):
    """``pkm transmission`` on the MJCF with the differential: the waist's motors are the tendons' motors, with their
    map, in the JSON and the text; not its joints."""
    with pytest.warns(PkmWarning, match="transmission 'head'.*mimic joints"):  # (the neck's gear: left out)
        assert cli.main(["transmission", str(XML), "--out", str(tmp_path), "--targets", "c", "--skip-unfit",
                         "--json"]) == 0
    [t] = json.loads(capsys.readouterr().out)["transmissions"]
    assert t["motors"] == ["waist_left_motor", "waist_right_motor"] and t["drives"] == ["waist_yaw", "waist_roll"]
    assert t["constant"] and t["motor_map"] == {"waist_left_motor": {"waist_yaw": 1.0, "waist_roll": 1.0},
                                                "waist_right_motor": {"waist_yaw": 1.0, "waist_roll": -1.0}}
    with pytest.warns(PkmWarning, match="transmission 'head'"):
        assert cli.main(["transmission", str(XML), "--out", str(tmp_path), "--targets", "c", "--skip-unfit"]) == 0
    text = capsys.readouterr().out
    assert "torso: motors waist_left_motor, waist_right_motor -> outputs waist_yaw, waist_roll" in text
    assert "waist_left_motor = 1 waist_yaw + 1 waist_roll; waist_right_motor = 1 waist_yaw - 1 waist_roll" in text
