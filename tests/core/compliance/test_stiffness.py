"""pkm.core.compliance.stiffness: the Gough-Stewart's stiffness is Gosselin's J^T diag(k) J from the legs' own
geometry, its exact deflection the equilibrium of the legs' forces solved by another solver, its natural frequencies
the linearised forward dynamics'; a Delta's compliance has rank 3 and says so; bad input is refused by name."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pinocchio as pin
import pytest
from scipy.optimize import root

import pkm
from pkm.core.compliance import stiffness, vibration_modes
from pkm.core.model.builder import from_strings
from pkm.errors import InvalidInputError, StiffnessError, UnknownNameError
from tests.core.compliance.conftest import legs

K_LEG = 2.0e6  # N/m: one axial spring per leg


def test_the_gough_stewart_stiffness_is_gosselins(gs, pose):
    """K = sum k r_i r_i^T, r_i = (u_i, (p_i - P) x u_i) from the anchors (Gosselin 1990), within 1e-9 relative,
    at a pose away from the reference; the compliance is its inverse."""
    K = stiffness(gs, pose, joints={j: K_LEG for j in gs.actuated_names})
    b, p, P, _ = legs(gs, pose)
    u = (p - b) / np.linalg.norm(p - b, axis=1)[:, None]
    r = np.hstack([u, np.cross(p - P, u)])
    gosselin = K_LEG * r.T @ r
    assert K.rank == 6 and not K.locked and set(K.sprung) == set(gs.actuated_names)
    assert np.abs(K.matrix - gosselin).max() <= 1e-9 * np.abs(gosselin).max()
    assert np.allclose(K.compliance @ gosselin, np.eye(6), atol=1e-9)
    k, directions = K.principal("force")
    assert np.all(np.diff(k) >= 0) and np.allclose(directions.T @ directions, np.eye(3), atol=1e-12)
    c = np.linalg.eigvalsh(K.compliance[:3, :3])  # (a pure force: the platform may turn)
    assert np.allclose(np.sort(1.0 / c), k, rtol=1e-12)


def test_the_exact_deflection_is_the_legs_equilibrium(gs, pose):
    """Under a constant wrench, the deflected pose balances the legs' spring forces and the wrench, solved over the
    platform's pose by scipy's hybrid method from the anchors alone: within 1e-8 relative; the first-order C W
    differs by the reported gap, which grows with the load."""
    K = stiffness(gs, pose, joints={j: K_LEG for j in gs.actuated_names})
    b, p0, P0, R0 = legs(gs, pose)
    local = (p0 - P0) @ R0  # (the anchors in the platform's frame)
    l0 = np.linalg.norm(p0 - b, axis=1)
    gaps = []
    for W in (np.array([300.0, -200.0, -1500.0, 20.0, -10.0, 30.0]), np.array([3e4, -2e4, -1.5e5, 2e3, -1e3, 3e3])):
        def balance(x, W=W):
            P, R = P0 + x[:3], pin.exp3(x[3:]) @ R0
            p = P + local @ R.T
            leg = p - b
            length = np.linalg.norm(leg, axis=1)
            force = -K_LEG * (length - l0)[:, None] * leg / length[:, None]  # (on the platform)
            return np.concatenate([force.sum(0) + W[:3], np.cross(p - P, force).sum(0) + W[3:]]) / np.abs(W).max()

        sol = root(balance, K.compliance @ W, method="hybr", options={"xtol": 1e-14})
        assert np.abs(balance(sol.x)).max() < 1e-12
        d = K.deflection(W)
        assert d.load_steps >= 1 and d.outside_limits == gs.outside_limits(d.q) == ()
        assert np.abs(d.displacement - sol.x).max() <= 1e-8 * np.abs(sol.x).max()
        assert np.allclose(d.first_order, K.compliance @ W)
        gaps.append(d.gap)
    assert 1e-5 < gaps[0] < gaps[1] < 1.0


def test_the_natural_frequencies_are_the_linearised_dynamics(gs, pose):
    """Without gravity, the legs' springs as efforts -k (l - l0) on the actuated joints: the eigenvalues of the
    forward dynamics linearised by central differences (each side closed by pkm.close_loops) are -w^2 of
    vibration_modes' frequencies, within 1e-5 relative; each mode shape has unit modal mass."""
    mech = pkm.load("gough_stewart")
    mech.model.gravity = pin.Motion.Zero()
    modes = vibration_modes(mech, pose, joints={j: K_LEG for j in mech.actuated_names})
    qa0 = mech.actuated_q(pose)
    h = 1e-6
    A = np.empty((mech.na, mech.na))
    for i in range(mech.na):
        side = []
        for sign in (1.0, -1.0):
            qa = qa0 + sign * h * np.eye(mech.na)[i]
            q = pkm.close_loops(mech, qa, pose).q
            side.append(pkm.forward_dynamics(mech, q, np.zeros(mech.na), -K_LEG * (qa - qa0))[mech.act_v])
        A[:, i] = (side[0] - side[1]) / (2 * h)
    f = np.sort(np.sqrt(-np.linalg.eigvals(A).real)) / (2 * math.pi)
    assert modes.free == 0 and len(modes.frequencies) == 6
    assert np.allclose(modes.frequencies, f, rtol=1e-5)
    M = pkm.core.differential.idle.joint_inertia(mech, pose)
    assert np.allclose(np.diag(modes.shapes.T @ M @ modes.shapes), 1.0, rtol=1e-9)


