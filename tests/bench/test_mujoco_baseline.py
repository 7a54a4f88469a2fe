"""pkm.bench.mujoco_baseline: why MuJoCo cannot run when it cannot, and the conversion of a Pinocchio state to
MuJoCo's coordinates joint by joint (free flyers, universal joints, mimic joints), checked by MuJoCo placing every
body where Pinocchio places the joint. (The efforts against pkm for four mechanisms are
``tests/core/formats/test_to_mjcf.py``; the Gough-Stewart's, with its universal joints, are here.)"""

from __future__ import annotations

import sys

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.bench.mujoco_baseline import MujocoRigid, unavailable
from pkm.core.formats.to_mjcf import body_names

pytestmark = pytest.mark.skipif(unavailable() is not None,
                                reason='MuJoCo is the bench extra\'s (pip install "pkm-robotics[bench]")')


def test_unavailable_says_how_to_install_when_mujoco_cannot_be_imported(monkeypatch):
    """None here (installed); with mujoco blocked, the reason and the pip line of the bench extra."""
    assert unavailable() is None
    monkeypatch.setitem(sys.modules, "mujoco", None)
    reason = unavailable()
    assert reason.startswith("MuJoCo is not installed (") and reason.endswith('pip install "pkm-robotics[bench]"')


def _state(mech, seed: int):
    rng = np.random.default_rng(seed)
    q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + 0.01 * rng.standard_normal(mech.na)).q
    v = pkm.velocities(mech, q, rng.standard_normal(mech.na))
    return q, v, pkm.accelerations(mech, q, v, rng.standard_normal(mech.na))


@pytest.mark.parametrize("name", ["gough_stewart", "hexapod", "prs3"])
def test_mujoco_places_every_body_where_pinocchio_places_its_joint(name, built):
    """After the state conversion and mj_fwdPosition, each joint's body has Pinocchio's position and orientation
    (1e-12): free-flyer quaternions reordered, universal joints split in two hinges, mimic joints scaled."""
    import mujoco

    mech = built(name)
    rigid = MujocoRigid(mech)
    q, v, a = _state(mech, 1)
    rigid._state(q, v, a)
    mujoco.mj_fwdPosition(rigid.model, rigid.data)
    pin.forwardKinematics(mech.model, mech.data, q)
    names = body_names(mech)
    for j in range(1, mech.model.njoints):
        b = mujoco.mj_name2id(rigid.model, mujoco.mjtObj.mjOBJ_BODY, names[j])
        np.testing.assert_allclose(rigid.data.xpos[b], mech.data.oMi[j].translation, atol=1e-12)
        np.testing.assert_allclose(rigid.data.xmat[b].reshape(3, 3), mech.data.oMi[j].rotation, atol=1e-12)


def test_mujoco_computes_the_gough_stewart_s_efforts(built):
    """Its universal joints and free platform through MuJoCo's hard-constraint solve: pkm.inverse_dynamics's efforts
    (1e-9 relative), at two states."""
    mech = built("gough_stewart")
    rigid = MujocoRigid(mech)
    for seed in (2, 3):
        q, v, a = _state(mech, seed)
        tau = pkm.inverse_dynamics(mech, q, v, a)
        assert np.abs(rigid.efforts(q, v, a) - tau).max() <= 1e-9 * max(1.0, np.abs(tau).max())
