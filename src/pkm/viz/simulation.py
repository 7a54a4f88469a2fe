"""The figure of a simulation (:func:`pkm.simulate`): four stacked panels sharing the time axis, the actuated
positions, their speeds, the efforts applied and the energies, with the time of the event that stopped the run
marked. matplotlib is the ``figures`` extra, imported when a figure is drawn."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pkm._optional import require
from pkm.core.dynamics.samples import column_units, columns
from pkm.core.dynamics.simulate import Simulation
from pkm.core.model.mechanism import Mechanism

WHAT = "the figure of a simulation (pkm.viz.simulation)"
"""What needs the ``figures`` extra, as :class:`~pkm.errors.MissingDependencyError` says it."""


def _unit(units: dict[str, str], names: list[str]) -> str:
    """The units of ``names``, joined when they differ (``rad, m``: revolute and prismatic actuators)."""
    return ", ".join(dict.fromkeys(units[n] for n in names))


def plot(mech: Mechanism, sim: Simulation, path: str | Path, *, title: str | None = None) -> Path:
    """Draw ``sim`` (a simulation of ``mech``) into ``path`` (PNG, 150 dpi): four panels over time [s]:

    1. the actuated positions ``q_a`` [rad or m], one line per actuator;
    2. their speeds ``qd_a`` [rad/s or m/s];
    3. the efforts applied ``tau_a`` [N m or N] (after saturation);
    4. the energies [J] as changes from the start, so that the balance reads off the panel: kinetic,
       potential ``- V(0)``, total ``- E(0)``, and ``work - dissipated``, which the total follows.

    A run stopped early has its event's time marked on every panel (a dashed vertical line, its kind in the
    legend).

    Returns:
        The path written (its folder created).

    Raises:
        MissingDependencyError: matplotlib is not installed (``pip install "pkm-robotics[figures]"``).
        InvalidInputError: ``sim`` is not a simulation of ``mech``.
    """
    require("figures", WHAT)
    from pkm._plot import figure, pyplot

    cols = columns(mech, sim)
    units = column_units(mech, sim)
    names = list(mech.actuated_names)
    t = cols["time"]
    fig, axes = figure(nrows=4, size=(7.0, 2.2))
    axes = np.asarray(axes).ravel()
    for ax, (prefix, label) in zip(axes[:3], (("q", "position"), ("qd", "speed"), ("tau", "effort"))):
        keys = [f"{prefix}.{n}" for n in names]
        for key, name in zip(keys, names):
            ax.plot(t, cols[key], label=name)
        ax.set_ylabel(f"{label} [{_unit(units, keys)}]")
    e0, v0 = cols["energy"][0], cols["potential"][0]
    ax = axes[3]
    ax.plot(t, cols["kinetic"], label="kinetic")
    ax.plot(t, cols["potential"] - v0, label="potential - V(0)")
    ax.plot(t, cols["energy"] - e0, label="total - E(0)")
    ax.plot(t, cols["work"] - cols["dissipated"], "--", label="work - dissipated")
    ax.set_ylabel("energy [J]")
    for ax in axes:
        if sim.event is not None:
            ax.axvline(sim.event.time, color="tab:red", ls=":", lw=1.5, label=f"stop: {sim.event.kind}")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5), frameon=False)
        ax.set_xlabel("time [s]")
        if len(t) > 1:  # (past the last sample when the run stopped early, so that its mark shows)
            ax.set_xlim(t[0], t[-1] + (0.03 * (t[-1] - t[0]) if sim.event is not None else 0.0))
    ended = f"stopped at {sim.event.time:.4g} s ({sim.event.kind})" if sim.event is not None else \
        f"{t[-1]:.4g} s" if len(t) else "no sample"
    fig.suptitle(title or f"{mech.name}: simulation, {sim.method}, {len(t)} samples, {ended}")
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(out, dpi=150)
    pyplot().close(fig)
    return out


__all__ = ["WHAT", "plot"]
