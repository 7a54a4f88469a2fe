"""pkm.bench.opcount without counting (the count takes about 2 s; ``tests/cli/test_bench.py`` runs it): its options,
and its table written from a result of the shape ``run`` returns."""

from __future__ import annotations

from pkm.bench import arguments, opcount

RESULT = {
    "boundary": "from the actuated rates to the efforts",
    "published": {"this paper": {"mul_div": 860, "add_sub": 680}, "Khalil 2011": {"mul_div": 1352, "add_sub": 778}},
    "ours": [{"actuation": "P", "mode": "numeric", "mul_div": 512, "add_sub": 430, "functions": {"sin": 3, "cos": 3},
              "ratio_to_paper": {"mul_div": 0.595, "add_sub": 0.632}},
             {"actuation": "R", "mode": "inertial", "mul_div": 700, "add_sub": 550, "functions": {},
              "ratio_to_paper": {"mul_div": 0.814, "add_sub": 0.809}}],
}


def test_it_takes_no_options_of_its_own():
    """Only --json and --quick; --quick changes nothing (QUICK is empty: no smaller size exists)."""
    args = arguments(opcount, ["--quick"])
    assert opcount.QUICK == {} and vars(args) == {"json": False, "quick": True}


def test_the_table_lists_the_published_counts_then_ours_then_the_boundary():
    """A header, one line per published count and per count of ours (actuation, mode, counts, functions) in the
    given order, and the boundary last."""
    lines = opcount.table(RESULT).splitlines()
    assert lines[0].split() == ["source", "mult/div", "add/sub", "functions"]
    assert lines[1].split()[-2:] == ["860", "680"] and lines[2].startswith("Khalil 2011")
    assert lines[3].startswith("pkm, P-actuated, numeric") and lines[3].split()[-6:] == ["512", "430", "3", "sin,",
                                                                                          "3", "cos"]
    assert lines[4].startswith("pkm, R-actuated, inertial") and lines[4].rstrip().endswith("550")
    assert lines[-1] == "boundary: from the actuated rates to the efforts" and lines[-2] == ""
