"""The checked-in ``urdf/`` files are the generators' output for the papers' reference designs,
as models (numbers to :data:`pkm.core.model.compare.RTOL` relative, :data:`~pkm.core.model.compare.ATOL`
absolute: another CPU's arithmetic rounds the last bits differently), and the wheel ships them
together with ``dynamics/``."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import pkm
from pkm.core.model.compare import document_differences, mechanism_differences
from pkm.data import spec_path, urdf_path
from pkm.mechanisms import module, names

ROOT = Path(__file__).resolve().parents[1]


def _report(what: str, diffs: list[str]) -> str:
    head = f"{what} differs from the generator's output in {len(diffs)} place(s):"
    return "\n".join([head, *diffs[:20], *(["..."] if len(diffs) > 20 else [])])


@pytest.mark.parametrize("name", names(with_files=True))
def test_checked_in_files_equal_generator_output(name):
    """``urdf/<name>.urdf`` and ``.closures.toml`` parse to what the generator writes: same elements,
    attributes, keys and strings, numbers within tolerance."""
    mod = module(name)
    params = mod.Params()
    diffs = document_differences(urdf_path(name).read_text(), mod.urdf_xml(params), "urdf")
    assert not diffs, _report(f"urdf/{name}.urdf", diffs)
    diffs = document_differences(spec_path(name).read_text(), mod.closure_spec(params).to_toml(), "toml")
    assert not diffs, _report(f"urdf/{name}.closures.toml", diffs)


@pytest.mark.parametrize("name", names(with_files=True))
def test_loading_the_files_gives_the_generated_mechanism(name, built):
    """``pkm.load`` (files) and the generator build the same model at the same reference."""
    diffs = mechanism_differences(pkm.load(name), built(name))
    assert not diffs, _report(f"pkm.load({name!r})", diffs)
    assert pkm.load(name).params == module(name).Params()  # read from the spec's [parameters], not assumed


def test_wheel_ships_urdf_and_dynamics(tmp_path):
    """The wheel contains every reference design and the dynamics data under ``pkm/_data``."""
    subprocess.run([sys.executable, "-m", "pip", "wheel", str(ROOT), "--no-deps", "--no-build-isolation",
                    "-q", "-w", str(tmp_path)], check=True)
    wheel = next(tmp_path.glob("pkm_robotics-*.whl"))
    shipped = set(zipfile.ZipFile(wheel).namelist())
    for name in names(with_files=True):
        assert f"pkm/_data/urdf/{name}.urdf" in shipped
        assert f"pkm/_data/urdf/{name}.closures.toml" in shipped
    assert "pkm/_data/dynamics/prs3_table2.toml" in shipped
    for folder, model in (("menagerie/agility_cassie", "cassie.xml"), ("menagerie/robotiq_2f85", "2f85.xml"),
                          ("menagerie/ufactory_xarm7", "xarm7.xml"),
                          ("toddlerbot/toddlerbot", "toddlerbot.xml")):  # (third-party robots, licence and source)
        for shipped_file in (model, "LICENSE", "SOURCE.txt"):
            assert f"pkm/_data/urdf/{folder}/{shipped_file}" in shipped
    assert "pkm/py.typed" in shipped
