"""Hypothesis settings profiles of the property tests, and the table of worst errors.

* ``ci`` (default): derandomized (the examples are a function of the test, reproducible in CI),
  no example database, no deadline; each test runs half the count its ``@examples(n)`` gives (20 to 60): the
  suite's time budget (``make test`` within 5 minutes of pytest on two cores) leaves the property tests about half
  a minute; the full counts are a long run's.
* ``long``: ``PKM_HYPOTHESIS_PROFILE=long pytest tests/properties`` runs 10 times the examples
  with fresh random seeds (failures are kept in ``.hypothesis/`` and replayed first).

With ``-v`` (or the ``long`` profile) the run ends with the worst value of every measured error.
"""

from __future__ import annotations

import os

from hypothesis import HealthCheck, Phase, settings

from tests.properties import CI_EXAMPLES, WORST

PROFILE_ENV = "PKM_HYPOTHESIS_PROFILE"

# no "explain" phase: it reruns a failing example hundreds of times to annotate it (half a minute here)
PHASES = (Phase.explicit, Phase.reuse, Phase.generate, Phase.target, Phase.shrink)
settings.register_profile("ci", max_examples=CI_EXAMPLES // 2, deadline=None, derandomize=True, database=None,
                          print_blob=True, phases=PHASES, suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("long", max_examples=10 * CI_EXAMPLES, deadline=None, derandomize=False,
                          print_blob=True, phases=PHASES, suppress_health_check=[HealthCheck.too_slow])
PROFILE = os.environ.get(PROFILE_ENV, "ci")
settings.load_profile(PROFILE)


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    """Print the worst value of every error the property tests measured (``tests.properties.record``), under
    ``-v`` or the ``long`` profile (``make test`` stays quiet)."""
    if not WORST or (config.option.verbose <= 0 and PROFILE == "ci"):
        return
    terminalreporter.section(f"pkm property tests: worst errors observed (hypothesis profile {PROFILE!r})")
    width = max(len(k) for k in WORST)
    for key in sorted(WORST):
        terminalreporter.write_line(f"{key:<{width}}  {WORST[key]:.3e}")
