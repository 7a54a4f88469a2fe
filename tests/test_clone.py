"""A clone with nothing beside it runs ``make test``: no test reads a folder outside the repository (the
``shared/`` folder the developers have beside their clone is not part of it). ``.ci/run`` also runs the tests that
use third-party robot files from a bare clone in an empty folder."""

from __future__ import annotations

import re
from pathlib import Path

TESTS = Path(__file__).resolve().parent
OUTSIDE = re.compile(r"\.\./shared|[\"']shared[\"']")


def test_no_test_reads_a_folder_beside_the_clone():
    found = [f"{path.relative_to(TESTS)}:{n}: {line.strip()}" for path in sorted(TESTS.rglob("*.py"))
             if path != Path(__file__).resolve()
             for n, line in enumerate(path.read_text().splitlines(), 1) if OUTSIDE.search(line)]
    assert found == []
