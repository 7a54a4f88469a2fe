"""Joint springs and dampers a model file states on joints (MJCF ``stiffness``, ``springref`` and ``damping``; an SDF
axis's ``<dynamics>``): kept in the closure spec's ``[springs.<joint>]`` tables, so that what the file says is
neither lost nor silently dropped::

    [springs.left-shin]
    stiffness = 1500.0      # N m/rad (a prismatic joint's: N/m)
    rest = 0.0              # rad (m): where the spring exerts nothing (MuJoCo's springref)
    damping = 0.1           # N m s/rad (N s/m)

A table may leave keys out (0). They are read, checked, written back by :func:`pkm.save` and named in the load notes;
pkm's dynamics do not apply their forces yet: a spring table describes the model, it changes no result. The damping
of an actuated joint is its drive's ``viscous`` friction (:mod:`pkm.core.model.actuators`), not a spring's.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from pkm.core.model.actuators import number_tables
from pkm.errors import SpecError

#: The keys of a ``[springs.<joint>]`` table, each 0 when left out.
SPRING_KEYS = ("stiffness", "rest", "damping")
_MAGNITUDE = 1e12  # (a stiffness or damping larger than this is no spring a file means: a unit mistake)


def parse_springs(raw: object, source: str) -> dict[str, dict[str, float]]:
    """The ``[springs]`` table of a closure spec (or a reader's): ``{joint: {key: value}}``, checked.

    Raises:
        SpecError: not a table of tables, an unknown key, a value that is not a finite number, a negative stiffness or
            damping, or one of 1e12 and more.
    """
    out = number_tables(raw, "springs", SPRING_KEYS, source)
    for joint, values in out.items():
        for key, value in values.items():
            if not math.isfinite(value):
                raise SpecError(source, f"springs.{joint}.{key} must be a finite number, got {value!r}")
            if key != "rest" and not 0.0 <= value < _MAGNITUDE:
                raise SpecError(source, f"springs.{joint}.{key} = {value!r}: a {key} is >= 0 and below {_MAGNITUDE:g}")
    return out


def describe(springs: Mapping[str, Mapping[str, float]]) -> str:
    """One line naming each spring and its values (for the load notes)."""
    return "; ".join(f"{j} (" + ", ".join(f"{k} {v:g}" for k, v in values.items()) + ")"
                     for j, values in springs.items())


__all__ = ["SPRING_KEYS", "describe", "parse_springs"]
