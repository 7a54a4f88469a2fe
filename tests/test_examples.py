"""Every script in ``examples/`` runs, from another working directory, and exits 0 (what a newcomer copies works)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from tests import bounded

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.py"))


def test_there_are_examples():
    assert EXAMPLES


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.name)
def test_the_example_runs(script, tmp_path):
    proc = bounded.run([sys.executable, str(script)], cwd=tmp_path, cpu=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip()
