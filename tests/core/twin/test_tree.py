"""pkm.core.twin: the symbolic twin of any mechanism equals Pinocchio (and pkm's own routes) on random states, to
1e-12: frame placements and Jacobians, closure residual, Jacobian and drift, RNEA, energies."""

from __future__ import annotations

from pathlib import Path

import casadi as cs
import numpy as np
import pinocchio as pin
import pytest

import pkm
from pkm.core import dynamics
from pkm.core.kinematics import constraints
from pkm.core.model.spec import Closure, ClosureSpec, TaskSpec
from pkm.core.twin import Twin
from pkm.errors import SpecError

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
FILES = {"rssr": EXAMPLES / "gepetto_rssr" / "robot.yaml",
         "gough_stewart": EXAMPLES / "gough_stewart" / "gough_stewart.closures.toml",
         "ankle": EXAMPLES / "ankle" / "ankle.closures.toml",
         "mjcf_fourbar": EXAMPLES / "mjcf_fourbar" / "fourbar.xml"}
TOL = 1e-12


def zoo() -> pkm.Mechanism:
    """A tree of every joint kind the twin handles that the example files lack: planar, unbounded revolute,
    unaligned revolute and prismatic, a mimic joint with a multiplier and an offset (URDF text); two chains tied
    by a frame closure and a point closure, placed so that the neutral configuration closes them."""
    rng = np.random.default_rng(4)

    def origin():
        return (f'<origin xyz="{" ".join(map(str, rng.uniform(-0.3, 0.3, 3)))}" '
                f'rpy="{" ".join(map(str, rng.uniform(-1, 1, 3)))}"/>')

    def link(name):
        m, c, I = rng.uniform(0.5, 2.0), rng.uniform(-0.1, 0.1, 3), rng.uniform(0.01, 0.05, 3)
        return (f'<link name="{name}"><inertial><origin xyz="{" ".join(map(str, c))}"/><mass value="{m}"/>'
                f'<inertia ixx="{I[0]}" iyy="{I[1]}" izz="{I[2]}" ixy="0" ixz="0" iyz="0"/></inertial></link>')

    def joint(name, kind, parent, child, axis="0 0 1", extra=""):
        limit = '<limit effort="1" velocity="1"/>' if kind in ("revolute", "prismatic") else ""
        return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>{origin()}'
                f'<axis xyz="{axis}"/>{limit}{extra}</joint>')

    urdf = ('<robot name="zoo"><link name="ground"/>' + "".join(link(n) for n in ("b1", "b2", "b3", "b4", "b5", "b6"))
            + joint("planar", "planar", "ground", "b1") + joint("spin", "continuous", "b1", "b2", "1 0 0")
            + joint("tilt", "revolute", "b2", "b3", "0.3 -0.5 0.8") + joint("slide", "prismatic", "b3", "b4", "0.8 -0.5 0.3")
            + joint("leader", "revolute", "ground", "b5", "0 1 0")
            + joint("follower", "revolute", "b5", "b6", "0 1 0", '<mimic joint="leader" multiplier="2.0" offset="0.3"/>')
            + "</robot>")
    model = pin.buildModelFromXML(urdf, mimic=True)
    j4, j6 = model.getJointId("slide"), model.getJointId("follower")
    d = model.createData()
    pin.forwardKinematics(model, d, pin.neutral(model))
    for name, at in (("tip", pin.SE3(pin.rpy.rpyToMatrix(0.2, -0.4, 0.9), np.array([0.05, 0.1, -0.02]))),
                     ("pin", pin.SE3(np.eye(3), np.array([0.1, 0.0, 0.0])))):
        model.addFrame(pin.Frame(f"{name}_a", j4, 0, at, pin.FrameType.OP_FRAME))
        model.addFrame(pin.Frame(f"{name}_b", j6, 0, d.oMi[j6].actInv(d.oMi[j4] * at), pin.FrameType.OP_FRAME))
    spec = ClosureSpec(mechanism="zoo", urdf="zoo.urdf", end_effector="tip_a", actuated=("leader",),
                       closures=(Closure("weld", "frame", "tip_a", "tip_b"), Closure("pin", "point", "pin_a", "pin_b")),
                       task=TaskSpec(("x",)), reference={})
    return pkm.Mechanism(model, spec)


def _mechanism(name: str) -> pkm.Mechanism:
    return pkm.load(FILES[name]) if name in FILES else pkm.load(name)


