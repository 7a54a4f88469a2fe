"""The calibration's files: the measurement table read and written, the calibrated mechanism written back.

**The table** (CSV with a header row, or Parquet, read by :func:`pkm.core.identification.measurements.read_table`,
so with its conventions and errors): ``m.<joint>`` per actuated joint [rad or m] (the readings), then what the
model measures: ``x, y, z`` [m] and ``roll, pitch, yaw`` [rad] (URDF's ``Rz(yaw) Ry(pitch) Rx(roll)``) for
``pose``; ``x, y, z`` for ``position``; ``x, y, yaw`` for ``planar``; ``q.<joint>`` [rad or m] per passive sensor
for ``passive``. Other columns are ignored.

**What is refused** (:class:`~pkm.errors.InvalidInputError` naming the row and the column): a missing column, a
value that is not a finite number (NaN rows), a reading outside the joint's limits or beyond 4 pi rad / 10 m (a
table in degrees or millimetres: :func:`~pkm.core.identification.measurements.check_positions`), a measured position farther from the base than ten times the mechanism's size
or an angle beyond pi (units again), too few poses for the base parameters, and a pose at which the nominal
mechanism does not close (outside the workspace).

**Writing back** (:func:`write_calibrated`): the calibrated joint origins set in the URDF, the mechanism assembled
again (:func:`~pkm.core.twin.design.design_mechanism`) and saved as a closure spec + URDF that :func:`pkm.load`
reads (:func:`pkm.save`), and as MJCF too where the mechanism was read from MJCF; the actuator offsets and gains and the measurement frames, which belong to the
instrument and the drives' readings rather than to the geometry, go to ``calibration.toml`` beside them, with each
estimated parameter's standard deviation and the accuracy before and after.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.calibration.estimate import Calibration
from pkm.core.calibration.measurement import CalibrationModel
from pkm.core.identification.measurements import MAX_REVOLUTE
from pkm.core.model.mechanism import Mechanism
from pkm.core.model.spec import as_path
from pkm.errors import InvalidInputError
from pkm.validation import instance_of

SIZE_FACTOR = 10.0  # a measured position beyond this many characteristic lengths: millimetres


def columns(model: CalibrationModel) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The table's reading columns and measurement columns for ``model``."""
    reads = tuple(f"m.{a}" for a in model.mech.actuated_names)
    meas = {"pose": ("x", "y", "z", "roll", "pitch", "yaw"), "position": ("x", "y", "z"),
            "planar": ("x", "y", "yaw")}.get(model.kind) or tuple(f"q.{s}" for s in model.sensors)
    return reads, meas


def to_layout(model: CalibrationModel, table: np.ndarray) -> np.ndarray:
    """Measurement columns (n x k, :func:`columns`) in :meth:`CalibrationModel.evaluate`'s layout."""
    if model.kind != "pose":
        return table.copy()
    out = np.empty((len(table), 12))
    out[:, :3] = table[:, :3]
    for k, (r, p, y) in enumerate(table[:, 3:]):
        out[k, 3:] = pin.rpy.rpyToMatrix(r, p, y).T.ravel()
    return out


def from_layout(model: CalibrationModel, y: np.ndarray) -> np.ndarray:
    """:func:`to_layout`'s inverse: ``x, y, z, roll, pitch, yaw`` for a pose."""
    if model.kind != "pose":
        return y.copy()
    rpy = [pin.rpy.matrixToRpy(row[3:].reshape(3, 3).T) for row in y]
    return np.hstack([y[:, :3], np.array(rpy)])


