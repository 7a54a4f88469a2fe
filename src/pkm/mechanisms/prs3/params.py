"""The design parameters of the 3-PRS (SI units, validated) and its fixed geometry."""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import cast

import numpy as np

from pkm.core.model.spec import parse_toml, read_text_file
from pkm.data import dynamics_path
from pkm.errors import InvalidInputError, InvalidParameterError, SpecError
from pkm.mechanisms._common import (
    check_finite,
    check_nonnegative,
    check_positive,
    param,
)
from pkm.validation import as_array

NAME = "prs3"


PHI = (0.0, 2.0 * math.pi / 3.0, 4.0 * math.pi / 3.0)


BRANCHES = {"slider_below": 1, "slider_above": -1}


DEFAULT_BRANCH = "slider_below"


ACTUATIONS = {"P": "slider", "R": "knee"}


TABLE2_FILE = "prs3_table2.toml"


TABLE2_FORMAT = "pkm.prs3_table2/1"


TABLE2_KEYS = {"kinematics": ("gamma", "l", "h", "g"),
               "dynamics": ("m1", "m2", "mp", "Izz2", "mx2", "my2", "Ixx3", "Iyy3", "Izz3", "Ixy3", "Ixz3", "Iyz3")}


# ---------------------------------------------------------------------- Table 2
@functools.cache
def table2() -> Mapping[str, float]:
    """Table 2 of the paper (SI), as stored in ``dynamics/prs3_table2.toml``.

    Returns:
        A read-only mapping with keys ``gamma l h g`` [rad, m] and ``m1 m2 mp`` [kg], ``Izz2`` [kg m^2],
        ``mx2 my2`` [kg m], ``Ixx3 Iyy3 Izz3 Ixy3 Ixz3 Iyz3`` [kg m^2].

    Raises:
        SpecError: The file is missing, not TOML, of another format, or lacks a key or a number.
    """
    path = dynamics_path(TABLE2_FILE)
    raw = parse_toml(read_text_file(path, "Table 2"), str(path))
    if raw.get("format") != TABLE2_FORMAT:
        raise SpecError(str(path), f"format {raw.get('format')!r}; this pkm reads {TABLE2_FORMAT!r}")
    out: dict[str, float] = {}
    for section, keys in TABLE2_KEYS.items():
        table = raw.get(section)
        if not isinstance(table, dict):
            raise SpecError(str(path), f"missing table [{section}]")
        for k in keys:
            v = table.get(k)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise SpecError(str(path), f"[{section}].{k} must be a finite number, got {v!r}")
            out[k] = float(v)
    return MappingProxyType(out)


def _from_table2(key: str, *units: str) -> float:
    """A field whose default is Table 2's ``key`` (read when a ``Prs3Params`` is made), with its units."""
    return cast(float, field(default_factory=lambda: table2()[key], metadata={"units": units, "length": None}))


