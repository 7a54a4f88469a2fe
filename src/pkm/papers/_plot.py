"""Figure helpers shared by the paper studies: headless matplotlib, one style."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def figure(*, ncols: int = 1, nrows: int = 1, size: tuple[float, float] = (6.4, 4.0)):
    """A new figure and its axes (Agg backend, no display needed)."""
    fig, axes = plt.subplots(nrows, ncols, figsize=(size[0] * ncols, size[1] * nrows), squeeze=False)
    return fig, axes if axes.size > 1 else axes[0, 0]


def save(fig, out_dir: Path | str, name: str) -> Path:
    """Write ``fig`` as ``out_dir/name.png`` (150 dpi) and close it."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"{name}.png"
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return path
