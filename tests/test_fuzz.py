"""The fuzz harness (tools/fuzz_report.py) at a small size: every entry point ends in ok or a PkmError."""

from __future__ import annotations

import importlib.util
import json
import os
import signal
import sys
import time
from pathlib import Path

import pytest

from pkm.mechanisms import module, names

TOOL = Path(__file__).resolve().parents[1] / "tools" / "fuzz_report.py"
#: Calls per entry point (half random, half adversarial): a smoke run (8 s of CPU; 30 took 21 s); the full run,
#: 10,000 a point, is tools/fuzz_report.py's, with its report committed.
CALLS = 10


@pytest.fixture(scope="module")
def fuzz():
    spec = importlib.util.spec_from_file_location("pkm_fuzz_report", TOOL)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["pkm_fuzz_report"] = mod  # (its workers are forked: they see what a test plants in it)
    spec.loader.exec_module(mod)
    return mod


#: The mechanisms the compiled kernels' entries draw from here (tests.fuzzing.KERNEL_MECHANISMS; the full run: all):
#: a planar and a spatial one, whose kernels the kernels' tests compile anyway. Each other mechanism's kernels were a
#: twin and C libraries built for a few calls: with all of them the smoke run took 16 s of CPU on a cold cache.
KERNEL_MECHANISMS = ("rrr3", "delta")


@pytest.fixture(scope="module")
def report(fuzz):
    names = [e.name for e in fuzz.ENTRIES]
    # (timeout: a hang's bound, a busy machine slowing a call 5x; one worker process: the entries' setup once, 8 s of
    # CPU where two took 10; the planted hangs below run on two)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(sys.modules["tests.fuzzing"], "KERNEL_MECHANISMS", KERNEL_MECHANISMS)  # (the forked worker's)
        return fuzz.run(names, CALLS, seed=11, jobs=1, timeout=120.0)


def test_harness_covers_the_public_entry_points(fuzz):
    """The registry names the loaders, the generic core, every mechanism's closed forms, indices and dynamics."""
    entries = {e.name for e in fuzz.ENTRIES}
    expected = {"pkm.load", "pkm.from_strings", "builder.from_files", "ClosureSpec.from_toml",
                "motion.load_motions", "pkm.solve_ik", "pkm.close_loops", "pkm.forward_jacobian",
                "pkm.inverse_jacobian", "pkm.velocities", "pkm.accelerations", "pkm.inverse_velocities",
                "pkm.inverse_accelerations", "pkm.diagnose", "indices.condition_number",
                "hexapod_reconfigure.optimal_beta", "Prs3Dynamics.forces", "Prs3Dynamics.batch",
                "KhalilProjection.inverse_dynamics", "hexapod.assembly_modes", "rrr3.forward_kinematics",
                "pkm.inverse_dynamics", "pkm.assemble", "formats.spec_from_gepetto", "formats.read_mjcf",
                "formats.read_sdf", "formats.read_hyrodyn", "pkm.load(file)", "formats.spec_skeleton", "pkm.quantity", "pkm.follow_task",
                "pkm.follow_actuators", "Kernels.inverse_dynamics", "Kernels.close_loops_path", "maps.task_map",
                "formats.mjcf_from_mechanism", "pkm.reconfigure", "pkm.sweep", "sweeps.space", "SweepResult",
                "differential.actuation", "pkm.load(package)", "Actuator", "pkm.with_actuators", "spec.actuators",
                "pkm.actuator_model", "ActuatorSpaceModel", "pkm.mass_matrix", "pkm.bias_efforts",
                "pkm.gravity_efforts", "pkm.coriolis_matrix", "pkm.operational_space", "pkm.forward_dynamics",
                "pkm.constraint_dynamics", "pkm.simulate", "pkm.regressor", "pkm.base_parameters",
                "pkm.estimate", "pkm.regressor_batch", "pkm.measurements", "pkm.capability", "Kernels.at",
                "pkm.calibration_parameters",
                "pkm.clearance", "clearance_map"}
    expected |= {f"pkm.build[{m}]" for m in names()}  # the registry, the tests' five-bar included
    expected |= {f"{m}.closed_form_ik" for m in names()}
    expected |= {f"{m}.closed_form_fk" for m in names() if module(m).closed_form_fk is not None}
    assert "fivebar.closed_form_fk" in expected
    assert expected <= entries, sorted(expected - entries)


def test_no_other_exception_and_no_silent_non_finite_result(report):
    """At :data:`CALLS` inputs per entry point, nothing but ok (finite) and PkmError comes out, nothing hangs, and no
    error carries a NaN."""
    bad = {nm: (e["other"], e["nonfinite"], e["hang"],
                e["examples_other"][:1] + e["examples_nonfinite"][:1] + e["examples_hang"][:1])
           for nm, e in report["entries"].items() if e["other"] or e["nonfinite"] or e["hang"] or e["error_nan"]}
    assert not bad, bad


def test_every_entry_point_was_tried_with_both_kinds_of_input(report):
    """Each entry point ran its :data:`CALLS` calls, half random and half adversarial, and some of each outcome
    occurred."""
    for nm, e in report["entries"].items():
        assert e["tried"] == CALLS and e["ok"] + e["pkm_error"] + e["other"] + e["nonfinite"] + e["hang"] == CALLS, nm
        assert sum(e["random"].values()) == sum(e["adversarial"].values()) == CALLS // 2 and e["cut"] is None, nm
    assert report["total"]["ok"] > 0 and report["total"]["pkm_error"] > 0


