"""Design sweeps on Dask: every design of a space scored by the library's analyses, results in Parquet.

::

    import pkm
    from pkm import sweeps

    res = pkm.sweep("rrr3", sweeps.grid(a="20cm:65cm:10", b="20cm:65cm:10", h="5cm:50cm:10"),
                    ["gci", "gci_area", "coverage"], out="rrr3.parquet")   # a LocalCluster, one worker per core
    res.best("gci_area", 3)                                                 # rows, best first
    res.pareto(["gci_area", "coverage"])                                    # rows on the front
    sweeps.plot(res, "figures/")                                            # parameter-objective and Pareto plots
    sweeps.write_best(res, "gci_area", "best/", n=3)                        # closure specs for pkm preview

The pieces: :mod:`~pkm.sweeps.space` (grids, Sobol', Latin hypercubes, tables), :mod:`~pkm.sweeps.family`
(what varies: a registered mechanism's design fields or a loaded one's joint origins), :mod:`~pkm.sweeps.objectives`
(what is scored), :mod:`~pkm.sweeps.engine` (Dask, chunks, Parquet, resume) and :mod:`~pkm.sweeps.figures`. No
submodule is named as one of the package's names (importing it would replace that name in the package).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pkm._lazy import lazy
from pkm.errors import SweepError

#: Where each name lives, imported on first use (the command line reads the objectives' names without the engine).
_WHERE = {"sweep": "pkm.sweeps.engine",
          **dict.fromkeys(("Candidate", "Family", "ModelFamily", "RegisteredFamily", "family_of"), "pkm.sweeps.family"),
          **dict.fromkeys(("OBJECTIVES", "Objective", "objective"), "pkm.sweeps.objectives"),
          **dict.fromkeys(("plot", "write_best"), "pkm.sweeps.figures"),
          **dict.fromkeys(("Stats", "SweepResult", "pareto_front", "read"), "pkm.sweeps.results"),
          **dict.fromkeys(("Designs", "Space", "grid", "latin_hypercube", "sobol", "table"), "pkm.sweeps.space"),
          "FORMAT": "pkm.sweeps.store"}

if TYPE_CHECKING:  # the static view of the lazy names
    from pkm.sweeps.engine import sweep
    from pkm.sweeps.family import Candidate, Family, ModelFamily, RegisteredFamily, family_of
    from pkm.sweeps.figures import plot, write_best
    from pkm.sweeps.objectives import OBJECTIVES, Objective, objective
    from pkm.sweeps.results import Stats, SweepResult, pareto_front, read
    from pkm.sweeps.space import Designs, Space, grid, latin_hypercube, sobol, table
    from pkm.sweeps.store import FORMAT

__getattr__, __dir__ = lazy("pkm.sweeps", globals(), _WHERE)

__all__ = ["FORMAT", "OBJECTIVES", "Candidate", "Designs", "Family", "ModelFamily", "Objective", "RegisteredFamily",
           "Space", "Stats", "SweepError", "SweepResult", "family_of", "grid", "latin_hypercube", "objective",
           "pareto_front", "plot", "read", "sobol", "sweep", "table", "write_best"]
