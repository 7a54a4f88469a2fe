"""Looking at a sweep: parameter-objective plots, Pareto fronts, and the best designs as closure specs.

(Not ``pkm/sweeps/plot.py``: a submodule named as the package's function :func:`pkm.sweeps.plot` replaces it in
the package as soon as the module is imported, ``sweeps.write_best`` first, say.)
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from pkm._optional import require
from pkm.errors import InvalidInputError, SweepError
from pkm.sweeps.family import from_description
from pkm.sweeps.results import SweepResult


def _result(result) -> SweepResult:
    return result if isinstance(result, SweepResult) else SweepResult.read(result)


def _label(res: SweepResult, name: str) -> str:
    o = res.objectives.get(name)
    if o is None:  # a parameter: its unit from the family's
        return f"{name} [{res.manifest.get('units', {}).get(name, 'SI')}]"
    unit = o.get("unit") or "-"
    arrow = {"max": " (higher is better)", "min": " (lower is better)"}.get(o.get("sense", ""), "")
    return f"{name} [{unit}]{arrow}"


def plot(result, out_dir, pareto: Sequence[str] | None = None) -> list[Path]:
    """Figures of a sweep (a :class:`SweepResult` or its file) in ``out_dir``:

    * ``sweep_parameters.png``: every objective against every parameter (one panel each; failed designs marked
      on the axis floor in red);
    * ``sweep_pareto.png``: each pair of the objectives ``pareto`` (default: every objective with a sense),
      the designs in grey and the Pareto front (by each objective's sense) in colour, joined.

    Returns:
        The paths written.

    Raises:
        MissingDependencyError: matplotlib (``pip install "pkm-robotics[figures]"``), or pyarrow to read a file
            (``pkm-robotics[sweeps]``), is not installed.
    """
    require("figures", "pkm.sweeps.plot")
    from pkm._plot import figure, save

    res = _result(result)
    params, objs = list(res.parameters), list(res.objectives)
    if not objs or not params:
        raise InvalidInputError("result", "nothing to plot: the sweep has no parameter or no objective")
    ok = res.ok
    out: list[Path] = []
    fig, axes = figure(ncols=len(params), nrows=len(objs), size=(3.2, 2.6))
    axes = np.atleast_2d(np.asarray(axes).reshape(len(objs), len(params)))
    for (i, o), (j, p) in itertools.product(enumerate(objs), enumerate(params)):
        ax = axes[i, j]
        x, y = res.column(p), res.column(o)
        ax.scatter(x[ok], y[ok], s=6, alpha=0.6, color="tab:blue", label="evaluated")
        if (~ok).any():
            floor = np.nanmin(y[ok]) if np.isfinite(y[ok]).any() else 0.0
            ax.scatter(x[~ok], np.full((~ok).sum(), floor), s=10, marker="x", color="tab:red", label="failed")
        ax.set(xlabel=_label(res, p), ylabel=_label(res, o))
        if i == 0 and j == 0:
            ax.legend(fontsize="small")
    fig.suptitle(f"{_family_title(res)}: {len(res)} designs ({int((~ok).sum())} failed)")
    out.append(save(fig, out_dir, "sweep_parameters"))

    names = list(pareto) if pareto else [o for o in objs if res.objectives[o].get("sense") in ("max", "min")]
    pairs = list(itertools.combinations(names, 2))
    if pairs:
        ncols = min(3, len(pairs))
        fig, axes = figure(ncols=ncols, nrows=-(-len(pairs) // ncols), size=(4.4, 3.8))
        panels = [axes] if len(pairs) == 1 else list(axes.ravel())
        for ax in panels[len(pairs):]:
            ax.set_visible(False)
        for ax, (a, b) in zip(panels, pairs):
            x, y = res.column(a), res.column(b)
            try:
                front = res.pareto([a, b])
            except SweepError:  # no design has both values (every design failed, say): no front to draw
                front = np.zeros(0, dtype=int)
            ax.scatter(x, y, s=6, color="0.7", label="designs")
            k = front[np.argsort(x[front])]
            ax.plot(x[k], y[k], "o-", color="tab:orange", ms=4, label=f"Pareto front ({len(front)})")
            ax.set(xlabel=_label(res, a), ylabel=_label(res, b))
            ax.legend(fontsize="small")
        fig.suptitle(f"{_family_title(res)}: Pareto fronts")
        out.append(save(fig, out_dir, "sweep_pareto"))
    return out


def _family_title(res: SweepResult) -> str:
    fam = res.manifest.get("family", {})
    return fam.get("registered") or Path(str(fam.get("source", "sweep"))).name


def write_best(result, by: str, out_dir, *, n: int = 3, mechanism=None) -> list[Path]:
    """The ``n`` best designs by objective ``by`` as closure specs (``best1.closures.toml`` and its URDF, ...) in
    ``out_dir``, ready for ``pkm preview``; ``mechanism``: the files of a loaded mechanism the sweep varied.

    Raises:
        SweepError: no design has a value of ``by`` (:meth:`~pkm.sweeps.SweepResult.best`).
        InvalidInputError: a loaded mechanism's files not given or not the same.
        Exception: whatever building the design raises (it could not assemble at its reference pose).
    """
    import pkm

    res = _result(result)
    family = from_description(res.manifest["family"], mechanism)
    rows = res.best(by, n)
    out = []
    for k, row in enumerate(rows, 1):
        mech = family.mechanism({p: row[p] for p in res.parameters})
        out.append(pkm.save(mech, Path(out_dir) / f"best{k}.closures.toml"))
    return out


__all__ = ["plot", "write_best"]