# ---------------------------------------------------------------------- parameters
@dataclass(frozen=True)
class Prs3Params:
    """3-PRS design; defaults from the paper's Table 2 (``dynamics/prs3_table2.toml``).

    Attributes:
        gamma: Angle between each rail and the base plane, in the leg plane [rad], in (0, pi)
            (pi/2: vertical rails).
        l: Coupler length, revolute centre to spherical centre [m] (1 m).
        h: Platform radius, centre to spherical joints [m] (0.5 m).
        g: Base radius, centre to where the rails meet the base plane [m] (1 m).
        actuation: ``"P"`` (sliders driven, as in sec. 5) or ``"R"`` (knees driven).
        m_slider: Slider mass m1 [kg] (0.5 kg = 0.1 m_p).
        m_coupler: Coupler mass m2 [kg] (0.5 kg = 0.1 m_p).
        m_platform: Platform mass m_p [kg] (5 kg).
        Ixx3, Iyy3, Izz3: Platform principal inertias about its centre of mass [kg m^2]
            (m_p h^2/4, m_p h^2/4, m_p h^2/2).
        Ixy3, Ixz3, Iyz3: Platform inertia tensor products (URDF ``ixy ixz iyz``) [kg m^2] (0).
        reference: Reference independent coordinates ``(z_p [m], beta [rad], phi [rad])``; None
            (default): found for the design (``reference_pose``: level, at the best-conditioned
            height). The sec. 5 trajectories start at z = 0.81 m (eq. 41).
        link_radius: Radius of a coupler's collision cylinder [m] (25 mm; illustrative: the paper
            gives no sizes).
        slider_size: Edge of a slider's collision cube, centred on the knee axis on the rail [m] (100 mm).
        platform_thickness: Thickness of the platform's collision disc (radius ``h``) [m] (50 mm).
        base_thickness: Thickness of the base's collision disc (radius ``g``, under the plane where the rails meet
            it) [m] (50 mm).
    """

    gamma: float = _from_table2("gamma", "rad")
    l: float = _from_table2("l", "m")
    h: float = _from_table2("h", "m")
    g: float = _from_table2("g", "m")
    actuation: str = param("P")
    m_slider: float = _from_table2("m1", "kg")
    m_coupler: float = _from_table2("m2", "kg")
    m_platform: float = _from_table2("mp", "kg")
    Ixx3: float = _from_table2("Ixx3", "kg m^2")
    Iyy3: float = _from_table2("Iyy3", "kg m^2")
    Izz3: float = _from_table2("Izz3", "kg m^2")
    Ixy3: float = _from_table2("Ixy3", "kg m^2")
    Ixz3: float = _from_table2("Ixz3", "kg m^2")
    Iyz3: float = _from_table2("Iyz3", "kg m^2")
    reference: tuple[float, float, float] | None = param(None, "m", "rad", length=3)
    link_radius: float = param(0.025, "m")
    slider_size: float = param(0.100, "m")
    platform_thickness: float = param(0.050, "m")
    base_thickness: float = param(0.050, "m")

    def __post_init__(self):
        check_positive(self, "l", "h", "g", "m_platform", "link_radius", "slider_size", "platform_thickness",
                       "base_thickness")
        check_nonnegative(self, "m_slider", "m_coupler")
        check_finite(self, "gamma", "Ixx3", "Iyy3", "Izz3", "Ixy3", "Ixz3", "Iyz3")
        if not 0.0 < self.gamma < math.pi:
            raise InvalidParameterError("gamma", f"rail angle must lie in (0, pi) rad (pi/2: vertical rails), "
                                                 f"got {self.gamma!r}", self.gamma)
        if not isinstance(self.actuation, str) or self.actuation not in ACTUATIONS:
            raise InvalidParameterError("actuation", f"use 'P' (sliders) or 'R' (knees), got {self.actuation!r}",
                                        self.actuation)
        _check_inertia(self.platform_inertia)
        if self.reference is not None:
            try:
                y = as_task(self.reference, "reference")
            except InvalidInputError as exc:
                raise InvalidParameterError("reference", str(exc), self.reference) from None
            object.__setattr__(self, "reference", tuple(float(v) for v in y))

    @property
    def platform_inertia(self) -> np.ndarray:
        """Platform inertia tensor about its centre of mass, platform axes [kg m^2]."""
        return np.array([[self.Ixx3, self.Ixy3, self.Ixz3],
                         [self.Ixy3, self.Iyy3, self.Iyz3],
                         [self.Ixz3, self.Iyz3, self.Izz3]])


def as_task(y, name: str) -> np.ndarray:
    arr = as_array(y, name, "3 numbers (z_p [m], beta [rad], phi [rad])")
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise InvalidInputError(name, f"expected 3 finite numbers (z_p, beta, phi), got shape {arr.shape}", y)
    if abs(arr[1]) >= math.pi / 2:
        raise InvalidInputError(name, f"pitch beta = {arr[1]!r} rad: Z-Y-X angles need |beta| < pi/2", y)
    return arr


def _check_inertia(I: np.ndarray) -> None:
    ev = np.linalg.eigvalsh(I)
    tol = 1e-12 * max(1.0, float(np.abs(ev).max()))
    if ev[0] < -tol or ev[0] + ev[1] < ev[2] - tol:
        raise InvalidParameterError("Ixx3", f"platform inertia (Ixx3 ... Iyz3) is not physical: principal moments "
                                            f"{ev.tolist()} must be >= 0 and obey the triangle inequality", I)


#: The protocol's name for the design dataclass.
Params = Prs3Params
