"""Screw algebra in Plücker coordinates: screws, twists, wrenches, the Klein form and the Lie product.

Conventions (those of Rico & Duffy and of Gallardo-Alvarado et al., used by the screw-theory
papers this library reproduces):

* A screw is a 6-vector ``$ = [s; s_O]``: the *primal* part ``s`` first, then the *dual* part
  ``s_O``, its moment about the pole ``O`` (the world origin unless said otherwise). A zero-pitch
  screw (a line, the screw of a revolute joint) through point ``r`` with unit direction ``s`` is
  ``[s; r x s]``; a screw of pitch ``h`` adds ``h s`` to the dual part; the screw of a prismatic
  joint along ``s`` is ``[0; s]``.
* A twist is ``V = [w; v_O]``: angular velocity, then the velocity of the body point that passes
  through the pole. (Pinocchio's ``Motion`` stores ``[v; w]``: ``DELTA @ V`` swaps the halves.)
* A wrench is ``[f; m_O]``: force, then moment about the pole.
* The *reduced acceleration* (acceleration state) of a body is ``A = [w_dot; a_O - w x v_O]``,
  ``a_O`` the acceleration of the body point at the pole: the time derivative of the twist with
  the pole held fixed (Pinocchio's spatial acceleration in ``WORLD`` axes, halves swapped).
* Klein form (reciprocal product): ``{$1; $2} = s1 . s2_O + s1_O . s2 = $1^T DELTA $2``. It is
  symmetric; two screws are reciprocal when it vanishes; ``{V; W}`` of a twist and a wrench is
  the power.
* Lie product: ``[$1, $2] = [s1 x s2; s1 x s2_O - s2 x s1_O]``, the time derivative of a screw
  ``$2`` carried by a body moving with twist ``$1``. For a serial chain with joint screws
  ``$_1..$_n`` and rates ``w_1..w_n``: ``V = sum w_j $_j`` and
  ``A = sum w_dot_j $_j + sum_{j<k} [w_j $_j, w_k $_k]`` (:func:`chain_lie_term`).

Every function works on one screw ``(6,)`` or on stacks ``(..., 6)`` (numpy broadcasting).
Nothing here knows about a mechanism.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from pkm.errors import InvalidInputError
from pkm.validation import as_array, as_scalar, finite_result

#: The polarity operator ``[[0, I], [I, 0]]`` (swaps primal and dual parts): ``{a; b} = a^T DELTA b``.
DELTA = np.block([[np.zeros((3, 3)), np.eye(3)], [np.eye(3), np.zeros((3, 3))]])


def _compatible(a: np.ndarray, b: np.ndarray, names: str, tail_a: int = 1, tail_b: int = 1) -> None:
    """The stack shapes of ``a`` and ``b`` (all but their last ``tail`` axes) must broadcast together."""
    try:
        np.broadcast_shapes(a.shape[:a.ndim - tail_a], b.shape[:b.ndim - tail_b])
    except ValueError:
        raise InvalidInputError(names, f"stacks of shapes {a.shape} and {b.shape} do not broadcast together; "
                                       "pass one of each or stacks of one length") from None


def _vec3(x: ArrayLike, name: str) -> np.ndarray:
    x = as_array(x, name, "3-vectors (..., 3)")
    if x.shape[-1:] != (3,) or not np.all(np.isfinite(x)):
        raise InvalidInputError(name, f"expected finite 3-vectors (..., 3), got shape {x.shape}", x)
    return x


def _screw(x: ArrayLike, name: str = "screw") -> np.ndarray:
    x = as_array(x, name, "screws (..., 6)")
    if x.shape[-1:] != (6,) or not np.all(np.isfinite(x)):
        raise InvalidInputError(name, f"expected finite screws (..., 6) = [primal; dual], got shape {x.shape}", x)
    return x


def cross(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """``a x b`` over the last axis of stacks of 3-vectors (broadcast; faster than ``np.cross`` on small stacks)."""
    a, b = np.asarray(a), np.asarray(b)
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=-1)


def screw(direction: ArrayLike, point: ArrayLike, pitch: float = 0.0) -> np.ndarray:
    """The screw of given unit ``direction`` through ``point`` [m] with ``pitch`` [m/rad].

    ``[s; r x s + h s]``. ``direction`` is normalised; it must not be zero.
    """
    s, r = _vec3(direction, "direction"), _vec3(point, "point")
    _compatible(s, r, "direction, point")
    pitch = as_scalar(pitch, "pitch", unit="m/rad")
    n = np.linalg.norm(s, axis=-1, keepdims=True)
    if np.any(n < 1e-12):
        raise InvalidInputError("direction", "a screw axis needs a non-zero direction", direction)
    s = s / n
    return finite_result(np.concatenate(np.broadcast_arrays(s, cross(r, s) + pitch * s), axis=-1), "screw")


def line(direction: ArrayLike, point: ArrayLike) -> np.ndarray:
    """The zero-pitch screw (a line; a revolute joint, a pure force) along ``direction`` through ``point``."""
    return screw(direction, point, 0.0)


def prismatic(direction: ArrayLike) -> np.ndarray:
    """The screw ``[0; s]`` of a prismatic joint (a pure translation, a pure couple) along ``direction``."""
    s = _vec3(direction, "direction")
    n = np.linalg.norm(s, axis=-1, keepdims=True)
    if np.any(n < 1e-12):
        raise InvalidInputError("direction", "a prismatic screw needs a non-zero direction", direction)
    return np.concatenate([np.zeros_like(s), s / n], axis=-1)


def klein(a: ArrayLike, b: ArrayLike) -> np.ndarray | float:
    """Klein form (reciprocal product) ``{a; b} = a_primal . b_dual + a_dual . b_primal``."""
    a, b = _screw(a, "a"), _screw(b, "b")
    _compatible(a, b, "a, b")
    k = finite_result(np.sum(a[..., :3] * b[..., 3:] + a[..., 3:] * b[..., :3], axis=-1), "Klein form")
    return float(k) if np.ndim(k) == 0 else k


def lie(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """Lie product ``[a, b] = [a_p x b_p; a_p x b_d - b_p x a_d]`` (antisymmetric)."""
    a, b = _screw(a, "a"), _screw(b, "b")
    _compatible(a, b, "a, b")
    ap, ad, bp, bd = a[..., :3], a[..., 3:], b[..., :3], b[..., 3:]
    return finite_result(np.concatenate([cross(ap, bp), cross(ap, bd) - cross(bp, ad)], axis=-1), "Lie product")


def shift(s: ArrayLike, point: ArrayLike) -> np.ndarray:
    """The same screw with its dual part referred to the pole ``point`` instead of O.

    ``s_Q = s_O - Q x s`` (for a twist: ``v_Q = v_O + w x Q``).
    """
    s, q = _screw(s, "s"), _vec3(point, "point")
    _compatible(s, q, "s, point")
    return finite_result(np.concatenate(np.broadcast_arrays(s[..., :3], s[..., 3:] - cross(q, s[..., :3])), axis=-1),
                         "shifted screw")


def transform(s: ArrayLike, rotation: ArrayLike, translation: ArrayLike) -> np.ndarray:
    """The screw moved by the rigid displacement ``x -> R x + p``: ``[R s; R s_O + p x R s]``.

    Also the change of coordinates from a frame with orientation ``R`` and origin ``p`` to the
    world (the adjoint action). ``rotation`` must be a 3x3 rotation (orthonormal to 1e-9, det +1).
    """
    s, p = _screw(s, "s"), _vec3(translation, "translation")
    _compatible(s, p, "s, translation")
    R = as_array(rotation, "rotation", "a 3x3 rotation matrix")
    if R.shape != (3, 3) or not np.all(np.isfinite(R)):
        raise InvalidInputError("rotation", f"expected a finite 3x3 matrix, got shape {R.shape}", rotation)
    defect = float(np.abs(R.T @ R - np.eye(3)).max())
    if defect > 1e-9 or np.linalg.det(R) < 0:
        raise InvalidInputError("rotation", f"not a rotation: max|R^T R - I| = {defect:.3g}, "
                                            f"det = {np.linalg.det(R):.6g}", rotation)
    Rs = s[..., :3] @ R.T
    return finite_result(np.concatenate(np.broadcast_arrays(Rs, s[..., 3:] @ R.T + cross(p, Rs)), axis=-1),
                         "transformed screw")


def pitch(s: ArrayLike) -> np.ndarray | float:
    """Pitch ``s . s_O / s . s`` [m/rad] (``inf`` for a pure translation or couple)."""
    s = _screw(s, "s")
    ss = np.sum(s[..., :3] ** 2, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = np.where(ss > 0.0, np.sum(s[..., :3] * s[..., 3:], axis=-1) / np.where(ss > 0.0, ss, 1.0), np.inf)
    return float(h) if np.ndim(h) == 0 else h


def axis_point(s: ArrayLike) -> np.ndarray:
    """The point of the screw axis closest to the pole: ``s x s_O / s . s`` [m] (non-zero primal only)."""
    s = _screw(s, "s")
    ss = np.sum(s[..., :3] ** 2, axis=-1, keepdims=True)
    if np.any(ss < 1e-24):
        raise InvalidInputError("s", "a pure translation/couple has no axis (zero primal part)", s)
    return finite_result(cross(s[..., :3], s[..., 3:]) / ss, "axis point")


def chain_twist(screws: ArrayLike, rates: ArrayLike) -> np.ndarray:
    """Twist ``sum_j w_j $_j`` of the last body of a serial chain (screws ``(..., n, 6)``, rates ``(..., n)``)."""
    S, w = _chain(screws, rates)
    return finite_result(np.einsum("...j,...jk->...k", w, S), "chain twist")


def chain_lie_term(screws: ArrayLike, rates: ArrayLike) -> np.ndarray:
    """Lie screw of acceleration of a serial chain: ``sum_{j<k} [w_j $_j, w_k $_k]``.

    With the joint screws of the current configuration and the joint rates, the reduced
    acceleration of the last body is ``sum_j w_dot_j $_j`` plus this term.

    Args:
        screws: Joint screws in chain order (base first), shape ``(..., n, 6)``.
        rates: Joint rates, shape ``(..., n)``.

    Returns:
        Shape ``(..., 6)``.
    """
    S, w = _chain(screws, rates)
    ws = w[..., None] * S
    before = np.cumsum(ws, axis=-2) - ws  # sum_{j<k} w_j $_j, for each k
    return finite_result(np.sum(lie(before, ws), axis=-2), "chain Lie term")


def _chain(screws: ArrayLike, rates: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    S = _screw(screws, "screws")
    w = as_array(rates, "rates", "joint rates (..., n)")
    if S.ndim < 2 or w.ndim < 1 or w.shape[-1] != S.shape[-2] or not np.all(np.isfinite(w)):
        raise InvalidInputError("rates", f"expected finite rates (..., n) for screws (..., n, 6) of shape {S.shape}, "
                                         f"got shape {w.shape}", rates)
    _compatible(S, w, "screws, rates", 2, 1)
    return S, w


__all__ = ["DELTA", "axis_point", "chain_lie_term", "chain_twist", "cross", "klein", "lie", "line", "pitch",
           "prismatic", "screw", "shift", "transform"]
