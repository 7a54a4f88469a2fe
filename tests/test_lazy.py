"""pkm._lazy: ``lazy`` (PEP 562 ``__getattr__``/``__dir__`` of a package whose names live in other modules) imports a
module on the first use of one of its names and keeps the name; ``delegate`` forwards every non-dunder name to one
module. Checked on a standard-library module blocked out of ``sys.modules`` (so the import is observable), and on
the packages that use them. (That pkm's declared lazy names resolve is ``tests/test_imports.py``.)"""

from __future__ import annotations

import importlib
import sys

import pytest

from pkm._lazy import delegate, lazy


def test_a_name_is_imported_on_first_use_and_then_kept_in_the_namespace(monkeypatch):
    """Making the hooks imports nothing; the first access imports the module and stores the value in the
    namespace (so Python finds it there next time without calling ``__getattr__``)."""
    monkeypatch.delitem(sys.modules, "colorsys", raising=False)
    namespace: dict = {"existing": 1}
    getattr_, _ = lazy("fakepkg", namespace, {"rgb_to_hsv": "colorsys", "dumps": "json"})
    assert "colorsys" not in sys.modules and "rgb_to_hsv" not in namespace
    value = getattr_("rgb_to_hsv")
    assert "colorsys" in sys.modules and value is sys.modules["colorsys"].rgb_to_hsv
    assert namespace["rgb_to_hsv"] is value and "dumps" not in namespace  # (only the name asked for)


def test_an_undeclared_name_is_an_attribute_error_naming_the_package():
    """A name missing from the table is the AttributeError Python's own modules give (hasattr and getattr with a
    default keep working), naming the package, and imports nothing."""
    getattr_, _ = lazy("fakepkg", {}, {"dumps": "json"})
    with pytest.raises(AttributeError, match=r"^module 'fakepkg' has no attribute 'loads'$"):
        getattr_("loads")


def test_dir_lists_the_loaded_and_the_declared_names_sorted_once():
    """dir() shows the namespace's names and the lazy ones, each once, sorted, before and after a load."""
    namespace: dict = {"b": 1, "dumps": None}
    getattr_, dir_ = lazy("fakepkg", namespace, {"dumps": "json", "a": "json"})
    assert dir_() == ["a", "b", "dumps"]
    getattr_("dumps")
    assert dir_() == ["a", "b", "dumps"]


def test_delegate_forwards_public_and_private_names_but_not_dunders(monkeypatch):
    """Any name, private ones included, is the module's (imported on first use); a dunder is refused without
    importing, so that probes such as ``__path__`` or ``__wrapped__`` do not load the module; a name the module
    lacks is an AttributeError."""
    monkeypatch.delitem(sys.modules, "colorsys", raising=False)
    getattr_ = delegate("colorsys")
    with pytest.raises(AttributeError):
        getattr_("__wrapped__")
    assert "colorsys" not in sys.modules
    assert getattr_("_v") is sys.modules["colorsys"]._v and getattr_("hls_to_rgb") is sys.modules["colorsys"].hls_to_rgb
    with pytest.raises(AttributeError, match="nothing_here"):
        getattr_("nothing_here")


def test_the_delegating_packages_give_their_main_module_s_names():
    """pkm.core.differential and pkm.core.dynamics answer with velocity's and projection's objects, private too."""
    import pkm.core.differential as differential
    import pkm.core.dynamics as dynamics
    from pkm.core.differential import velocity
    from pkm.core.dynamics import projection

    assert differential._passive_map is velocity._passive_map
    assert dynamics.KhalilProjection is projection.KhalilProjection
    assert not hasattr(differential, "__nothing__")


def test_the_packages_give_the_names_of_the_modules_they_were():
    """pkm.core.differential and pkm.core.dynamics are packages now; the names of the modules they were
    (differential.py, dynamics.py) are read from them as before."""
    differential = importlib.import_module("pkm.core.differential")
    dynamics = importlib.import_module("pkm.core.dynamics")
    velocity = importlib.import_module("pkm.core.differential.velocity")
    projection = importlib.import_module("pkm.core.dynamics.projection")
    assert differential.diagnose is velocity.diagnose and differential.actuation is velocity.actuation
    assert dynamics.KhalilProjection is projection.KhalilProjection and dynamics.partition is projection.partition
    with pytest.raises(AttributeError):
        differential.nothing_of_that_name  # noqa: B018
