"""examples/mjcf_gripper: a gripper whose two four-bar fingers' drivers are tied by an <equality><joint> and
driven through one <tendon><fixed>: loaded by pkm.load, the coupling and the tendon actuator honoured, the
closed fingers checked against the four-bars solved by hand (circle intersection in the finger's plane). (Its
equalities are not in name order: Pinocchio 4.1 returns them sorted by name, which swapped the two pins.)"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pkm

GRIPPER = Path(__file__).resolve().parents[3] / "examples" / "mjcf_gripper" / "gripper.xml"
A, B0, C0, D = (np.array(p) for p in ([0.01, 0.0], [0.01, 0.04], [0.04, 0.045], [0.035, 0.0]))  # (x, z) [m]


def _hand_solved_c(theta: float) -> np.ndarray:
    """The right finger's coupler-follower pin C (x, z) [m] at driver angle ``theta`` [rad] (axis -y: B turns
    towards -x), the intersection of the circles about B and D nearer to its file position."""
    L_ab, L_bc, L_dc = np.linalg.norm(B0 - A), np.linalg.norm(C0 - B0), np.linalg.norm(C0 - D)
    B = A + L_ab * np.array([-np.sin(theta), np.cos(theta)])
    d = np.linalg.norm(D - B)
    a = (L_bc**2 - L_dc**2 + d**2) / (2 * d)
    h = np.sqrt(L_bc**2 - a**2)
    mid, perp = B + a * (D - B) / d, np.array([-(D - B)[1], (D - B)[0]]) / d
    return min((mid + h * perp, mid - h * perp), key=lambda c: np.linalg.norm(c - C0))


def test_the_gripper_loads_with_its_coupling_and_its_tendon_actuator():
    mech = pkm.load(GRIPPER)
    assert mech.actuated_names == ("left_driver",) and mech.model.nq == 5  # right_driver follows: no coordinate
    assert [c.name for c in mech.spec.closures] == ["right_pin", "left_pin"]
    assert any("tendon 'split'" in n and "actuated joint left_driver" in n for n in mech.notes)
    assert mech.limits["left_driver"] == pytest.approx((0.0, np.radians(40)), abs=1e-15)
    m, d = mech.model, mech.data
    for theta in (0.35, 0.6):
        q = pkm.close_loops(mech, [theta], tol=1e-12).q
        pin.framesForwardKinematics(m, d, q)
        c = _hand_solved_c(theta)
        right = d.oMf[mech.frame_id("right_pin_a")].translation
        left = d.oMf[mech.frame_id("left_pin_a")].translation
        assert np.abs(right[[0, 2]] - c).max() <= 1e-9  # [m]: both routes to 1e-12 closure
        assert np.abs(left - right * [-1, 1, 1]).max() <= 1e-9  # right = left: the fingers mirror each other
        # a positive driver angle closes the fingers: the pads (x = +-0.035 m at qpos0) move towards x = 0
        pads = [d.oMf[mech.frame_id(f"{side}_pad")].translation[0] for side in ("right", "left")]
        assert 0.0 < pads[0] < 0.035 - 0.01 and pads[1] == pytest.approx(-pads[0], abs=1e-9)