def test_a_three_degree_of_freedom_delta_is_rigid_in_rotation_and_says_so():
    """The Delta's motors as springs: a compliance of rank 3 (translations only), .matrix refused naming the rank,
    principal stiffnesses finite under a force and infinite under a moment; its drives left out: all locked, the
    compliance zero."""
    delta = pkm.load("delta")
    K = stiffness(delta, delta.q_reference, joints={j: 500.0 for j in delta.actuated_names})
    assert K.rank == 3
    with pytest.raises(StiffnessError, match="rank 3 of 6") as err:
        _ = K.matrix
    assert err.value.kind == "rigid" and err.value.rank == 3
    assert np.all(np.isfinite(K.principal("force")[0])) and np.all(np.isinf(K.principal("moment")[0]))
    locked = stiffness(delta, delta.q_reference)
    assert locked.rank == 0 and set(locked.locked) == set(delta.actuated_names) and not locked.compliance.any()


def test_a_motion_no_spring_resists_and_bad_input_are_refused(gs, pose):
    legs = {j: K_LEG for j in gs.actuated_names}
    with pytest.raises(StiffnessError, match="no spring resists") as err:
        stiffness(gs, pose, joints={**legs, "leg3": 0.0})
    assert err.value.kind == "free" and "leg3" in err.value.joints
    with pytest.raises(UnknownNameError):
        stiffness(gs, pose, joints={"leg7": 1.0})
    with pytest.raises(InvalidInputError, match="one-coordinate"):
        stiffness(gs, pose, joints={"u1": 1.0})
    for bad in (-1.0, 1e308):  # (1e12 and more: a unit mistake, as in a spec's springs; a rigid joint is left out)
        with pytest.raises(InvalidInputError, match="leg1"):
            stiffness(gs, pose, joints={"leg1": bad})
    with pytest.raises(InvalidInputError, match="not closed"):
        stiffness(gs, pin.integrate(gs.model, pose, np.r_[np.zeros(6), 0.01, np.zeros(gs.nv - 7)]), joints=legs)
    with pytest.raises(InvalidInputError, match="rigid"):
        stiffness(gs, pose, joints=legs, links="beams")
    with pytest.raises(InvalidInputError):
        stiffness(gs, pose, joints=legs).deflection([1.0, 2.0, math.nan, 0, 0, 0])


