"""Transmissions: a whole robot's closed sub-mechanisms as maps between motors and serial joints (issue 44).

:func:`transmissions` splits a robot into its serial tree and its closed sub-mechanisms
(:mod:`~pkm.core.transmissions.decompose`), each a :class:`Transmission`
(:mod:`~pkm.core.transmissions.transmission`) with its position, velocity and effort maps and the dynamics the
serial-equivalent model (:mod:`~pkm.core.transmissions.serial`) lacks, in output coordinates
(:mod:`~pkm.core.transmissions.coordinates`).
"""

from pkm.core.transmissions.decompose import transmissions
from pkm.core.transmissions.transmission import Transmission

__all__ = ["Transmission", "transmissions"]