def _check(mech: pkm.Mechanism, q_samples, rng) -> dict[str, float]:
    tw = Twin(mech)
    frames = sorted({mech.ee_frame, *(f for pair in mech.closure_frames for f in pair)})
    out = {"r": tw.closure_residual, "J": tw.closure_jacobian, "g": tw.closure_drift, "tau": tw.rnea,
           "T": tw.kinetic_energy, "V": tw.potential_energy}
    for f in frames:
        out[f"p{f}"] = tw.frame_placement(f).p
        out[f"R{f}"] = tw.frame_placement(f).R
        out[f"J{f}"] = tw.frame_jacobian(f)
    fun = tw.function("check", out)
    err: dict[str, float] = {}
    for q in q_samples:
        v, a = rng.normal(size=mech.nv), rng.normal(size=mech.nv)
        got = fun(q=q, v=v, a=a)
        d = mech.model.createData()
        pin.computeJointJacobians(mech.model, d, q)
        pin.updateFramePlacements(mech.model, d)
        ref = {"r": constraints.residual(mech, q), "J": constraints.jacobian(mech, q),
               "g": constraints.drift(mech, q, v), "tau": pin.rnea(mech.model, mech.model.createData(), q, v, a)}
        ref["T"], ref["V"] = dynamics.energy(mech, q, v)
        for f in frames:
            ref[f"p{f}"], ref[f"R{f}"] = d.oMf[f].translation, d.oMf[f].rotation
            ref[f"J{f}"] = pin.getFrameJacobian(mech.model, d, f, pin.LOCAL_WORLD_ALIGNED)
        for k, r in ref.items():
            key = k if k in ("r", "J", "g", "tau", "T", "V") else k[0]
            scale = max(1.0, float(np.abs(r).max()))
            err[key] = max(err.get(key, 0.0), float(np.abs(np.array(got[k]).ravel() - np.ravel(r)).max()) / scale)
    return err


@pytest.mark.parametrize("name", [*pkm.MECHANISMS, *FILES])
def test_the_twin_equals_pinocchio_on_random_states(name):
    """Shipped mechanisms (the hexapod's mimic joints included) and files with ball, universal and free-flyer joints:
    every quantity to 1e-12 (relative to its size) at random configurations, velocities and accelerations."""
    mech = _mechanism(name)
    rng = np.random.default_rng(0)
    qs = [pin.randomConfiguration(mech.model, -np.ones(mech.nq), np.ones(mech.nq)) for _ in range(3)]
    err = _check(mech, qs, rng)
    assert max(err.values()) <= TOL, err


def test_every_joint_kind_of_the_zoo():
    """Planar, unbounded revolute, unaligned axes, a mimic joint scaled by 2 and offset by 0.3, a frame closure."""
    mech = zoo()
    kinds = {j.kind for j in mech.joints.values()}
    assert {"JointModelPlanar", "JointModelRUBX", "JointModelRevoluteUnaligned", "JointModelPrismaticUnaligned",
            "JointModelMimic"} <= kinds
    rng = np.random.default_rng(1)
    qs = [pin.randomConfiguration(mech.model, -np.ones(mech.nq), np.ones(mech.nq)) for _ in range(4)]
    err = _check(mech, qs, rng)
    assert max(err.values()) <= TOL, err


