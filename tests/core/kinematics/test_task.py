"""pkm.core.kinematics.task: Z-Y-X angles, rotation checks, the task map's retract/error pair."""

from __future__ import annotations

import numpy as np
import pytest

import pkm
from pkm.core.kinematics.task import TaskMap, as_rotation, zyx_angles, zyx_matrix
from pkm.errors import InvalidInputError


def test_zyx_angles_and_matrix_are_inverse():
    rng = np.random.default_rng(0)
    for _ in range(50):
        rpy = rng.uniform([-3.0, -1.5, -3.0], [3.0, 1.5, 3.0])
        np.testing.assert_allclose(zyx_angles(zyx_matrix(*rpy)), rpy, atol=1e-12)


def test_as_rotation_projects_printed_matrices_and_refuses_others():
    R = zyx_matrix(0.3, -0.2, 0.1)
    printed = np.round(R, 4)
    P = as_rotation(printed)
    np.testing.assert_allclose(P.T @ P, np.eye(3), atol=1e-14)
    assert np.abs(P - R).max() < 1e-4
    with pytest.raises(InvalidInputError, match="det R"):
        as_rotation(-R)
    with pytest.raises(InvalidInputError):
        as_rotation(2.0 * R)


@pytest.mark.parametrize("name", ["fivebar", "rrr3", "hexapod"])
def test_retract_and_error_are_inverse(name, built):
    """error(y, retract(y, d)) = d for small tangent steps (1e-10), positions, angles and joint outputs alike."""
    mech = built(name)
    task = TaskMap(mech)
    y = task.value(mech.q_reference)
    rng = np.random.default_rng(1)
    for _ in range(10):
        d = 0.05 * rng.standard_normal(task.size)
        np.testing.assert_allclose(task.error(task.retract(y, d), y), d, atol=1e-10)


def test_a_task_of_several_frames(tmp_path):
    """[task.frames]: the Gough-Stewart platform with coordinates of three of its sockets as the task (no end
    effector; socket 1's x y z, socket 3's x z and socket 5's z fix the platform): named keys, a partial target (the platform moved 1 cm along x and 2 cm
    up), FK/IK round trip, the Jacobian against finite differences, saved and loaded."""
    import dataclasses
    from pathlib import Path

    from pkm.core.model.compare import mechanism_differences
    from pkm.core.model.spec import TaskSpec
    from tests.fd import forward_jacobian_error

    stewart = pkm.load(Path(__file__).resolve().parents[3] / "examples" / "gough_stewart" / "gough_stewart.closures.toml")
    spec = dataclasses.replace(stewart.spec, end_effector=None, task=TaskSpec(
        (), (), {"socket1": ("x", "y", "z"), "socket3": ("x", "z"), "socket5": ("z",)}), reference={})
    mech = pkm.from_strings(stewart.urdf, spec)
    assert pkm.TaskMap.of(mech).keys == ("socket1.x", "socket1.y", "socket1.z", "socket3.x", "socket3.z", "socket5.z")
    assert pkm.diagnose(mech, mech.q_reference).classification == "regular"
    assert mech.n_task == 6 and pkm.TaskMap.of(mech).kinds["socket5.z"] == "length"
    home = pkm.task_values(mech, mech.q_reference)
    moved = {"socket1.x": home["socket1.x"] + 0.01, "socket3.x": home["socket3.x"] + 0.01,
             "socket1.z": f"{(home['socket1.z'] + 0.02) * 100!r}cm", "socket3.z": home["socket3.z"] + 0.02,
             "socket5.z": home["socket5.z"] + 0.02}
    ik = pkm.solve_ik(mech, moved)
    expected = {**home, "socket1.x": home["socket1.x"] + 0.01, "socket3.x": home["socket3.x"] + 0.01,
                "socket1.z": home["socket1.z"] + 0.02, "socket3.z": home["socket3.z"] + 0.02,
                "socket5.z": home["socket5.z"] + 0.02}
    assert pkm.task_values(mech, ik.q) == pytest.approx(expected, abs=1e-9)
    at = mech.joint("platform").idx_q
    start, end = mech.q_reference[at:at + 7], ik.q[at:at + 7]
    assert np.allclose(end - start, [0.01, 0.0, 0.02, 0.0, 0.0, 0.0, 0.0], atol=1e-9)  # a translation
    fk = pkm.close_loops(mech, mech.actuated_q(ik.q), mech.q_reference)
    task = pkm.TaskMap.of(mech)
    assert np.abs(task.error(task.value(fk.q), task.value(ik.q))).max() <= 1e-9
    assert forward_jacobian_error(mech, ik.q) <= 1e-6
    path = pkm.save(mech, tmp_path / "sockets.closures.toml")
    assert "[task.frames]" in path.read_text()
    assert mechanism_differences(pkm.load(path), mech) == []


@pytest.mark.parametrize("frames, message", [
    ({"socket1": []}, "task.frames.socket1 is empty"), ({"socket1": ["w"]}, "unknown"),
    ({"nowhere": ["x"]}, "nowhere"), ({"socket1": ["x", "y", "z"], "socket2": ["pose"]}, "only 6 joints are actuated")])
def test_bad_task_frames_are_refused(frames, message, tmp_path):
    from pathlib import Path

    from pkm.errors import SpecError

    folder = Path(__file__).resolve().parents[3] / "examples" / "gough_stewart"
    text = (folder / "gough_stewart.closures.toml").read_text().replace(
        '[task]\ncomponents = ["pose"]', '[task]\ncomponents = ["x"]\n[task.frames]\n'
        + "".join(f"{k} = {v!r}\n".replace("'", '"') for k, v in frames.items()))
    (tmp_path / "gough_stewart.urdf").write_text((folder / "gough_stewart.urdf").read_text())
    (tmp_path / "bad.closures.toml").write_text(text)
    with pytest.raises(SpecError, match=message):
        pkm.load(tmp_path / "bad.closures.toml")
