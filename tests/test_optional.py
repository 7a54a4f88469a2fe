"""pkm._optional, in this process: ``missing``, ``require`` and ``module`` with extras' modules blocked through
``sys.modules[name] = None`` (as if not installed). (The same in a fresh interpreter with every extra blocked,
through the public capabilities, is ``tests/test_extras.py``; EXTRAS against pyproject.toml is
``tests/test_dependencies.py``.)"""

from __future__ import annotations

import sys
import types

import pytest

from pkm._optional import EXTRAS, missing, module, require
from pkm.errors import InvalidInputError, MissingDependencyError


@pytest.mark.parametrize("extra", list(EXTRAS))
def test_each_extra_is_complete_here_and_each_blocked_module_is_named_by_its_distribution(extra, monkeypatch):
    """In the dev environment nothing is missing; blocking every module of an extra lists their distributions in
    the table's order, and require names the first."""
    assert missing(extra) == []
    require(extra, "x")
    for top in EXTRAS[extra]:
        monkeypatch.setitem(sys.modules, top, None)
    assert missing(extra) == list(EXTRAS[extra].values())
    first = next(iter(EXTRAS[extra].values()))
    with pytest.raises(MissingDependencyError) as info:
        require(extra, "the thing")
    assert (info.value.package, info.value.extra) == (first, extra)
    assert str(info.value) == (f"the thing needs {first}, which pkm's {extra!r} extra installs: "
                               f"pip install \"pkm-robotics[{extra}]\"")


def test_only_the_modules_asked_for_are_checked(monkeypatch):
    """require(..., modules) ignores a blocked module of the extra that the capability does not use, and the
    order of the answer is the table's, not the caller's."""
    monkeypatch.setitem(sys.modules, "distributed", None)
    monkeypatch.setitem(sys.modules, "cloudpickle", None)
    require("sweeps", "reading results", ["pyarrow"])
    assert missing("sweeps", ["pyarrow", "dask"]) == []
    assert missing("sweeps", ["cloudpickle", "distributed"]) == ["cloudpickle", "distributed"]
    assert missing("sweeps") == ["distributed", "cloudpickle"]


def test_a_module_without_a_spec_counts_as_missing(monkeypatch):
    """A stand-in module whose __spec__ is None (find_spec raises ValueError) is reported missing, not an error."""
    monkeypatch.setitem(sys.modules, "mujoco", types.ModuleType("mujoco"))
    assert missing("bench") == ["mujoco"]


def test_module_imports_a_submodule_after_checking_its_top_level(monkeypatch):
    """module('dask.utils') is that submodule; with dask blocked it is the extra's error naming dask (the top
    level's distribution), not an ImportError of the submodule, and the submodule is not imported."""
    assert module("dask.utils", extra="sweeps", what="x") is sys.modules["dask.utils"]
    monkeypatch.delitem(sys.modules, "dask.utils")
    monkeypatch.setitem(sys.modules, "dask", None)
    with pytest.raises(MissingDependencyError, match=r"^sweeping needs dask, ") as info:
        module("dask.utils", extra="sweeps", what="sweeping")
    assert info.value.package == "dask" and "dask.utils" not in sys.modules


@pytest.mark.parametrize("call", [lambda: missing("plots"), lambda: require("Sweeps", "x"),
                                  lambda: module("dask", extra="dask", what="x")])
def test_an_unknown_extra_is_invalid_input_listing_the_extras(call):
    """An extra that pyproject.toml does not define (case matters) is refused naming the four that exist."""
    with pytest.raises(InvalidInputError, match="one of sweeps, figures, homotopy, bench") as info:
        call()
    assert info.value.name == "extra"


def test_a_module_outside_the_extra_is_invalid_input():
    """require('figures', ..., ['numpy']) names the module and the extra's modules."""
    with pytest.raises(InvalidInputError, match="numpy"):
        require("figures", "x", ["numpy"])
