"""Checks shared by the tests of the third-party robots pkm ships (tests/test_menagerie_robots.py,
tests/test_published_robots.py): licence and source beside the file, the loops closed again from a moved seed, a
transmission's round trip, MuJoCo on the same file."""

from __future__ import annotations

import re

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.formats.catalogue import CATALOGUE, catalogue_path
from pkm.core.formats.to_mjcf import qpos_of


def check_shipped(name: str, model_file: str, holder: str, source: tuple[str, ...]) -> str:
    """``name`` is in the catalogue as ``model_file``, its LICENSE names ``holder``, its SOURCE.txt holds every string
    of ``source`` (repository, path, commit), and the file neither loads nor uses a mesh; the file's text."""
    path = catalogue_path(name)
    assert path.name == model_file and name in CATALOGUE
    assert holder in (path.parent / "LICENSE").read_text()
    text = (path.parent / "SOURCE.txt").read_text()
    assert all(s in text for s in source), source
    model = path.read_text()
    assert not re.search(r"<mesh[^>]*\bfile=", model) and 'mesh="' not in model  # (a class's mesh scale may stay)
    return model


def check_closes_from_a_moved_seed(mech: pkm.Mechanism, step: float = 0.02) -> None:
    """The loops close again (1e-10) with the motors held (1e-12) from the reference's passive joints moved by up to
    ``step`` [rad or m]."""
    qa = mech.actuated_q(mech.q_reference)
    moved = step * np.random.default_rng(0).uniform(-1.0, 1.0, mech.nv)
    moved[mech.act_v] = 0.0
    fk = pkm.close_loops(mech, qa, pin.integrate(mech.model, mech.q_reference, moved))
    assert fk.residual <= 1e-10 and np.abs(mech.actuated_q(fk.q) - qa).max() <= 1e-12


def check_round_trip(t, offset: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Motors ``offset`` from the reference -> outputs -> motors comes back to 1e-10; ``(qm, q_sub)`` there."""
    qm = t.mechanism.actuated_q(t.q_reference) + offset
    qo, q_sub = t.outputs_from_motors(qm)
    back, _ = t.motors_from_outputs(qo, q_sub)
    assert np.abs(back - qm).max() <= 1e-10, t.name
    return qm, q_sub


class MujocoAt:
    """MuJoCo (the bench extra: the reference, not a dependency) on shipped robot ``name``'s own file, at Pinocchio's
    configuration ``q`` of ``mech`` (each joint's ``qpos`` by name: quaternions reordered, mimic joints at their
    ratios, a free joint's placement folded in), at rest."""

    def __init__(self, mech: pkm.Mechanism, name: str, q: np.ndarray):
        self.mujoco = mujoco = pytest.importorskip("mujoco")
        self.mech, self.q = mech, q
        self.m = m = mujoco.MjModel.from_xml_path(str(catalogue_path(name)))
        m.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE  # (efc_J as an nefc x nv array)
        self.d = d = mujoco.MjData(m)
        base = mech.base.name if mech.base is not None else ""
        self.joints = [mech.model.getJointId(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, k) or base)
                       for k in range(m.njnt)]
        for k, j in enumerate(self.joints):
            seg = qpos_of(mech.model, j, q)
            d.qpos[m.jnt_qposadr[k]:m.jnt_qposadr[k] + len(seg)] = seg

    def forward(self) -> None:
        self.mujoco.mj_forward(self.m, self.d)

    def held(self) -> np.ndarray:
        """The accelerations with the equalities held exactly (after :meth:`forward`): the KKT system of MuJoCo's
        own mass matrix (armature included), forces (actuators, applied, passive: springs; bias: gravity) and
        equality Jacobian, by least squares (unique in the accelerations where rows are redundant)."""
        m, d = self.m, self.d
        M = np.zeros((m.nv, m.nv))
        self.mujoco.mj_fullM(m, d, M)
        assert np.all(d.efc_type[:d.nefc] == self.mujoco.mjtConstraint.mjCNSTR_EQUALITY)  # (no limit, no contact)
        J = d.efc_J[:d.nefc * m.nv].reshape(d.nefc, m.nv)
        kkt = np.block([[M, J.T], [J, np.zeros((d.nefc, d.nefc))]])
        f = d.qfrc_actuator + d.qfrc_applied + d.qfrc_passive - d.qfrc_bias
        return np.linalg.lstsq(kkt, np.r_[f, np.zeros(d.nefc)])[0][:m.nv]

    def dofs(self, x: np.ndarray) -> np.ndarray:
        """Pinocchio's joint-space vector ``x`` (accelerations at rest, or efforts) in MuJoCo's dofs (a free joint's
        linear entries in world axes: at rest, ``R x``; a mimic joint's, its leader's times its scaling)."""
        mech, m = self.mech, self.m
        pin.forwardKinematics(mech.model, mech.data, self.q)
        out = np.zeros(m.nv)
        for k, j in enumerate(self.joints):
            jm, at = mech.model.joints[j], m.jnt_dofadr[k]
            out[at:at + jm.nv] = x[jm.idx_v:jm.idx_v + jm.nv]
            if jm.shortname() == "JointModelMimic":
                out[at] = jm.extract().scaling * x[jm.idx_v]
            if m.jnt_type[k] == self.mujoco.mjtJoint.mjJNT_FREE:
                out[at:at + 3] = mech.data.oMi[j].rotation @ x[jm.idx_v:jm.idx_v + 3]
        return out

    def body_gap(self) -> float:
        """The largest distance [m] between a body's origin in MuJoCo and in pkm (after :meth:`forward`)."""
        mech, m = self.mech, self.m
        pin.framesForwardKinematics(mech.model, mech.data, self.q)
        return max(float(np.abs(mech.data.oMf[mech.model.getFrameId(
            self.mujoco.mj_id2name(m, self.mujoco.mjtObj.mjOBJ_BODY, b), pin.FrameType.BODY)].translation
            - self.d.xpos[b]).max()) for b in range(1, m.nbody))

    def equality_rows(self) -> np.ndarray:
        """MuJoCo's violations of its equality rows (after :meth:`forward`): m, rad, or rad for a joint equality."""
        d = self.d
        return d.efc_pos[:d.nefc][d.efc_type[:d.nefc] == self.mujoco.mjtConstraint.mjCNSTR_EQUALITY]


def check_mjcf_round_trip(mech: pkm.Mechanism, step: np.ndarray) -> None:
    """pkm's MJCF of ``mech`` read back: the same motors, and at the motors moved by ``step`` from the reference
    (closed by each model from its own reference) every joint where ``mech`` puts it (1e-12 m; the writer names the
    bodies after their joints' links, so joints are what both name alike)."""
    from pkm.core.formats.load import load_texts
    from pkm.core.formats.to_mjcf import mjcf_from_mechanism

    back = load_texts({f"{mech.name}.xml": mjcf_from_mechanism(mech)})
    assert back.actuated_names == mech.actuated_names
    models = []
    for m in (mech, back):
        q = pkm.close_loops(m, m.actuated_q(m.q_reference) + step, m.q_reference).q
        pin.forwardKinematics(m.model, m.data, q)
        models.append({m.model.names[j]: m.data.oMi[j].translation.copy() for j in range(1, m.model.njoints)})
    assert set(models[1]) == set(models[0])
    assert max(float(np.abs(models[0][j] - models[1][j]).max()) for j in models[0]) <= 1e-12
