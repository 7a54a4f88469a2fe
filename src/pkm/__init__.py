"""pkm: parallel kinematic machines on Pinocchio."""

__version__ = "0.1.0"
