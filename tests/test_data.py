"""pkm.data: the shipped data folders are found, every registered mechanism with files has its URDF and closure spec
where urdf_path/spec_path say (and the spec names that URDF), the dynamics files are there, and a missing folder or
an unknown kind is an error. (That the files equal the generators' output is ``tests/test_reference_files.py``.)"""

from __future__ import annotations

import pytest

from pkm import data
from pkm.core.model.spec import ClosureSpec
from pkm.errors import InvalidInputError, PkmError
from pkm.mechanisms import REGISTRY, names


@pytest.mark.parametrize("kind", ["urdf", "dynamics"])
def test_each_data_folder_exists_and_is_absolute(kind):
    """data_dir gives an existing absolute folder of that name (checkout or wheel layout alike)."""
    folder = data.data_dir(kind)
    assert folder.is_dir() and folder.is_absolute() and folder.name == kind


@pytest.mark.parametrize("name", names(with_files=True))
def test_every_mechanism_with_files_has_its_urdf_and_spec_and_the_spec_names_that_urdf(name):
    """urdf_path/spec_path point into the urdf folder at <name>.urdf and <name>.closures.toml, both files; the
    registry's ``reference`` is that spec; the spec's ``urdf`` key is the URDF's file name."""
    urdf, spec = data.urdf_path(name), data.spec_path(name)
    assert urdf.is_file() and spec.is_file()
    assert urdf.parent == spec.parent == data.data_dir("urdf")
    assert (urdf.name, spec.name) == (f"{name}.urdf", f"{name}.closures.toml") == (f"{name}.urdf", REGISTRY[name].reference)
    parsed = ClosureSpec.from_toml(spec.read_text(encoding="utf-8"), str(spec))
    assert parsed.mechanism == name and parsed.urdf == urdf.name


def test_every_top_level_file_of_the_urdf_folder_belongs_to_a_registered_mechanism():
    """No orphan reference files: each ``*.urdf`` / ``*.closures.toml`` at the folder's top is a registered
    mechanism's (subfolders hold other robots' packages)."""
    folder = data.data_dir("urdf")
    stems = {p.name.removesuffix(".closures.toml").removesuffix(".urdf") for p in folder.iterdir() if p.is_file()}
    assert stems == set(names(with_files=True))


@pytest.mark.parametrize("filename", ["prs3_table2.toml", "prs3_motions.toml"])
def test_the_dynamics_files_the_library_reads_exist(filename):
    """The 3-PRS Table 2 and its motion laws, read by pkm.mechanisms.prs3 and pkm.motion, are in the folder."""
    path = data.dynamics_path(filename)
    assert path.is_file() and path.parent == data.data_dir("dynamics") and path.stat().st_size > 0


def test_a_missing_data_folder_is_a_pkm_error_naming_the_kind(monkeypatch, tmp_path):
    """An installation without its data (neither ``pkm/_data/<kind>`` nor a checkout's ``<kind>/``) fails naming
    the folder, not with a FileNotFoundError later."""
    monkeypatch.setattr(data, "_PKG", tmp_path / "a" / "b" / "pkm")
    with pytest.raises(PkmError, match=r"pkm's dynamics/ data folder is missing"):
        data.data_dir("dynamics")
    (tmp_path / "a" / "b" / "pkm" / "_data" / "urdf").mkdir(parents=True)  # (the wheel's layout is looked at first)
    assert data.data_dir("urdf") == tmp_path / "a" / "b" / "pkm" / "_data" / "urdf"


def test_an_unknown_data_kind_is_an_invalid_input_error():
    """Only 'urdf' and 'dynamics' exist; another kind is pkm's InvalidInputError (a ValueError) naming it."""
    with pytest.raises(InvalidInputError, match="'meshes'"):
        data.data_dir("meshes")

