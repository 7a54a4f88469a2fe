"""Deprecated alias of :mod:`pkm.core.differential.indices` (moved in 0.2.0): import that module instead."""

from typing import TYPE_CHECKING

from pkm._moved import alias

if TYPE_CHECKING:  # (what type checkers see: the module's names)
    from pkm.core.differential.indices import *  # noqa: F403

alias(__name__, "pkm.core.differential.indices")
