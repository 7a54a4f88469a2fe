"""``pkm report``: the hexapod's rows; an unknown paper."""

from __future__ import annotations

import json

from tests.cli.helpers import one_error_line, run


def test_report_writes_the_hexapod_rows_and_refuses_an_unknown_paper(tmp_path):
    """``pkm report --paper hexapod --no-figures`` writes summary.json and prints every row; a bad paper exits 2."""
    proc = run("report", "--out", str(tmp_path), "--paper", "hexapod", "--no-figures")
    assert proc.returncode == 0, proc.stderr
    rows = json.loads((tmp_path / "summary.json").read_text())["papers"]["hexapod"]["rows"]
    assert rows and all(r["id"] in proc.stdout for r in rows)
    assert (tmp_path / "report.md").exists() and not (tmp_path / "figures").exists()
    bad = run("report", "--out", str(tmp_path), "--paper", "hexapod", "--paper", "ufo")
    assert bad.returncode == 2 and "valid papers: 'hexapod', 'rrr3', 'delta', 'prs3'" in one_error_line(bad)
