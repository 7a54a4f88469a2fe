"""What the tests of pkm.viz read back: the commands of a snapshot page, decoded, and forward kinematics
computed here on a fresh ``pin.Data``."""

from __future__ import annotations

import base64
import json
import re

import numpy as np
import pinocchio as pin
import umsgpack

import pkm
from pkm.viz.bodies import CENTRE_OF_MASS

TOL = 1e-9  # m, on placements sent as float64
TOL_F32 = 1e-6  # m, on mesh vertices (meshcat sends geometry as float32)


def decode(page: str) -> list[dict]:
    """The commands embedded in a snapshot page: a JSON list of base64 strings, each msgpack."""
    match = re.search(r'<script type="application/json" id="pkm-meshcat-commands">(.*?)</script>', page, re.DOTALL)
    assert match, "the page carries no pkm-meshcat-commands element"
    return [umsgpack.unpackb(base64.b64decode(s)) for s in json.loads(match.group(1))]


def by_path(cmds: list[dict], kind: str) -> dict[str, dict]:
    out = {}
    for c in cmds:
        if c["type"] == kind:
            assert c["path"] not in out, f"two {kind} commands for {c['path']}"
            out[c["path"]] = c
    return out


def matrix(cmd: dict) -> np.ndarray:
    """A set_transform's matrix (three.js sends column-major)."""
    return np.array(cmd["matrix"], dtype=float).reshape(4, 4).T


def vertices(obj: dict) -> np.ndarray:
    array = obj["object"]["geometries"][0]["data"]["attributes"]["position"]["array"]
    assert array.type == 0x17  # Float32Array
    return np.frombuffer(array.data, dtype=np.float32).reshape(-1, 3).astype(float)


def fk(mech, q) -> pin.Data:
    """Forward kinematics of ``mech`` at ``q`` on a data of its own."""
    data = mech.model.createData()
    pin.forwardKinematics(mech.model, data, q)
    pin.updateFramePlacements(mech.model, data)
    return data


def frame_placement(mech, data, name: str) -> np.ndarray:
    return data.oMf[mech.model.getFrameId(name)].homogeneous


def point(mech, data, name: str, host: str) -> np.ndarray:
    """World position of joint or frame ``name``; a joint as the point where body ``host`` carries it; ``host``'s
    centre of mass for :data:`~pkm.viz.bodies.CENTRE_OF_MASS`."""
    model = mech.model
    if name == CENTRE_OF_MASS:
        j = model.getJointId(host)
        return data.oMi[j].act(model.inertias[j].lever)
    if model.existJointName(name) and name != host:
        j = model.getJointId(name)
        return (data.oMi[model.parents[j]] * model.jointPlacements[j]).translation
    if model.existJointName(name):
        return data.oMi[model.getJointId(name)].translation
    return data.oMf[model.getFrameId(name)].translation


def assembled(mech, step: float = 0.03) -> np.ndarray:
    """An assembled configuration: actuated coordinates moved off the reference by ``step``, loops closed."""
    qa = mech.actuated_q(mech.q_reference) + step * np.linspace(1.0, -0.5, mech.na)
    res = pkm.close_loops(mech, qa, mech.q_reference)
    assert res.converged
    return res.q
