r"""The limits a time law must hold: each actuator's effort under its torque-speed curve, its speed and its
acceleration.

**Effort**: :math:`|\tau_i| \le T_i(|\omega_i|)` with :math:`\omega_i = \dot q_{a,i}` the joint's speed and
:math:`T_i` a concave, non-increasing curve written as the lower envelope of lines,
:math:`T_i(\omega) = \min_k (\alpha_k - \beta_k \omega)` (:math:`\alpha_k > 0`, :math:`\beta_k \ge 0`):

* a constant peak: one line :math:`(\tau_{peak}, 0)` (default: each drive's :attr:`pkm.Actuator.max_effort`);
* a **linear motor line** :math:`\tau_{peak} (1 - |\omega| / \omega_0)` (:math:`\omega_0` the no-load speed):
  one line :math:`(\tau_{peak}, \tau_{peak} / \omega_0)`;
* a **table** of points :math:`(\omega_j, \tau_j)`, linear between them: one line per segment, the first value
  held flat from :math:`\omega = 0`; it must be concave and non-increasing (a motor's curve: flat, then falling),
  else it is refused.

**Speed**: :math:`|\dot q_{a,i}| \le V_i` (default: the drives' ``velocity_limit``). **Acceleration**:
:math:`|\ddot q_{a,i}| \le A_i` (default: none). **Jerk is not limited** (a time-optimal law of this kind is
bang-bang in :math:`\ddot s`: its jerk is unbounded at the switches; see :mod:`pkm.core.timing.solve`).

Every limit is planned at ``(1 - margin)`` of its value (``margin``, default 1e-3), so that the efforts between
the grid points, which the planner does not see, stay within the true limits (:mod:`pkm.core.timing.verify`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.errors import InvalidInputError
from pkm.validation import as_scalar

#: Limits are planned at ``(1 - MARGIN)`` of their values by default.
MARGIN = 1e-3


@dataclass(frozen=True)
class Limits:
    r"""Per-actuator limits (see the module doc), SI in each joint's units.

    Attributes:
        lines: (na x k x 2): the effort curve's lines :math:`(\alpha, \beta)` [N m, N m s/rad] (padded with
            ``(inf, 0)``).
        speed: (na,) :math:`V` [rad/s, m/s] (``inf``: none).
        acceleration: (na,) :math:`A` [rad/s^2, m/s^2] (``inf``: none).
        margin: The relative margin the planner keeps from every limit.
        names: The actuated joints.
    """

    lines: np.ndarray
    speed: np.ndarray
    acceleration: np.ndarray
    margin: float
    names: tuple[str, ...]

    def effort_limit(self, omega: ArrayLike) -> np.ndarray:
        r""":math:`T_i(|\omega_i|)` (n x na) [N m, N] at joint speeds ``omega`` (n x na), without the margin."""
        w = np.abs(np.atleast_2d(np.asarray(omega, dtype=float)))
        alpha, beta = self.lines[..., 0], self.lines[..., 1]
        return np.min(alpha[None] - beta[None] * w[..., None], axis=-1)

    @property
    def peak(self) -> np.ndarray:
        """The efforts at rest (na,) [N m, N]."""
        return self.effort_limit(np.zeros(len(self.names)))[0]

    @property
    def speed_dependent(self) -> bool:
        """Whether some effort limit falls with speed."""
        return bool(np.any(self.lines[..., 1] > 0.0))


def _lines_of_table(table: ArrayLike, joint: str) -> list[tuple[float, float]]:
    t = np.asarray(table, dtype=float)
    if t.ndim != 2 or t.shape[1] != 2 or len(t) < 2 or not np.all(np.isfinite(t)) or np.any(t < 0.0) \
            or np.any(np.diff(t[:, 0]) <= 0.0):
        raise InvalidInputError("table", f"actuator {joint!r}: expected rows (speed >= 0, effort >= 0), speeds "
                                         "increasing, at least two", table)
    slope = -np.diff(t[:, 1]) / np.diff(t[:, 0])  # (beta of each segment)
    if np.any(slope < -1e-12) or np.any(np.diff(slope) < -1e-12 * max(1.0, float(np.abs(slope).max()))):
        raise InvalidInputError("table", f"actuator {joint!r}: the torque-speed table must be non-increasing and "
                                         "concave (flat, then falling); a convex curve is not a limit this planner "
                                         "can take", table)
    lines = [(float(t[0, 1]), 0.0)]
    for j in range(len(t) - 1):
        beta = max(float(slope[j]), 0.0)
        lines.append((float(t[j, 1] + beta * t[j, 0]), beta))
    return lines


def _per_actuator(value: ArrayLike, na: int, what: str) -> np.ndarray:
    arr = np.broadcast_to(np.asarray(value, dtype=float), (na,)).copy() if np.ndim(value) == 0 else \
        np.asarray(value, dtype=float)
    if arr.shape != (na,) or np.any(np.isnan(arr)) or np.any(arr <= 0.0):
        raise InvalidInputError(what, f"expected one number > 0 (or inf) or {na}, one per actuator", value)
    return arr


def actuator_limits(mech: Mechanism, *, peak: ArrayLike | None = None, omega0: ArrayLike | None = None,
                    table: ArrayLike | None = None, speed: ArrayLike | None = None,
                    acceleration: ArrayLike | None = None, margin: float = MARGIN) -> Limits:
    """The limits of ``mech``'s actuators (module doc); each argument one number for all or one per actuator.

    Args:
        mech: The mechanism.
        peak: The effort at rest [N m, N]; default each drive's :attr:`~pkm.Actuator.max_effort`.
        omega0: The no-load speed of a linear motor line [rad/s, m/s]; default none (a constant peak).
        table: A torque-speed table, rows ``(speed, effort)`` (the same for every actuator) instead of
            ``peak``/``omega0``.
        speed: The speed limits; default the drives' ``velocity_limit``.
        acceleration: The acceleration limits; default none.
        margin: The relative margin planned from every limit, in [0, 0.5).

    Raises:
        InvalidInputError: a value that is not > 0, a table that is not concave and non-increasing, no finite
            effort limit at all.
    """
    mech = check_mechanism(mech)
    na, names = mech.na, tuple(mech.actuated_names)
    margin = as_scalar(margin, "margin", low=0.0, high=0.5)
    if margin >= 0.5:
        raise InvalidInputError("margin", "expected a margin in [0, 0.5)", margin)
    if table is not None:
        if peak is not None or omega0 is not None:
            raise InvalidInputError("table", "give a table or peak/omega0, not both", table)
        per = [_lines_of_table(table, j) for j in names]
    else:
        tau = _per_actuator([a.max_effort for a in mech.actuators] if peak is None else peak, na, "peak")
        w0 = _per_actuator(math.inf if omega0 is None else omega0, na, "omega0")
        per = [[(float(t), float(t / w) if math.isfinite(w) else 0.0)] for t, w in zip(tau, w0)]
    if not all(any(math.isfinite(a) for a, _ in p) for p in per):
        raise InvalidInputError("peak", "an actuator has no finite effort limit: give peak (pkm.with_actuators, "
                                        "or the limits here)", [p[0][0] for p in per])
    k = max(len(p) for p in per)
    lines = np.array([p + [(math.inf, 0.0)] * (k - len(p)) for p in per])
    V = _per_actuator([a.velocity_limit for a in mech.actuators] if speed is None else speed, na, "speed")
    A = _per_actuator(math.inf if acceleration is None else acceleration, na, "acceleration")
    return Limits(lines, V, A, margin, names)


def parse_limits(mech: Mechanism, text: str | None, margin: float = MARGIN) -> Limits:
    """The limits of the command line: ``"peak=3.9,omega0=10,speed=3,acceleration=500"`` (keys as
    :func:`actuator_limits`' arguments, one number each, for every actuator; empty: the drives' own). Where the
    actuators are all revolute (or all prismatic) a value may carry its unit, as every joint value does
    (:func:`pkm.units.parse_joint_value`): ``peak=3.9 N m``, ``speed=300rpm``, ``omega0=600deg/s``.

    Raises:
        InvalidInputError: an unknown key or a value that is not a number (UnitError: a unit of another kind).
    """
    from pkm.units import parse_joint_value, parse_quantity

    keys = ("peak", "omega0", "speed", "acceleration")
    order = {"peak": "effort", "omega0": "rate", "speed": "rate", "acceleration": "acceleration"}
    revolute = {j.revolute for j in mech.actuated}
    given: dict[str, float] = {}
    for part in (text or "").split(","):
        if not part.strip():
            continue
        key, _, value = part.partition("=")
        key = key.strip()
        if key not in keys:
            raise InvalidInputError("limits", f"unknown limit {key!r}: use {', '.join(keys)} (key=value, comma "
                                              "separated)", text)
        if len(revolute) == 1:
            given[key] = parse_joint_value(value.strip(), next(iter(revolute)), order[key], key)
        else:  # (mixed actuators: one number for all, SI)
            given[key] = parse_quantity(value.strip(), set(), key, "SI")
    return actuator_limits(mech, margin=margin, **given)  # type: ignore[arg-type]


__all__ = ["MARGIN", "Limits", "actuator_limits", "parse_limits"]
