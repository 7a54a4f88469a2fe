"""A mechanism's kinematics and dynamics as a self-contained C99 library (:func:`export_c`, ``pkm export c``)."""

from pkm.core.export.library import CLibrary, export_c
from pkm.core.export.model import ExportError

__all__ = ["CLibrary", "ExportError", "export_c"]
