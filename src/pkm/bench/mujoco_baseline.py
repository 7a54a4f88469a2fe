"""MuJoCo's rigid inverse dynamics of a closed-loop mechanism: the external baseline of :mod:`pkm.bench.twin`.

The mechanism is written as MJCF (:func:`pkm.core.formats.to_mjcf.mjcf_from_mechanism`) and loaded by MuJoCo. At a
consistent state ``(q, v, a)`` (Pinocchio's coordinates, converted per joint: quaternions ``w x y z``, a free
body's linear velocity in world axes, a mimic joint's own coordinate), ``mj_fwdPosition`` gives the equality
constraints' Jacobian ``J_c`` and ``mj_rne`` the joint forces ``M a + c(q, v)`` (gravity included); the actuated
efforts and the loops' multipliers solve ``B^T tau + J_c^T lambda = rne`` (``nv x (na + nc)``) by least squares.
This is MuJoCo with hard constraints; ``mj_inverse`` itself treats them as soft and returns other efforts.

MuJoCo is a benchmark-only dependency (the ``bench`` extra: ``pip install "pkm-robotics[bench]"``): :func:`unavailable`
says why it cannot run.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from pkm.core.formats.to_mjcf import body_names, mjcf_from_mechanism
from pkm.core.model.mechanism import Mechanism


def unavailable() -> str | None:
    """None when MuJoCo can be imported, else why not."""
    try:
        import mujoco  # noqa: F401
    except ImportError as e:
        return f"MuJoCo is not installed ({e}); pip install \"pkm-robotics[bench]\""
    return None


class MujocoRigid:
    """MuJoCo's model of ``mech`` and its rigid inverse dynamics (see the module doc)."""

    def __init__(self, mech: Mechanism):
        import mujoco

        self.mj = mujoco
        self.mech = mech
        self.model = mujoco.MjModel.from_xml_string(mjcf_from_mechanism(mech))
        self.model.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE  # efc_J as an nefc x nv array
        self.data = mujoco.MjData(self.model)
        self._rne = np.zeros(self.model.nv)
        m, pm = self.model, mech.model
        names = body_names(mech)
        self._joints = []  # (pinocchio joint, kind, mujoco qpos address, mujoco dof address, mimic scale, offset)
        for j in range(1, pm.njoints):
            b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, names[j])
            jnt = int(m.body_jntadr[b])
            jm = pm.joints[j]
            kind = jm.shortname().removeprefix("JointModel")
            scale, offset = 1.0, 0.0
            if kind == "Mimic":
                e = jm.extract()
                scale, offset = float(e.scaling), float(e.offset)
            self._joints.append((jm, kind, int(m.jnt_qposadr[jnt]), int(m.jnt_dofadr[jnt]), scale, offset))
        self._act = [int(m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, pm.names[j.id])])
                     for j in mech.actuated]

    def _state(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        d = self.data
        for jm, kind, qa, da, scale, offset in self._joints:
            iq, iv, nq, nv = jm.idx_q, jm.idx_v, jm.nq, jm.nv
            if kind == "FreeFlyer":
                R = pin.Quaternion(q[iq + 6], q[iq + 3], q[iq + 4], q[iq + 5]).toRotationMatrix()
                d.qpos[qa:qa + 3] = q[iq:iq + 3]
                d.qpos[qa + 3:qa + 7] = [q[iq + 6], q[iq + 3], q[iq + 4], q[iq + 5]]
                lin, w = v[iv:iv + 3], v[iv + 3:iv + 6]
                d.qvel[da:da + 3], d.qvel[da + 3:da + 6] = R @ lin, w
                d.qacc[da:da + 3] = R @ (a[iv:iv + 3] + np.cross(w, lin))
                d.qacc[da + 3:da + 6] = a[iv + 3:iv + 6]
            elif kind == "Spherical":
                d.qpos[qa:qa + 4] = [q[iq + 3], q[iq], q[iq + 1], q[iq + 2]]
                d.qvel[da:da + 3], d.qacc[da:da + 3] = v[iv:iv + 3], a[iv:iv + 3]
            elif kind in ("RUBX", "RUBY", "RUBZ"):
                d.qpos[qa] = np.arctan2(q[iq + 1], q[iq])
                d.qvel[da], d.qacc[da] = v[iv], a[iv]
            elif kind == "Mimic":
                d.qpos[qa] = offset + scale * q[iq]
                d.qvel[da], d.qacc[da] = scale * v[iv], scale * a[iv]
            else:  # one coordinate, or a universal joint's two
                d.qpos[qa:qa + nq], d.qvel[da:da + nv], d.qacc[da:da + nv] = q[iq:iq + nq], v[iv:iv + nv], a[iv:iv + nv]

    def efforts(self, q, v, a) -> np.ndarray:
        """The actuator efforts (na) at a consistent state ``(q, v, a)`` in Pinocchio's coordinates."""
        mj, m, d = self.mj, self.model, self.data
        self._state(np.asarray(q, dtype=float), np.asarray(v, dtype=float), np.asarray(a, dtype=float))
        mj.mj_fwdPosition(m, d)
        mj.mj_comVel(m, d)  # the bodies' velocities, which mj_rne reads
        mj.mj_rne(m, d, 1, self._rne)
        mj.mj_passive(m, d)  # (the joints' springs: efforts the actuators need not give; dampers, like pkm, left out)
        J = d.efc_J[:d.nefc * m.nv].reshape(d.nefc, m.nv) if d.nefc else np.zeros((0, m.nv))
        B = np.zeros((m.nv, len(self._act)))
        B[self._act, np.arange(len(self._act))] = 1.0
        x = np.linalg.lstsq(np.hstack([B, J.T]), self._rne - d.qfrc_spring, rcond=None)[0]
        return x[:len(self._act)]


def equality_violation(m: Any, d: Any) -> float:
    """The largest violation of MuJoCo's equality constraints in ``d`` (after its position stage) [m, rad]: the
    equality rows' ``efc_pos``, a weld's three angular rows divided by its ``torquescale`` (``eq_data[10]``, which
    MuJoCo multiplies them by: :mod:`pkm.core.formats.to_mjcf` writes 10) to give the angle."""
    import mujoco

    rows = np.flatnonzero(d.efc_type[:d.nefc] == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY))
    if not len(rows):
        return 0.0
    ids = d.efc_id[rows]
    first = {e: i for i, e in reversed(list(zip(rows, ids)))}  # (each equality's first row)
    scale = np.array([m.eq_data[e, 10] if m.eq_type[e] == mujoco.mjtEq.mjEQ_WELD and i - first[e] >= 3 else 1.0
                      for i, e in zip(rows, ids)])
    return float(np.abs(d.efc_pos[rows] / scale).max())


__all__ = ["MujocoRigid", "equality_violation", "unavailable"]