def test_a_free_vibration_simulated_has_the_natural_frequency():
    """The Delta without gravity, its motors held by servo springs (a controller -k (qa - qa0)), started at rest with a
    small rate along its third mode's shape: pkm.simulate's motion, Fourier-transformed (Hann window, zero padded,
    parabolic peak), oscillates at that mode's frequency within 1 % (2e-5 measured)."""
    delta = pkm.load("delta")
    delta.model.gravity = pin.Motion.Zero()
    k, q0 = 500.0, delta.q_reference
    modes = vibration_modes(delta, q0, joints={j: k for j in delta.actuated_names})
    qa0, f = delta.actuated_q(q0), modes.frequencies[2]
    shape = modes.shapes[delta.act_v, 2]
    v0 = 2 * math.pi * f * 1e-3 * shape / np.abs(shape).max()  # (1 mrad of amplitude: the linear regime)
    dt = 1.0 / (64 * f)
    sim = pkm.simulate(delta, q0, v0, duration=8 / f, dt=dt, friction=False, limits=False,
                       controller=lambda t, q, v: -k * (delta.actuated_q(q) - qa0))
    x = (sim.q[:, delta.act_q] - qa0) @ shape
    spectrum = np.abs(np.fft.rfft(x * np.hanning(len(x)), 64 * len(x)))
    freq = np.fft.rfftfreq(64 * len(x), dt)
    i = int(np.argmax(spectrum))
    a, b, c = np.log(spectrum[i - 1:i + 2])
    peak = freq[i] + 0.5 * (a - c) / (a - 2 * b + c) * (freq[1] - freq[0])
    assert abs(peak / f - 1.0) < 0.01


def _frame_element(p1, p2, EA, EI):
    """The 2-D Euler-Bernoulli frame element's stiffness (6 x 6: ux, uy, rotation at each end), global axes."""
    d = np.asarray(p2) - np.asarray(p1)
    length = float(np.linalg.norm(d))
    c, s = d / length
    a, b1, b2, b3 = EA / length, 12 * EI / length**3, 6 * EI / length**2, EI / length
    k = np.array([[a, 0, 0, -a, 0, 0], [0, b1, b2, 0, -b1, b2], [0, b2, 4 * b3, 0, -b2, 2 * b3],
                  [-a, 0, 0, a, 0, 0], [0, -b1, -b2, 0, b1, -b2], [0, b2, 2 * b3, 0, -b2, 4 * b3]])
    R = np.kron(np.eye(2), np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]]))
    return R.T @ k @ R


def test_compliant_links_agree_with_a_frame_finite_element_model():
    """The 3-RRR with its six links as aluminium rods (Euler-Bernoulli) and servo springs on the motors: the in-plane
    block (x, y, yaw) of pkm's compliance equals a 2-D frame finite-element model written here (one beam element a
    link, hinges at the elbows and wrists, the platform rigid, the motors rotational springs to ground), within
    1e-6 relative; the links' compliance adds to the motors' (the rigid-link compliance is smaller)."""
    from pkm.core.compliance import Beam

    rrr3 = pkm.load("rrr3")
    q, k_m, rod = rrr3.q_reference, 2.0e3, Beam(E=7.0e10, radius=0.004)
    links = {f"{part}_{i}": rod for part in ("proximal", "distal") for i in (1, 2, 3)}
    motors = {j: k_m for j in rrr3.actuated_names}
    C = stiffness(rrr3, q, joints=motors, links=links).compliance[np.ix_([0, 1, 5], [0, 1, 5])]
    rigid = stiffness(rrr3, q, joints=motors).compliance[np.ix_([0, 1, 5], [0, 1, 5])]

    m, d = rrr3.model, rrr3.data
    pin.forwardKinematics(m, d, q)
    pin.updateFramePlacements(m, d)
    joint = lambda name: d.oMi[m.getJointId(name)].translation[:2]
    P = d.oMf[rrr3.ee_frame].translation[:2]
    EA, EI = rod.E * math.pi * rod.radius**2, rod.E * math.pi * rod.radius**4 / 4
    n = 3 + 6 * 3  # platform (ux, uy, rotation); per leg: the elbow's ux, uy and the rotations A, B-, B+, C
    K = np.zeros((n, n))
    for i in (1, 2, 3):
        A, B = joint(f"motor_{i}"), joint(f"elbow_{i}")
        C_i = joint("wrist_1") if i == 1 else d.oMf[m.getFrameId(f"leg{i}_tip")].translation[:2]
        o = 3 + 6 * (i - 1)
        at = lambda *cols: np.array([[1.0 if c == j else 0.0 for j in range(n)] for c in cols])
        at_A = np.vstack([np.zeros((2, n)), at(o + 2)])
        at_B_proximal, at_B_distal = at(o, o + 1, o + 3), at(o, o + 1, o + 4)
        rigid_C = np.zeros((3, n))
        rigid_C[:2, :3] = [[1, 0, -(C_i - P)[1]], [0, 1, (C_i - P)[0]]]  # (the platform's point C_i)
        rigid_C[2, o + 5] = 1.0
        for p1, p2, T in ((A, B, np.vstack([at_A, at_B_proximal])), (B, C_i, np.vstack([at_B_distal, rigid_C]))):
            K += T.T @ _frame_element(p1, p2, EA, EI) @ T
        K[o + 2, o + 2] += k_m
    fem = np.linalg.solve(K, np.eye(n)[:, :3])[:3]
    assert np.abs(C - fem).max() <= 1e-6 * np.abs(fem).max()
    assert np.all(np.linalg.eigvalsh(C - rigid) > 0.0)


