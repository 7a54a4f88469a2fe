"""The mechanism registry (pkm.mechanisms.REGISTRY): every entry imports and implements the protocol, and
every consumer sees the tests' toy five-bar, registered with one line in ``tests/conftest.py``."""

from __future__ import annotations

import dataclasses

import pytest

import pkm
from pkm import papers
from pkm.data import data_dir
from pkm.errors import InvalidInputError, UnknownNameError
from pkm.mechanisms import REGISTRY, MechanismDefinition, MechanismModule, definition, names, register, unregister


@pytest.mark.parametrize("name", names())
def test_every_entry_imports_and_implements_the_protocol(name):
    entry = REGISTRY[name]
    mod = entry.module()
    assert isinstance(mod, MechanismModule)
    assert mod.NAME == entry.name == name and entry.title
    assert dataclasses.is_dataclass(mod.Params) and mod.Params.__dataclass_params__.frozen
    assert mod.closed_form_fk is None or callable(mod.closed_form_fk)
    mech = mod.build(mod.Params())
    assert mech.name == name and pkm.load(name).nq == mech.nq
    if entry.reference is not None:
        assert (data_dir("urdf") / entry.reference).is_file()
    if entry.paper is not None:
        assert entry.paper in papers.names() and papers.module(entry.paper).TITLE


def test_the_toy_is_one_more_mechanism_everywhere():
    """The five-bar, registered by the tests, is listed, loads (built: it ships no files) and has no paper."""
    assert names() == ("hexapod", "rrr3", "delta", "prs3", "gough_stewart", "fivebar")
    assert names(with_files=True) == ("hexapod", "rrr3", "delta", "prs3", "gough_stewart")
    assert "fivebar" in pkm.MECHANISMS and "fivebar" not in papers.names()
    assert pkm.load("fivebar").spec.task.components == ("x", "y")


def test_register_refuses_a_taken_name_an_incomplete_package_and_other_objects():
    with pytest.raises(InvalidInputError, match="registered already"):
        register(MechanismDefinition("delta", "again", "pkm.mechanisms.delta"))
    with pytest.raises(InvalidInputError, match="does not implement MechanismModule"):
        register(MechanismDefinition("half", "a package without the closed forms", "pkm.mechanisms.delta.workspace"))
    with pytest.raises(InvalidInputError):
        register("delta")
    with pytest.raises(InvalidInputError, match="declares no CLOSED_FORMS"):
        register(MechanismDefinition("fast", "a sweeps module that is not one", "tests.fivebar", sweeps="pkm.errors"))
    assert "half" not in REGISTRY and "fast" not in REGISTRY


@pytest.mark.parametrize("name", [n for n in names() if REGISTRY[n].sweeps is not None])
def test_every_sweeps_module_declares_closed_forms_of_library_objectives(name):
    """An entry's ``sweeps`` is a module of its own package mapping objectives of :mod:`pkm.sweeps` to closed forms,
    whose options do not redefine the objectives' own."""
    import importlib

    from pkm.sweeps.objectives import OBJECTIVES, ClosedForm

    entry = REGISTRY[name]
    assert entry.sweeps.startswith(entry.package + ".")
    forms = importlib.import_module(entry.sweeps).CLOSED_FORMS
    assert forms and set(forms) <= set(OBJECTIVES), sorted(set(forms) - set(OBJECTIVES))
    for objective, closed in forms.items():
        assert isinstance(closed, ClosedForm) and callable(closed.function)
        assert not set(closed.options) & set(OBJECTIVES[objective].generic_options), (objective, closed.options)


def test_register_and_unregister_round_trip():
    entry = register(MechanismDefinition("fivebar_again", "the toy twice", "tests.fivebar"))
    try:
        assert definition("fivebar_again") is entry and "fivebar_again" in names()
    finally:
        unregister("fivebar_again")
    with pytest.raises(UnknownNameError, match="fivebar"):
        definition("fivebar_again")


def test_tangent_scale_spreads_the_task_scale_over_coordinates():
    assert definition("hexapod").tangent_scale(["x", "wz", "beta_1"]) == [0.03, 0.08, 0.3]
