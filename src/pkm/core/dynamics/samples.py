"""A :class:`~pkm.core.dynamics.simulate.Simulation` as a table: one row per sample, one named column per quantity,
each with its unit; written as Parquet (pyarrow, the ``sweeps`` extra, imported when writing) or CSV.

The columns, in order (``<joint>`` each actuated joint in ``mech.actuated`` order, ``<key>`` each task coordinate
of :attr:`pkm.core.TaskMap.keys`, a pose's orientation as its Z-Y-X angles):

* ``time`` [s];
* ``q.<joint>`` [rad or m], ``qd.<joint>`` [rad/s or m/s], ``qdd.<joint>`` [rad/s^2 or m/s^2]: the actuated
  coordinates, rates and accelerations;
* ``tau.<joint>`` [N m or N]: the efforts applied (after saturation);
* ``task.<key>`` [m or rad]: the task coordinates;
* ``kinetic``, ``potential``, ``energy`` (their sum), ``work`` (the actuators', since the start), ``dissipated``
  (by friction, since the start) [J].

:func:`energy_balance` is ``E(end) - E(0) - work + dissipated``: zero but for the integration error (and the
trapezoidal rule of ``work`` and ``dissipated``).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from pkm._optional import module
from pkm.core.dynamics.simulate import Simulation
from pkm.core.kinematics.task import TaskMap
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import InvalidInputError

_RATE = {"rad": "rad/s", "m": "m/s"}
_ACCELERATION = {"rad": "rad/s^2", "m": "m/s^2"}
ENERGIES = ("kinetic", "potential", "energy", "work", "dissipated")
"""The energy columns [J], last in the table."""


def _check(mech: Mechanism, sim: Simulation) -> tuple[Mechanism, Simulation]:
    mech = check_mechanism(mech)
    if not isinstance(sim, Simulation):
        raise InvalidInputError("sim", f"expected a pkm Simulation (pkm.simulate), got {type(sim).__name__}", sim)
    if sim.actuated.shape[1:] != (mech.na,) or sim.q.shape[1:] != (mech.nq,):
        raise InvalidInputError("sim", f"a simulation of another mechanism ({sim.actuated.shape[1]} actuated "
                                       f"coordinates, {mech.name} has {mech.na})", sim)
    return mech, sim


def column_units(mech: Mechanism, sim: Simulation) -> dict[str, str]:
    """``{column: unit}`` of :func:`columns`, in the table's order (module doc)."""
    mech, sim = _check(mech, sim)
    joints = {j.name: "rad" if j.revolute else "m" for j in mech.actuated}
    units = {"time": "s"}
    units.update({f"q.{n}": u for n, u in joints.items()})
    units.update({f"qd.{n}": _RATE[u] for n, u in joints.items()})
    units.update({f"qdd.{n}": _ACCELERATION[u] for n, u in joints.items()})
    units.update({f"tau.{n}": "N m" if u == "rad" else "N" for n, u in joints.items()})
    units.update({f"task.{k}": "rad" if kind == "angle" else "m" for k, kind in TaskMap.of(mech).kinds.items()})
    units.update({e: "J" for e in ENERGIES})
    return units


def columns(mech: Mechanism, sim: Simulation) -> dict[str, np.ndarray]:
    """The simulation's samples as ``{column: values (N,)}`` in SI (module doc; :func:`column_units` their units).

    Raises:
        InvalidInputError: ``sim`` is not a simulation of ``mech``.
    """
    mech, sim = _check(mech, sim)
    names = mech.actuated_names
    out: dict[str, np.ndarray] = {"time": np.asarray(sim.time, dtype=float)}
    for prefix, values in (("q", sim.actuated), ("qd", sim.actuated_velocity), ("qdd", sim.actuated_acceleration),
                           ("tau", sim.efforts)):
        values = np.zeros((len(sim), mech.na)) if values is None else np.asarray(values, dtype=float)
        out.update({f"{prefix}.{n}": values[:, i].copy() for i, n in enumerate(names)})
    keys = TaskMap.of(mech).keys
    task = np.array([[row[k] for k in keys] for row in map(TaskMap.of(mech).named, sim.q)]).reshape(len(sim), len(keys))
    out.update({f"task.{k}": task[:, i].copy() for i, k in enumerate(keys)})
    out.update(kinetic=sim.kinetic.copy(), potential=sim.potential.copy(), energy=sim.energy,
               work=sim.work.copy(), dissipated=sim.dissipated.copy())
    return out


def energy_balance(sim: Simulation) -> float:
    """``E(end) - E(0) - work + dissipated`` [J]: the energy the integration created (zero for an exact one)."""
    if not isinstance(sim, Simulation):
        raise InvalidInputError("sim", f"expected a pkm Simulation (pkm.simulate), got {type(sim).__name__}", sim)
    if not len(sim.time):
        return 0.0
    e = sim.energy
    return float(e[-1] - e[0] - sim.work[-1] + sim.dissipated[-1])


def metadata(mech: Mechanism, sim: Simulation) -> dict[str, object]:
    """What a written table carries besides its columns: the mechanism, the integrator, the event, the units."""
    mech, sim = _check(mech, sim)
    event = None if sim.event is None else {"kind": sim.event.kind, "time": sim.event.time,
                                             "detail": sim.event.detail}
    return {"mechanism": mech.name, "method": sim.method, "samples": len(sim), "event": event,
            "actuated": list(mech.actuated_names), "units": column_units(mech, sim)}


def write_csv(cols: dict[str, np.ndarray], path: str | Path) -> Path:
    """Columns of equal length as CSV: a header of their names, then the numbers as ``repr`` of floats (exact);
    the folder created. The one CSV layout of pkm's samples tables (simulations, excitations), which
    :func:`pkm.measurements` reads."""
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    with out.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(list(cols))
        for row in zip(*cols.values()):
            w.writerow([repr(float(v)) for v in row])
    return out


def write(mech: Mechanism, sim: Simulation, path: str | Path) -> Path:
    """Write the table of :func:`columns`: CSV when ``path`` ends in ``.csv`` (a header of the column names, numbers
    as ``repr`` of floats, the units in :func:`column_units`), otherwise Parquet with the units in each field's
    metadata (``unit``) and :func:`metadata` as JSON under the schema's ``pkm`` key.

    Returns:
        The path written (its folder created).

    Raises:
        MissingDependencyError: Parquet without pyarrow (``pip install "pkm-robotics[sweeps]"``).
        InvalidInputError: ``sim`` is not a simulation of ``mech``.
    """
    cols = columns(mech, sim)
    out = Path(path)
    if out.suffix.lower() == ".csv":
        return write_csv(cols, out)
    what = "writing a simulation as Parquet (or give a .csv path)"
    pa = module("pyarrow", extra="sweeps", what=what)
    pq = module("pyarrow.parquet", extra="sweeps", what=what)
    units = column_units(mech, sim)
    fields = [pa.field(name, pa.float64(), metadata={"unit": units[name]}) for name in cols]
    schema = pa.schema(fields, metadata={"pkm": json.dumps(metadata(mech, sim))})
    table = pa.table({n: pa.array(v, type=pa.float64()) for n, v in cols.items()}, schema=schema)
    out.parent.mkdir(parents=True, exist_ok=True)
    pq.write_table(table, out)
    return out


__all__ = ["ENERGIES", "column_units", "columns", "energy_balance", "metadata", "write", "write_csv"]