def test_bad_links_are_refused_by_name():
    from pkm.core.compliance import Beam

    rrr3 = pkm.load("rrr3")
    q, motors, rod = rrr3.q_reference, {j: 2e3 for j in rrr3.actuated_names}, Beam(E=7e10, radius=0.004)
    with pytest.raises(UnknownNameError, match="link 'proximal_9'"):
        stiffness(rrr3, q, joints=motors, links={"proximal_9": rod})
    with pytest.raises(InvalidInputError, match="symmetric positive definite"):
        stiffness(rrr3, q, joints=motors, links={"proximal_1": -np.eye(6)})
    with pytest.raises(InvalidInputError, match="carries no joint"):
        stiffness(rrr3, q, joints=motors, links={"platform_center": rod})
    with pytest.raises(InvalidInputError, match="rigid links"):
        stiffness(rrr3, q, joints=motors, links={"proximal_1": rod}).deflection([1.0, 0, 0, 0, 0, 0])
    with pytest.raises(InvalidInputError, match="rigid links"):
        stiffness(rrr3, q, joints=motors, links={"proximal_1": rod}).loaded([1.0, 0, 0, 0, 0, 0])
    with pytest.raises(InvalidInputError):
        Beam(E=7e10, radius=0.004, inner=0.005)
    m, d = rrr3.model, rrr3.data  # (a 6 x 6 of one's own, in the link's axes (x along it): the beam's, alike)
    pin.framesForwardKinematics(m, d, q)
    length = np.linalg.norm(d.oMi[m.getJointId("elbow_1")].translation - d.oMi[m.getJointId("motor_1")].translation)
    own = stiffness(rrr3, q, joints=motors, links={"proximal_1": rod.compliance(length)}).compliance
    beam = stiffness(rrr3, q, joints=motors, links={"proximal_1": rod}).compliance
    assert np.abs(own - beam).max() <= 1e-9 * np.abs(beam).max()


