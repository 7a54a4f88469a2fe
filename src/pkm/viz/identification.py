"""Identification's figures: an excitation against its limits, and measured against predicted efforts. matplotlib is
the ``figures`` extra, imported when a figure is drawn."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pkm._optional import require
from pkm.core.identification.excitation import Excitation
from pkm.core.identification.export import Validation
from pkm.core.model.joints import stated_limits
from pkm.core.model.mechanism import Mechanism


def _units(mech: Mechanism) -> tuple[str, str, str]:
    revolute = [mech.joints[n].revolute for n in mech.actuated_names]
    pos = ", ".join(dict.fromkeys("rad" if r else "m" for r in revolute))
    rate = ", ".join(dict.fromkeys("rad/s" if r else "m/s" for r in revolute))
    effort = ", ".join(dict.fromkeys("N m" if r else "N" for r in revolute))
    return pos, rate, effort


def _save(fig: object, path: str | Path) -> Path:
    from pkm._plot import pyplot

    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()  # type: ignore[attr-defined]
    fig.savefig(out, dpi=150)  # type: ignore[attr-defined]
    pyplot().close(fig)
    return out


def excitation_figure(mech: Mechanism, excitation: Excitation, path: str | Path) -> Path:
    """Three panels over one period [s]: the actuated positions, rates and the model's efforts, each actuator a line,
    its finite limits dashed; the caption gives the condition number reached and the margins.

    Raises:
        MissingDependencyError: matplotlib is not installed (``pip install "pkm-robotics[figures]"``).
    """
    require("figures", "the figure of an excitation (pkm.viz.identification)")
    from pkm._plot import figure

    pos, rate, effort = _units(mech)
    fig, axes = figure(nrows=3, size=(7.0, 2.2))
    axes = np.asarray(axes).ravel()
    lo, hi = stated_limits(mech.model, mech.act_q)
    speed = [a.velocity_limit for a in mech.actuators]
    force = [a.effort_limit for a in mech.actuators]
    t = excitation.t
    qa = excitation(t)[0]
    series = ((qa, "position", pos, list(zip(lo, hi))), (excitation.QD, "rate", rate, [(-s, s) for s in speed]),
              (excitation.TAU, "effort (model)", effort, [(-f, f) for f in force]))
    for ax, (values, label, unit, limits) in zip(axes, series):
        for k, name in enumerate(mech.actuated_names):
            line, = ax.plot(t, values[:, k], label=name)
            low, high = limits[k]
            span = np.ptp(values)
            for bound in (low, high):  # (a limit far outside the motion would squash it: drawn only when near)
                if np.isfinite(bound) and abs(bound - values[:, k].mean()) <= 3.0 * max(span, 1e-12):
                    ax.axhline(bound, color=line.get_color(), ls="--", lw=0.8, label=f"{name} limit")
        ax.set_ylabel(f"{label} [{unit}]")
        ax.set_xlabel("time [s]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    margins = ", ".join(f"{k} {v:.2g}" for k, v in excitation.margins.items())
    fig.suptitle(f"{mech.name}: excitation, condition number {excitation.condition_start:.3g} -> "
                 f"{excitation.condition:.3g}\nno figure (identification); margins: {margins}", fontsize=9)
    return _save(fig, path)


def fit_figure(mech: Mechanism, validation: Validation, path: str | Path, *, title: str = "") -> Path:
    """One panel per actuator over time [s]: the measured efforts and the identified model's prediction, the
    relative RMS error in each panel's legend.

    Raises:
        MissingDependencyError: matplotlib is not installed (``pip install "pkm-robotics[figures]"``).
    """
    require("figures", "the figure of an identified model (pkm.viz.identification)")
    from pkm._plot import figure

    fig, axes = figure(nrows=mech.na, size=(7.0, 2.0))
    axes = np.atleast_1d(np.asarray(axes)).ravel()
    for k, (ax, name) in enumerate(zip(axes, mech.actuated_names)):
        unit = "N m" if mech.joints[name].revolute else "N"
        ax.plot(validation.t, validation.measured[:, k], color="0.6", lw=1.5, label="measured (filtered)")
        ax.plot(validation.t, validation.predicted[:, k], color="tab:blue", lw=1.0,
                label=f"predicted ({validation.relative[k]:.2g} % RMS)")
        ax.set_ylabel(f"{name} [{unit}]")
        ax.set_xlabel("time [s]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
    fig.suptitle(f"{mech.name}: measured and predicted efforts{': ' + title if title else ''}\n"
                 "no figure (identification)", fontsize=9)
    return _save(fig, path)


__all__ = ["excitation_figure", "fit_figure"]
