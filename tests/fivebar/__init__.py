"""A toy planar five-bar, registered by the tests only (``tests/conftest.py``): the proof that a fifth
mechanism is one folder plus one registry entry.

Two motors at ``A_1 = (-d/2, 0)`` and ``A_2 = (d/2, 0)`` turn proximal links of length ``l1``; distal
links of length ``l2`` meet at the tip ``P = (x, y)``, the task. The loop is closed by a point
closure between the two distal tips. Working modes: the elbows' bending signs.
"""

from __future__ import annotations

from tests.fivebar.kinematics import (
    closed_form_configuration,
    closed_form_fk,
    closed_form_ik,
    inverse_kinematics,
    reference_pose,
)
from tests.fivebar.model import build, closure_spec, urdf_xml
from tests.fivebar.params import BRANCHES, NAME, FiveBarParams, Params

__all__ = ["BRANCHES", "NAME", "FiveBarParams", "Params", "build", "closed_form_configuration", "closed_form_fk",
           "closed_form_ik", "closure_spec", "inverse_kinematics", "reference_pose",
           "urdf_xml"]
