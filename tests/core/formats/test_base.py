"""The one table of model-file formats: every format pkm reads is a registered Format, and a new one is one reader
and one registry line (a toy format registered here is loaded by pkm.load and written out by pkm spec init)."""

from __future__ import annotations

import numpy as np
import pytest

import pkm
from pkm.core.formats import base
from pkm.core.kinematics import constraints
from pkm.core.model.spec import Closure
from pkm.errors import InvalidInputError
from tests import fivebar


def test_the_table_names_every_format_pkm_reads():
    assert set(base.FORMATS) == {"urdf", "mjcf", "sdf", "usd"}
    assert base.suffixes() == {".urdf": "urdf", ".xml": "mjcf", ".mjcf": "mjcf", ".sdf": "sdf", ".usda": "usd",
                               ".usd": "usd", ".usdc": "usd"}
    assert base.by_root("mujoco").name == "mjcf" and base.by_root("nothing") is None
    assert base.by_root("") is None and base.FORMATS["usd"].opens  # (USD has no root element: its reader opens it)
    from pkm.core.formats import SUFFIXES  # (the old constant, read from the table)

    assert SUFFIXES == base.suffixes()


def _read_toy(text: str, source: str) -> base.Imported:
    """A toy format: ``<toy actuated="a b" loop="frame_a frame_b">`` wrapping a URDF's <robot>."""
    from lxml import etree

    root = etree.fromstring(text.encode())
    urdf = etree.tostring(root.find("robot")).decode()
    a, b = root.get("loop").split()
    return base.Imported(urdf, (Closure("toy_loop", "point", a, b),), {}, tuple(root.get("actuated").split()),
                         "toy", "toy", notes=("read by the toy reader",))


def test_a_registered_format_is_read_by_pkm_load_and_spec_init(tmp_path, monkeypatch):
    monkeypatch.setitem(base.FORMATS, "toy", base.Format("toy", (".toy",), "toy", _read_toy))
    urdf = fivebar.urdf_xml(fivebar.Params()).split("?>", 1)[-1]
    path = tmp_path / "five.toy"
    path.write_text(f'<toy actuated="motor_1 motor_2" loop="tip_1 tip_2">{urdf}</toy>')
    mech = pkm.load(path)
    assert mech.actuated_names == ("motor_1", "motor_2") and mech.notes[0] == "read by the toy reader"
    assert np.abs(constraints.residual(mech, mech.q_reference)).max() <= 1e-10
    from pkm.core.formats.imported import spec_skeleton

    text, complete = spec_skeleton(path)
    assert complete and 'urdf = "five.toy"' in text and "toy_loop: point closure between tip_1 and tip_2" in text


def test_only_a_format_is_registered():
    with pytest.raises(InvalidInputError, match="Format"):
        base.register_format(("toy", ".toy"))  # type: ignore[arg-type]
