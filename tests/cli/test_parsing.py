"""pkm.cli.parsing: every parameter's units, from its metadata and its docstring."""

from __future__ import annotations

import dataclasses
import re

import pytest

import pkm
from pkm import cli
from pkm.mechanisms import module

CASES = [(name, f.name) for name in pkm.MECHANISMS for f in dataclasses.fields(module(name).Params)]


@pytest.mark.parametrize("mechanism,field", CASES)
def test_every_parameter_has_a_unit_in_its_metadata_and_docstring(mechanism, field):
    """Every Params field carries units that the CLI knows in its metadata, the same as in brackets in its docstring,
    unless it is text or an integer."""
    info = cli.param_info(mechanism)[field]
    assert info.description, f"{mechanism}.{field} is not in the Attributes section"
    if info.unitless:
        return
    assert info.units, f"{mechanism}.{field}: no unit in its metadata (pkm.mechanisms._common.param)"
    known = {"m", "rad", "kg", "kg m^2", "-"}
    assert set(info.units) <= known, info.units
    documented = tuple(dict.fromkeys(re.findall(r"\[([A-Za-z][A-Za-z0-9^ /*.-]*|-)\]", info.description)))
    assert info.units == documented, f"{mechanism}.{field}: metadata {info.units} but the docstring says {documented}"


def test_attribute_parser_reads_grouped_entries_and_continuations():
    """A grouped docstring entry gives each field the same unit; a continued entry keeps its continuation."""
    prs3 = cli.param_info("prs3")
    assert prs3["Ixx3"].units == prs3["Izz3"].units == ("kg m^2",)
    assert prs3["reference"].units == ("m", "rad")
    assert "(eq. 41)" in prs3["reference"].description and prs3["reference"].length == 3
    assert cli.param_info("delta")["La"].units == ("m",) and cli.param_info("delta")["La"].default == 0.11
