"""pkm.viz.encode: an animation's keyframes are the forward kinematics of each sample; bad configurations,
trajectories and times raise a PkmError saying so."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm import viz
from pkm.errors import InvalidInputError, PkmError
from tests.viz.helpers import TOL, assembled, by_path, decode, fk, frame_placement, matrix


@pytest.mark.parametrize("times, keys", [(None, [0.0, 1.0, 2.0]), ([0.0, 0.5, 2.0], [0.0, 15.0, 60.0])])
def test_animation_keyframes_are_forward_kinematics(case, times, keys):
    """A 3-sample trajectory gives, for every body, position and quaternion keys equal to FK at each sample."""
    mech, scene, qs = case
    traj = np.array([qs[0], qs[1], assembled(mech, -0.02)])
    cmds = decode(viz.snapshot_html(mech, trajectory=traj, times=times))
    (anim,) = [c for c in cmds if c["type"] == "set_animation"]
    clips = {a["path"]: a["clip"] for a in anim["animations"]}
    assert set(clips) == {b.path for b in scene.bodies}
    datas = [fk(mech, q) for q in traj]
    err = 0.0
    for b in scene.bodies:
        clip = clips[b.path]
        assert clip["fps"] == viz.FPS
        tracks = {t["name"]: t for t in clip["tracks"]}
        pos, quat = tracks[".position"]["keys"], tracks[".quaternion"]["keys"]
        assert [k["time"] for k in pos] == keys and [k["time"] for k in quat] == keys
        for k, data in enumerate(datas):
            x, y, z, w = quat[k]["value"]
            got = pin.SE3(pin.Quaternion(w, x, y, z).toRotationMatrix(), np.array(pos[k]["value"])).homogeneous
            err = max(err, np.abs(got - frame_placement(mech, data, b.frame) @ b.offset).max())
    assert err <= TOL
    # the still pose is the first sample
    first = by_path(cmds, "set_transform")[f"{viz.ROOT}/joints/{mech.actuated_names[0]}"]
    assert np.abs(matrix(first) - datas[0].oMi[mech.model.getJointId(mech.actuated_names[0])].homogeneous).max() <= TOL


# ------------------------------------------------------------------------------------------- errors
@pytest.mark.parametrize("bad, message", [
    (lambda m: np.zeros(m.nq + 1), "expected shape"),
    (lambda m: np.full(m.nq, np.nan), "non-finite"),
    (lambda m: "q", "expected"),
])
def test_bad_q_raises_pkm_error(case, bad, message):
    """A q of the wrong size, with NaNs or of the wrong type raises a PkmError saying so."""
    mech, _, _ = case
    with pytest.raises(PkmError, match=message):
        viz.snapshot_html(mech, bad(mech))


def test_unnormalised_quaternion_raises_pkm_error():
    """A free-flyer quaternion of norm 2 in q is refused with a PkmError naming the joint."""
    mech = pkm.load("prs3")
    q = mech.q_reference.copy()
    j = mech.joint("platform")
    q[j.idx_q + 3:j.idx_q + 7] *= 2.0
    with pytest.raises(InvalidInputError, match="quaternion of joint 'platform'"):
        viz.snapshot_html(mech, q)


@pytest.mark.parametrize("kw, message", [
    ({"trajectory": np.zeros((3, 2))}, r"expected shape \(N, 12\)"),
    ({"trajectory": np.zeros((0, 12))}, "N >= 1"),
    ({"trajectory": [[np.nan] * 12]}, r"trajectory\[0\]"),
    ({"trajectory": np.zeros((3, 12)), "times": [0.0, 0.2, 0.1]}, "strictly increasing"),
    ({"trajectory": np.zeros((3, 12)), "times": [0.0, 0.1]}, r"shape \(3,\)"),
    ({"times": [0.0]}, "without a trajectory"),
])
def test_bad_trajectory_or_times_raise_pkm_error(kw, message):
    """A malformed trajectory or times array raises an InvalidInputError saying what is wrong."""
    with pytest.raises(InvalidInputError, match=message):
        viz.snapshot_html(pkm.load("delta"), **kw)
