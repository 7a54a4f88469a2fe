"""meshcat, imported on first use, and the error saying how to install it when it is missing."""

from __future__ import annotations

import warnings

from pkm.errors import PkmError


class VizDependencyError(PkmError, ImportError):
    """meshcat (or its msgpack encoder) is not installed.

    Attributes:
        missing: The module that could not be imported.
    """

    def __init__(self, missing: str):
        self.missing = missing
        super().__init__("pkm.viz needs meshcat: pip install meshcat")


def load_meshcat():
    """The meshcat modules pkm.viz uses, imported on first use."""
    try:
        with warnings.catch_warnings():  # meshcat imports its server, which imports a deprecated zmq module
            warnings.simplefilter("ignore", DeprecationWarning)
            import meshcat.animation
            import meshcat.commands
            import meshcat.geometry
            import meshcat.path
            import umsgpack
    except ImportError as exc:
        raise VizDependencyError(exc.name or "meshcat") from None
    return meshcat, umsgpack