def test_the_drives_servo_stiffness_is_the_default_and_an_argument_wins(gs, pose):
    """Actuator.stiffness (the spec's [actuators.<joint>] stiffness, with its unit) gives the same stiffness as the
    same numbers in joints= (1e-12 relative); joints= wins where given; a [springs] spring on a driven joint adds in
    parallel; each joint's source is stated."""
    legs = gs.actuated_names
    given = {j: f"{K_LEG * (1 + 0.1 * i) / 1e3:.17g} N/mm" for i, j in enumerate(legs)}  # (N/mm: 1e3 N/m)
    driven = pkm.with_actuators(gs, {j: {"stiffness": v} for j, v in given.items()})
    explicit = stiffness(gs, pose, joints={j: K_LEG * (1 + 0.1 * i) for i, j in enumerate(legs)})
    field = stiffness(driven, pose)
    assert field.sources == dict.fromkeys(legs, "actuator") and explicit.sources == dict.fromkeys(legs, "joints")
    assert np.abs(field.matrix - explicit.matrix).max() <= 1e-12 * np.abs(explicit.matrix).max()
    over = stiffness(driven, pose, joints={legs[0]: 3 * K_LEG})
    assert over.sprung[legs[0]] == 3 * K_LEG and over.sources[legs[0]] == "joints"
    assert over.sources[legs[1]] == "actuator"
    spec = dataclasses.replace(driven.spec, springs={legs[0]: {"stiffness": 0.5 * K_LEG}})
    both = from_strings(driven.urdf, spec, driven.params, "gs")
    parallel = stiffness(both, pose)
    assert parallel.sources[legs[0]] == "actuator+spring"
    assert parallel.sprung[legs[0]] == pytest.approx(1.5 * K_LEG, rel=1e-15)


def test_the_loaded_stiffness_is_the_derivative_of_the_deflection(gs, pose):
    """Stiffness.loaded(W): the inverse of the deflected pose's derivative with respect to the wrench, by central
    differences of .deflection (steps 1e-5 of the load; the pose's change as a world-aligned twist) within 1e-6
    relative (2e-9 measured), 14 % from the unloaded stiffness; W = 0 gives .matrix (1e-12); a pure force (a
    conservative load) gives a symmetric K_t, a moment in world axes (not conservative) an unsymmetric one."""
    K = stiffness(gs, pose, joints={j: K_LEG for j in gs.actuated_names})
    assert np.abs(K.loaded(np.zeros(6)).matrix - K.matrix).max() <= 1e-12 * np.abs(K.matrix).max()
    W = np.array([3e4, -2e4, -1.5e5, 2e3, -1e3, 3e3])
    loaded = K.loaded(W)
    assert np.allclose(loaded.deflection.q, K.deflection(W).q, rtol=0, atol=1e-12)

    def pose_of(q):
        pin.framesForwardKinematics(gs.model, gs.data, q)
        M = gs.data.oMf[gs.ee_frame]
        return M.translation.copy(), M.rotation.copy()

    C = np.empty((6, 6))
    for i in range(6):
        h = 1e-5 * np.abs(W[:3] if i < 3 else W[3:]).max()
        (pp, Rp), (pm, Rm) = (pose_of(K.deflection(W + s * h * np.eye(6)[i]).q) for s in (1.0, -1.0))
        C[:, i] = np.concatenate([pp - pm, pin.log3(Rp @ Rm.T)]) / (2 * h)
    Kt = loaded.matrix
    assert np.abs(np.linalg.inv(C) - Kt).max() <= 1e-6 * np.abs(Kt).max()
    assert np.abs(Kt - K.matrix).max() > 0.1 * np.abs(K.matrix).max()
    assert np.abs(Kt - Kt.T).max() > 1e-5 * np.abs(Kt).max()
    force = K.loaded(np.r_[W[:3], 0.0, 0.0, 0.0]).matrix
    assert np.abs(force - force.T).max() <= 1e-9 * np.abs(force).max()


def test_a_configuration_outside_the_limits_is_flagged(gs, pose):
    """Legs 27 cm longer than the reference's (past their 1 m stroke): the stiffness is given, its outside_limits
    names every leg as Mechanism.outside_limits does and its repr says so; inside them, nothing is flagged."""
    legs = {j: K_LEG for j in gs.actuated_names}
    far = pkm.close_loops(gs, gs.actuated_q(gs.q_reference) + 0.27).q
    K = stiffness(gs, far, joints=legs)
    assert K.outside_limits == gs.outside_limits(far) == tuple(gs.actuated_names)
    assert "OUTSIDE the position limits: leg1" in repr(K)
    inside = stiffness(gs, pose, joints=legs)
    assert inside.outside_limits == () and "OUTSIDE" not in repr(inside)
