"""pkm.bench.twin without timing: the smooth actuator path it drives every mechanism along (consistent positions,
rates and accelerations around the reference), its options, and its table written from a result of the shape
``run`` returns. (``tests/cli/test_bench.py`` runs it quick.)"""

from __future__ import annotations

import numpy as np
import pytest

from pkm.bench import arguments, twin


@pytest.mark.parametrize("name", ["delta", "hexapod"])
def test_the_path_is_smooth_and_consistent_around_the_reference(name, built):
    """qa, qd, qdd are (n, na); qa starts at the reference plus amp sin(phase), stays within 0.01 of it; qd and qdd
    are its time derivatives over the 2 s span (central differences, 1e-5 relative to their peak)."""
    mech = built(name)
    n = 2001
    qa, qd, qdd = twin._path(mech, n)
    assert qa.shape == qd.shape == qdd.shape == (n, mech.na)
    ref = mech.actuated_q(mech.q_reference)
    assert np.abs(qa - ref).max() <= 0.01 + 1e-15 and np.abs(qa - ref).max() > 0.003
    dt = 2.0 / (n - 1)
    for x, dx in ((qa, qd), (qd, qdd)):
        fd = (x[2:] - x[:-2]) / (2 * dt)
        assert np.abs(fd - dx[1:-1]).max() <= 1e-5 * np.abs(dx).max()


def test_quick_sizes_apply_to_the_options_not_given():
    """--quick gives n 100, repeat 1, calls 50, except an option the command line sets."""
    assert vars(arguments(twin, ["--quick"])) == {"json": False, "quick": True, "n": 100, "repeat": 1, "calls": 50}
    assert arguments(twin, ["--quick", "-n", "50"]).n == 50
    assert arguments(twin, []).n == 20_000


def _row(mujoco: bool) -> dict:
    return {"kernel_batch_c_us": 0.5, "kernel_batch_numpy_us": 2.0, "kernel_call_us": 10.0, "core_us": 100.0,
            "closure_path_us_per_solve": 5.0, "closure_core_us_per_solve": 50.0,
            "mujoco_rigid_us": 20.0 if mujoco else None, **({} if mujoco else {"mujoco": "not installed"}),
            "operation_count": {"mul": 1200, "add": 900},
            "max_effort_difference_to_core": {"kernel_batch_c": 1e-12}}


def test_the_table_has_a_column_per_mechanism_and_dashes_for_what_was_not_run():
    """Routes a mechanism lacks (the hand-written batch outside the 3-PRS, MuJoCo when absent) are '-'; the
    operation counts and the effort differences are listed; a missing MuJoCo is said with its reason."""
    result = {"mechanisms": {"prs3": {**_row(True), "hand_written_batch_us": 1.5}, "delta": _row(False)}}
    lines = twin.table(result).splitlines()
    assert lines[0].split() == ["us", "per", "sample", "prs3", "delta"]
    hand = next(ln for ln in lines if ln.startswith("hand-written batch"))
    assert hand.split()[-2:] == ["1.500", "-"]
    mj = next(ln for ln in lines if ln.startswith("MuJoCo rigid solve"))
    assert mj.split()[-2:] == ["20.000", "-"]
    assert "1200/900" in next(ln for ln in lines if ln.startswith("operations"))
    assert "delta: MuJoCo not run (not installed)" in lines and "prs3: max |tau - core| kernel_batch_c 1.0e-12" in lines