def test_a_joint_the_twin_does_not_handle_is_refused():
    model = pin.Model()
    j = model.addJoint(0, pin.JointModelSphericalZYX(), pin.SE3.Identity(), "zyx")
    model.appendBodyToJoint(j, pin.Inertia.Random(), pin.SE3.Identity())
    model.addFrame(pin.Frame("a", j, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    model.addFrame(pin.Frame("b", j, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    j2 = model.addJoint(j, pin.JointModelRX(), pin.SE3.Identity(), "r")
    model.appendBodyToJoint(j2, pin.Inertia.Random(), pin.SE3.Identity())
    spec = ClosureSpec(mechanism="zyx", urdf="s.urdf", end_effector=None, actuated=("r",),
                       closures=(Closure("c", "point", "a", "b"),), task=TaskSpec((), ("r",)), reference={})
    with pytest.raises(SpecError, match="does not handle a Pinocchio JointModelSphericalZYX"):
        Twin(pkm.Mechanism(model, spec))


@pytest.mark.parametrize("name", [*pkm.MECHANISMS, "gough_stewart", "mjcf_fourbar"])
def test_the_twins_efforts_equal_the_generic_inverse_dynamics(name):
    """G^T rnea from the twin, at states from pkm.velocities and pkm.accelerations: pkm.inverse_dynamics to 1e-10
    relative; the same function mapped over a batch of samples gives the same numbers; its derivative in v
    against central differences (1e-6 relative)."""
    mech = _mechanism(name)
    tw = Twin(mech)
    fun = tw.function("tau", {"tau": tw.actuated_efforts})
    rng = np.random.default_rng(5)
    q = mech.q_reference
    states = []
    for _ in range(3):
        v = pkm.velocities(mech, q, rng.normal(size=mech.na))
        states.append((q, v, pkm.accelerations(mech, q, v, rng.normal(size=mech.na))))
    for q, v, a in states:
        ref = pkm.inverse_dynamics(mech, q, v, a)
        assert np.abs(np.array(fun(q, v, a)).ravel() - ref).max() <= 1e-10 * max(1.0, np.abs(ref).max())
    Q, V, A = (np.column_stack([s[k] for s in states]) for k in range(3))
    batch = np.array(fun.map(len(states))(Q, V, A))
    assert np.abs(batch - np.column_stack([np.array(fun(*s)).ravel() for s in states])).max() <= 1e-13
    dtau_dv = tw.function("d", {"d": cs.jacobian(tw.actuated_efforts, tw.v)})
    q, v, a = states[0]
    h = 1e-6
    fd = np.column_stack([(np.array(fun(q, v + e, a)) - np.array(fun(q, v - e, a))).ravel() / (2 * h)
                          for e in h * np.eye(mech.nv)])
    exact = np.array(dtau_dv(q, v, a))
    assert np.linalg.norm(exact - fd) <= 1e-6 * max(1.0, np.linalg.norm(exact))


def test_idle_motions_are_left_to_the_generic_route():
    twin = Twin(_mechanism("ankle"))
    for what in ("actuated_efforts", "passive_map", "accelerations", "closure_step"):
        with pytest.raises(SpecError, match="idle motions"):
            getattr(twin, what)


def test_a_twin_function_compiles_to_c_or_says_why_not(tmp_path, monkeypatch):
    """With a C compiler the efforts run as compiled C and equal the SX function (1e-13); without one the SX
    function comes back, saying so."""
    import shutil

    from pkm.core.twin import compile_function

    mech = _mechanism("prs3")
    tw = Twin(mech)
    fun = tw.function("prs3_tau", {"tau": tw.actuated_efforts})
    q, v, a = mech.q_reference, np.full(mech.nv, 0.1), np.full(mech.nv, -0.2)
    compiled, how = compile_function(fun, tmp_path)
    if shutil.which("cc") or shutil.which("gcc") or shutil.which("clang"):
        assert how.startswith("C (") and len(list(tmp_path.glob("prs3_tau-*.so"))) == 1
    assert np.abs(np.array(compiled(q, v, a)) - np.array(fun(q, v, a))).max() <= 1e-13
    monkeypatch.setattr(shutil, "which", lambda name: None)
    same, how = compile_function(fun, tmp_path / "none")
    assert same is fun and "no C compiler" in how


@pytest.mark.parametrize("name", ["delta", "prs3", "hexapod", "gough_stewart", "mjcf_fourbar"])
def test_the_twins_rate_maps_and_newton_step_equal_the_generic_core(name):
    """G, the joint rates and accelerations from the actuated ones (1e-10 relative), and the loop closure's
    Gauss-Newton step from a perturbed configuration (the least-squares step of numpy, 1e-10), then the steps
    iterated by the twin close the loops (1e-12)."""
    mech = _mechanism(name)
    tw = Twin(mech)
    fun = tw.function("maps", {"G": tw.passive_map, "vel": tw.velocities, "acc": tw.accelerations},
                      ("q", "v", "qd", "qdd"))
    rng = np.random.default_rng(8)
    q = mech.q_reference
    qd, qdd = rng.normal(size=mech.na), rng.normal(size=mech.na)
    v = pkm.velocities(mech, q, qd)
    out = fun(q=q, v=v, qd=qd, qdd=qdd)
    ref_G = pkm.passive_map(mech, q)
    assert np.abs(np.array(out["G"]) - ref_G).max() <= 1e-10 * max(1.0, np.abs(ref_G).max())
    assert np.abs(np.array(out["vel"]).ravel() - v).max() <= 1e-10 * max(1.0, np.abs(v).max())
    ref_a = pkm.accelerations(mech, q, v, qdd)
    assert np.abs(np.array(out["acc"]).ravel() - ref_a).max() <= 1e-10 * max(1.0, np.abs(ref_a).max())
    step = tw.function("step", {"dq": tw.closure_step}, ("q",))
    dq = np.zeros(mech.nv)
    dq[mech.passive_v] = 0.01 * rng.normal(size=len(mech.passive_v))
    qp = pin.integrate(mech.model, q, dq)
    Jp = constraints.jacobian(mech, qp)[:, mech.passive_v]
    expected = np.linalg.lstsq(Jp, -constraints.residual(mech, qp), rcond=None)[0]
    got = np.array(step(qp)).ravel()
    assert np.abs(got[mech.passive_v] - expected).max() <= 1e-10 * max(1.0, np.abs(expected).max())
    assert np.abs(np.delete(got, mech.passive_v)).max() == 0.0
    for _ in range(8):
        qp = pin.integrate(mech.model, qp, np.array(step(qp)).ravel())
    assert np.abs(constraints.residual(mech, qp)).max() <= 1e-12


def test_the_task_is_built_on_the_twin_and_kept_with_it():
    """The twin does not import its task (tests/test_import_graph.py): ``TaskTwin.of`` gives one per twin, whose
    target is laid out as the task map's values, and ``Twin.task`` says where it went."""
    from pkm.core.twin.task import TaskTwin

    mech = pkm.load("rrr3")
    tw = Twin(mech)
    task = TaskTwin.of(tw)
    assert TaskTwin.of(tw) is task and task.tw is tw
    assert task.task_target.shape == (pkm.TaskMap.of(mech).value_size, 1)
    with pytest.raises(AttributeError, match=r"moved to pkm\.core\.twin\.task\.TaskTwin\.of\(twin\)"):
        tw.task  # noqa: B018
