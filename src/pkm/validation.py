"""Validation of inputs at pkm's public entry points: numpy only, so that pure-numpy modules import cheaply.

Each helper turns what a user may pass (lists, tuples, numpy arrays, numbers; hence ``x: object``) into a
validated float or array, and anything else (strings, booleans, None, complex numbers, ragged lists,
overflowing ints, non-finite values) into an :class:`~pkm.errors.InvalidInputError` naming the
argument; :func:`finite_result` turns a NaN or infinity that arose inside into a
:class:`~pkm.errors.NonFiniteError` instead of returning it.
"""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike

from pkm.errors import InvalidInputError, NonFiniteError


def wrap_angle(angle: ArrayLike) -> np.ndarray:
    """Angle(s) brought into (-pi, pi] [rad]."""
    return np.pi - np.mod(np.pi - np.asarray(angle, dtype=float), 2.0 * np.pi)


_T = TypeVar("_T")

#: |value| above this, in SI units (m, rad, kg, s...), is taken for a unit error or garbage (inputs and files).
ABSURD = 1e6


def as_array(x: object, name: str, what: str = "numbers") -> np.ndarray:
    """``x`` as a float array of any shape, refusing what is not numbers.

    Strings, booleans, ``None``, complex numbers, ragged nestings and objects are refused with an
    :class:`InvalidInputError` naming ``name`` (numpy would turn ``"1.5"`` into 1.5 and ``True``
    into 1.0 silently); so are integers too large for a float. Finiteness is not checked here.
    """
    if isinstance(x, (str, bytes)) or x is None:
        raise InvalidInputError(name, f"expected {what}, got {type(x).__name__}", x)
    try:
        raw = np.asarray(x)
        if raw.dtype.kind not in "iuf":
            if raw.dtype.kind == "b":
                raise InvalidInputError(name, f"expected {what}, got booleans", x)
            if raw.dtype.kind != "O":
                raise InvalidInputError(name, f"expected {what}, got an array of {raw.dtype}", x)
            if any(isinstance(v, (str, bytes, bool, np.bool_, complex)) or v is None for v in raw.ravel()):
                raise InvalidInputError(name, f"expected {what}, got {type(x).__name__} holding non-numbers", x)
        arr = np.asarray(raw, dtype=float)
    except InvalidInputError:
        raise
    except (TypeError, ValueError, OverflowError):
        raise InvalidInputError(name, f"expected {what}, got {type(x).__name__} that is not a (regular) array of "
                                      "real numbers", x) from None
    return arr


def instance_of(x: object, cls: type[_T] | tuple[type[_T], ...], name: str, what: str) -> _T:
    """``x`` itself if it is a ``cls``, else an :class:`InvalidInputError` naming ``name`` and saying what was
    expected (``what``: the kind of object and where to get one) and what came (a configuration array passed where
    a mode or a calibration model belongs: never the ``AttributeError`` the first use of it would raise)."""
    if not isinstance(x, cls):
        raise InvalidInputError(name, f"expected {what}, got {type(x).__name__}", x)
    return x


def as_choice(x: object, choices: tuple[str, ...], name: str) -> str:
    """``x`` if it is one of the names ``choices``, else an :class:`InvalidInputError` naming ``name`` and listing
    them (an array in its place too: ``x in choices`` would compare it element by element and raise numpy's
    ``ValueError``)."""
    if not isinstance(x, str) or x not in choices:
        raise InvalidInputError(name, f"use one of {list(choices)}, got {x!r}", x)
    return x


def bounded(arr: np.ndarray, name: str, given: object = None) -> np.ndarray:
    """``arr`` (coordinates: m, rad) unchanged where every entry's magnitude is at most :data:`ABSURD`, else an
    :class:`InvalidInputError` naming ``name`` and the first entry beyond (a unit mistake or garbage).

    The one rule for the coordinates every entry point takes (configurations, actuated values, seeds, task targets,
    waypoints: the library, the command line and the service alike): a revolute coordinate of 1e308 rad is refused,
    not wrapped into (-pi, pi] (a float that large has no digits left below 2 pi: its wrap is noise). Within the
    bound an angle's wrap keeps 1e6 x eps = 2e-10 rad. Non-finite entries are the caller's to refuse."""
    a = np.asarray(arr)
    with np.errstate(invalid="ignore"):
        over = np.abs(a) > ABSURD
    if np.any(over):
        at = tuple(int(i) for i in np.argwhere(over)[0])
        where = f" at entry {at[0] if len(at) == 1 else list(at)}" if at else ""
        raise InvalidInputError(name, f"holds {float(a[at]):.6g}{where}, beyond {ABSURD:g} (SI units: m, rad): a "
                                      "unit mistake or garbage (a coordinate is never wrapped silently)",
                                arr if given is None else given)
    return arr


