"""pkm.cache: results stored under their inputs and code, computed again when either changes."""

from __future__ import annotations

import json

import pytest

from pkm import cache


@pytest.fixture
def folder(tmp_path, monkeypatch):
    monkeypatch.setenv("PKM_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("PKM_CACHE", raising=False)
    return tmp_path


def _counting():
    calls = []

    def compute():
        calls.append(1)
        return {"value": 0.1 + 0.2, "list": [1, 2.5e-300], "text": "é"}

    return calls, compute


def test_a_result_is_computed_once_and_given_back_exactly(folder):
    calls, compute = _counting()
    first = cache.cached("rows", ["a", 1.0], compute, code=["pkm.cache"])
    again = cache.cached("rows", ["a", 1.0], compute, code=["pkm.cache"])
    assert first == again and len(calls) == 1
    assert again["value"] == 0.1 + 0.2  # floats round-trip exactly through JSON
    assert len(list((folder / "rows").glob("*.json"))) == 1


def test_other_inputs_or_other_code_compute_again(folder):
    calls, compute = _counting()
    cache.cached("rows", ["a", 1.0], compute, code=["pkm.cache"])
    cache.cached("rows", ["a", 1.0 + 1e-15], compute, code=["pkm.cache"])
    cache.cached("rows", ["a", 1.0], compute, code=["pkm.units"])
    assert len(calls) == 3


def test_off_damaged_or_unwritable_means_computed(folder, monkeypatch):
    calls, compute = _counting()
    cache.cached("rows", "k", compute)
    (entry,) = (folder / "rows").glob("*.json")
    entry.write_text("{not json")
    assert cache.cached("rows", "k", compute)["text"] == "é" and len(calls) == 2
    assert json.loads(entry.read_text())["value"]["text"] == "é"  # (rewritten)
    monkeypatch.setenv("PKM_CACHE", "0")
    cache.cached("rows", "k", compute)
    assert len(calls) == 3
    monkeypatch.setenv("PKM_CACHE", "1")
    monkeypatch.setenv("PKM_CACHE_DIR", str(entry))  # a file, not a folder: nothing can be written there
    assert cache.cached("rows", "k", compute)["list"] == [1, 2.5e-300] and len(calls) == 4


def test_the_twin_kernels_live_in_the_same_cache(folder):
    from pkm.core.twin.codegen import cache_dir

    assert cache_dir() == folder / "twin" == cache.cache_dir() / "twin"


def _compute_once(folder, log, started, out):
    """A child's cached call whose computation notes itself in ``log`` and holds on until a second asker waits; its
    answer written to ``out``."""
    import os
    import time

    os.environ["PKM_CACHE_DIR"] = str(folder)

    def compute():
        with open(log, "a") as fh:
            fh.write("computed\n")
        started.set()
        time.sleep(0.3)  # (the other process asks meanwhile)
        return {"pid": os.getpid()}

    out.write_text(json.dumps(cache.cached("rows", "asked twice", compute)))


def test_two_processes_asking_at_once_compute_once(folder, tmp_path):
    """A second process asking for an entry being computed waits for it and reads it: one computation, one value
    (the first's: its pid)."""
    import multiprocessing

    ctx = multiprocessing.get_context("fork")
    log, started = tmp_path / "log.txt", ctx.Event()
    first = ctx.Process(target=_compute_once, args=(folder, log, started, tmp_path / "a.json"))
    first.start()
    started.wait()
    second = ctx.Process(target=_compute_once, args=(folder, log, started, tmp_path / "b.json"))
    second.start()
    first.join()
    second.join()
    assert first.exitcode == second.exitcode == 0
    assert (tmp_path / "a.json").read_text() == (tmp_path / "b.json").read_text()
    assert log.read_text() == "computed\n"
