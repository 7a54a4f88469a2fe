"""Shared fixtures: mechanisms built once per session; the test-only toy mechanism registered; one folder of
pkm's cache for the whole run, shared by the workers and the subprocesses the tests start (``PKM_CACHE_DIR``:
:func:`pytest_configure`), so that a kernel is compiled once, each paper's rows are computed once, and nothing is
written to the user's cache.

``tests/fivebar`` is a mechanism that exists only here: registering it (one line) puts it
through every test that iterates the registry (generic core, property tests, fuzzing, scenes),
which proves that a mechanism is one folder plus one registry entry.
"""

from __future__ import annotations

import dataclasses
import os
import shutil
import tempfile

import pytest

# Before numpy loads (pkm imports it below; no plugin has loaded it by now), unless the caller set them: OpenBLAS runs
# one thread in each test process. The suite runs two pytest-xdist workers on two cores, each with OpenBLAS's
# threads (one a core): they only oversubscribed the cores (a 360 x 130 SVD: 18 ms of CPU on two threads, 2 ms on
# one; the whole suite 284-289 -> 270 s of pytest), and a thread count that follows the machine's cores made the
# SVDs' last bits depend on the machine CI runs on (the suite's warnings: 49 at two threads, 43 at one; every test
# passes either way). OpenBLAS's idle threads, where a caller sets more, sleep at once instead of
# spinning 2^28 cycles after each call (spinning threads took the CPU the other worker needed). The subprocesses the
# tests start inherit both.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_THREAD_TIMEOUT", "4")

from pkm.mechanisms import MechanismDefinition, module, register

register(MechanismDefinition("fivebar", "toy planar five-bar (tests only)", "tests.fivebar", task_scale=(0.03, 0.0, 0.0)))


#: The tests that read the papers' rows (:func:`pkm.papers.rows`, computed once per run into the shared cache, the
#: hexapod's alone 26 s of CPU): first, the longest work at the start of the run (a process asking for rows another
#: is computing waits for them: :func:`pkm.cache.cached`).
PAPER_ROWS = ("tests/core/identification/test_precise.py", "tests/test_readme.py::test_shell_line_runs[pkm report",
              "tests/papers/", "tests/test_report.py", "tests/test_report_rows_unchanged.py",
              "tests/cli/test_report.py")


def pytest_collection_modifyitems(config, items):
    items.sort(key=lambda item: not item.nodeid.startswith(PAPER_ROWS))  # (stable: the rows' readers, then the rest)


@pytest.fixture(scope="session")
def offline_browser(tmp_path_factory):
    """``offline_browser(width, height, cache)``: the session's headless Chromium with the outside network off, on a
    blank page of that size (:class:`tests.browser.Shared`: one Chromium a worker, not one a test)."""
    from tests.browser import Shared

    shared = Shared(tmp_path_factory.mktemp("chromium"))
    try:
        yield shared
    finally:
        shared.close()


@pytest.fixture(scope="session")
def built():
    """``built(name)``: the reference design of a mechanism, generated from its parameters, cached."""
    cache = {}

    def get(name: str):
        if name not in cache:
            cache[name] = module(name).build()
        return cache[name]

    return get


@pytest.fixture(scope="session")
def zygote():
    """:class:`tests.warm.Zygote`: Python blocks and example scripts each run in a fresh process forked from one warm
    interpreter (its imports paid once a worker, not once a process), closed at the session's end."""
    from tests.warm import Zygote

    z = Zygote()
    yield z
    z.close()


@pytest.fixture(scope="session")
def all_actuated():
    """The toy five-bar with its elbows actuated too: no passive coordinate, the loop closure only a check that the
    actuated values close the loop (built with the warning that the elbows depend on the motors)."""
    import pkm
    from pkm.errors import PkmWarning

    five = module("fivebar").build()  # (not the fixture built: a test module may define its own)
    with pytest.warns(PkmWarning, match=r"\['elbow_1', 'elbow_2'\] depend on the others"):
        return pkm.from_strings(five.urdf, dataclasses.replace(five.spec, actuated=("motor_1", "motor_2", "elbow_1",
                                                                                     "elbow_2")))


@pytest.fixture(scope="session")
def redundant():
    """The toy five-bar with one elbow actuated too: redundant actuation with passive joints left (three actuators,
    mobility two; built with the warning that the elbow depends on the motors)."""
    import pkm
    from pkm.errors import PkmWarning

    five = module("fivebar").build()
    with pytest.warns(PkmWarning, match=r"\['elbow_1'\] depend on the others"):
        return pkm.from_strings(five.urdf, dataclasses.replace(five.spec, actuated=("motor_1", "motor_2", "elbow_1")))


def pytest_configure(config):
    """One cache folder for the whole run (``PKM_CACHE_DIR``: compiled twins, the papers' rows), made by the
    controlling process before pytest-xdist starts its workers, which inherit it with the subprocesses they start:
    each kernel is compiled and each paper's rows computed once per run, and nothing is written to the user's
    cache. A fresh folder every run: nothing computed by an earlier run (or another version) is reused."""
    if os.environ.get("PYTEST_XDIST_WORKER") is None:
        folder = tempfile.mkdtemp(prefix="pkm-test-cache-")
        config._pkm_cache = (folder, os.environ.get("PKM_CACHE_DIR"))
        os.environ["PKM_CACHE_DIR"] = folder


def pytest_unconfigure(config):
    if hasattr(config, "_pkm_cache"):
        folder, previous = config._pkm_cache
        shutil.rmtree(folder, ignore_errors=True)
        if previous is None:
            os.environ.pop("PKM_CACHE_DIR", None)
        else:
            os.environ["PKM_CACHE_DIR"] = previous
