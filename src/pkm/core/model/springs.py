"""Joint springs and dampers a model file states on joints (MJCF ``stiffness``, ``springref`` and ``damping``; an SDF
axis's ``<dynamics>``): kept in the closure spec's ``[springs.<joint>]`` tables, so that what the file says is
neither lost nor silently dropped::

    [springs.left-shin]
    stiffness = 1500.0      # N m/rad (a prismatic joint's: N/m)
    rest = 0.0              # rad (m): where the spring exerts nothing (MuJoCo's springref)
    damping = 0.1           # N m s/rad (N s/m)

A table may leave keys out (0). They are read, checked, written back by :func:`pkm.save` and named in the load notes,
and the dynamics apply them:

* a spring's **stiffness** ``k`` about its ``rest`` exerts the joint effort ``τ_s = -k (q - rest)``
  (:attr:`JointSprings.efforts`, one nv vector for the mechanism, :attr:`Mechanism.springs
  <pkm.core.model.mechanism.Mechanism.springs>`), of potential energy ``½ k (q - rest)²``. It enters every route that
  uses the tree's efforts: :func:`pkm.inverse_dynamics` (each method), :func:`pkm.forward_dynamics` (both methods),
  the actuator-space model (``h_a`` and the static efforts ``g_a``, :mod:`pkm.core.dynamics.model`), the potential
  energy of :func:`pkm.core.dynamics.projection.energy` and :func:`pkm.simulate` (Python and C), the compiled twin
  (:mod:`pkm.core.twin`), and the identification's measured efforts (a known effort, subtracted). A spring on an
  actuated joint is applied as well (a spring in the drive: the actuator's effort is what is left);
* a spring's **damping** ``c`` is the joint's viscous friction: written into Pinocchio's ``damping`` of the joint,
  where a drive's ``viscous`` goes (:mod:`pkm.core.model.actuators`), it is part of the friction ``f_a``
  (``-c v``): applied where friction is (:func:`pkm.simulate`, by default; :func:`pkm.forward_dynamics` with
  ``friction=True``), counted in a simulation's dissipated energy, and left out of the inverse dynamics as a drive's
  friction is. On an actuated joint it adds to its drive's ``viscous`` (a damper in parallel with the drive: a model
  file's damping of a driven joint is its drive's, :mod:`pkm.core.formats.mjcf`, not a spring's); the drive's
  ``viscous`` (:attr:`Mechanism.actuators <pkm.core.model.mechanism.Mechanism.actuators>`) stays its own.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from pkm.core.model.actuators import MAGNITUDE, number_tables
from pkm.errors import SpecError

if TYPE_CHECKING:
    import pinocchio as pin

#: The keys of a ``[springs.<joint>]`` table, each 0 when left out.
SPRING_KEYS = ("stiffness", "rest", "damping")


def parse_springs(raw: object, source: str) -> dict[str, dict[str, float]]:
    """The ``[springs]`` table of a closure spec (or a reader's): ``{joint: {key: value}}``, checked.

    Raises:
        SpecError: not a table of tables, an unknown key, a value that is not a finite number, a negative stiffness or
            damping, or one of 1e12 and more.
    """
    out = number_tables(raw, "springs", SPRING_KEYS, source)
    for joint, values in out.items():
        for key, value in values.items():
            if not math.isfinite(value):
                raise SpecError(source, f"springs.{joint}.{key} must be a finite number, got {value!r}")
            if key != "rest" and not 0.0 <= value < MAGNITUDE:
                raise SpecError(source, f"springs.{joint}.{key} = {value!r}: a {key} is >= 0 and below {MAGNITUDE:g}")
    return out


@dataclass(frozen=True, eq=False)
class JointSprings:
    """A mechanism's joint springs, in its Pinocchio coordinates (the one-coordinate joints with a stiffness).

    Attributes:
        nv: The model's velocity size.
        idx_q: The sprung joints' configuration indices.
        idx_v: Their velocity indices.
        stiffness: Their stiffness ``k`` [N m/rad, N/m].
        rest: Their rest position [rad, m].
        names: Their joint names.
    """

    nv: int
    idx_q: np.ndarray
    idx_v: np.ndarray
    stiffness: np.ndarray
    rest: np.ndarray
    names: tuple[str, ...] = ()

    def __bool__(self) -> bool:
        """Whether any spring exerts an effort (a stiffness)."""
        return bool(self.idx_v.size)

    def stretch(self, q: np.ndarray) -> np.ndarray:
        """``q - rest`` on the sprung joints [rad, m]."""
        return np.asarray(q, dtype=float)[self.idx_q] - self.rest

    def efforts(self, q: np.ndarray) -> np.ndarray:
        """The springs' joint efforts ``τ_s = -k (q - rest)`` (nv,) [N m, N] (zero off the sprung joints)."""
        out = np.zeros(self.nv)
        if self.idx_v.size:
            out[self.idx_v] = -self.stiffness * self.stretch(q)
        return out

    def energy(self, q: np.ndarray) -> float:
        """The springs' potential energy ``Σ ½ k (q - rest)²`` [J]."""
        return float(0.5 * self.stiffness @ self.stretch(q) ** 2) if self.idx_v.size else 0.0


def joint_springs(model: pin.Model, springs: Mapping[str, Mapping[str, float]]) -> JointSprings:
    """The :class:`JointSprings` of ``springs`` (checked tables on one-coordinate joints of ``model``), those of zero
    stiffness left out."""
    sprung = [(n, model.joints[model.getJointId(n)], t.get("stiffness", 0.0), t.get("rest", 0.0))
              for n, t in springs.items() if t.get("stiffness", 0.0) != 0.0]
    return JointSprings(model.nv, np.array([j.idx_q for _, j, _, _ in sprung], dtype=int),
                        np.array([j.idx_v for _, j, _, _ in sprung], dtype=int),
                        np.array([k for _, _, k, _ in sprung], dtype=float),
                        np.array([r for _, _, _, r in sprung], dtype=float), tuple(n for n, _, _, _ in sprung))


def describe(springs: Mapping[str, Mapping[str, float]]) -> str:
    """One line naming each spring and its values (for the load notes)."""
    return "; ".join(f"{j} (" + ", ".join(f"{k} {v:g}" for k, v in values.items()) + ")"
                     for j, values in springs.items())


def spring_notes(springs: Mapping[str, Mapping[str, float]]) -> tuple[str, ...]:
    """The load note naming the springs a model file states (none: no note)."""
    return (f"joint springs read into [springs] (applied by pkm's dynamics): {describe(springs)}",) if springs else ()


__all__ = ["MAGNITUDE", "SPRING_KEYS", "JointSprings", "describe", "joint_springs", "parse_springs", "spring_notes"]
