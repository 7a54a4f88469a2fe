"""Drawing figures with every one inspected (pkm._plot.problems) as it is saved."""

from __future__ import annotations

import contextlib
from pathlib import Path
from unittest import mock

from matplotlib.figure import Figure

from pkm import _plot


@contextlib.contextmanager
def inspected(*, paper: bool = True):
    """Within: every matplotlib figure saved to a file, by any code of this process, is inspected as it is saved
    (after its layout; ``paper``: as a paper study's figure); yields ``{file stem: problems}``."""
    found: dict[str, list[str]] = {}
    real = Figure.savefig

    def savefig(fig, fname, *args, **kw):
        found[Path(fname).stem] = _plot.problems(fig, paper=paper)
        return real(fig, fname, *args, **kw)

    with mock.patch.object(Figure, "savefig", savefig):
        yield found


def draw_checked(module, out_dir):
    """``(paths, {figure: problems})`` of ``module.figures(out_dir)``."""
    with inspected() as found:
        paths = module.figures(out_dir)
    return paths, found


def uncovered(module, figures, series) -> list[str]:
    """What keeps ``module.SERIES`` (figure -> the CSV series holding its numbers) from covering every figure drawn,
    one line each: a figure it does not list, a series it names that ``series()`` did not write, a series without a
    header and a row of numbers."""
    written = {Path(p).stem: Path(p) for p in series}
    out = [f"{Path(f).stem}: no series listed" for f in figures if Path(f).stem not in module.SERIES]
    for fig, names in module.SERIES.items():
        for name in names:
            if name not in written:
                out.append(f"{fig}: its series {name!r} was not written")
                continue
            with written[name].open() as fh:
                head, first = fh.readline(), fh.readline()
            if "," not in head or not any(c.isdigit() for c in first):
                out.append(f"{fig}: {name}.csv has no header and numbers")
    return out
