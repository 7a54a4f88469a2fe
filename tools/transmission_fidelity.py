"""The fidelity table and figure of issue 44 (:mod:`pkm.core.transmissions.fidelity`): a chirp and a walking-like
swing of motor torques, 2 s, on the humanoid ankle and knee (and, with ``--leg``, Gepetto's battobot's right ankle),
(a) the closed loop by pkm.simulate, (b) the serial model in MuJoCo with constant armature, (c) with pkm's ΔM, Δh.

    python tools/transmission_fidelity.py [OUT_DIR] [--leg]

Prints the Markdown table; writes ``OUT_DIR/transmission_fidelity.png`` (the output errors of (b) and (c) against
(a) over time, log scale) when matplotlib is installed. Needs MuJoCo (the ``bench`` extra). Takes a few minutes.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import pkm
from pkm.core.transmissions.fidelity import fidelity, table

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def main(argv: list[str]) -> None:
    out = Path(next((a for a in argv if not a.startswith("--")), "out/figures"))
    robots = {"humanoid_ankle": pkm.load(EXAMPLES / "humanoid_ankle" / "ankle.closures.toml"),
              "humanoid_knee": pkm.load(EXAMPLES / "humanoid_knee" / "knee.closures.toml")}
    picks = [(name, pkm.transmissions(mech)[0]) for name, mech in robots.items()]
    if "--leg" in argv:
        picks.append(("battobot_6d", next(t for t in pkm.transmissions(pkm.load("gepetto:battobot_6d"))
                                          if t.name == "foot_assembly")))
    rows = []
    for _, t in picks:
        rows += fidelity(t, duration=2.0, dt=1e-3)
    print(table(rows))
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    fig, axes = plt.subplots(len(rows), 1, figsize=(8, 2.2 * len(rows)), sharex=True)
    for ax, r in zip(np.atleast_1d(axes), rows):
        time = np.arange(len(r.traces["a"])) * r.dt
        for key, label in (("b", "(b) constant armature"), ("c", "(c) serial + ΔM + Δh")):
            ax.semilogy(time, np.abs(r.traces[key] - r.traces["a"]).max(axis=1) + 1e-17, label=label)
        ax.set_title(f"{r.transmission}, {r.profile}: output error against the closed loop", fontsize=9)
        ax.set_ylabel("rad")
    np.atleast_1d(axes)[0].legend(fontsize=8)
    np.atleast_1d(axes)[-1].set_xlabel("t [s]")
    out.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(out / "transmission_fidelity.png", dpi=110)


if __name__ == "__main__":
    main(sys.argv[1:])
