"""pkm.core.model.compare: documents and mechanisms compared after parsing, numbers within tolerance."""

from __future__ import annotations

import pytest

import pkm
from pkm.core.model.compare import ATOL, RTOL, close, document_differences, mechanism_differences
from pkm.errors import InvalidInputError

URDF = """<?xml version='1.0' encoding='utf-8'?>
<robot name="r">
  <link name="base"/>
  <link name="arm"/>
  <joint name="j" type="revolute">
    <origin xyz="0.1 0.0 0.0" rpy="0.0 -0.0 {yaw}"/>
    <parent link="base"/><child link="arm"/>
    <limit effort="1.0" velocity="1.0" lower="-1.0" upper="1.0"/>
  </joint>
</robot>
"""


def test_close_is_relative_with_an_absolute_floor():
    """The stated rule: |a - b| <= rtol max(|a|, |b|) + atol."""
    assert close(-2.094395102393196, -2.0943951023931957)  # one ulp apart: another CPU's sin/cos
    assert close(-0.0, -7.7e-18)  # a round-off zero
    assert not close(1.0, 1.0 + 3 * RTOL)
    assert not close(0.0, 2 * ATOL)


def test_last_bit_differences_are_the_same_document():
    """A URDF whose numbers differ in the last bit, or in the sign of a zero, is the same model."""
    a = URDF.format(yaw="-2.094395102393196")
    b = URDF.format(yaw="-2.0943951023931957").replace("-0.0", "0.0")
    assert document_differences(a, b, "urdf") == []


def test_a_changed_number_is_named_with_its_place_and_size():
    """A real change is reported where it is (element, attribute, index) and by how much."""
    diffs = document_differences(URDF.format(yaw="0.5"), URDF.format(yaw="0.5000001"), "urdf")
    assert len(diffs) == 1
    assert "joint['j']/origin@rpy[2]" in diffs[0] and "differ by 1e-07" in diffs[0]


def test_structure_and_strings_must_be_equal():
    """Another element, another name, a missing attribute: each is a difference."""
    a = URDF.format(yaw="0")
    assert document_differences(a, a.replace('name="arm"', 'name="link"'), "urdf")
    assert document_differences(a, a.replace(' effort="1.0"', ""), "urdf") == [
        "/robot['r']/joint['j']/limit@effort: only in the first"]


def test_toml_documents_compare_keys_strings_and_numbers():
    a = 'x = "a"\n[t]\nv = [1.0, 2.0]\n'
    assert document_differences(a, 'x = "a"\n[t]\nv = [1.0, 2.0000000000000004]\n', "toml") == []
    assert document_differences(a, 'x = "a"\n[t]\nv = [1.0, 2.1]\n', "toml")[0].startswith("t.v[1]: 2.0 vs 2.1")
    assert document_differences(a, 'x = "b"\n[t]\nv = [1.0, 2.0]\n', "toml") == ["x: 'a' != 'b'"]
    assert document_differences(a, 'x = "a"\n[t]\nv = [1.0]\n', "toml") == ["t.v: 2 entries vs 1"]


def test_unknown_kind_is_refused():
    with pytest.raises(InvalidInputError):
        document_differences("", "", "yaml")


def test_mechanisms_of_two_designs_differ_where_the_design_does(built):
    """The Delta with another base radius differs in the placements that R sets and in its reference."""
    assert mechanism_differences(built("delta"), built("delta")) == []
    diffs = mechanism_differences(built("delta"), pkm.build("delta", R=0.151))
    assert diffs and any("placement" in d for d in diffs) and any("reference" in d for d in diffs)
    assert mechanism_differences(built("delta"), built("rrr3"))[0].startswith("nq")
