"""Every script in ``examples/`` runs, from another working directory, and exits 0 (what a newcomer copies works)."""

from __future__ import annotations

from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.py"))


def test_there_are_examples():
    assert EXAMPLES


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.name)
def test_the_example_runs(script, tmp_path, zygote):
    """``python examples/X.py`` from a scratch directory (a process of its own, as :mod:`tests.warm` forks it)."""
    proc = zygote.run(script=script, cwd=tmp_path, cpu=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip()
