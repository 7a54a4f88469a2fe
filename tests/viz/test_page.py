"""pkm.viz.page and pkm.viz.backend: the page is self-contained and deterministic and starts no process; a missing
meshcat or an unwritable path raise a PkmError."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import pkm
from pkm import viz
from pkm.errors import InvalidInputError, PkmError
from tests.viz.helpers import decode


def test_missing_meshcat_raises_pkm_error_saying_how_to_install(monkeypatch):
    """Without meshcat, pkm.viz raises a PkmError telling to pip install meshcat."""
    monkeypatch.setitem(sys.modules, "meshcat", None)
    with pytest.raises(viz.VizDependencyError, match=r"^pkm.viz needs meshcat: pip install meshcat$") as info:
        viz.snapshot_html(pkm.load("delta"))
    assert isinstance(info.value, PkmError)


def test_write_html_to_a_missing_folder_raises_pkm_error(tmp_path):
    """Writing into a folder that does not exist raises an InvalidInputError with the path."""
    with pytest.raises(InvalidInputError, match="cannot write"):
        viz.write_html(tmp_path / "nope" / "delta.html", pkm.load("delta"))


# ------------------------------------------------------------------------------------ page and show
def test_snapshot_is_self_contained_deterministic_and_starts_no_process(monkeypatch, tmp_path):
    """The page inlines meshcat's viewer, loads nothing from the network, is the same twice, and starts no process."""
    def no_process(*args, **kwargs):
        raise AssertionError("pkm.viz started a process")

    monkeypatch.setattr(subprocess, "Popen", no_process)
    mech = pkm.load("delta")
    page = viz.snapshot_html(mech)
    import meshcat

    js = (Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js").read_text(encoding="utf-8")
    assert js in page
    assert "<script src" not in page and "http://" not in page.replace(js, "")
    assert "https://" not in page.replace(js, "")
    assert viz.snapshot_html(mech) == page
    out = viz.write_html(tmp_path / "delta.html", mech)
    assert out == tmp_path / "delta.html" and out.read_text(encoding="utf-8") == page
    assert decode(page) == viz.read_commands(page)
