"""The compliance tests' Gough-Stewart, its pose away from the reference and its legs' anchors."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import pkm


@pytest.fixture(scope="module")
def gs():
    return pkm.load("gough_stewart")


@pytest.fixture(scope="module")
def pose(gs):
    """A configuration away from the reference: the legs 1 to 3 cm longer or shorter (the platform moved and tilted)."""
    return pkm.close_loops(gs, gs.actuated_q(gs.q_reference) + [0.02, -0.01, 0.03, 0.0, 0.015, -0.02]).q


def legs(gs, q):
    """``(b, p, P, R)``: each leg's base and platform anchors, the platform's origin and rotation (world), from the
    model."""
    m, d = gs.model, gs.data
    pin.forwardKinematics(m, d, q)
    pin.updateFramePlacements(m, d)
    b = np.array([d.oMi[m.getJointId(f"u{i}")].translation for i in range(1, 7)])
    p = np.array([(d.oMi[cm.joint2_id] * cm.joint2_placement).translation for cm in gs.constraint_models])
    return b, p, d.oMf[gs.ee_frame].translation.copy(), d.oMf[gs.ee_frame].rotation.copy()
