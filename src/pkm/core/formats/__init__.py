"""The closed-loop model formats pkm reads besides its own closure spec, each turned into one
representation (:class:`~pkm.core.formats.base.Imported`: URDF text, loops, joint types, actuators):

* :mod:`~pkm.core.formats.gepetto`: URDF + YAML in the convention of Gepetto's toolbox-parallel-robots;
* :mod:`~pkm.core.formats.hyrodyn`: a robot URDF + HyRoDyn's ``submechanisms.yml`` (DFKI; Phobos's SMURF), loops as
  numerical submechanisms' loop constraints;
* :mod:`~pkm.core.formats.mjcf`: MuJoCo's MJCF, loops as ``<equality>`` connect/weld;
* :mod:`~pkm.core.formats.sdf`: SDFormat, loops as links with several parent joints;
* :mod:`~pkm.core.formats.usd`: USD, a UsdPhysics articulation, loops as joints excluded from it (``usd-core``, the
  ``usd`` extra);
* :mod:`~pkm.core.formats.urdfplus`: a URDF with MIT's URDF+ ``<loop>`` or urdfdom's proposed ``<constraint>``
  elements (read through the URDF format's reader);
* :mod:`~pkm.core.formats.packages`: models an installed package ships, by name.

A closure spec's ``urdf`` key may name an MJCF or SDF file as well as a URDF: the file's loops and
joint types are added to the spec's (:func:`~pkm.core.formats.imported.import_model`).
:mod:`~pkm.core.formats.load` makes mechanisms of them (through :mod:`pkm.core.model.builder`);
:mod:`~pkm.core.formats.to_mjcf` writes any mechanism as MJCF (for MuJoCo, and back), :mod:`~pkm.core.formats.to_gepetto`
as Gepetto's URDF + YAML, :mod:`~pkm.core.formats.to_urdfplus` as URDF+, :mod:`~pkm.core.formats.to_usd` as USD; :mod:`~pkm.core.formats.writers`
chooses among them and pkm's spec by suffix (:func:`pkm.save`, ``pkm convert``).

The names below are imported on first use, so that importing one format module does not import the others.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pkm._lazy import lazy

_WHERE = {"FORMATS": "pkm.core.formats.base", "Format": "pkm.core.formats.base", "register_format": "pkm.core.formats.base",
          "SUFFIXES": "pkm.core.formats.base", "Imported": "pkm.core.formats.base",
          "import_model": "pkm.core.formats.imported", "gepetto_files": "pkm.core.formats.gepetto",
          "spec_from_gepetto": "pkm.core.formats.gepetto", "load_gepetto": "pkm.core.formats.load",
          "load_path": "pkm.core.formats.load"}

if TYPE_CHECKING:
    from pkm.core.formats.base import FORMATS, SUFFIXES, Format, Imported, register_format
    from pkm.core.formats.gepetto import gepetto_files, spec_from_gepetto
    from pkm.core.formats.imported import import_model
    from pkm.core.formats.load import load_gepetto, load_path

__getattr__, __dir__ = lazy("pkm.core.formats", globals(), _WHERE)

__all__ = ["FORMATS", "SUFFIXES", "Format", "Imported", "gepetto_files", "import_model", "load_gepetto", "load_path", "register_format", "spec_from_gepetto"]