def read_data(model: CalibrationModel, data: str | Path | Mapping[str, ArrayLike]) -> tuple[np.ndarray, np.ndarray]:
    """The readings (n x na) and measurements (:meth:`CalibrationModel.evaluate`'s layout) of a table (module doc):
    read, and the readings checked, by the identification's route
    (:func:`~pkm.core.identification.measurements.read_columns`, :func:`~pkm.core.identification.measurements.
    check_positions`).

    Raises:
        InvalidInputError: the cases of the module doc, naming the row and the column.
    """
    from pkm.core.identification.measurements import check_positions, read_columns

    reads, meas = columns(model)
    table, source = read_columns(data, reads + meas, ", ".join(reads + meas))
    mech = model.mech
    M = table[:, :mech.na]
    check_positions(mech, M, reads, source)
    Y = table[:, mech.na:]
    L = SIZE_FACTOR * max(mech.characteristic_length, 1e-9)
    for i, c in enumerate(meas):
        length = c in ("x", "y", "z") or (c.startswith("q.") and not mech.joints[c[2:]].revolute)
        cap = L if length else np.pi + 1e-9 if c in ("roll", "pitch", "yaw") else MAX_REVOLUTE
        # (a tracker's x, y, z are in its own frame, metres away from the base: their spread about the median is
        # what the mechanism's size bounds, not their distance from the tracker)
        about = float(np.median(Y[:, i])) if c in ("x", "y", "z") else 0.0
        out = np.flatnonzero(np.abs(Y[:, i] - about) > cap)
        if out.size:
            r = int(out[0])
            where = f" from the column's median {about:.6g}" if about else ""
            raise InvalidInputError(c, f"{source}, row {r + 1}, column {c!r}: {Y[r, i]:.6g} is over {cap:.6g}{where} "
                                       f"{'m (ten times the mechanism' + chr(39) + 's size)' if length else 'rad'} (SI "
                                       f"units: is the table in {'mm' if length else 'degrees'}?)", Y[r, i])
    for k, qa in enumerate(M):  # (outside the workspace: the nominal mechanism does not close there)
        try:
            model.seeds(qa[None])
        except InvalidInputError:
            raise InvalidInputError("m", f"{source}, row {k + 1}, columns {', '.join(reads)}: the nominal mechanism "
                                         f"does not close at these readings (outside the workspace?)", qa) from None
    return M, to_layout(model, Y)


def write_data(model: CalibrationModel, path: str | Path, readings: np.ndarray, measured: np.ndarray) -> Path:
    """Write readings and measurements (:meth:`CalibrationModel.evaluate`'s layout) as a CSV table (module doc), by
    :func:`pkm.core.dynamics.samples.write_csv` (pkm's one CSV layout: numbers as ``repr`` of floats, exact)."""
    from pkm.core.dynamics.samples import write_csv

    reads, meas = columns(model)
    table = np.hstack([readings, from_layout(model, measured)])
    return write_csv({name: table[:, k] for k, name in enumerate(reads + meas)}, path)


def calibrated_mechanism(cal: Calibration) -> Mechanism:
    """The mechanism with the calibrated joint origins (module doc)."""
    return cal.model.mechanism(cal.x)


def write_calibrated(cal: Calibration, out: str | Path) -> tuple[Path, ...]:
    """Write the calibrated mechanism into folder ``out`` (module doc): the spec's path (what :func:`pkm.load`
    takes), ``calibration.toml``'s and, where the mechanism was read from MJCF, the calibrated MJCF's.

    Examples:
        >>> import tempfile
        >>> import pkm
        >>> from pkm.core.calibration.estimate import perturbed, simulate
        >>> model = pkm.CalibrationModel(pkm.load("prs3"), "pose")
        >>> poses = pkm.calibration_poses(model, 12, spread=0.2, pool=14).readings
        >>> cal = pkm.calibrate(model, poses, simulate(model, perturbed(model, seed=1), poses, seed=2))
        >>> spec, toml = pkm.write_calibrated(cal, tempfile.mkdtemp())  # (and the MJCF, for a model read from one)
        >>> spec.name, toml.name, pkm.load(spec).name
        ('prs3.closures.toml', 'calibration.toml', 'prs3')
    """
    from pkm.core.formats.writers import write

    cal, out = instance_of(cal, Calibration, "cal", "a pkm.Calibration (pkm.calibrate(model, readings, measured))"), \
        as_path(out, "out")
    mech = calibrated_mechanism(cal)
    spec = write(mech, out, "pkm").files[0]
    lines = [f"# pkm calibration of {cal.model.mech.name} ({cal.model.kind} measurements); SI units",
             f"model = {cal.model.kind!r}", f"chi2 = {cal.chi2!r}", "", "[values]"]
    origins = set(cal.model.parameters.origins)
    lines += [f"{n!r} = {v!r}" for k, (n, v) in enumerate(cal.values().items()) if k not in origins]
    lines += ["", "[std]"] + [f"{n!r} = {s!r}" for n, (_, s) in cal.changes().items()]
    for label, acc in (("before", cal.before), ("after", cal.after)):
        lines += ["", f"[accuracy.{label}]"] + [f"{k} = {v!r}" for k, v in acc.as_dict().items()]
    path = out / "calibration.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    if _from_mjcf(cal.model.mech):
        return spec, path, write(mech, out, "mjcf").files[0]
    return spec, path


def _from_mjcf(mech: Mechanism) -> bool:
    """Whether ``mech`` was read from an MJCF file."""
    from pkm.core.formats.imported import format_of

    source = Path(mech.source)
    if source.suffix.lower() not in (".xml", ".mjcf") or not source.is_file():
        return False
    return format_of(source, source.read_text(encoding="utf-8", errors="replace")).name == "mjcf"


__all__ = ["calibrated_mechanism", "columns", "from_layout", "read_data", "to_layout", "write_calibrated",
           "write_data"]
