r"""The serial-equivalent model: the tree with only the output joints and the bodies they carry.

Rule: every joint of a sub-mechanism that is not an output (the motors, the rods' joints) is removed with the bodies
it carries, and its reflected inertia (the rotors') with it: their mass and inertia are dropped from the serial model
and carried by ``ΔM`` and ``Δh`` (:class:`~pkm.core.transmissions.transmission.Transmission`). The outputs keep
their own armature, if the file gives one, in both models.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin


def serial_tree(model: pin.Model, outputs: Sequence[str]) -> pin.Model:
    """A copy of ``model`` (a sub-mechanism's) in which every joint but ``outputs`` is massless: its body's (and its
    welded bodies') inertia zero, its armature zero. Since every output hangs from the root through outputs only,
    the massless joints move nothing the outputs carry: the copy's mass matrix and bias, restricted to the outputs'
    rows and columns, are the serial-equivalent model's."""
    serial = model.copy()
    keep = set(outputs)
    armature = np.array(serial.armature, dtype=float)
    for j in range(1, serial.njoints):
        if serial.names[j] not in keep:
            serial.inertias[j] = pin.Inertia.Zero()
            jm = serial.joints[j]
            armature[jm.idx_v:jm.idx_v + jm.nv] = 0.0
    serial.armature = armature
    return serial


__all__ = ["serial_tree"]
