"""The exported C's Newton driver (:mod:`pkm.core.export.runtime`) on the Delta, exported and compiled once: a cold
start of the forward kinematics from the exported reference reaches what ``pkm.close_loops`` reaches from the
reference over the workspace (before, one Newton jump from the reference left for the mirror assembly, z = +0.20, or
stopped NOT_CONVERGED after 20 iterations), the closed form's actuated coordinates seed it, and the README's first
example prints what the README says."""

from __future__ import annotations

import re
import shutil
import warnings

import numpy as np
import pytest

import pkm
from pkm.core.export import export_c
from pkm.core.export.harness import build
from pkm.core.export.library import STATUS
from pkm.errors import ModeChangeWarning

pytestmark = pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler (cc)")


@pytest.fixture(scope="module")
def delta(tmp_path_factory):
    """The Delta's library, exported and built once (-O0: the test checks answers, not speed)."""
    mech = pkm.load("delta")
    return mech, build(export_c(mech, tmp_path_factory.mktemp("delta")), optimise="-O0")


def test_a_cold_start_from_the_reference_reaches_what_close_loops_reaches(delta):
    """A 4 x 4 x 2 grid of actuator values up to 1.2 rad from the reference's, each solved by the C from the exported
    reference in its assembly mode and by pkm.close_loops from the reference: where pkm converges without leaving the
    reference's modes, the C answers OK or OUTSIDE_LIMITS with the same task value (1e-9 m)."""
    mech, h = delta
    ref = mech.q_reference
    task = pkm.TaskMap.of(mech)
    grid = [np.array([a, b, c]) for a in np.linspace(-1.2, 0.8, 4) for b in np.linspace(-1.0, 0.9, 4) for c in (-0.9, 0.5)]
    got = h.run("fk", np.array([np.hstack([qa, ref, [0.0]]) for qa in grid]))
    compared = 0
    for qa, row in zip(grid, got):
        with warnings.catch_warnings():
            warnings.simplefilter("error", ModeChangeWarning)
            try:
                res = pkm.close_loops(mech, qa)
            except (pkm.PkmError, ModeChangeWarning):
                continue
        status = STATUS[int(row[0])]
        assert status in ("OK", "OUTSIDE_LIMITS"), (qa, status, row[2])
        assert np.abs(row[4 + mech.nq:] - task.value(res.q)).max() <= 1e-9, qa
        compared += 1
    assert compared >= 24, compared  # (most of the grid lies in the reference's modes)


def test_the_closed_form_seeds_the_first_solution(delta):
    """The paper's closed form (Python: the library has none) for a task value, then fk from the reference in its assembly mode: that task value
    (1e-9 m), status OK (it landed on the mirror mode, z = +0.20, as LEFT_MODE, before)."""
    from pkm.mechanisms.delta.kinematics import inverse_kinematics

    mech, h = delta
    y = np.array([0.02, -0.01, -0.36])
    qa = inverse_kinematics(mech.params, y)
    row = h.run("fk", np.hstack([qa, mech.q_reference, [0.0]])[None])[0]
    assert STATUS[int(row[0])] == "OK" and np.abs(row[4 + mech.nq:] - y).max() <= 1e-9, row[4 + mech.nq:]


def test_the_readme_says_how_to_start_and_its_first_line_is_what_the_c_prints(delta):
    mech, h = delta
    text = (h.lib.directory / "README.md").read_text()
    assert "delta_q_reference" in text and "DELTA_FK_MODE_REFERENCE" in text and "pkm.solve_ik" in text
    qa = np.array([float(x) for x in re.search(r"qa = \(([^)]*)\)", text).group(1).split(",")])
    assert np.abs(qa - mech.actuated_q(mech.q_reference)).max() >= 0.1  # (a cold start, not a warm one)
    main = re.search(r"qa_first\[DELTA_NA\] = \{([^}]*)\}", (h.lib.directory / "main.c").read_text()).group(1)
    assert np.abs(np.array([float(x) for x in main.split(",")]) - qa).max() <= 1e-9  # (main.c's is the README's)
    row = h.run("fk", np.hstack([qa, mech.q_reference, [0.0]])[None])[0]
    shown = " ".join(f"{n}={0.0 if abs(v) < 5e-10 else v:.6f}" for n, v in zip(("x", "y", "z"), row[4 + mech.nq:]))
    assert f"first fk: status {int(row[0])}, {shown}\n" in text and int(row[0]) == 0
