"""The acceptance set: closed-loop mechanisms pkm did not generate, in every format it reads, each loaded from its
file with no edits and given every generic answer (issue "bring your own mechanism").

Each mechanism (``examples/<folder>``, listed in ``examples/README.md`` with its source): assembled from its
files (closure residual <= 1e-10); forward then inverse kinematics back to the same actuators and task (<= 1e-9);
the forward Jacobian against Richardson-extrapolated finite differences of the loop closure (<= 1e-6 relative);
inverse then forward dynamics, every route (Khalil's projection and virtual work; the actuator-space model and
Pinocchio's ``constraintDynamics``), gives back the actuated and task accelerations (<= 1e-10 relative); the efforts
balance the power ``tau . qd_a = dE/dt`` (<= 1e-7 relative, the energy's rate from finite differences), idle motions
included: their rates are those of least kinetic energy (docs/conventions.md), so that no idle motion takes power
(the closed path's spin angle follows the loop closure, not the rates, which matters only where a body's energy
depends on its spin angle: none here); ``pkm fk``, ``pkm ik`` and ``pkm preview --html`` on its path.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm import cli
from pkm.core import dynamics
from pkm.core.kinematics import constraints
from pkm.errors import ModeChangeWarning, SpecError
from tests.fd import forward_jacobian_error, richardson

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
#: name -> (path, format)
ACCEPTANCE = {
    "fivebar": (EXAMPLES / "gepetto_fivebar", "URDF + YAML (Gepetto)"),
    "rssr": (EXAMPLES / "gepetto_rssr" / "robot.yaml", "URDF + YAML (Gepetto)"),
    "rpr3": (EXAMPLES / "rpr3" / "rpr3.closures.toml", "URDF + pkm spec"),
    "gough_stewart": (EXAMPLES / "gough_stewart" / "gough_stewart.closures.toml", "URDF + pkm spec"),
    "ankle": (EXAMPLES / "ankle" / "ankle.closures.toml", "URDF + pkm spec"),
    "knee": (EXAMPLES / "knee" / "knee.closures.toml", "URDF + pkm spec"),
    "mjcf_fourbar": (EXAMPLES / "mjcf_fourbar" / "fourbar.xml", "MJCF"),
    "slider_crank": (EXAMPLES / "sdf_slider_crank" / "slider_crank.closures.toml", "SDF + pkm spec"),
}
_CACHE: dict[str, pkm.Mechanism] = {}


def load(name: str) -> pkm.Mechanism:
    if name not in _CACHE:
        _CACHE[name] = pkm.load(ACCEPTANCE[name][0])
    return _CACHE[name]


def moved(mech: pkm.Mechanism) -> np.ndarray:
    """A closed configuration away from the reference: every actuator moved by 0.03 (rad or m), alternating."""
    qa = mech.actuated_q(mech.q_reference) + 0.03 * (-1.0) ** np.arange(mech.na)
    return pkm.close_loops(mech, qa, mech.q_reference, tol=1e-12).q


def test_the_set_covers_every_format_and_the_named_structures():
    formats = {fmt for _, fmt in ACCEPTANCE.values()}
    assert {"URDF + YAML (Gepetto)", "URDF + pkm spec", "MJCF", "SDF + pkm spec"} <= formats
    assert len(ACCEPTANCE) >= 8
    listed = (EXAMPLES / "README.md").read_text()
    for path, _ in ACCEPTANCE.values():
        assert path.exists()
        assert path.relative_to(EXAMPLES).parts[0] in listed  # each one's source is stated


@pytest.mark.parametrize("name", ACCEPTANCE)
def test_it_loads_assembled(name):
    mech = load(name)
    assert constraints.worst_closure(mech, constraints.residual(mech, mech.q_reference))[0] <= 1e-10
    assert mech.outside_limits(mech.q_reference) == ()


@pytest.mark.parametrize("name", ACCEPTANCE)
def test_forward_then_inverse_kinematics_round_trip(name):
    mech = load(name)
    q = moved(mech)
    y = pkm.TaskMap.of(mech).value(q)
    ik = pkm.solve_ik(mech, y, mech.q_reference, tol=1e-12)
    assert np.abs(mech.actuated_q(ik.q) - mech.actuated_q(q)).max() <= 1e-9
    assert np.abs(pkm.TaskMap.of(mech).error(y, pkm.TaskMap.of(mech).value(ik.q))).max() <= 1e-9


@pytest.mark.parametrize("name", ACCEPTANCE)
def test_forward_jacobian_matches_finite_differences(name):
    assert forward_jacobian_error(load(name), moved(load(name))) <= 1e-6


def check_every_route_gives_back(mech: pkm.Mechanism, q: np.ndarray, v: np.ndarray, a: np.ndarray,
                                 qdd: np.ndarray) -> None:
    """Inverse then forward dynamics: the efforts of every inverse route that takes the mechanism (``"khalil"``
    refuses some structures), fed to both forward routes (Pinocchio's ``constraintDynamics`` refuses mimic joints),
    give back the actuated accelerations ``qdd`` (1e-10 relative) and, through ``constraintDynamics``, the task
    accelerations (1e-10 relative)."""
    J, bias = pkm.TaskMap.of(mech).jacobian(q), pkm.TaskMap.of(mech).bias(q, v)
    mimic = any(j.shortname() == "JointModelMimic" for j in mech.model.joints)
    for method in dynamics.METHODS:
        try:
            tau = pkm.inverse_dynamics(mech, q, v, a, method=method)
        except SpecError:
            assert method == "khalil"
            continue
        for forward in dynamics.FORWARD_METHODS[:1 if mimic else 2]:
            # (constraintDynamics: proximal iterations where planar loops are closed by 3-D or 6-D equations)
            a_back = dynamics.forward_dynamics(mech, q, v, tau, method=forward)
            assert np.abs(a_back[mech.act_v] - qdd).max() <= 1e-10 * max(1.0, np.abs(qdd).max()), (method, forward)
            assert np.abs(J @ (a_back - a)).max() <= 1e-10 * max(1.0, np.abs(J @ a + bias).max()), (method, forward)


def check_efforts_give_back_accelerations(mech: pkm.Mechanism, q: np.ndarray):
    """Efforts for random actuated rates and accelerations at ``q``: every route gives them back
    (:func:`check_every_route_gives_back`). Returns ``(qd, qdd, tau)``."""
    rng = np.random.default_rng(3)
    qd, qdd = rng.normal(size=mech.na), rng.normal(size=mech.na)
    v = pkm.velocities(mech, q, qd)
    a = pkm.accelerations(mech, q, v, qdd)
    check_every_route_gives_back(mech, q, v, a, qdd)
    return qd, qdd, pkm.inverse_dynamics(mech, q, v, a)


@pytest.mark.parametrize("name", ACCEPTANCE)
def test_inverse_dynamics_gives_back_the_accelerations_and_balances_the_power(name):
    mech = load(name)
    q = moved(mech)
    qd, qdd, tau = check_efforts_give_back_accelerations(mech, q)

    def energy_rate(h):  # dE/dt along the closed motion with the actuators at qa + t qd + t^2/2 qdd
        def E(t):
            qt = pkm.close_loops(mech, mech.actuated_q(q) + t * qd + t * t / 2 * qdd, q, tol=1e-13).q
            return sum(dynamics.energy(mech, qt, pkm.velocities(mech, qt, qd + t * qdd)))
        return np.array([(E(h) - E(-h)) / (2 * h)])

    power = tau @ qd
    assert abs(power - richardson(energy_rate, 1e-3)[0]) <= 1e-7 * max(np.abs(tau).max() * np.abs(qd).max(), 1.0)


@pytest.mark.parametrize("name", ACCEPTANCE)
def test_the_command_line_runs_on_its_file(name, tmp_path, capsys):
    mech = load(name)
    path = str(ACCEPTANCE[name][0])
    q = moved(mech)
    joints = [f"{n}={float(v)!r}" for n, v in zip(mech.actuated_names, mech.actuated_q(q))]
    assert cli.main(["fk", path, "--joints", *joints]) == 0
    task = json.loads(capsys.readouterr().out)["task"]
    assert cli.main(["ik", path, "--pose", *(f"{k}={v!r}" for k, v in task.items())]) == 0
    back = json.loads(capsys.readouterr().out)["actuated"]
    assert np.allclose([back[n] for n in mech.actuated_names], mech.actuated_q(q), atol=1e-8)
    page = tmp_path / "preview.html"
    assert cli.main(["preview", path, "--html", str(page)]) == 0
    assert page.stat().st_size > 10_000


def test_the_mjcf_four_bar_keeps_its_link_lengths():
    """An independent check of the MJCF route: along the crank's turn, the coupler pin stays 0.25 m from the
    rocker's pivot and sqrt(0.1125) m from the crank pin, and the crank pin is on its 0.1 m circle."""
    mech = load("mjcf_fourbar")
    d = mech.data
    for theta in np.linspace(-0.6, 0.6, 7):
        q = pkm.close_loops(mech, [theta], mech.q_reference).q
        import pinocchio as pin

        pin.framesForwardKinematics(mech.model, d, q)
        B = d.oMf[mech.frame_id("coupler")].translation
        C = d.oMf[mech.frame_id("pin_c_a")].translation
        assert np.allclose(B, [0.1 * np.sin(theta), 0.0, 0.1 * np.cos(theta)], atol=1e-12)
        assert abs(np.linalg.norm(C - [0.3, 0.0, 0.0]) - 0.25) <= 1e-10
        assert abs(np.linalg.norm(C - B) - np.sqrt(0.1125)) <= 1e-10


def test_the_sdf_slider_crank_follows_its_closed_form():
    """x = r cos(theta) + sqrt(l^2 - r^2 sin^2(theta)), the slider's travel from its pose at theta = 0. From the
    reference (theta = 0.5) the crank crosses the dead centre (theta = 0, where dx/dtheta = -r sin(theta)(1 + ...)
    vanishes: the slider's two working modes meet) to reach theta < 0: those loop closures warn, the others not."""
    mech = load("slider_crank")
    r, l = 0.08, 0.25
    theta_ref = mech.actuated_q(mech.q_reference)[0]
    for theta in np.linspace(-1.0, 1.0, 9):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ModeChangeWarning)
            q = pkm.close_loops(mech, [theta], mech.q_reference).q
        x = r * np.cos(theta) + np.sqrt(l**2 - (r * np.sin(theta)) ** 2)
        assert abs(q[mech.joint("rail").idx_q] - (x - (r + l))) <= 1e-10
        crossed = theta != 0.0 and np.sign(np.sin(theta)) != np.sign(np.sin(theta_ref))
        assert [w.message.changed for w in caught if w.category is ModeChangeWarning] == \
            ([("working",)] if crossed else [])
