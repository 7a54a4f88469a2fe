"""Figure helpers shared by the paper studies: headless matplotlib, one style, and the check a published figure
must pass (:func:`problems`: units on every axis, a legend entry for every line, a colour bar for every image)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def figure(*, ncols: int = 1, nrows: int = 1, size: tuple[float, float] = (6.4, 4.0)):
    """A new figure and its axes (Agg backend, no display needed)."""
    fig, axes = plt.subplots(nrows, ncols, figsize=(size[0] * ncols, size[1] * nrows), squeeze=False)
    return fig, axes if axes.size > 1 else axes[0, 0]


def save(fig, out_dir: Path | str, name: str, *, layout: bool = True) -> Path:
    """Write ``fig`` as ``out_dir/name.png`` (150 dpi) and close it; ``layout``: tighten it first (False: the
    caller did, leaving room for a figure legend)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{name}.png"
    if layout:
        fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return path


_UNIT = "["  # an axis label states its unit in brackets: "R [mm]", "GCI [-]"


def problems(fig) -> list[str]:
    """What keeps ``fig`` from being published as it is, one line each (empty: none).

    Every axes that shows data has x and y labels with a unit in brackets (``[-]`` for a pure number); every line
    and scatter drawn carries a label that a legend of the figure shows (one legend may serve several panels; an
    axes with a single one may go without); every image or filled contour has a colour bar.
    """
    import matplotlib.collections as mcoll
    import matplotlib.contour as mcontour
    import matplotlib.image as mimage

    out = []
    bars = {ax for ax in fig.axes if getattr(ax, "_colorbar", None) is not None or ax.get_label() == "<colorbar>"}
    legends = [lg for lg in fig.legends] + [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    shown = {t.get_text() for lg in legends for t in lg.get_texts()}  # (a legend may serve several panels)
    barred = [im for ax in fig.axes for im in ax.get_images() + list(ax.collections)
              if getattr(im, "colorbar", None) is not None]  # (one bar may serve images of one colour scale)
    for k, ax in enumerate(fig.axes):
        if ax in bars or not ax.get_visible():
            continue
        name = ax.get_title() or f"axes {k}"
        lines = [ln for ln in ax.get_lines() if ln.get_visible()]
        dots = [c for c in ax.collections if isinstance(c, mcoll.PathCollection)]
        images = [im for im in ax.get_images() if isinstance(im, mimage.AxesImage)] + \
                 [c for c in ax.collections if isinstance(c, mcontour.ContourSet) and c.filled]
        if not (lines or dots or images or ax.patches):
            continue
        for axis, label in (("x", ax.get_xlabel()), ("y", ax.get_ylabel())):
            if _UNIT not in label:
                out.append(f"{name}: the {axis} label {label!r} states no unit in brackets")
        drawn = lines + dots
        if len(drawn) > 1:
            for artist in drawn:
                label = artist.get_label()
                if label.startswith("_") or label not in shown:
                    out.append(f"{name}: a line or marker set ({label!r}) is not in the legend")
        for im in images:
            if getattr(im, "colorbar", None) is None and not any(_same_scale(im, other) for other in barred):
                out.append(f"{name}: an image without a colour bar")
    return out


def _same_scale(a, b) -> bool:
    """Two images coloured by one colour map over one range (a shared colour bar reads both)."""
    return a.get_cmap().name == b.get_cmap().name and tuple(a.get_clim()) == tuple(b.get_clim())
