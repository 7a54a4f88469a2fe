"""Stiffness and first-frequency maps over a workspace map's nodes (:func:`stiffness_map`): the smallest and largest
principal stiffness under a pure force, the smallest under a pure moment, the anisotropy, and the first natural
frequency, at every node of a :func:`pkm.workspace_map` made with ``configurations=True`` (its inverse kinematics
solved in C, in one working mode)."""

from __future__ import annotations

import csv
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from pkm.core.analysis.maps import WorkspaceMap
from pkm.core.compliance.stiffness import RTOL, Links, stiffness
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import InvalidInputError, PkmError, UnknownNameError


@dataclass(frozen=True)
class StiffnessMap:
    """Stiffness indices per node (NaN where unreachable, or where the stiffness has no answer: a motion no spring
    resists).

    Attributes:
        axes: The workspace map's ``(name, values)`` per axis (arrays shaped as its arrays).
        reachable: The nodes with indices.
        force_min, force_max: The smallest and largest principal stiffness under a pure force [N/m] (``inf`` along a
            rigid direction).
        moment_min: The smallest principal stiffness under a pure moment [N m/rad].
        first_frequency: The first natural frequency [Hz], or None where not asked.
        failures: ``{message: nodes}`` of the nodes the stiffness refused.
    """

    axes: tuple[tuple[str, np.ndarray], ...]
    reachable: np.ndarray = field(repr=False)
    force_min: np.ndarray = field(repr=False)
    force_max: np.ndarray = field(repr=False)
    moment_min: np.ndarray = field(repr=False)
    first_frequency: np.ndarray | None = field(repr=False)
    failures: dict[str, int]

    @property
    def anisotropy(self) -> np.ndarray:
        """``force_max / force_min`` (>= 1; ``inf`` where a direction is rigid and another is not)."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.force_max / self.force_min

    def summary(self) -> dict[str, Any]:
        """The worst and best of each index over the reachable nodes (SI), and the refusals."""
        out: dict[str, Any] = {"nodes": int(self.reachable.sum()), "refused": dict(self.failures)}
        if not self.reachable.any():
            return out
        pick = self.reachable
        out["force_min_N_per_m"] = {"worst": float(np.min(self.force_min[pick])),
                                    "best": float(np.max(self.force_min[pick]))}
        out["moment_min_N_m_per_rad"] = {"worst": float(np.min(self.moment_min[pick])),
                                         "best": float(np.max(self.moment_min[pick]))}
        out["anisotropy"] = {"worst": float(np.max(self.anisotropy[pick])), "best": float(np.min(self.anisotropy[pick]))}
        if self.first_frequency is not None:
            out["first_frequency_Hz"] = {"worst": float(np.min(self.first_frequency[pick])),
                                         "best": float(np.max(self.first_frequency[pick]))}
        return out

    def write_csv(self, path: str | Path) -> Path:
        """One row per node: the axes' values, whether it has indices, then each index (SI)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        grids = np.meshgrid(*[v for _, v in reversed(self.axes)], indexing="ij")  # (as the workspace map's arrays)
        coords = {name: g.ravel() for (name, _), g in zip(reversed(self.axes), grids)}
        columns = {"force_min_N_per_m": self.force_min, "force_max_N_per_m": self.force_max,
                   "moment_min_N_m_per_rad": self.moment_min, "anisotropy": self.anisotropy}
        if self.first_frequency is not None:
            columns["first_frequency_Hz"] = self.first_frequency
        names, reach = [n for n, _ in self.axes], self.reachable.ravel()
        flat = {k: v.ravel() for k, v in columns.items()}
        with path.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow([*names, "reachable", *columns])
            for i in range(reach.size):
                w.writerow([repr(float(coords[n][i])) for n in names] + [int(reach[i])]
                           + [repr(float(flat[k][i])) if reach[i] else "" for k in columns])
        return path


def stiffness_map(mech: Mechanism, wmap: WorkspaceMap, *, joints: Mapping[str, object] | None = None,
                  links: Links | None = None, frequencies: bool = False, rtol: float = RTOL) -> StiffnessMap:
    """The stiffness indices (and with ``frequencies`` the first natural frequency) at every reachable node of
    ``wmap`` (:func:`pkm.workspace_map` with ``configurations=True``), the springs of ``joints`` and ``links`` as in
    :func:`pkm.stiffness`.

    Raises:
        InvalidInputError: ``wmap`` kept no configurations or is another mechanism's; as :func:`pkm.stiffness` for
            ``joints`` and ``links`` (its other refusals, node by node, are counted in ``failures``).
        UnknownNameError: a joint or link that does not exist.
    """
    mech = check_mechanism(mech)
    if wmap.q is None or wmap.q.shape[-1] != mech.nq or wmap.mechanism != mech.name:
        raise InvalidInputError("wmap", "give a map of this mechanism made with workspace_map(..., "
                                        "configurations=True)", wmap)
    shape = wmap.reachable.shape
    values = {k: np.full(shape, np.nan) for k in ("fmin", "fmax", "mmin", "freq")}
    reachable = np.zeros(shape, dtype=bool)
    failures: dict[str, int] = {}
    for idx in zip(*np.nonzero(wmap.reachable)):
        q = wmap.q[idx]
        try:
            K = stiffness(mech, q, joints=joints, links=links, rtol=rtol)
            if frequencies:
                f = K.vibration_modes().frequencies
                values["freq"][idx] = f[0] if len(f) else np.nan
        except (InvalidInputError, UnknownNameError):
            raise  # (the springs or links given: the same at every node)
        except PkmError as exc:  # (a node where a motion no spring resists moves the end effector)
            key = f"{type(exc).__name__}: {exc}"[:120]
            failures[key] = failures.get(key, 0) + 1
            continue
        force, moment = K.principal("force")[0], K.principal("moment")[0]
        values["fmin"][idx], values["fmax"][idx], values["mmin"][idx] = force[0], force[-1], moment[0]
        reachable[idx] = True
    return StiffnessMap(wmap.axes, reachable, values["fmin"], values["fmax"], values["mmin"],
                        values["freq"] if frequencies else None, failures)


__all__ = ["StiffnessMap", "stiffness_map"]
