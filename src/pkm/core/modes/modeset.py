"""The outcome of a search for every mode: :class:`Mode` (one real solution, verified by the core) and
:class:`ModeSet` (all of them and the account of the homotopy), shared by :mod:`~pkm.core.modes.assembly`,
:mod:`~pkm.core.modes.working` and :mod:`~pkm.core.modes.generic`."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from pkm.core.collision.interference import checks_collisions, minimum_distances
from pkm.core.kinematics import constraints
from pkm.core.model.mechanism import Mechanism
from pkm.core.modes.certify import Certificate
from pkm.core.modes.continuation import Path
from pkm.errors import ConvergenceError

#: A solution is real when its imaginary part is below this, relative to its size.
REAL_TOL = 1e-8
#: Every recovered configuration closes its loops to this [m or rad].
VERIFY_TOL = 1e-10


def by_distance(mech: Mechanism, modes: list[tuple]) -> list[tuple]:
    """Modes (tuples whose first item is a configuration) sorted by distance from the reference configuration, the
    distance to 10 significant digits and then the configuration to 1e-9 deciding: modes at one distance (a
    symmetric mechanism's mirror modes) keep one order whatever the last bits of their homotopy paths."""
    ref = mech.q_reference

    def key(m: tuple) -> tuple:
        d = float(np.linalg.norm(mech.difference(ref, m[0])))
        return (float(f"{d:.9e}"), tuple(np.round(np.asarray(m[0], dtype=float), 9) + 0.0))

    return sorted(modes, key=key)


@dataclass(frozen=True)
class Mode:
    """One real solution: an assembly mode (or, from :func:`~pkm.core.modes.working.working_modes`, a working mode).

    Attributes:
        label: Its number in the set (0, 1, ...), sorted by distance from the reference configuration.
        q: The full configuration (every joint), recovered by the core.
        residual: Its closure residual (infinity norm) [m or rad], <= :data:`VERIFY_TOL`.
        point: The polynomial system's solution (real; the unknowns of the reduced equations, or of the generic route's:
            each unknown joint's ``(cos, sin)`` or coordinate).
        certificate: Smale's alpha test on the polished point.
        path: The index of the Bertini path that ended there (several when a mode is reached twice; one per leg for
            a working mode).
        outside_limits: The joints outside the position limits the files state (kept: a mode is geometry; whether
            the machine can reach it is the limits' business).
        clearance: The smallest signed distance between the bodies checked for collision [m] (negative: two
            interpenetrate; kept, as a mode outside the limits), where the mechanism has collision geometry
            (:mod:`pkm.core.collision`); else None.
    """

    label: int
    q: np.ndarray
    residual: float
    point: np.ndarray
    certificate: Certificate
    path: tuple[int, ...]
    outside_limits: tuple[str, ...] = ()
    clearance: float | None = None

    @property
    def interferes(self) -> bool:
        """Whether two checked bodies interpenetrate in this mode (False where none are checked)."""
        return self.clearance is not None and self.clearance < 0.0


@dataclass(frozen=True)
class ModeSet:
    """Every real solution found, and the account of how it was found.

    Attributes:
        modes: The real solutions as :class:`Mode` (configurations verified by the core).
        complete: Every path ended (finite or at infinity), so the set holds every isolated real solution
            (with probability one); False as soon as one path failed.
        method: How the set was found (the homotopy, its start system and bound).
        n_paths: Paths tracked.
        bound: The Bezout number the start system has (total degree or multihomogeneous).
        n_complex: Finite solutions that are not real.
        n_infinite: Paths that went to infinity.
        n_exceptional: Finite real solutions that are not poses (Study's exceptional set ``e = 0``).
        failed: The paths that failed, with Bertini's code.
        reduction: The reduced structure (:meth:`pkm.core.modes.reduce.Reduction.describe`).
        seconds: Wall time of the homotopy [s].
    """

    modes: tuple[Mode, ...]
    complete: bool
    method: str
    n_paths: int
    bound: int
    n_complex: int
    n_infinite: int
    n_exceptional: int
    failed: tuple[Path, ...]
    reduction: str
    seconds: float

    def __len__(self) -> int:
        return len(self.modes)

    def __iter__(self) -> Iterator[Mode]:
        return iter(self.modes)

    def __getitem__(self, k: int) -> Mode:
        return self.modes[k]

    @property
    def interfering(self) -> tuple[int, ...]:
        """The labels of the modes in which two checked bodies interpenetrate (:attr:`Mode.interferes`)."""
        return tuple(m.label for m in self.modes if m.interferes)

    def summary(self) -> str:
        """One sentence: the real assembly modes found, then the polynomial system's other solutions, counted as
        what they are (not assembly modes, no failure: complex ones, real ones off the poses, paths to infinity),
        the homotopy and whether the set is complete."""
        state = "complete" if self.complete else f"NOT complete: {len(self.failed)} path(s) failed"
        return (f"{len(self.modes)} real assembly mode(s); the polynomial system's other solutions, which are no "
                f"assembly mode: {self.n_complex} complex, {self.n_exceptional} exceptional (real, not a pose: "
                f"Study's e = 0), {self.n_infinite} at infinity; from {self.n_paths} paths of {self.method}; {state}")


def _clearance(mech: Mechanism, q: np.ndarray) -> float | None:
    """:attr:`Mode.clearance` at ``q``."""
    return float(minimum_distances(mech, q[None])[0]) if checks_collisions(mech) else None


def _check(mech: Mechanism, q: np.ndarray) -> float:
    res = float(np.abs(constraints.residual(mech, q)).max())
    if not res <= VERIFY_TOL:
        raise ConvergenceError("the core's check of a recovered mode", res, 0, VERIFY_TOL)
    return res
