"""Generic start systems for parameter homotopies: one family of reduced equations (a group and its legs' kinds,
``"SE3:ssssss"``) solved once at random complex parameters, then every member of the family is reached by
tracking only those solutions (Morgan & Sommese 1989: along a straight path from generic complex parameters,
every isolated solution of the target is the end of a path from a generic solution, with probability one).

The six-sphere family (every 6-SS, RUS, UPS platform) has 40 generic solutions (Raghavan 1993; Husty 1996) out of
the 128 paths of its total-degree start: 40 paths instead of 128 for every solve. The families pkm ships are in
``starts/*.json``, written by ``tools/generic_starts.py``; another family is solved on first use and kept for the
process.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.modes.continuation import solve
from pkm.core.modes.equations import N_UNKNOWNS, equations
from pkm.core.modes.polynomial import Poly, variables

_DIR = Path(__file__).resolve().parent / "starts"
#: Parameters per leg kind and group (:func:`pkm.core.modes.equations.leg_parameters`).
_N_PARAMS = {("SE3", "s"): 7, ("SE3", "c"): 11, ("T3", "s"): 7, ("T3", "c"): 11, ("SE2", "s"): 5}


@dataclass(frozen=True)
class GenericStart:
    """A family's generic solutions.

    Attributes:
        signature: The family (``"SE3:ssssss"``).
        params: The generic complex parameters, one array per leg.
        points: The generic isolated solutions that are poses (complex, nonsingular; Study's exceptional set
            ``e = 0`` and the other singular ends left out).
        total_degree: Paths of the total-degree solve that found them.
        n_failed: Its failed paths (0, or the start is not known to be complete).
        seed: The random generator's seed of the parameters.
    """

    signature: str
    params: tuple[np.ndarray, ...]
    points: tuple[np.ndarray, ...]
    total_degree: int
    n_failed: int
    seed: int

    @property
    def complete(self) -> bool:
        return self.n_failed == 0

    def to_json(self) -> str:
        def cplx(a: ArrayLike) -> list[list[float]]:
            return [[float(z.real), float(z.imag)] for z in np.asarray(a, dtype=complex)]

        return json.dumps({"format": "pkm.generic_start/1", "signature": self.signature, "seed": self.seed,
                           "total_degree": self.total_degree, "n_failed": self.n_failed,
                           "params": [cplx(p) for p in self.params], "points": [cplx(p) for p in self.points]},
                          indent=1)

    @classmethod
    def from_json(cls, text: str) -> GenericStart:
        raw = json.loads(text)

        def cplx(rows: Iterable[Sequence[float]]) -> np.ndarray:
            return np.array([complex(a, b) for a, b in rows])

        return cls(raw["signature"], tuple(cplx(p) for p in raw["params"]), tuple(cplx(p) for p in raw["points"]),
                   int(raw["total_degree"]), int(raw["n_failed"]), int(raw["seed"]))


def _group_kinds(signature: str) -> tuple[str, str]:
    group, kinds = signature.split(":")
    return group, kinds


def compute(signature: str, seed: int = 0, threads: int = 2) -> GenericStart:
    """Solve the family at random complex parameters (a total-degree homotopy)."""
    group, kinds = _group_kinds(signature)
    rng = np.random.default_rng(seed)
    params = tuple(rng.normal(size=_N_PARAMS[group, k]) + 1j * rng.normal(size=_N_PARAMS[group, k]) for k in kinds)
    cont = solve(equations(group, params, variables(N_UNKNOWNS[group])), projective=group == "SE3", threads=threads)
    # isolated solutions of a generic member are nonsingular; singular ends lie on the exceptional set or on
    # other positive-dimensional components (the circle family has 48 of them) and start nothing
    points = tuple(p.point for p in cont.paths if p.point is not None and not p.singular
                   and (group != "SE3" or np.linalg.norm(p.point[:4]) > 1e-6 * np.linalg.norm(p.point)))
    return GenericStart(signature, params, points, len(cont.paths), len(cont.failed), seed)


@functools.cache
def generic_start(signature: str) -> GenericStart:
    """The family's generic start: shipped (``starts/``), or computed once per process."""
    path = _DIR / f"{signature.replace(':', '-')}.json"
    if path.is_file():
        return GenericStart.from_json(path.read_text())
    return compute(signature)


def path_parameters(target: Sequence[np.ndarray | Sequence[float]], start: GenericStart, t: Poly) \
        -> list[list[Poly]]:
    """The parameters along the straight path ``(1 - t) target + t generic`` (``t`` a polynomial variable)."""
    return [[(1.0 - t) * float(a) + t * complex(g) for a, g in zip(P, G)] for P, G in zip(target, start.params)]
