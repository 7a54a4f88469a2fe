"""The fuzz harness (tools/fuzz_report.py) at a small size: every entry point ends in ok or a PkmError."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

from pkm.mechanisms import module, names

TOOL = Path(__file__).resolve().parents[1] / "tools" / "fuzz_report.py"


@pytest.fixture(scope="module")
def fuzz():
    spec = importlib.util.spec_from_file_location("pkm_fuzz_report", TOOL)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["pkm_fuzz_report"] = mod  # the worker processes unpickle run_chunk from this name
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def report(fuzz):
    names = [e.name for e in fuzz.ENTRIES]
    return fuzz.run(names, 30, seed=11, jobs=2, timeout=20.0)


def test_harness_covers_the_public_entry_points(fuzz):
    """The registry names the loaders, the generic core, every mechanism's closed forms, indices and dynamics."""
    entries = {e.name for e in fuzz.ENTRIES}
    expected = {"pkm.load", "Mechanism.from_strings", "Mechanism.from_files", "ClosureSpec.from_toml",
                "motion.load_motions", "pkm.solve_ik", "pkm.close_loops", "pkm.forward_jacobian",
                "pkm.inverse_jacobian", "pkm.velocities", "pkm.accelerations", "pkm.inverse_velocities",
                "pkm.inverse_accelerations", "pkm.diagnose", "indices.condition_number",
                "hexapod_reconfigure.optimal_beta", "Prs3Dynamics.forces", "Prs3Dynamics.batch",
                "KhalilProjection.inverse_dynamics", "hexapod.assembly_modes", "rrr3.forward_kinematics",
                "pkm.inverse_dynamics", "pkm.assemble", "formats.spec_from_gepetto", "formats.read_mjcf",
                "formats.read_sdf", "pkm.load(file)", "formats.spec_skeleton", "pkm.quantity", "pkm.follow_task",
                "pkm.follow_actuators", "Kernels.inverse_dynamics", "Kernels.close_loops_path", "maps.task_map",
                "formats.mjcf_from_mechanism", "pkm.reconfigure", "pkm.sweep", "sweeps.space"}
    expected |= {f"pkm.build[{m}]" for m in names()}  # the registry, the tests' five-bar included
    expected |= {f"{m}.closed_form_ik" for m in names()}
    expected |= {f"{m}.closed_form_fk" for m in names() if module(m).closed_form_fk is not None}
    assert "fivebar.closed_form_fk" in expected
    assert expected <= entries, sorted(expected - entries)


def test_no_other_exception_and_no_silent_non_finite_result(report):
    """At 30 inputs per entry point, nothing but ok (finite) and PkmError comes out, and no error carries a NaN."""
    bad = {nm: (e["other"], e["nonfinite"], e["examples_other"][:1] + e["examples_nonfinite"][:1])
           for nm, e in report["entries"].items() if e["other"] or e["nonfinite"] or e["error_nan"]}
    assert not bad, bad


def test_every_entry_point_was_tried_with_both_kinds_of_input(report):
    """Each entry point ran its 30 calls, half random and half adversarial, and some of each outcome occurred."""
    for nm, e in report["entries"].items():
        assert e["tried"] == 30 and e["ok"] + e["pkm_error"] + e["other"] + e["nonfinite"] == 30, nm
        assert sum(e["random"].values()) == 15 and sum(e["adversarial"].values()) == 15, nm
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
