"""Sensitivity and tolerance allocation: the end-effector pose error each geometric error causes over the workspace.

For each calibration parameter but the measurement frames, the error ``delta`` (0.1 mm on a length, 0.1 degree on
an angle, ``1e-4`` on a gain, by default) is propagated to the end effector's pose at every given pose by the exact
Jacobian (:mod:`~pkm.core.calibration.measurement`: the loops closed, the implicit function theorem), to first order:
``|J_p[:, k]| delta`` [m] and ``|J_R[:, k]| delta`` [rad] (the rotation vector). The table gives their RMS and
maximum over the poses, sorted by the largest position error: which tolerances cost most accuracy, before a robot
exists. The test checks the first-order errors against the mechanism closed again with the parameter changed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.calibration.measurement import CalibrationModel, check_model
from pkm.errors import InvalidInputError

#: The default errors by unit: 0.1 mm, 0.1 degree, 1e-4 of a gain.
DELTA = {"m": 1e-4, "rad": np.deg2rad(0.1), "1": 1e-4}


@dataclass(frozen=True)
class ToleranceRow:
    """One parameter's effect: its ``delta`` (SI) and the pose errors it causes, ``position`` (rms, max) [m] and
    ``orientation`` (rms, max) [rad] (None for a position-only model)."""

    name: str
    unit: str
    delta: float
    position: tuple[float, float]
    orientation: tuple[float, float] | None


def tolerance_table(model: CalibrationModel, readings: ArrayLike, delta: dict[str, float] | None = None) \
        -> tuple[ToleranceRow, ...]:
    """The tolerance table of ``model`` (a ``pose`` or ``position`` model) over the poses ``readings`` (module doc),
    the most costly parameter first; parameters that move nothing are left out.

    Raises:
        InvalidInputError: a ``planar`` or ``passive`` model, or ``model`` no :class:`CalibrationModel`.

    Examples:
        >>> import pkm
        >>> model = pkm.CalibrationModel(pkm.load("prs3"), "pose")
        >>> rows = pkm.tolerance_table(model, pkm.calibration_poses(model, 12, spread=0.2, pool=14).readings)
        >>> rows[0].name, round(rows[0].position[1] * 1e3, 2)  # (0.1 degree on the slider's pitch: mm at the tool)
        ('slider_2.pitch', 2.26)
    """
    model = check_model(model)
    if model.kind not in ("pose", "position"):
        raise InvalidInputError("model", "a tolerance table needs a pose or position model", model.kind)
    d = dict(DELTA, **(delta or {}))
    y, J, _ = model.evaluate(None, readings)
    _, Jr = model.residual(y, y, J)
    assert Jr is not None
    P = model.parameters
    rows = []
    for k, (name, unit) in enumerate(zip(P.names, P.units)):
        if name.startswith(("tracker.", "target.")):
            continue
        e = d[unit]
        pos = np.linalg.norm(Jr[:, :3, k], axis=1) * e
        if not np.any(pos > 0.0) and (model.kind == "position" or not np.any(Jr[:, 3:, k])):
            continue
        rot = np.linalg.norm(Jr[:, 3:, k], axis=1) * e if model.kind == "pose" else None
        rows.append(ToleranceRow(name, unit, e, (float(np.sqrt(np.mean(pos ** 2))), float(pos.max())),
                                 None if rot is None else (float(np.sqrt(np.mean(rot ** 2))), float(rot.max()))))
    return tuple(sorted(rows, key=lambda r: -r.position[1]))


__all__ = ["DELTA", "ToleranceRow", "tolerance_table"]
