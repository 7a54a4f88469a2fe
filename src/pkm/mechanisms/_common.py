"""Helpers shared by the mechanism modules (geometry, parameter checks, packaging)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from pkm.core.mechanism import Mechanism
from pkm.core.spec import ClosureSpec
from pkm.errors import InvalidParameterError


def rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rod_inertia(mass: float, length: float, axis: int) -> np.ndarray:
    """Inertia about the centre of a thin rod of given length along coordinate ``axis``."""
    I = np.full(3, mass * length**2 / 12.0)
    I[axis] = 0.0
    return np.diag(I)


def check_positive(obj, *names: str) -> None:
    """Each named field of ``obj`` must be a finite number > 0."""
    for n in names:
        v = getattr(obj, n)
        if not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
            raise InvalidParameterError(n, f"must be a finite number > 0 (SI units), got {v!r}", v)


def check_nonnegative(obj, *names: str) -> None:
    for n in names:
        v = getattr(obj, n)
        if not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
            raise InvalidParameterError(n, f"must be a finite number >= 0 (SI units), got {v!r}", v)


def check_finite(obj, *names: str) -> None:
    for n in names:
        v = getattr(obj, n)
        if not isinstance(v, (int, float)) or not math.isfinite(v):
            raise InvalidParameterError(n, f"must be a finite number, got {v!r}", v)


def spec_parameters(params) -> dict[str, float | str]:
    """The dataclass fields as a flat table for the closure spec (tuples expanded)."""
    out: dict[str, float | str] = {}
    for f in dataclasses.fields(params):
        v = getattr(params, f.name)
        if isinstance(v, (tuple, list)):
            for k, x in enumerate(v):
                out[f"{f.name}_{k + 1}"] = float(x)
        elif isinstance(v, str):
            out[f.name] = v
        else:
            out[f.name] = float(v)
    return out


def make_mechanism(urdf: str, spec: ClosureSpec, params) -> Mechanism:
    return Mechanism.from_strings(urdf, spec, params, source=f"<{spec.mechanism} generator>")
