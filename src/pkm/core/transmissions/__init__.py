"""Transmissions: a whole robot's closed sub-mechanisms as maps between motors and serial joints (issue 44).

:func:`transmissions` splits a robot into its serial tree and its closed sub-mechanisms
(:mod:`~pkm.core.transmissions.decompose`), each a :class:`Transmission`
(:mod:`~pkm.core.transmissions.transmission`) with its position, velocity and effort maps and the dynamics the
serial-equivalent model (:mod:`~pkm.core.transmissions.serial`) lacks, in output coordinates
(:mod:`~pkm.core.transmissions.coordinates`); :func:`serial_equivalent` builds the robot's serial-equivalent model,
with each output's box limits (:mod:`~pkm.core.transmissions.limits`), and :func:`write_serial_equivalent` writes it as
URDF, MJCF and a JSON data file.
"""

from pkm.core.transmissions.decompose import transmissions
from pkm.core.transmissions.limits import OutputLimits, output_limits
from pkm.core.transmissions.serial import SerialEquivalent, serial_equivalent, write_serial_equivalent
from pkm.core.transmissions.transmission import Transmission

__all__ = ["OutputLimits", "SerialEquivalent", "Transmission", "output_limits", "serial_equivalent", "transmissions",
           "write_serial_equivalent"]
