"""The humanoid ankle (``examples/humanoid_ankle``: MJCF with ``<connect>`` loops and motors, its outputs in a
four-line spec) and knee (``examples/humanoid_knee``: URDF + spec, a four-bar) against routes that are not pkm's:

* the ankle's inverse kinematics (pkm's generic Newton, the exported C's Newton and its closed form, both
  branches) equals each leg's circle-sphere intersection, written here from the file's geometry, to 1e-10 over the feasible pitch-roll region; the knee's
  equals the four-bar's circle-circle intersection;
* the largest pure-pitch and pure-roll torques (:func:`pkm.capability`) equal linear programs over the motor torques
  (``scipy.optimize.linprog``: the statics ``τ_m = Jᵀ w + g_a`` with the motors' box) to 1e-9;
* each vertex of the feasible region is stopped by a motor or joint limit, or by the singularity bound, to 1e-6;
* MuJoCo, running the user's own MJCF file (the knee: pkm's MJCF of it, its loop stiff), follows the same motor torques as
  :func:`pkm.simulate` within the bound of :mod:`pkm.bench.simulation`: ``2 S r + 2 ε`` (``S`` the sensitivity of
  the motors to a closure opening under the law, ``r`` MuJoCo's largest constraint violation, ``ε`` RK4's error).
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import scipy.optimize

import pkm
from pkm.core.analysis.region import feasible_region

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
ANKLE_XML = EXAMPLES / "humanoid_ankle" / "ankle.xml"
AXES = ("ankle_pitch", "ankle_roll")
# the ankle's geometry, as ankle.xml states it: motor axes (along y) through M, cranks R long along -x at 0, heel
# balls B on the foot, rods L
M = {"left": np.array([0.0, 0.032, 0.24]), "right": np.array([0.0, -0.032, 0.17])}
B = {"left": np.array([-0.035, 0.032, -0.02]), "right": np.array([-0.035, -0.032, -0.02])}
L = {"left": 0.26, "right": 0.19}
R = 0.035


def rot_y(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def ankle_closed_form(pitch: float, roll: float, other: tuple[bool, bool] = (False, False)) -> np.ndarray:
    """Each motor's angle: its crank tip ``M + R_y(a) (-R, 0, 0)`` on the sphere of radius L about the heel ball
    ``R_y(pitch) R_x(roll) B``: ``A cos a + B sin a = C``, the root of the reference's branch (a = 0 at neutral), or
    the other root for the legs ``other`` names."""
    out = []
    for side, flip in zip(("left", "right"), other):
        d = rot_y(pitch) @ rot_x(roll) @ B[side] - M[side]
        a_, b_, c_ = 2.0 * R * d[0], -2.0 * R * d[2], L[side] ** 2 - R ** 2 - d @ d
        out.append(math.atan2(b_, a_) + (1.0 if flip else -1.0) * math.acos(c_ / math.hypot(a_, b_)))
    return np.array(out)


def test_the_closed_form_is_the_files_geometry():
    assert np.abs(ankle_closed_form(0.0, 0.0)).max() <= 1e-15  # (the rods are vertical at neutral)


@pytest.fixture(scope="module")
def ankle():
    return pkm.load(EXAMPLES / "humanoid_ankle" / "ankle.closures.toml")


@pytest.fixture(scope="module")
def region(ankle):
    return feasible_region(ankle, AXES, directions=12, singularity=1e-2)


def _grid(region, n: int = 7) -> list[tuple[float, float]]:
    lo, hi = region.vertices.min(0), region.vertices.max(0)
    points = [(p, r) for p in np.linspace(lo[0], hi[0], n) for r in np.linspace(lo[1], hi[1], n)]
    return [(p, r) for p, r in points if region.contains(np.array([p, r]))]


def test_the_ankle_map_is_the_circle_sphere_intersection(ankle, region, tmp_path):
    points = _grid(region)
    assert len(points) >= 25
    q = ankle.q_reference
    Q, worst = [], 0.0
    for p, r in points:
        q = pkm.solve_ik(ankle, [p, r], q, tol=1e-14).q
        Q.append(q)
        worst = max(worst, float(np.abs(ankle.actuated_q(q) - ankle_closed_form(p, r)).max()))
    assert worst <= 1e-10
    if shutil.which("cc") is None:
        return
    from pkm.core.export import export_c
    from pkm.core.export.harness import build

    h = build(export_c(ankle, tmp_path / "ankle"))
    rows = np.hstack([np.array(points), np.array(Q), np.zeros((len(points), 1))])  # (from the solution: mode 0)
    rows[1:, 2:2 + ankle.nq] = np.array(Q[:-1])  # each from the previous pose, as a controller calls it
    out = h.run("ik", rows)
    assert (out[:, 0] == 0).all() and (out[:, 3] == 0).all()
    closed = np.array([ankle_closed_form(p, r) for p, r in points])
    assert np.abs(out[:, 4 + ankle.nq:] - closed).max() <= 1e-10
    # the library's own closed form (no iteration), in mode 0 and with the left leg on its other branch (mode 1:
    # the crank up, outside the motor's travel)
    assert not h.lib.closed_form
    direct = h.run("ik_actuators", np.hstack([np.array(points), np.zeros((len(points), 1))]))
    assert (direct[:, 0] == 0).all() and np.abs(direct[:, 3:] - closed).max() <= 1e-10
    flipped = h.run("ik_actuators", np.hstack([np.array(points), np.ones((len(points), 1))]))
    other = np.array([ankle_closed_form(p, r, (True, False)) for p, r in points])
    gap = (flipped[:, 3:] - other + np.pi) % (2 * np.pi) - np.pi  # (the library's angle within pi of the reference's)
    assert np.abs(gap).max() <= 1e-10 and np.abs(flipped[:, 3:]).max() <= np.pi and (flipped[:, 0] == 3).all()


def test_the_torque_extremes_are_linear_programs(ankle, region):
    limit = np.array([a.effort_limit for a in ankle.actuators])
    for p, r in _grid(region, 3):
        q = pkm.solve_ik(ankle, [p, r]).q
        c = pkm.capability(ankle, q, "wrench")
        K, g = pkm.inverse_jacobian(ankle, q), pkm.gravity_efforts(ankle, q)
        for i, axis in enumerate(AXES):  # the joint torque w = Kᵀ (τ_m - g_a) along one axis, none on the other
            for sign, value in zip((1.0, -1.0), c.along[axis]):
                lp = scipy.optimize.linprog(-sign * K[:, i], A_eq=K[:, 1 - i][None], b_eq=[K[:, 1 - i] @ g],
                                            bounds=list(zip(-limit, limit)), method="highs")
                assert lp.status == 0
                assert abs(sign * (K[:, i] @ (lp.x - g)) - value) <= 1e-9 * abs(value), (p, r, axis)


def test_each_vertex_of_the_region_is_stopped_by_a_limit_or_the_singularity(ankle, region):
    for vertex, why in zip(region.vertices, region.binding):
        q = pkm.solve_ik(ankle, list(vertex)).q
        if why.startswith("joint"):
            joint, side = why.split()[1], why.split()[4]
            value = float(np.atleast_1d(ankle.q_to_dict(q)[joint])[0])
            assert abs(value - ankle.limits[joint][0 if side == "low" else 1]) <= 1e-6, why
        else:
            assert "singularity" in why
            d = pkm.diagnose(ankle, q)
            assert abs(min(d.direct_distance, d.inverse_distance) - region.singularity) <= 1e-6
    # a polygon, not its box: the motors cut the joints' box at its corners (0.80 rad² against the box's 0.66)
    assert region.area > 1.1 * 4 * float(np.prod(region.box()))
    assert {"joint motor_left", "joint motor_right"} & {b.split(" at ")[0] for b in region.binding}


def test_the_knee_map_is_the_four_bar(tmp_path):
    knee = pkm.load(EXAMPLES / "humanoid_knee" / "knee.closures.toml")
    # knee.urdf: motor axis at (0, 0.30), crank 0.06 along -x at 0; lever point P on the shank, rod between them
    P = np.array([-0.04 * math.cos(0.9), -0.04 * math.sin(0.9)])
    rod = math.hypot(P[0] + 0.06, P[1] - 0.30)
    q = knee.q_reference
    for k in np.linspace(0.0, 1.5, 16):
        p = np.array([P[0] * math.cos(k) + P[1] * math.sin(k), -P[0] * math.sin(k) + P[1] * math.cos(k)])
        d = p - np.array([0.0, 0.30])  # crank tip (-0.06 cos a, 0.06 sin a): A cos a + B sin a = C
        a_, b_, c_ = 2 * 0.06 * d[0], -2 * 0.06 * d[1], rod ** 2 - 0.06 ** 2 - d @ d
        closed = math.atan2(b_, a_) - math.acos(c_ / math.hypot(a_, b_))
        q = pkm.solve_ik(knee, [k], q, tol=1e-14).q
        assert abs(knee.actuated_q(q)[0] - closed) <= 1e-10, k


@pytest.mark.parametrize("name", ["ankle", "knee"])
def test_mujoco_follows_pkms_forward_dynamics(name):
    pytest.importorskip("mujoco")
    from pkm.bench.simulation import STIFF_SOLIMP, ChirpLaw, _error_estimate, mujoco_run, pkm_run, sensitivity

    spec = EXAMPLES / f"humanoid_{name}" / f"{name}.closures.toml"
    mech, duration, dt = pkm.load(spec), 0.5, 1e-3
    q0 = mech.q_reference
    law = ChirpLaw.at(mech, q0, duration)
    sim = pkm_run(mech, q0, law, duration, dt, friction=True)
    eps = _error_estimate(sim.actuated, pkm_run(mech, q0, law, duration, 2 * dt, friction=True).actuated)
    if name == "ankle":  # the user's file, its equalities as it sets them (solref 0.002 s)
        _, qa, residual, _ = mujoco_run(mech, q0, law, duration, dt, path=ANKLE_XML)
    else:  # pkm's MJCF of the URDF, its equalities stiff (MuJoCo's default lets the shank sag 5 mm)
        _, qa, residual, _ = mujoco_run(mech, q0, law, duration, dt, ([2 * dt, 1.0], list(STIFF_SOLIMP)))
    n = min(len(qa), len(sim.time))
    difference = float(np.abs(qa[:n] - sim.actuated[:n]).max())
    bound = 2.0 * sensitivity(mech, q0, law) * float(residual.max()) + 2.0 * eps
    assert float(np.abs(sim.actuated - law.qa0).max()) > 5e-3  # (the motors do move: 0.01 rad)
    assert difference <= bound, (difference, bound)
