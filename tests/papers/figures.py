"""Drawing figures with every one inspected (pkm.papers._plot.problems) as it is saved."""

from __future__ import annotations

import contextlib
from unittest import mock

from pkm.papers import _plot


@contextlib.contextmanager
def inspected(*modules):
    """Within: every figure saved through ``pkm.papers._plot.save`` (and the ``save`` that ``modules`` imported)
    is inspected first; yields ``{figure name: problems}``."""
    found: dict[str, list[str]] = {}
    real = _plot.save

    def save(fig, where, name, **kw):
        found[name] = _plot.problems(fig)
        return real(fig, where, name, **kw)

    with contextlib.ExitStack() as stack:
        for target in (_plot, *modules):
            stack.enter_context(mock.patch.object(target, "save", save))
        yield found


def draw_checked(module, out_dir):
    """``(paths, {figure: problems})`` of ``module.figures(out_dir)``."""
    with inspected(module) as found:
        paths = module.figures(out_dir)
    return paths, found
