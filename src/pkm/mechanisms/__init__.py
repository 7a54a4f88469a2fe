"""The four mechanisms of the papers, one module each.

Every package offers ``NAME``, ``Params`` (frozen dataclass, SI units), ``build(params)``,
``urdf_xml(params)``, ``closure_spec(params)`` and the closed forms
``closed_form_ik``, ``closed_form_configuration`` (and ``closed_form_fk`` where the paper
has one) over the task vector of :class:`pkm.core.TaskMap`.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from pkm.errors import UnknownNameError

NAMES = ("hexapod", "rrr3", "delta", "prs3")
TITLES = {
    "hexapod": "reconfigurable hexapod of two 3-RUS sub-manipulators (Sanchez-Alonso et al. 2016)",
    "rrr3": "planar 3-RRR (singularities and global condition index)",
    "delta": "Delta robot with reconfigurable base radius R (Hernandez Reyna & Sandoval-Castro 2018)",
    "prs3": "3-PRS (Diaz-Rodriguez et al. 2016: kinematics and inverse dynamics)",
}


def module(name: str) -> ModuleType:
    """The module of mechanism ``name``."""
    if not isinstance(name, str) or name not in NAMES:
        raise UnknownNameError("mechanism", repr(name) if not isinstance(name, str) else name, NAMES)
    return importlib.import_module(f"pkm.mechanisms.{name}")
