"""Figure helpers shared by pkm's figures (the paper studies, capability maps, sweeps, simulations, identification
runs, benchmarks): headless matplotlib, one style, and the check a published figure
must pass (:func:`problems`: a caption line naming the paper's figure, units on every axis, a legend entry for every
line, a colour bar for every image, no text cut off by the figure's edge). matplotlib is the ``figures`` extra,
imported on the first figure (:func:`pyplot`), so that the studies' numbers need none."""

from __future__ import annotations

import functools
from pathlib import Path

from pkm._optional import module

#: What needs the ``figures`` extra, as :class:`~pkm.errors.MissingDependencyError` says it.
WHAT = "pkm's figures (the papers', sweep plots)"


@functools.cache
def pyplot():
    """``matplotlib.pyplot`` on the Agg backend (no display needed), imported once.

    Raises:
        MissingDependencyError: matplotlib is not installed (``pip install "pkm-robotics[figures]"``).
    """
    module("matplotlib", extra="figures", what=WHAT).use("Agg")
    return module("matplotlib.pyplot", extra="figures", what=WHAT)


def figure(*, ncols: int = 1, nrows: int = 1, size: tuple[float, float] = (6.4, 4.0)):
    """A new figure and its axes (Agg backend, no display needed)."""
    fig, axes = pyplot().subplots(nrows, ncols, figsize=(size[0] * ncols, size[1] * nrows), squeeze=False)
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
    pyplot().close(fig)
    return path


_UNIT = "["  # an axis label states its unit in brackets: "R [mm]", "GCI [-]"


def problems(fig, *, paper: bool = True) -> list[str]:
    """What keeps ``fig`` from being published as it is, one line each (empty: none).

    The figure has a caption line (its suptitle, or the title of its only axes) that, for a ``paper`` study's
    figure, names the paper's figure (``Fig. N``) or says that the paper has none (``no figure``); every axes
    that shows data has x and y labels with a unit in brackets (``[-]`` for a pure number); every line and
    scatter drawn carries a label that a legend of the figure shows (one legend may serve several panels; an axes
    with a single one may go without); every image, mesh or filled contour has a colour bar; no title, label or
    legend text runs past the figure's edge (judged as the figure stands: check it after its layout, as it is
    saved).
    """
    pyplot()
    import matplotlib.collections as mcoll
    import matplotlib.contour as mcontour
    import matplotlib.image as mimage

    out = []
    shown_axes = [ax for ax in fig.axes if ax.get_visible() and ax.get_label() != "<colorbar>"]
    caption = fig._suptitle.get_text() if getattr(fig, "_suptitle", None) is not None else ""
    if not caption and len(shown_axes) == 1:
        caption = shown_axes[0].get_title()
    if not caption:
        out.append("no caption line (a suptitle naming the design and the paper's figure)")
    elif paper and "Fig." not in caption and "no figure" not in caption:
        out.append(f"the caption {caption!r} names no paper figure ('Fig. N', or 'no figure')")
    out += _clipped(fig)
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
                 [c for c in ax.collections if isinstance(c, mcoll.QuadMesh)
                  or (isinstance(c, mcontour.ContourSet) and c.filled)]
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


def _clipped(fig) -> list[str]:
    """Texts (titles, axis labels, legend entries) that run past the figure's edge."""
    renderer = fig.canvas.get_renderer()
    fig.draw_without_rendering()
    box = fig.bbox
    texts = [fig._suptitle] if getattr(fig, "_suptitle", None) is not None else []
    for ax in fig.axes:
        texts += [ax.title, ax._left_title, ax._right_title, ax.xaxis.label, ax.yaxis.label]
        if ax.get_legend() is not None:
            texts += list(ax.get_legend().get_texts())
    for lg in fig.legends:
        texts += list(lg.get_texts())
    out = []
    for t in texts:
        if not t.get_visible() or not t.get_text():
            continue
        e = t.get_window_extent(renderer)
        if e.x0 < box.x0 - 1 or e.x1 > box.x1 + 1 or e.y0 < box.y0 - 1 or e.y1 > box.y1 + 1:
            out.append(f"the text {t.get_text()[:60]!r} runs past the figure's edge")
    return out


def _same_scale(a, b) -> bool:
    """Two images coloured by one colour map over one range (a shared colour bar reads both)."""
    return a.get_cmap().name == b.get_cmap().name and tuple(a.get_clim()) == tuple(b.get_clim())
