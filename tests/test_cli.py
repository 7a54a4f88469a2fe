"""The tests of the ``pkm`` command line are in ``tests/cli/``, one module per module or command of pkm.cli.

This module keeps the helpers importable from their former place (``tests.core.formats.test_gepetto`` imports
``run`` from here); import them from :mod:`tests.cli.helpers`.
"""

from __future__ import annotations

from tests.cli.helpers import default_sigint, one_error_line, run

__all__ = ["default_sigint", "one_error_line", "run"]