def as_vector(x: object, n: int, name: str) -> np.ndarray:
    """``x`` as a finite float vector of shape (n,), or :class:`InvalidInputError` naming ``name``."""
    arr = as_array(x, name, f"{n} numbers")
    if arr.shape != (n,):
        raise InvalidInputError(name, f"expected shape ({n},), got {arr.shape}; pass a flat list of {n} numbers", x)
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(name, f"holds non-finite values at {np.flatnonzero(~np.isfinite(arr)).tolist()}; "
                                      "pass finite numbers", x)
    return arr.copy()


def as_scalar(x: object, name: str, *, low: float | None = None, high: float | None = None, strict_low: bool = False,
              unit: str = "") -> float:
    """``x`` as one finite float (a number or a one-element array), optionally within bounds.

    Args:
        x: The value.
        name: Its name, for the message.
        low, high: Bounds (inclusive; ``low`` exclusive with ``strict_low``).
        unit: Unit shown in the message.

    Raises:
        InvalidInputError: Not a number, not finite, or out of bounds.
    """
    arr = as_array(x, name, "a number")
    if arr.size != 1:
        raise InvalidInputError(name, f"expected one number, got shape {arr.shape}", x)
    v = float(arr.reshape(()))
    u = f" {unit}" if unit else ""
    if not math.isfinite(v):
        raise InvalidInputError(name, f"must be a finite number{u}, got {v!r}", x)
    if low is not None and (v <= low if strict_low else v < low):
        raise InvalidInputError(name, f"must be {'>' if strict_low else '>='} {low:g}{u}, got {v!r}", x)
    if high is not None and v > high:
        raise InvalidInputError(name, f"must be <= {high:g}{u}, got {v!r}", x)
    return v


def as_count(x: object, name: str, *, low: int = 1, high: int = 10**7) -> int:
    """``x`` as an integer in ``[low, high]`` (iteration limits, numbers of seeds or nodes)."""
    if isinstance(x, bool) or not isinstance(x, (int, np.integer)):
        raise InvalidInputError(name, f"expected an integer in [{low}, {high}], got {type(x).__name__} {x!r}", x)
    if not low <= int(x) <= high:
        raise InvalidInputError(name, f"expected an integer in [{low}, {high}], got {int(x)}", x)
    return int(x)


def as_tolerance(x: object, name: str = "tol", *, high: float = 1.0) -> float:
    """``x`` as a tolerance: a finite number in ``(0, high]``."""
    return as_scalar(x, name, low=0.0, high=high, strict_low=True)


def symmetric_positive_definite(A: np.ndarray, rtol: float = 1e-9) -> bool:
    """Whether the square matrix ``A`` (finite) is symmetric to ``rtol`` of its largest entry (scale-free: a
    compliance of 1e-9 m/N as a stiffness of 1e9 N/m) and positive definite."""
    A = np.asarray(A, dtype=float)
    if A.ndim != 2 or A.shape[0] != A.shape[1] or not A.size or not np.all(np.isfinite(A)):
        return False
    top = float(np.max(np.abs(A)))
    return bool(top > 0.0 and np.max(np.abs(A - A.T)) <= rtol * top
                and np.linalg.eigvalsh(0.5 * (A + A.T)).min() > 0.0)


def finite_result(x: _T, what: str, detail: str = "") -> _T:
    """``x`` unchanged if every number in it is finite, else :class:`~pkm.errors.NonFiniteError`.

    The last guard of a public routine: a NaN or an infinity that slipped past the input checks
    (an overflow, a vanishing divisor) becomes an error instead of a silent result.
    """
    try:
        finite = bool(np.all(np.isfinite(np.asarray(x, dtype=float))))
    except (ValueError, TypeError):  # (a result of parts of different shapes: each part checked)
        finite = all(bool(np.all(np.isfinite(np.asarray(part, dtype=float)))) for part in x)  # type: ignore[attr-defined]
    if not finite:
        raise NonFiniteError(what, x, detail or "the inputs are probably too large or the configuration is "
                                               "degenerate; check the units (SI) and the magnitudes")
    return x
