"""Checks shared by ``tests/mechanisms/<name>/test_params.py``: what a design dataclass's docstring states (each
field's unit in brackets, its default in parentheses) against its fields' metadata and defaults, and the refusal of
bad lengths and masses naming the field."""

from __future__ import annotations

import dataclasses
import math
import re

import pytest

from pkm.errors import InvalidParameterError

#: The unit spellings of the design fields (``pkm.mechanisms._common.param``).
UNITS = {"m", "rad", "kg", "kg m^2", "-"}
#: A number, or a list of numbers, with a unit, opening a parenthesis: ``(110 mm)``, ``(0.5 kg = 0.1 m_p)``.
_STATED = re.compile(r"\((-?\d[\d.]*(?:, -?\d[\d.]*)*) (mm|cm|m|kg|deg)\b")
_SCALE = {"mm": 1e-3, "cm": 1e-2, "m": 1.0, "kg": 1.0, "deg": math.pi / 180.0}
#: Values a length or a mass must not take: zero, negative, not finite, absurd (> 1e6 in SI: a unit error).
NOT_POSITIVE = [0.0, -0.05, math.nan, math.inf, -math.inf, 2e6]


def attribute_docs(cls) -> dict[str, str]:
    """``{field: its text}`` from the ``Attributes:`` section of ``cls``'s docstring (``a, b: text`` gives both)."""
    doc = cls.__doc__ or ""
    section = doc.split("Attributes:", 1)[1]
    out: dict[str, str] = {}
    current: list[str] = []
    for line in section.splitlines():
        m = re.match(r"^ {8}([A-Za-z_][\w, ]*):\s(.*)$", line)
        if m:
            current = [n.strip() for n in m.group(1).split(",")]
            for n in current:
                out[n] = m.group(2)
        elif line.startswith(" " * 12) and current:
            for n in current:
                out[n] += " " + line.strip()
        elif line.strip() and not line.startswith(" " * 8):
            break
    return out


def stated_defaults(cls) -> dict[str, tuple[float, ...]]:
    """The values the docstring states for the fields, in SI: the first ``(number unit`` of each field's text."""
    out = {}
    for name, text in attribute_docs(cls).items():
        m = _STATED.search(text)
        if m:
            out[name] = tuple(float(v) * _SCALE[m.group(2)] for v in m.group(1).split(", "))
    return out


def check_documented_defaults(cls, expected_fields: set[str]) -> None:
    """Each value the docstring states is the field's default (1e-12 relative), and it states one for at least
    ``expected_fields`` (the parser cannot pass by finding nothing)."""
    stated = stated_defaults(cls)
    assert expected_fields <= set(stated), sorted(expected_fields - set(stated))
    params = cls()
    for name, values in stated.items():
        default = getattr(params, name)
        got = tuple(default) if isinstance(default, tuple) else (default,)
        assert len(got) == len(values) and all(math.isclose(g, v, rel_tol=1e-12, abs_tol=1e-15)
                                               for g, v in zip(got, values)), (name, got, values)


def check_units_metadata(cls) -> None:
    """Every field has ``units`` and ``length`` metadata; numbers and tuples of numbers have units of the known
    spellings, text and integers none; a tuple default's length is its ``length``; each field's documented units
    (in brackets) are its metadata's."""
    docs = attribute_docs(cls)
    assert set(docs) == {f.name for f in dataclasses.fields(cls)}, "every field is documented"
    for f in dataclasses.fields(cls):
        assert {"units", "length"} <= set(f.metadata), f.name
        units = tuple(f.metadata["units"])
        assert set(units) <= UNITS, (f.name, units)
        if f.type in ("str", "int"):
            assert units == () and f.metadata["length"] is None, f.name
        else:
            assert units, f"{f.name} ({f.type}) has no unit"
        default = f.default if f.default is not dataclasses.MISSING else f.default_factory()
        if isinstance(default, tuple):
            assert f.metadata["length"] == len(default), f.name
        elif default is None:
            assert isinstance(f.metadata["length"], int) and f.metadata["length"] > 0, f.name
        assert set(re.findall(r"\[([^\[\],]+)\]", docs[f.name])) == set(units), (f.name, docs[f.name], units)


def check_refused(cls, field: str, value, **others) -> InvalidParameterError:
    """``cls(field=value, **others)`` is an InvalidParameterError whose ``name`` is ``field``, named in the message."""
    with pytest.raises(InvalidParameterError) as info:
        cls(**{field: value}, **others)
    err = info.value
    assert err.name == field and str(err).startswith(f"{field}: "), str(err)
    return err
