"""MuJoCo Menagerie's robots shipped with pkm, loaded by name (:mod:`pkm.core.formats.catalogue`), meshes removed,
the commit and every change in each folder's ``SOURCE.txt``.

Cassie (Agility Robotics, MIT: ``urdf/menagerie/agility_cassie/``): a real humanoid's legs as published, whose bodies
and joints share names, whose reference is its ``home`` key (open by about 2 mm, as MuJoCo's soft equalities leave
it), and whose knee loop is no transmission. Robotiq's 2F-85 gripper (BSD-2-Clause:
``urdf/menagerie/robotiq_2f85/``): two adaptive four-bar fingers closed by connects on bodies whose joints state a
``pos``, one motor on a tendon over both drivers. UFACTORY's xArm7 (BSD-3-Clause: ``urdf/menagerie/ufactory_xarm7/``):
an arm carrying a gripper of two parallelogram fingers closed by connects, the drivers tied by a gear equality (a
mimic joint with children under the arm, where Pinocchio 4.1's ``crba`` is wrong: its dynamics checked against
MuJoCo's). Each robot is loaded once per module (0.1 to 0.2 s)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core.dynamics.projection import constraint_dynamics
from pkm.core.kinematics import constraints
from pkm.errors import PkmError, PkmWarning, TransmissionError
from tests.fd import constraint_jacobian_error, forward_jacobian_error, rel
from tests.shipped import (
    MujocoAt,
    check_closes_from_a_moved_seed,
    check_mjcf_round_trip,
    check_round_trip,
    check_shipped,
)
from tests.test_acceptance import check_efforts_give_back_accelerations, moved

FEET = ("left-foot", "right-foot")


@pytest.fixture(scope="module")
def cassie() -> pkm.Mechanism:
    return pkm.load("menagerie:cassie")


@pytest.fixture(scope="module")
def feet(cassie):
    with pytest.warns(PkmWarning, match="left out"):  # (the knee loops: see the test of the knee)
        return pkm.transmissions(cassie, skip_unfit=True)


def test_it_ships_with_its_licence_and_source_and_no_mesh():
    text = check_shipped("menagerie:cassie", "cassie.xml", "Agility Robotics", (
        "google-deepmind/mujoco_menagerie", "agility_cassie/cassie.xml", "1b428b08bb26ca6024e7b21e8ff21a59f847eb87"))
    assert "mesh" not in text


def test_it_loads_at_its_home_key_closed_inside_every_limit_with_no_dependent_actuator(cassie):
    """The reference is the ``home`` key, its ten motors held (to 1e-15) and its loops closed (1e-10), inside every
    joint's range; no actuator depends on the others (from ``qpos0`` the foot crank sat at 0, outside [-140, -30]
    deg, and the foot motors were dependent)."""
    q = cassie.q_reference
    assert constraints.worst_closure(cassie, constraints.residual(cassie, q))[0] <= 1e-10
    assert cassie.outside_limits(q, tol=0.0) == () and cassie.dependent_actuators == ()
    home = dict(zip(cassie.actuated_names, (0.00449956, 0, 0.497301, -1.1997, -1.59681, -0.00449956, 0, 0.497301,
                                            -1.1997, -1.59681)))
    assert np.abs(cassie.actuated_q(q) - np.array(list(home.values()))).max() <= 1e-15
    assert any("<key name='home'>" in n for n in cassie.notes)
    assert cassie.model.frames[cassie.frame_id("left-hip-pitch")].type == pin.FrameType.BODY  # (a joint shares it)


def test_it_assembles_and_its_loops_close_again_from_a_seed_moved_by_0_02_rad(cassie):
    assert pkm.assemble(cassie).residual <= 1e-12
    check_closes_from_a_moved_seed(cassie)


def test_its_two_foot_transmissions_are_found_and_round_trip(feet):
    """Each foot's four-bar (foot motor, crank, plantar rod) is a transmission: motors +0.1 rad -> outputs ->
    motors comes back to 1e-10."""
    by_motor = {t.motors: t for t in feet}
    assert {(m,) for m in FEET} <= set(by_motor)
    for motor in FEET:
        check_round_trip(by_motor[(motor,)])


def test_its_knee_is_no_transmission_and_is_refused_by_name(cassie):
    """The knee loop (achilles rod to the heel spring) moves the shin and tarsus springs as well: three outputs for
    one motor, refused with a TransmissionError naming it (never Pinocchio's frame-name ValueError)."""
    with pytest.raises(TransmissionError) as err:
        pkm.transmissions(cassie)
    assert err.value.transmission == "left-tarsus" and err.value.reason == "outputs"
    assert "left-knee" in err.value.joints


def test_it_simulates_with_the_defaults(cassie):
    """10 ms with no effort (pkm.simulate holds the free pelvis where the reference puts it): no event, the loops
    closed (1e-10), and the energy balance (kinetic + potential + dissipated - work) constant to 1e-3 of the
    potential energy spent."""
    sim = pkm.simulate(cassie, duration=0.01)
    assert sim.event is None and sim.time[-1] == pytest.approx(0.01)
    assert np.max(sim.residual) <= 1e-10
    balance = sim.kinetic + sim.potential + sim.dissipated - sim.work
    assert np.abs(balance - balance[0]).max() <= 1e-3 * (sim.potential[0] - sim.potential[-1])


def test_its_leaf_springs_are_read_noted_and_saved(cassie, feet, tmp_path):
    """The shin (1500 N m/rad) and heel (1250 N m/rad) leaf springs and the passive joints' damping are ``[springs]``
    entries, named in the notes, written back by ``pkm.save`` (the spec loads back with the same tables) and carried
    into the foot transmissions' sub-mechanisms."""
    springs = cassie.spec.springs
    assert springs["left-shin"] == {"stiffness": 1500.0, "rest": 0.0, "damping": 0.1}
    assert springs["right-heel-spring"] == {"stiffness": 1250.0, "rest": 0.0}
    assert any("left-shin (stiffness 1500, rest 0, damping 0.1)" in n for n in cassie.notes)
    spec = pkm.ClosureSpec.from_toml(pkm.save(cassie, tmp_path / "cassie.closures.toml").read_text())
    assert spec.springs == springs
    assert all(t.mechanism.spec.springs == {f"{t.motors[0].partition('-')[0]}-foot-crank": {"damping": 1.0}}
               for t in feet)


def test_its_leaf_springs_moved_by_the_idle_rule_are_said_once():
    """The idle motions move Cassie's sprung leaf-spring joints: the first dynamics query warns, naming them, that
    their motion follows the idle-motion rule and not the springs (once a mechanism: the next query is silent)."""
    import warnings

    cassie = pkm.load("menagerie:cassie")  # (a fresh one: the warning is once a mechanism)
    with pytest.warns(PkmWarning, match=r"sprung joints \['left-shin', 'left-heel-spring', 'right-shin', "
                                        r"'right-heel-spring'\].*idle-motion rule"):
        pkm.actuator_model(cassie, cassie.q_reference)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pkm.actuator_model(cassie, cassie.q_reference)


def test_its_free_pelvis_moves_as_pinocchio_and_mujoco_say(cassie):
    """Forward dynamics with the pelvis free (the default), at a pose closed 0.1 rad from home, random motor efforts
    and rates and a random pelvis twist: the motors', the pelvis' and every other acceleration out of the idle
    motions equal Pinocchio's constraintDynamics of the same model to 1e-8 relative (measured 1.9e-13; the idle ones,
    three per leg: the shin, tarsus and heel-spring leaf springs with the achilles rod's spin, are the convention's,
    no idle motion in the mass metric, and are left out), and constraintDynamics' centre of mass falls at g (no
    wrench on a free body but gravity; the convention's idle accelerations move the legs' mass, so pkm's full
    vector does not: 4.75 m/s^2 off here). At rest, constraintDynamics (every joint, the leaf springs' efforts
    included) equals MuJoCo on the same file, the efforts through its motors and gears, with its four connects held
    exactly (:meth:`~tests.shipped.MujocoAt.held`; ten of the twelve rows independent, each knee loop being planar)
    to 1e-8 (measured 1e-11); MuJoCo's own soft answer at its stiffest equalities (solref 1e-4 s, solimp 0.9999)
    stays 5.3e-4 off: its softness, bounded here at 2e-3."""
    rng = np.random.default_rng(3)
    q = pkm.close_loops(cassie, cassie.actuated_q(cassie.q_reference) + 0.1 * rng.uniform(-1, 1, cassie.na),
                        cassie.q_reference).q
    tau = 10.0 * rng.normal(size=cassie.na)
    rates = np.zeros(cassie.nv)
    rates[cassie.base_v], rates[cassie.act_v] = rng.normal(size=6), rng.normal(size=cassie.na)
    model = pkm.actuator_model(cassie, q, rates)
    N = model.idle
    assert model.base == "free" and N.shape[1] == 6 and not np.any(N[cassie.base_v]) and not np.any(N[cassie.act_v])
    a = pkm.forward_dynamics(cassie, q, model.v, tau)
    a_cd = constraint_dynamics(cassie, q, model.v, tau)
    assert rel(a - N @ (N.T @ a), a_cd - N @ (N.T @ a_cd)) <= 1e-8
    pin.centerOfMass(cassie.model, cassie.data, q, model.v, a_cd)
    assert np.abs(cassie.data.acom[0] - cassie.model.gravity.linear).max() <= 1e-8 * 9.81
    rest = np.zeros(cassie.nv)
    a_cd = constraint_dynamics(cassie, q, rest, tau)
    a = pkm.forward_dynamics(cassie, q, rest, tau)
    assert rel(a[cassie.act_v], a_cd[cassie.act_v]) <= 1e-8 and rel(a[cassie.base_v], a_cd[cassie.base_v]) <= 1e-8
    mj = MujocoAt(cassie, "menagerie:cassie", q)
    m, d = mj.m, mj.d
    efforts = dict(zip(cassie.actuated_names, tau))  # (through the file's motors and gears)
    d.ctrl[:] = [efforts[mj.mujoco.mj_id2name(m, mj.mujoco.mjtObj.mjOBJ_ACTUATOR, k)] / m.actuator_gear[k, 0]
                 for k in range(m.nu)]
    assert np.all(np.abs(d.ctrl) <= m.actuator_ctrlrange[:, 1])  # (no control clamped)
    mj.forward()
    exact = mj.held()
    assert rel(mj.dofs(a_cd), exact) <= 1e-8
    m.opt.timestep = 5e-5  # (MuJoCo clamps a time constant to twice the step)
    m.eq_solref[:] = [1e-4, 1.0]
    m.eq_solimp[:] = [0.9999, 0.9999, 0.001, 0.5, 2.0]
    mj.forward()
    assert rel(d.qacc, exact) <= 2e-3


# ---------------------------------------------------------------------- the grippers: Robotiq's 2F-85, the xArm7's
@dataclass(frozen=True)
class Gripper:
    """What a shipped gripper's tests expect of it."""

    file: str
    source: tuple[str, ...]  # (LICENSE's holder, then the repository, path, commit and licence SOURCE.txt names)
    actuated: tuple[str, ...]
    reference: tuple[float, ...]  # (the actuated values of the reference)
    said: tuple[str, ...]  # (in the notes)
    idle: int  # (idle motions: an adaptive finger keeps one freedom no motor drives)
    springs: tuple[str, ...]


MENAGERIE = ("google-deepmind/mujoco_menagerie", "1b428b08bb26ca6024e7b21e8ff21a59f847eb87")
GRIPPERS = {
    "menagerie:robotiq_2f85": Gripper(
        "2f85.xml", ("ROS-Industrial", *MENAGERIE, "robotiq_2f85/2f85.xml", "BSD-2-Clause"), ("left_driver_joint",),
        (0.0,), ("tendon 'split'", "read as a mimic coupling: right_driver_joint = 1 left_driver_joint"), 2,
        ("left_spring_link_joint", "right_spring_link_joint")),
    "menagerie:xarm7": Gripper(
        "xarm7.xml", ("UFACTORY", MENAGERIE[0], "ufactory_xarm7/xarm7.xml", "a2014268d77c6a8cd642a523628fc82a900b83b7",
                      "BSD-3-Clause"), (*(f"joint{k}" for k in range(1, 8)), "left_driver_joint"),
        (0, -0.247, 0, 0.909, 0, 1.15644, 0, 0),
        ("tendon 'split'", "<key name='home'>",  # (the unnamed gear by its rank: ``joint1`` is the arm's first joint)
         "<equality><joint> 1 (unnamed) read as a mimic coupling: left_driver_joint = 1 right_driver_joint"), 0,
        ("left_inner_knuckle_joint", "right_inner_knuckle_joint")),
}
_LOADED: dict[str, pkm.Mechanism] = {}


def gripper(name: str) -> pkm.Mechanism:
    """Shipped gripper ``name``, loaded once per test process."""
    if name not in _LOADED:
        _LOADED[name] = pkm.load(name)
    return _LOADED[name]


@pytest.mark.parametrize("name", GRIPPERS)
def test_the_gripper_ships_and_loads_with_its_motor_on_the_tendon_over_both_drivers(name):
    """Menagerie's Robotiq 2F-85 (BSD-2-Clause) and UFACTORY's xArm7 (BSD-3-Clause: seven arm motors and the gripper),
    meshes removed: the gripper's one motor acts on the tendon ``split`` (half of each driver), the drivers tied by a
    joint equality (one a mimic of the other, as the notes say): one actuated joint; the two finger loops are point
    closures, closed at the reference (MuJoCo's qpos0, the xArm's ``home`` key) to 1e-12 inside every limit with no
    dependent actuator. Each of the 2F-85's adaptive fingers keeps one freedom no motor drives (two idle motions,
    held by the spring links' springs, which are read); the xArm's are parallelograms (none; the inner knuckles'
    springs read). Assembly closes (1e-12), the loops close again from a moved seed, the closures' Jacobian equals
    differences (1e-7 relative), and the forward Jacobian too (1e-6 relative, Richardson)."""
    mech, expected = gripper(name), GRIPPERS[name]
    check_shipped(name, expected.file, expected.source[0], expected.source[1:])
    assert mech.actuated_names == expected.actuated and mech.base is None
    assert [c.type for c in mech.spec.closures] == ["point", "point"]
    notes = " ".join(mech.notes)
    assert all(s in notes for s in expected.said) and "name='joint1'" not in notes
    q = mech.q_reference
    assert np.abs(mech.actuated_q(q) - expected.reference).max() <= 1e-15
    assert constraints.worst_closure(mech, constraints.residual(mech, q))[0] <= 1e-12
    assert mech.outside_limits(q, tol=0.0) == () and mech.dependent_actuators == ()
    assert pkm.diagnose(mech, q).idle_motions == expected.idle
    assert set(mech.spec.springs) == set(expected.springs)
    assert pkm.assemble(mech).residual <= 1e-12
    check_closes_from_a_moved_seed(mech)
    assert constraint_jacobian_error(mech, q) <= 1e-7
    assert forward_jacobian_error(mech, moved(mech)) <= 1e-6


@pytest.mark.parametrize("name", GRIPPERS)
def test_mujoco_holds_the_gripper_s_connects_where_pkm_closes_them(name):
    """At pkm's closed pose with every motor 0.3 rad from the reference, MuJoCo on the same file puts every body where
    pkm does (1e-12 m) and finds its two connects and the drivers' equality held (1e-12 m or rad). Before, pkm took
    Pinocchio's anchors, in the followers' joint frames (19 mm from their bodies' on the 2F-85): the connects stood
    0.46 mm open and the followers were idle spins. pkm's MJCF of it, read back, closes there with every joint in
    place (1e-12 m)."""
    mech = gripper(name)
    q = pkm.close_loops(mech, mech.actuated_q(mech.q_reference) + 0.3, mech.q_reference).q
    mj = MujocoAt(mech, name, q)
    mj.forward()
    assert mj.body_gap() <= 1e-12
    rows = mj.equality_rows()
    assert rows.size == 2 * 3 + 1 and np.abs(rows).max() <= 1e-12
    check_mjcf_round_trip(mech, np.full(mech.na, 0.3))


def test_the_2f85_s_underactuated_fingers_are_refused_as_transmissions():
    """Each adaptive finger has two freedoms and one input: no transmission. The refusals are TransmissionErrors:
    the left finger's outputs leave the motor free, the right finger's loop holds no actuated joint (its driver
    follows the left one by the gear equality, which the refusal names), and with both left out nothing remains
    (``no_loop``)."""
    robotiq = gripper("menagerie:robotiq_2f85")
    with pytest.raises(TransmissionError):
        pkm.transmissions(robotiq)
    with pytest.warns(PkmWarning) as caught, pytest.raises(TransmissionError) as err:
        pkm.transmissions(robotiq, skip_unfit=True)
    assert err.value.reason == "no_loop"
    said = " ".join(str(w.message) for w in caught)
    assert "with the outputs held the motors can move" in said and "hold no actuated joint" in said
    assert "'right_driver_joint' follows 'left_driver_joint'" in said


def test_mujoco_accelerates_the_xarm_as_pkm_does():
    """Pinocchio's ``constraintDynamics`` refuses mimic joints (a PkmError naming it), so the xArm's dynamics is
    checked against MuJoCo on the same file, at pkm's closed pose with every motor 0.3 rad from home, at rest under
    random motor efforts (the file's servo gains, the passive joints' armature, which pkm says it does not read,
    friction loss and contacts off in MuJoCo): every joint's acceleration from ``pkm.forward_dynamics`` equals MuJoCo's with its equalities held exactly (1e-8
    relative, measured 2.7e-12), and inverse then forward dynamics gives the accelerations back; forward dynamics
    asked twice answers the same (Pinocchio 4.1's ``crba`` on a reused ``Data`` drifted by 0.29 rad/s^2 a call
    here)."""
    xarm = gripper("menagerie:xarm7")
    q = pkm.close_loops(xarm, xarm.actuated_q(xarm.q_reference) + 0.3, xarm.q_reference).q
    mj = MujocoAt(xarm, "menagerie:xarm7", q)
    tau = np.random.default_rng(3).normal(size=xarm.na)
    with pytest.raises(PkmError, match="mimic"):
        constraint_dynamics(xarm, q, np.zeros(xarm.nv), tau)
    a = pkm.forward_dynamics(xarm, q, np.zeros(xarm.nv), tau)
    assert np.array_equal(pkm.forward_dynamics(xarm, q, np.zeros(xarm.nv), tau), a)
    m, d, mujoco = mj.m, mj.d, mj.mujoco
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS
    m.actuator_gainprm[:], m.actuator_biasprm[:] = 0.0, 0.0  # (the efforts applied instead, on the motors' joints)
    joints = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, k) for k in range(m.njnt)]
    for k, name in enumerate(joints):
        if name in xarm.actuated_names:
            d.qfrc_applied[m.jnt_dofadr[k]] = tau[xarm.actuated_names.index(name)]
        else:
            m.dof_armature[m.jnt_dofadr[k]] = 0.0
    mj.forward()
    assert rel(mj.dofs(a), mj.held()) <= 1e-8
    check_efforts_give_back_accelerations(xarm, moved(xarm))


def test_the_xarm_s_left_finger_is_a_transmission_and_its_right_one_is_refused_by_name():
    """The left finger's parallelogram (its driver, the motor) is a transmission: motor +0.1 rad -> output (the
    inner knuckle) -> motor back to 1e-10, the effort map the transpose of the output's differences (1e-7 relative).
    The right finger's loop holds no actuated joint (its driver follows the left one by the gear equality): a
    TransmissionError naming the coupling, and ``skip_unfit`` leaves it out with a warning."""
    xarm = gripper("menagerie:xarm7")
    with pytest.raises(TransmissionError) as err:
        pkm.transmissions(xarm)
    assert err.value.transmission == "right_driver_joint" and "follows 'left_driver_joint'" in str(err.value)
    with pytest.warns(PkmWarning, match="right_driver_joint"):
        (t,) = pkm.transmissions(xarm, skip_unfit=True)
    assert t.motors == ("left_driver_joint",)
    qm, q_sub = check_round_trip(t)
    h = 1e-6
    J = (t.outputs_from_motors(qm + h, q_sub)[0] - t.outputs_from_motors(qm - h, q_sub)[0]) / (2 * h)
    assert np.abs(t.effort_map(q_sub) - J.T).max() <= 1e-7 * np.abs(J).max()