def test_a_planted_bug_is_classified_as_other(fuzz, monkeypatch):
    """The classifier is not blind: an entry point raising TypeError counts as other with a repro,
    one returning NaN counts as nonfinite."""
    def broken(g, adversarial):
        return (lambda x: x + None), (1.0,), {}

    def nan(g, adversarial):
        return (lambda: {"value": [1.0, float("nan")]}), (), {}

    monkeypatch.setattr(fuzz, "ENTRIES", fuzz.ENTRIES + [fuzz.Entry("planted.type_error", broken),
                                                        fuzz.Entry("planted.nan", nan)])
    rep = fuzz.run(["planted.type_error", "planted.nan"], 4, jobs=1)
    te, nn = rep["entries"]["planted.type_error"], rep["entries"]["planted.nan"]
    assert te["other"] == 4 and te["examples_other"][0]["type"] == "TypeError"
    assert "planted.type_error" in te["examples_other"][0]["repro"]
    assert nn["nonfinite"] == 4 and nn["ok"] == 0


def test_a_call_that_hangs_is_a_hang_never_waited_on(fuzz, monkeypatch):
    """A call past the timeout that gives control back (a sleep) is interrupted there; one that does not (SIGALRM
    ignored, as a thread blocked on a lock is deaf to it) has its worker killed and replaced, and the rest of its
    chunk runs in the new worker: both counted as hang with their repro, the other calls as usual."""
    def sleeper(g, adversarial):
        return (lambda s: time.sleep(s) if adversarial else s), (30.0,), {}

    def deaf(g, adversarial):
        def block(s):
            if adversarial:
                signal.signal(signal.SIGALRM, signal.SIG_IGN)
                time.sleep(s)
            return s
        return block, (30.0,), {}

    def exits(g, adversarial):
        return (lambda s: os._exit(3) if adversarial else s), (30.0,), {}

    monkeypatch.setattr(fuzz, "ENTRIES", fuzz.ENTRIES + [fuzz.Entry("planted.sleep", sleeper),
                                                        fuzz.Entry("planted.deaf", deaf),
                                                        fuzz.Entry("planted.exit", exits)])
    t0 = time.monotonic()
    rep = fuzz.run(["planted.sleep", "planted.deaf", "planted.exit"], 3, jobs=2, timeout=0.2, grace=0.3)
    assert time.monotonic() - t0 < 10
    for nm, outcome in (("planted.sleep", "hang"), ("planted.deaf", "hang"), ("planted.exit", "other")):
        e = rep["entries"][nm]
        assert (e["tried"], e["ok"], e[outcome]) == (3, 2, 1), (nm, e)
        repro = e[f"examples_{outcome}"][0]["repro"]  # (the call, from the worker that took over)
        assert repro.startswith(f"[{nm}] tests.test_fuzz.") and repro.endswith("(30.0)"), repro
    assert rep["entries"]["planted.exit"]["examples_other"][0]["type"] == "WorkerDied"
    assert rep["total"]["hang"] == 2


def test_the_time_bounds_cut_an_entry_and_say_so(fuzz, monkeypatch):
    """An entry point whose calls use up its seconds gets fewer calls, reported (tried, cut); so does the run
    past its total bound."""
    def slow(g, adversarial):
        return (lambda: time.sleep(0.05)), (), {}

    monkeypatch.setattr(fuzz, "ENTRIES", fuzz.ENTRIES + [fuzz.Entry("planted.slow", slow)])
    rep = fuzz.run(["planted.slow"], 1000, jobs=1, entry_seconds=0.2)
    e = rep["entries"]["planted.slow"]
    assert 1 <= e["tried"] <= 8 and e["ok"] == e["tried"] and e["cut"] == "entry", e  # (4 on a quiet machine)
    rep = fuzz.run(["planted.slow"], 1000, jobs=1, total_seconds=0.2)
    assert 1 <= rep["entries"]["planted.slow"]["tried"] <= 8 and rep["entries"]["planted.slow"]["cut"] == "total"
    assert "1 entry point(s) stopped by a time bound" in fuzz.table(rep)


def test_the_time_a_cheap_entry_leaves_goes_to_a_slow_one(fuzz, monkeypatch, capsys):
    """By default (no --entry-seconds) an entry point's share of the run's bound is re-divided as others finish: a
    slow entry needing more than half the bound (2 s of 3), stopped at its first share (1.5 s), gets all its calls
    once a cheap one is done, where equal fixed shares would have cut it; and the output of the calls on the
    process's stderr (descriptor 2, as C++ libraries print) is counted, not shown."""
    def cheap(g, adversarial):
        return (lambda: os.write(2, b"chatter from a C library\n")), (), {}

    def slow(g, adversarial):
        return (lambda: time.sleep(0.05)), (), {}

    fuzz.ctx()  # (built here, the forked worker has it: no build within the bound)
    monkeypatch.setattr(fuzz, "ENTRIES", fuzz.ENTRIES + [fuzz.Entry("planted.slow", slow),
                                                        fuzz.Entry("planted.cheap", cheap)])
    assert fuzz.main(["--only", "planted.", "--n", "40", "--jobs", "1", "--total-seconds", "3", "--json",
                      "--no-progress"]) == 0
    out, err = capsys.readouterr()
    rep = json.loads(out)
    s, c = rep["entries"]["planted.slow"], rep["entries"]["planted.cheap"]
    assert (s["tried"], s["ok"], s["cut"]) == (40, 40, None) and s["seconds"] > 1.5, s
    assert (c["tried"], c["output_calls"], c["output_lines"]) == (40, 40, 40), c
    assert c["output_example"].startswith("chatter from a C library") and s["output_lines"] == 0
    assert "chatter" not in err and "40 line(s) printed by libraries in 40 call(s)" in fuzz.table(rep)
