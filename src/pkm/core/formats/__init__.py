"""The closed-loop model formats pkm reads besides its own closure spec, each turned into one
representation (:class:`~pkm.core.formats.imported.Imported`: URDF text, loops, joint types, actuators):

* :mod:`~pkm.core.formats.gepetto`: URDF + ``robot.yaml`` in the convention of Gepetto's
  toolbox-parallel-robots;
* :mod:`~pkm.core.formats.mjcf`: MuJoCo's MJCF, loops as ``<equality>`` connect/weld;
* :mod:`~pkm.core.formats.sdf`: SDFormat, loops as links with several parent joints.

A closure spec's ``urdf`` key may name an MJCF or SDF file as well as a URDF: the file's loops and
joint types are added to the spec's (:func:`~pkm.core.formats.imported.import_model`).
:mod:`~pkm.core.formats.to_mjcf` writes any mechanism as MJCF (for MuJoCo, and back).
"""

from pkm.core.formats.gepetto import gepetto_files, load_gepetto, spec_from_gepetto
from pkm.core.formats.imported import SUFFIXES, Imported, import_model

__all__ = ["SUFFIXES", "Imported", "gepetto_files", "import_model", "load_gepetto", "spec_from_gepetto"]
