"""The checked-in ``urdf/`` files are the generators' output for the papers' reference designs,
and the wheel ships them together with ``dynamics/``."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

import pkm
from pkm.data import spec_path, urdf_path
from pkm.mechanisms import NAMES, module

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("name", NAMES)
def test_checked_in_files_equal_generator_output(name):
    """``urdf/<name>.urdf`` and ``.closures.toml`` equal what the generator writes (tools/generate_urdf.py)."""
    mod = module(name)
    params = mod.Params()
    assert urdf_path(name).read_text() == mod.urdf_xml(params), "run: python tools/generate_urdf.py"
    assert spec_path(name).read_text() == mod.closure_spec(params).to_toml(), "run: python tools/generate_urdf.py"


@pytest.mark.parametrize("name", NAMES)
def test_loading_the_files_gives_the_generated_mechanism(name, built):
    """``pkm.load`` (files) and the generator build the same model at the same reference."""
    loaded, generated = pkm.load(name), built(name)
    assert (loaded.nq, loaded.nv, loaded.na, loaded.n_constraints) == (
        generated.nq, generated.nv, generated.na, generated.n_constraints)
    assert np.array_equal(loaded.q_reference, generated.q_reference)


def test_wheel_ships_urdf_and_dynamics(tmp_path):
    """The wheel contains every reference design and the dynamics data under ``pkm/_data``."""
    subprocess.run([sys.executable, "-m", "pip", "wheel", str(ROOT), "--no-deps", "--no-build-isolation",
                    "-q", "-w", str(tmp_path)], check=True)
    wheel = next(tmp_path.glob("pkm-*.whl"))
    names = set(zipfile.ZipFile(wheel).namelist())
    for name in NAMES:
        assert f"pkm/_data/urdf/{name}.urdf" in names
        assert f"pkm/_data/urdf/{name}.closures.toml" in names
    assert "pkm/_data/dynamics/prs3_table2.toml" in names
    assert "pkm/py.typed" in names
