"""pkm.core.formats.to_mjcf: any mechanism written as MJCF loads back (pkm's MJCF reader) as the same mechanism, and
MuJoCo (when installed) computes the same efforts from it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm.bench.mujoco_baseline import MujocoRigid, unavailable
from pkm.core.formats.to_mjcf import mjcf_from_mechanism
from pkm.errors import SpecError

FOURBAR = Path(__file__).resolve().parents[3] / "examples" / "mjcf_fourbar" / "fourbar.xml"


def _mechanism(name: str) -> pkm.Mechanism:
    return pkm.load(FOURBAR) if name == "mjcf_fourbar" else pkm.load(name)


def _state(mech: pkm.Mechanism, seed: int):
    rng = np.random.default_rng(seed)
    q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + 0.01 * rng.standard_normal(mech.na)).q
    v = pkm.velocities(mech, q, rng.standard_normal(mech.na))
    return q, v, pkm.accelerations(mech, q, v, rng.standard_normal(mech.na))


def _moved(src: pkm.Mechanism, dst: pkm.Mechanism, q, v, a):
    """``(q, v, a)`` of ``src`` in ``dst``'s coordinates, joint by joint name."""
    out = [np.zeros(dst.model.nq), np.zeros(dst.nv), np.zeros(dst.nv)]
    for j in range(1, src.model.njoints):
        js, jd = src.model.joints[j], dst.model.joints[dst.model.getJointId(src.model.names[j])]
        assert (js.nq, js.nv) == (jd.nq, jd.nv)
        out[0][jd.idx_q:jd.idx_q + jd.nq] = q[js.idx_q:js.idx_q + js.nq]
        out[1][jd.idx_v:jd.idx_v + jd.nv] = v[js.idx_v:js.idx_v + js.nv]
        out[2][jd.idx_v:jd.idx_v + jd.nv] = a[js.idx_v:js.idx_v + js.nv]
    return out


@pytest.mark.parametrize("name", ["prs3", "delta", "rrr3", "mjcf_fourbar"])
def test_a_written_mechanism_loads_back_as_itself(name, tmp_path):
    """Same joints, actuators and closures; at closed states of the original the copy is closed (1e-12) and its
    efforts are the original's (1e-8 relative: Pinocchio's reader applies the file's ``boundinertia``, which lifts
    the Delta's point masses to 1e-12 kg m^2, as MuJoCo does; 1e-12 elsewhere)."""
    mech = _mechanism(name)
    path = tmp_path / f"{name}.xml"
    path.write_text(mjcf_from_mechanism(mech))
    back = pkm.load(path)
    assert [c.name for c in back.spec.closures] == [c.name for c in mech.spec.closures]
    assert [c.type for c in back.spec.closures] == [c.type for c in mech.spec.closures]
    assert [back.model.names[j.id] for j in back.actuated] == [mech.model.names[j.id] for j in mech.actuated]
    for seed in range(3):
        q, v, a = _state(mech, seed)
        qb, vb, ab = _moved(mech, back, q, v, a)
        assert np.abs(pkm.core.kinematics.constraints.residual(back, qb)).max() <= 1e-12
        tau, tau_b = pkm.inverse_dynamics(mech, q, v, a), pkm.inverse_dynamics(back, qb, vb, ab)
        bound = 1e-8 if name == "delta" else 1e-12
        assert np.linalg.norm(tau_b - tau) <= bound * max(np.linalg.norm(tau), 1e-12)


def test_joints_mjcf_cannot_express_are_refused():
    from tests.core.twin.test_tree import zoo

    with pytest.raises(SpecError, match="MJCF has no"):
        mjcf_from_mechanism(zoo())  # its planar joint


@pytest.mark.skipif(unavailable() is not None, reason="MuJoCo is a benchmark-only dependency")
@pytest.mark.parametrize("name", ["prs3", "delta", "hexapod", "rrr3"])
def test_mujoco_computes_the_same_efforts(name):
    """MuJoCo's hard-constraint solve on the written file equals pkm.inverse_dynamics to 1e-8 (the bound MuJoCo puts
    on point masses' inertia, 1e-12 kg m^2, moves the Delta's and the hexapod's efforts by about 1e-9)."""
    mech = _mechanism(name)
    rigid = MujocoRigid(mech)
    for seed in range(3):
        q, v, a = _state(mech, seed)
        tau = pkm.inverse_dynamics(mech, q, v, a)
        assert np.abs(rigid.efforts(q, v, a) - tau).max() <= 1e-8 * max(1.0, np.abs(tau).max())
