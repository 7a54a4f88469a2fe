"""pkm.bench.simulation_speed run quick (a few seconds: to check it runs and what it compares, not its timings): the
fused C kernel's M_a and h_a equal the Python model's, the C and Python backends the same Delta run; its start is a
stable equilibrium (why the 10-s run stays regular); its table, with MuJoCo's rows or the reason they are absent."""

from __future__ import annotations

import json

import numpy as np

import pkm
from pkm.bench import NAMES, arguments, simulation_speed


def test_the_start_is_a_stable_equilibrium():
    """At the pose (0, 0, -0.35) m the gravity stiffness dg_a/dq_a (central differences along the closure) is
    positive definite: the constant efforts g_a hold the Delta there stably; the direct singularity is far."""
    mech, q0, g = simulation_speed._start()
    qa, h = mech.actuated_q(q0), 1e-5
    K = np.column_stack([(pkm.gravity_efforts(mech, pkm.close_loops(mech, qa + h * e, q0).q)
                          - pkm.gravity_efforts(mech, pkm.close_loops(mech, qa - h * e, q0).q)) / (2 * h)
                         for e in np.eye(mech.na)])
    assert np.linalg.eigvalsh(0.5 * (K + K.T)).min() > 0.05
    assert np.allclose(g, pkm.gravity_efforts(mech, q0)) and pkm.diagnose(mech, q0).direct_distance > 0.05


def test_a_quick_run_compares_and_prints():
    assert "simulation_speed" in NAMES
    args = arguments(simulation_speed, quick=True)
    assert args.duration == 0.2 and args.python_duration == 0.05
    result = json.loads(json.dumps(simulation_speed.run(args)))  # (JSON-ready, as pkm bench --json prints it)
    for name in ("prs3", "delta"):
        row = result["model"][name]
        assert row["max_relative_difference_to_python"] <= 1e-10 and row["c_batch_us"] > 0.0
    sim = result["simulation"]
    assert sim["event"] is None and sim["steps"] == 200
    assert max(sim["difference_to_python"].values()) <= 1e-9
    lines = simulation_speed.table(result).splitlines()
    assert lines[0].split()[-2:] == ["prs3", "delta"]
    assert any(ln.strip().startswith("C backend") for ln in lines)
    assert any(ln.strip().startswith(("MuJoCo, RK4", "MuJoCo not run")) for ln in lines)
    sim.pop("mujoco_rk4_s", None)
    sim["mujoco"] = "not installed"
    assert "  MuJoCo not run (not installed)" in simulation_speed.table(result).splitlines()
