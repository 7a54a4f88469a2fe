r"""A transmission: a closed sub-mechanism between its motors and the serial joints it drives (its outputs).

:func:`pkm.transmissions` makes them from a whole robot (:mod:`pkm.core.transmissions.decompose`: the rules). Each
holds its sub-mechanism alone (:attr:`Transmission.mechanism`, a :class:`pkm.Mechanism` rooted at
:attr:`Transmission.root`, the motors actuated, the outputs its task) and answers the maps a serial controller or
simulator needs, in the sub-mechanism's configuration ``q_sub`` (its ``nq``, as the solvers return it):

* the position maps motors -> outputs (the sub-mechanism's loop closure, warm-started from ``guess``) and outputs ->
  motors (its inverse kinematics), both pkm's bounded Newton solvers (:class:`~pkm.errors.ConvergenceError`);
* the velocity map ``J = ∂o/∂m`` (``ȯ = J ṁ``, :func:`pkm.forward_jacobian` of the sub-mechanism) and its inverse
  (:class:`~pkm.errors.SingularityError` where singular);
* the effort maps by the power balance ``τ_mᵀ ṁ = τ_oᵀ ȯ``: ``τ_m = Jᵀ τ_o`` and ``τ_o = J⁻ᵀ τ_m``, computed by the
  other route, the outputs independent (:mod:`pkm.core.transmissions.coordinates`), so that ``effort_map = Jᵀ`` is a
  check;
* what the serial-equivalent model lacks (:func:`~pkm.core.transmissions.coordinates.serial_tree`: the tree with
  the outputs only, the bodies they carry, and every other joint's body welded to its parent at the reference, its
  mass carried by the nearest output above it or by the root), in output coordinates: ``ΔM = M_o - M_s`` and
  ``Δh = h_o - h_s`` (the welded bodies' motion about their anchors and the rotors, less the welded mass's own
  share: a diagonal entry can be negative), so that serial model + ΔM + Δh is the closed-loop model exactly:
  ``(M_s + ΔM) ö + h_s + Δh = τ_o`` is the sub-mechanism's dynamics with the root held where the robot's reference
  puts it.

Its motors may drive the sub-mechanism's actuated joints ``q_a`` (:attr:`Transmission.drives`) through a constant
map (a differential: the spec's ``[motors]``, :mod:`pkm.core.model.motors`): the motors' coordinates are
``u = C q_a`` (:attr:`Transmission.motor_matrix`, the identity without ``[motors]``), and every map above is in the
motors' coordinates: positions ``q_a = C⁻¹ u``, ``J = J_a C⁻¹``, ``τ_m = C⁻ᵀ J_aᵀ τ_o`` (``J_a = ∂o/∂q_a``). A
differential over serial joints alone (no loop) is a transmission whose outputs are those joints: ``qo = C⁻¹ u``,
``J = C⁻¹`` constant, ``τ_m = C⁻ᵀ τ_o``, ``τ_o = Cᵀ τ_m``, and ``ΔM = 0``, ``Δh = 0`` (the serial model keeps
every body it moves; the reflected inertia pkm models per actuated joint, ``[actuators]`` or MJCF's ``armature``,
stays on the output joints it belongs to).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pkm.core.differential.velocity import RTOL, forward_jacobian, inverse_jacobian
from pkm.core.kinematics.solve import close_loops, solve_ik
from pkm.core.model.mechanism import Mechanism
from pkm.core.model.plausibility import require_physical
from pkm.core.model.scale import JacobianScales
from pkm.core.transmissions.coordinates import CLOSURE_RTOL, OutputSplit, output_model, output_split, serial_tree
from pkm.errors import SingularityError, TransmissionError
from pkm.validation import as_vector

#: Below this, an idle motion's motor component or the outputs' dependence (homogenised, relative) counts as zero.
SINGULAR = 1e-7


@dataclass(frozen=True)
class Transmission:
    """One closed sub-mechanism of a robot, between its motors and its output joints (module doc).

    Attributes:
        name: The transmission's name (given in ``outputs=``, else generated: :mod:`pkm.core.transmissions.decompose`).
        mechanism: The closed sub-mechanism alone, rooted at ``root`` (held where the robot's reference puts it),
            the motors actuated, the outputs its task (``TaskSpec(components=(), joints=outputs)``).
        root: The robot's body the sub-mechanism hangs from.
        motors: The motors: the actuated joints (names as in the whole robot), or the ``[motors]`` that drive them
            through a constant map (:attr:`motor_matrix`; a differential's motors by their names).
        outputs: The serial joints the serial-equivalent model keeps (as many as motors).
        passive: The sub-mechanism's other joints (rods, cranks' balls), in the model's order.
    """

    name: str
    mechanism: Mechanism = field(repr=False)
    root: str
    motors: tuple[str, ...]
    outputs: tuple[str, ...]
    passive: tuple[str, ...]

    # ------------------------------------------------------------------ indices
    @functools.cached_property
    def out_q(self) -> np.ndarray:
        """The outputs' indices in ``q_sub``."""
        return np.array([self.mechanism.joints[n].idx_q for n in self.outputs], dtype=int)

    @functools.cached_property
    def out_v(self) -> np.ndarray:
        """The outputs' indices in the sub-mechanism's velocities."""
        return np.array([self.mechanism.joints[n].idx_v for n in self.outputs], dtype=int)

    @property
    def k(self) -> int:
        """The number of motors (= of outputs)."""
        return len(self.motors)

    @property
    def drives(self) -> tuple[str, ...]:
        """The actuated joints the motors drive (:attr:`motors` themselves without ``[motors]``)."""
        return self.mechanism.actuated_names

    @property
    def welded(self) -> tuple[str, ...]:
        """The sub-mechanism's joints the serial-equivalent model welds at the reference: the drives that are no
        outputs (the motors' joints; none for a differential, whose drives are its outputs) and the passive joints."""
        return (*(d for d in self.drives if d not in self.outputs), *self.passive)

    @property
    def motor_matrix(self) -> np.ndarray:
        """``C`` (k x k): the motors' coordinates ``u = C q_a`` from :attr:`drives`' (module doc; the identity
        without ``[motors]``). Its rows are :attr:`motors`, its columns :attr:`drives`."""
        return self.mechanism.motor_map.matrix

    @property
    def constant(self) -> bool:
        """Whether the maps are constant: a differential over serial joints (no loop: its sub-mechanism's one closure
        ties a frame to itself; module doc)."""
        return all(fa == fb for fa, fb in self.mechanism.closure_frames)

    def _to_drives(self, qm: ArrayLike) -> np.ndarray:
        """The drives' coordinates ``C⁻¹ u`` of the motors' ``u``."""
        u = as_vector(qm, self.k, "qm")
        return u if self.mechanism.motor_map.identity else np.linalg.solve(self.motor_matrix, u)

    def _from_drives(self, X: np.ndarray) -> np.ndarray:
        """``C X``: the drives' rows of ``X`` as the motors'."""
        return X if self.mechanism.motor_map.identity else self.motor_matrix @ X

    def _per_motor(self, X: np.ndarray) -> np.ndarray:
        """``X C⁻¹``: columns per drive of ``X`` as per motor."""
        return X if self.mechanism.motor_map.identity else np.linalg.solve(self.motor_matrix.T, X.T).T

    @property
    def q_reference(self) -> np.ndarray:
        """The sub-mechanism's reference configuration (the robot's reference)."""
        return self.mechanism.q_reference

    def check(self) -> None:
        """Raise :class:`~pkm.errors.TransmissionError` (``reason="singular"``) where, at the reference, the outputs do
        not hold the motors or are not independent, or the motors do not hold the outputs."""
        sub = self.mechanism
        sp = output_split(sub, sub.q_reference, self.out_v, sub.act_v)
        if sp.motor_leak > SINGULAR or sp.dependence > SINGULAR:
            why = ("with the outputs held the motors can move" if sp.motor_leak > SINGULAR
                   else "the closures constrain the outputs among themselves")
            raise TransmissionError(self.name, "singular", f"the outputs {list(self.outputs)} are singular at the "
                                    f"reference: {why} (motor component of a free motion {sp.motor_leak:.3g}, "
                                    f"dependence {sp.dependence:.3g}); choose other outputs (outputs={{...}})",
                                    self.outputs, max(sp.motor_leak, sp.dependence))
        try:
            forward_jacobian(sub, sub.q_reference)
        except SingularityError as exc:
            raise TransmissionError(self.name, "singular", f"the motors {list(self.motors)} do not hold the outputs "
                                    f"at the reference: {exc}", self.motors, exc.sigma_min) from exc

    # ------------------------------------------------------------------ positions
    def outputs_from_motors(self, qm: ArrayLike, guess: ArrayLike | None = None, *, tol: float | None = None,
                            max_iter: int = 30) -> tuple[np.ndarray, np.ndarray]:
        """Forward kinematics: ``(qo, q_sub)`` for the motors at ``qm`` [rad or m] (the sub-mechanism's loop closure,
        seeded with the configuration ``guess``, default the reference; ``tol`` on the closure residual, its
        lengths in the sub-mechanism's characteristic length as :func:`~pkm.core.kinematics.solve.close_loops`',
        default :data:`~pkm.core.transmissions.coordinates.CLOSURE_RTOL`).
        Raises :class:`~pkm.errors.ConvergenceError` when the loops do not close within ``max_iter`` Newton
        iterations per continuation step."""
        if self.constant:  # (a differential: q_a = C⁻¹ u, no loop to close)
            q = self.mechanism.with_actuated(self._guess(guess), self._to_drives(qm))
            return q[self.out_q].copy(), q
        tol = CLOSURE_RTOL if tol is None else tol
        q = close_loops(self.mechanism, self._to_drives(qm), guess, tol=tol, max_iter=max_iter).q
        return q[self.out_q].copy(), q

    def motors_from_outputs(self, qo: ArrayLike, guess: ArrayLike | None = None, *, tol: float | None = None,
                            max_iter: int = 30) -> tuple[np.ndarray, np.ndarray]:
        """Inverse kinematics: ``(qm, q_sub)`` for the outputs at ``qo`` [rad or m] (the sub-mechanism's inverse
        kinematics, seeded with ``guess``, default the reference; ``tol`` as :meth:`outputs_from_motors`')."""
        if self.constant:  # (a differential: its outputs are its drives)
            q = self._guess(guess)
            q[self.out_q] = as_vector(qo, self.k, "qo")
            return self._from_drives(self.mechanism.actuated_q(q)), q
        tol = CLOSURE_RTOL if tol is None else tol
        q = solve_ik(self.mechanism, as_vector(qo, self.k, "qo"), guess, tol=tol, max_iter=max_iter).q
        return self._from_drives(self.mechanism.actuated_q(q)), q

    def _guess(self, guess: ArrayLike | None) -> np.ndarray:
        return (self.q_reference if guess is None else self.mechanism.check_q(guess, "guess")).copy()

    # ------------------------------------------------------------------ rates and efforts
    def velocity_map(self, q_sub: ArrayLike) -> np.ndarray:
        """``J = ∂o/∂m`` (k x k): ``ȯ = J ṁ`` at the closed configuration ``q_sub``."""
        return self._per_motor(forward_jacobian(self.mechanism, q_sub))

    def inverse_velocity_map(self, q_sub: ArrayLike) -> np.ndarray:
        """``J⁻¹ = ∂m/∂o`` (k x k): ``ṁ = J⁻¹ ȯ``; :class:`~pkm.errors.SingularityError` where the outputs do not hold
        the motors."""
        return self._from_drives(inverse_jacobian(self.mechanism, q_sub))

    def _held(self, sp: OutputSplit) -> OutputSplit:
        """``sp``, or :class:`~pkm.errors.SingularityError` (kind ``"outputs"``) where the outputs do not determine
        the sub-mechanism there (the test :meth:`check` makes at the reference, with the same bound
        :data:`SINGULAR`): every map and model in output coordinates is undefined there, not a least-squares
        answer."""
        if sp.motor_leak > SINGULAR or sp.dependence > SINGULAR:
            raise SingularityError("outputs", sp.sigma, f"transmission {self.name!r}: the outputs "
                                   f"{list(self.outputs)} do not determine the sub-mechanism here (motor component of "
                                   f"a free motion {sp.motor_leak:.3g}, dependence {sp.dependence:.3g})",
                                   distance=max(sp.motor_leak, sp.dependence))
        return sp

    def _split(self, q_sub: ArrayLike) -> OutputSplit:
        return self._held(output_split(self.mechanism, self.mechanism.check_q(q_sub, "q_sub"), self.out_v,
                                       self.mechanism.act_v))

    def effort_map(self, q_sub: ArrayLike) -> np.ndarray:
        """``Jᵀ`` (k x k): the motor efforts ``τ_m = Jᵀ τ_o`` that hold the output efforts ``τ_o`` (the power balance)
        [N m or N], computed with the outputs independent (``J⁻ᵀ = Ĝ_mᵀ``, inverted: a second route to ``J``);
        :class:`~pkm.errors.SingularityError` where the motors do not hold the outputs, decided as
        :meth:`velocity_map` decides it (``Ĝ_m`` homogenised by the characteristic length, its relative smallest
        singular value under :data:`pkm.core.differential.velocity.RTOL`)."""
        sub = self.mechanism
        Gm = self._split(q_sub).G[sub.act_v]
        cols = JacobianScales.of(sub).columns
        s = np.linalg.svd(Gm * cols[self.out_v][None, :] / cols[sub.act_v][:, None], compute_uv=False)
        if not s[-1] > RTOL * s[0]:
            raise SingularityError("direct", float(s[-1]), f"transmission {self.name!r}: the motors do not hold the "
                                   "outputs here: no motor efforts balance an output effort",
                                   distance=float(s[-1] / s[0]) if s[0] > 0.0 else 0.0)
        return self._per_motor(np.linalg.inv(Gm)).T

    def inverse_effort_map(self, q_sub: ArrayLike) -> np.ndarray:
        """``J⁻ᵀ`` (k x k): the output efforts ``τ_o = J⁻ᵀ τ_m`` the motor efforts ``τ_m`` produce [N m or N];
        :class:`~pkm.errors.SingularityError` where the outputs do not determine the sub-mechanism."""
        return self._from_drives(self._split(q_sub).G[self.mechanism.act_v]).T

    # ------------------------------------------------------------------ dynamics in output coordinates
    def output_model(self, q_sub: ArrayLike, qd_o: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """``(M_o, h_o)``: the closed-loop model in output coordinates at ``q_sub`` and the output rates ``qd_o``
        (:mod:`pkm.core.transmissions.coordinates`) [kg m^2, N m]."""
        sub = self.mechanism
        M, h, sp = output_model(sub, sub.check_q(q_sub, "q_sub"), as_vector(qd_o, self.k, "qd_o"), self.out_v,
                                sub.act_v)
        self._held(sp)
        return M, h

    @functools.cached_property
    def serial(self) -> pin.Model:
        """The serial-equivalent model of the sub-mechanism (:func:`pkm.core.transmissions.coordinates.serial_tree`):
        its model with every joint but the outputs welded to its parent at the reference (their bodies' mass carried
        by the nearest output above them, or by the root; the motors' rotors removed)."""
        return serial_tree(self.mechanism.model, self.outputs, self.mechanism.q_reference)

    def serial_model(self, q_sub: ArrayLike, qd_o: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """``(M_s, h_s)``: the serial-equivalent model's mass matrix and bias (Coriolis, centrifugal, gravity) in the
        outputs [kg m^2, N m]."""
        require_physical(self.mechanism, "the serial-equivalent model")
        q = self.mechanism.check_q(q_sub, "q_sub")
        v = np.zeros(self.mechanism.nv)
        v[self.out_v] = as_vector(qd_o, self.k, "qd_o")
        data = self.serial.createData()
        M = pin.crba(self.serial, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        h = pin.rnea(self.serial, data, q, v, np.zeros(self.mechanism.nv)) - self.mechanism.springs.efforts(q)
        return M[np.ix_(self.out_v, self.out_v)], h[self.out_v]  # (the outputs' own springs: their rows of τ_s)

    def delta_mass(self, q_sub: ArrayLike) -> np.ndarray:
        """``ΔM = M_o - M_s`` (k x k) [kg m^2]: the mass matrix the serial-equivalent model (the rods and cranks
        welded at the reference) lacks, in output coordinates: the rods' and cranks' motion about where they are
        welded, the rotors, less the welded mass's share (it may be indefinite)."""
        zero = np.zeros(self.k)
        return self.output_model(q_sub, zero)[0] - self.serial_model(q_sub, zero)[0]

    def delta_bias(self, q_sub: ArrayLike, qd_o: ArrayLike) -> np.ndarray:
        """``Δh = h_o - h_s`` (k) [N m]: the Coriolis, centrifugal and gravity efforts (and the closures' drift) the
        serial-equivalent model lacks, at the output rates ``qd_o`` [rad/s or m/s]."""
        return self.output_model(q_sub, qd_o)[1] - self.serial_model(q_sub, qd_o)[1]


__all__ = ["SINGULAR", "Transmission"]
