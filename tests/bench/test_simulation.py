"""pkm.bench.simulation (issue 29's acceptance numbers), quick: runs of 0.1 s (0.05 s tracking), thresholds asserted.

Energy: the spring runs conserve the energy (spring included) to 1e-6 relative to the largest kinetic energy;
with viscous friction it never rises by more than one step's change of the frictionless run, and ``E +
dissipated`` is constant to the trapezoid's own error (Simpson's rule: 1e-6). Chirp: pkm's closure residual is
<= 1e-12; the Baumgarte and MuJoCo (default and stiff equalities) trajectories are within their stated bounds.
Computed torque: 1e-6 with the exact model, far more with a 10 % heavier platform in the controller's model.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from pkm.bench import arguments, simulation


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("simulation")
    return json.loads(json.dumps(simulation.run(arguments(simulation, ["--out", str(out)], quick=True)))), out


def test_quick_sizes_apply_to_the_options_not_given():
    """--quick gives runs of 0.1 s (tracking 0.05 s) on two mechanisms (one shipped, one loaded), except what the command line sets."""
    args = arguments(simulation, ["--quick", "--duration", "0.2"])
    assert (args.duration, args.chirp_duration, args.tracking_duration) == (0.2, 0.1, 0.05)
    assert args.mechanisms == ["delta", "ankle"]
    assert arguments(simulation, []).mechanisms == [*simulation.SHIPPED, *simulation.ACCEPTANCE]


def test_energy_is_conserved_with_the_spring_and_decreases_with_friction(quick):
    result, _ = quick
    assert list(result["energy"]) == ["delta", "ankle"]
    for name, e in result["energy"].items():
        assert "skipped" not in e, name
        free, spring, friction = e["free"], e["spring"], e["friction"]
        assert free["drift_relative"] is None or free["drift_relative"] <= 1e-6, name
        assert not spring["event"] and spring["seconds"] == pytest.approx(0.1), name
        assert spring["drift_relative"] <= 1e-6, name
        assert friction["monotone"] and friction["largest_rise_J"] <= friction["rise_tolerance_J"], name
        assert friction["balance_within_trapezoid_error"], name
        assert friction["balance_simpson_relative"] <= 1e-6, name
        assert 0.0 < friction["energy_left"] < 1.0, name


def test_independent_simulators_agree_within_their_bounds(quick):
    result, _ = quick
    assert list(result["chirp"]) == ["delta", "prs3", "ankle"]
    for name, c in result["chirp"].items():
        assert c["pkm"]["max_residual"] <= 1e-12 and not c["pkm"]["event"], name
        b = c["baumgarte"]
        assert b["within"] and b["max_difference"] <= b["bound"] <= 1e-8, name
        for key in ("mujoco", "mujoco_stiff"):
            m = c[key]
            if "skipped" in m:
                continue
            assert m["within"] and m["max_difference"] <= m["bound"], (name, key)
        if "skipped" not in c["mujoco"]:  # the stiffer equalities open less and follow pkm closer
            assert c["mujoco"]["eq_solref"] == [0.02, 1.0] and c["mujoco_stiff"]["eq_solref"] == [0.002, 1.0]
            assert c["mujoco_stiff"]["max_residual"] < 0.1 * c["mujoco"]["max_residual"]
            assert c["mujoco_stiff"]["max_difference"] < 0.1 * c["mujoco"]["max_difference"]


def test_computed_torque_tracks_to_1e_6_with_the_exact_model(quick):
    result, out = quick
    for name, c in result["tracking"].items():
        assert c["exact"]["max_error"] <= 1e-6, name
        assert c["heavier"]["max_error"] > 100.0 * c["exact"]["max_error"], name
        assert c["heavier"]["max_error"] < 0.2 * max(c["amplitude"]), name
    assert result["figure"] == str(out / "simulation_tracking.png") and (out / "simulation_tracking.png").stat().st_size


def test_the_table_lists_every_section(quick):
    result, _ = quick
    text = simulation.table(result)
    for header in ("Energy", "Chirp", "Computed torque", "Baumgarte Kp 10000"):
        assert header in text
    assert all(name in text for name in result["energy"])


def test_the_heavier_copy_leaves_the_mechanism_alone(built):
    """The controller's model: the platform's mass and rotational inertia times 1.1, same centre of mass; the
    mechanism itself is unchanged."""
    mech = built("delta")
    j = mech.model.frames[mech.ee_frame].parentJoint
    before = mech.model.inertias[j].mass
    heavy = simulation.heavier(mech)
    assert heavy.model.inertias[j].mass == pytest.approx(1.1 * before) and mech.model.inertias[j].mass == before
    assert np.allclose(heavy.model.inertias[j].lever, mech.model.inertias[j].lever)
    others = [k for k in range(1, mech.model.njoints) if k != j]
    assert all(heavy.model.inertias[k].mass == mech.model.inertias[k].mass for k in others)


def test_the_reference_trajectory_s_rates_are_its_derivatives():
    """q_r starts at q_a0 at rest; its rates and accelerations are its central differences (1e-6 relative)."""
    ref = simulation.Reference(np.array([0.1, -0.2]), np.array([0.05, 0.005]), np.array([0.5, 1.0]))
    t = np.linspace(0.0, 2.0, 2001)
    r, rd, rdd = ref(t)
    assert np.allclose(r[0], [0.1, -0.2]) and np.allclose(rd[0], 0.0)
    h = t[1] - t[0]
    assert np.abs((r[2:] - r[:-2]) / (2 * h) - rd[1:-1]).max() <= 1e-4 * np.abs(rd).max()
    assert np.abs((rd[2:] - rd[:-2]) / (2 * h) - rdd[1:-1]).max() <= 1e-4 * np.abs(rdd).max()


def test_the_table_says_what_was_not_run(quick):
    """Without MuJoCo its columns are dashes and the reason is printed; a mechanism whose files are absent (an
    installed wheel has no examples/) is listed as skipped."""
    import copy

    result = copy.deepcopy(quick[0])
    for c in result["chirp"].values():
        c["mujoco"] = c["mujoco_stiff"] = {"skipped": "MuJoCo is not installed (blocked)"}
    result["energy"]["rssr"] = {"skipped": "examples/ absent (an installed wheel)"}
    lines = simulation.table(result).splitlines()
    delta = next(ln for ln in lines if ln.startswith("delta ") and "e-" in ln and ln.split()[-1] == "-")
    assert delta.split()[-3:] == ["-", "-", "-"]
    assert any("MuJoCo is not installed (blocked)" in ln for ln in lines)
    assert "rssr           skipped: examples/ absent (an installed wheel)" in lines
    assert not any(ln.startswith("MuJoCo, stiffer") for ln in lines)


def test_acceptance_mechanisms_are_skipped_without_the_checkout_s_examples(monkeypatch):
    """Here examples/ is found; without it (an installed wheel) the acceptance set's names give the reason."""
    assert simulation.examples() is not None
    monkeypatch.setattr(simulation, "examples", lambda: None)
    assert simulation.mechanism("ankle") == "examples/ absent (an installed wheel)"
    assert simulation.mechanism("nope").startswith("unknown here")
