"""Transmission kernels: a closed sub-mechanism's maps between its motors and its output joints, from ONE generator
(the twin's CasADi expressions, :mod:`pkm.core.twin`) to three targets: C99
(:func:`pkm.core.export.emit.c_function`), JAX (:func:`pkm.core.twin.jaxgen.jax_source`) and NVIDIA Warp
(:mod:`pkm.core.twin.warpgen`); written out for a robot's software by :mod:`pkm.core.transmissions.targets`
(``pkm transmission``).

A transmission here is a mechanism ``mech`` (the closed sub-mechanism alone, ``actuated`` = its motors ``m``) and
``k = na`` output joints ``o`` (one-coordinate joints of the tree: revolute or prismatic). Where ``[motors]`` drive
the actuated joints ``q_a`` through a constant map (a differential: ``u = C q_a``, :mod:`pkm.core.model.motors`), the
motors' coordinates are ``u``: every kernel's ``qm``, ``J`` and ``J_inv`` are composed with ``C`` (``q_a = C⁻¹ u``,
``J = J_a C⁻¹``, ``J_inv = C J_a⁻¹``); a differential over serial joints (no loop: its outputs are its joints) has
constant maps and ``ΔM = Δh = 0``. The kernels (:data:`KERNELS`), each an SX function of one sample after CSE:

* ``fk`` ``(q, qm) -> (q_out, qo, status, residual)``: motors to outputs. Newton on the closure with the motors set
  to ``qm``, warm-started from ``q`` (the previous solution), :data:`ITERATIONS` iterations of one step
  (:meth:`TransmissionKernels.step`; no branch: the same instructions for every sample and every GPU thread), then
  :meth:`TransmissionKernels.finish`: unrolled in the in-process C (:meth:`TransmissionKernels.function`), a loop
  over the one step in the exported C, in JAX and in Warp (:meth:`TransmissionKernels.looped`; the battobot ankle's C
  file 1.8 MB -> 0.5 MB, gcc -O2 four times faster; JAX's first jit of its fk 74 s -> 10 s; its Warp module
  1.94 MB -> 0.64 MB, its cold compile on Warp's CPU device 42-52 s -> 12-15 s of CPU, bit for bit the same
  outputs); each step the twin's sparse LU of the passive columns (pivots fixed at the reference) or, with idle
  motions (a rod spinning between two balls), the least-norm step (:meth:`TransmissionKernels._newton`), at most
  :data:`MAX_STEP` long. ``residual`` is the largest closure
  residual at ``q_out`` [m, rad];
  ``status`` (:data:`STATUS`): 0 ``OK`` (``residual <= tol``, by default :data:`RTOL` times the characteristic
  length), 1 ``NOT_CONVERGED``, 2 ``SINGULAR`` (a pivot under :data:`~pkm.core.twin.kernels.PIVOT_FLOOR` relative to
  the reference at some iteration), 4 ``OUTSIDE_LIMITS`` (converged, but a joint of ``q_out``, the motors' and the
  outputs' among them, lies beyond the limit its file states: ``q_out`` is the solution all the same);
* ``ik`` ``(q, qo) -> (q_out, qm, status, residual)``: outputs to motors, the same Newton with the outputs held;
* ``maps`` ``(q) -> (J, J_inv, pivot)``: the velocity map ``qdot_o = J qdot_m`` (k x k) and its inverse, each from
  its own closure solve (motors driving, outputs driving); the effort maps are their transposes by power balance:
  ``tau_m = Jᵀ tau_o`` and ``tau_o = J_invᵀ tau_m``;
* ``delta`` ``(q, qdo) -> (dM, dh, pivot)``: what a serial-equivalent model lacks, in output coordinates: ``ΔM(q) =
  M_o - M_s`` (k x k) [kg m², kg] and ``Δh(q, qdot_o) = h_o - h_s`` (k) [N m, N];
* ``fk_j_dm`` ``(q, qm) -> (q_out, qo, J, dM, status)``: ``fk`` then ``J`` and ``ΔM`` at its solution, fused (what a
  learning simulator's step needs; :mod:`pkm.bench.transmissions` times it); ``SINGULAR`` also where a solve of
  ``J`` or ``ΔM`` has a pivot under the floor.

Definitions. ``M_o``, ``h_o`` are the closed-loop model in output coordinates: the actuator-space model
(:class:`~pkm.core.twin.dynamics.ActuatorTwin`, as :func:`pkm.mass_matrix`, :func:`pkm.bias_efforts`) of the same
mechanism with the outputs as its actuated joints: ``M_o = G_oᵀ M G_o``, ``h_o = G_oᵀ (h + M Ġ_o qdot_o)`` with
``G_o = ∂q/∂o`` (rotor armature and gravity included, idle motions mass-orthogonal). ``M_s``, ``h_s`` are the
serial-equivalent model's (:func:`pkm.core.transmissions.coordinates.serial_tree`): the tree with every joint but the
outputs welded to its parent at the reference (the rods' and the cranks' mass carried by the nearest output above
them or by the root, the rotors dropped; each output hangs from the root through outputs only),
as RNEA of the twin with only the outputs moving. Hence ``M_s + ΔM = M_o`` and ``h_s + Δh = h_o`` exactly, and
``M_a = Jᵀ M_o J`` (tested against :func:`pkm.mass_matrix`, :func:`pkm.bias_efforts` and
:class:`~pkm.core.transmissions.transmission.Transmission`'s Python reference).

Every kernel takes and returns SI values in Pinocchio's conventions; arrays are the CasADi functions' nonzeros,
matrices column-major. Equal across targets to 1e-12 in double precision (the tests).

Derivatives: JAX differentiates a solve (:data:`SOLVES`) at its solution by the implicit function theorem
(:meth:`TransmissionKernels.tangent`, :data:`JAX_RUNTIME`): ``∂qo/∂qm`` is ``J``, ``∂qm/∂qo`` of ``ik`` is ``J_inv``,
the configuration's the closure's tangent (the idle motions' coordinates held), the warm start's zero; never a
derivative through the iterations.
"""

from __future__ import annotations

import dataclasses
import functools
import os
from collections.abc import Callable, Sequence

import casadi as cs
import numpy as np
from numpy.typing import ArrayLike

from pkm.core.export.library import LIMIT_TOL
from pkm.core.model.joints import stated_limits
from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.core.model.scale import JacobianScales
from pkm.core.transmissions.coordinates import closure_tol, lumped_inertias
from pkm.core.transmissions.transmission import Transmission
from pkm.core.twin.dynamics import ActuatorTwin, cholesky, cholesky_solve
from pkm.core.twin.kernels import PIVOT_FLOOR
from pkm.core.twin.spatial import Expr
from pkm.core.twin.tree import Twin
from pkm.core.twin.warpgen import Loop
from pkm.errors import InvalidInputError, SpecError, TransmissionError
from pkm.validation import as_array, as_count, as_tolerance

#: Newton iterations of ``fk`` and ``ik``: on the humanoid ankle, 3 reach 1e-12 from a warm start 0.01 rad
#: away (a controller's previous solution: 2 do not), 5 from the reference over ±0.25 rad of both motors (4 do not,
#: for 15% of the samples: ``NOT_CONVERGED``); 8 leave a margin.
ITERATIONS = 8
#: The largest Newton step [rad, characteristic lengths]: a longer one (from a guess near a singular configuration)
#: is shortened to it; near the solution the step is Newton's. (From the reference, 8 iterations: the Talos-like
#: ankle's FK converges for 200 of 200 motor positions within ±0.05 rad, its IK for 180 with this bound, 171 with
#: 0.2 and 187 without; the humanoid ankle's and the battobot's every sample either way.)
MAX_STEP = 0.5
#: The largest closure residual at which a solve counts as converged, relative to the sub-mechanism's characteristic
#: length (:func:`~pkm.core.transmissions.coordinates.closure_tol`: 1e-12 m on a sub-mechanism of 0.1 m, where it was
#: 1e-12 m on any).
RTOL = 1e-11
#: The status codes, in order from 0 (``INVALID_INPUT``: the C target's own check of its inputs, before the kernel).
#: The status codes, in order from 0 (``INVALID_INPUT``: the C target's own check of its inputs, before the kernel;
#: ``OUTSIDE_LIMITS``: a solve converged to a configuration with a joint beyond its stated limit by more than
#: :data:`pkm.core.export.library.LIMIT_TOL`: a motor, an output or a rod's joint).
STATUS = ("OK", "NOT_CONVERGED", "SINGULAR", "INVALID_INPUT", "OUTSIDE_LIMITS")

#: Each kernel's inputs and outputs.
KERNELS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "fk": (("q", "qm"), ("q_out", "qo", "status", "residual")),
    "ik": (("q", "qo"), ("q_out", "qm", "status", "residual")),
    "maps": (("q",), ("J", "J_inv", "pivot")),
    "delta": (("q", "qdo"), ("dM", "dh", "pivot")),
    "fk_j_dm": (("q", "qm"), ("q_out", "qo", "J", "dM", "status")),
}


def _driven(mech: Mechanism, actuated: Sequence[str]) -> Mechanism:
    """``mech`` with ``actuated`` as its actuated joints (the same Pinocchio model, closures and reference)."""
    out = Mechanism(mech.model, dataclasses.replace(mech.spec, actuated=tuple(actuated), motors={}), urdf=mech.urdf,
                    source=mech.source)
    out.q_reference = mech.q_reference.copy()
    return out


class TransmissionKernels:
    """The transmission kernels of a closed sub-mechanism (see the module doc).

    Args:
        mech: The closed sub-mechanism, its actuated joints the motors.
        outputs: The output joints (as many as motors; one-coordinate joints of ``mech``).
        name: The transmission's name (default the mechanism's): C names, files.
        iterations: Newton iterations of ``fk`` and ``ik``.
        tol: Convergence tolerance of ``fk`` and ``ik`` on the largest closure residual [m, rad] (default :data:`RTOL`
            times the sub-mechanism's characteristic length).

    Raises:
        TransmissionError: the outputs are not one-coordinate joints of ``mech``, are motors, are not as many as
            the motors (``reason="outputs"``), or the motors or the outputs do not determine the sub-mechanism at the
            reference (a closure solve without a pivot there, ``reason="singular"``).
    """

    def __init__(self, mech: Mechanism, outputs: Sequence[str], *, name: str | None = None,
                 iterations: int = ITERATIONS, tol: float | None = None):
        self.mech = check_mechanism(mech)
        self.name = name or mech.name
        self.outputs = tuple(outputs)
        #: The motors (:attr:`pkm.Transmission.motors`) and the actuated joints they drive through the constant map
        #: ``C`` (:attr:`motor_matrix`: ``u = C q_a``, the identity without ``[motors]``); ``constant``: a
        #: differential over serial joints (its sub-mechanism's one closure ties a frame to itself), its outputs
        #: its drives.
        self.motors = tuple(mech.motor_map.names)
        self.drives = tuple(mech.actuated_names)
        self.motor_matrix = mech.motor_map.matrix
        self.constant = all(fa == fb for fa, fb in mech.closure_frames)
        self.iterations = as_count(iterations, "iterations", high=100)
        self.tol = closure_tol(self.mech, RTOL) if tol is None else as_tolerance(tol, "tol")
        for o in self.outputs:
            j = mech.joints.get(o)
            if j is None or j.nq != 1 or j.nv != 1:
                raise TransmissionError(self.name, "outputs", f"output {o!r} is not a one-coordinate joint of the "
                                        f"sub-mechanism (its joints: {sorted(mech.joints)})", (o,))
            if o in self.drives and not self.constant:
                raise TransmissionError(self.name, "outputs", f"output {o!r} is a motor", (o,))
        if self.constant and set(self.outputs) != set(self.drives):
            raise TransmissionError(self.name, "outputs", f"a differential's outputs are its joints "
                                    f"{list(self.drives)}", self.outputs)
        if len(set(self.outputs)) != len(self.motors):
            raise TransmissionError(self.name, "outputs", f"{len(set(self.outputs))} distinct outputs for "
                                    f"{len(self.motors)} motors {list(self.motors)}", self.outputs)
        try:
            self.driven = _driven(mech, self.outputs)  # (the same mechanism, the outputs driving)
            self._twin_m = ActuatorTwin(Twin(self.mech))
            self._twin_o = ActuatorTwin(Twin(self.driven))
        except SpecError as e:  # (a closure LU without a pivot at the reference)
            raise TransmissionError(self.name, "singular", f"the motors {list(self.motors)} or the outputs "
                                    f"{list(self.outputs)} do not determine the sub-mechanism at the reference "
                                    f"({e.args[0] if e.args else e})", self.outputs) from None
        self.q = self._twin_m.tw.q  # the one configuration symbol every kernel takes
        self.qdo = self._twin_o.tw.qd  # the output rates' symbol
        self.k = len(self.motors)
        self.motor_q = [mech.joints[m].idx_q for m in self.drives]
        self.output_q = [mech.joints[o].idx_q for o in self.outputs]
        self.motor_v = [mech.joints[m].idx_v for m in self.drives]
        self.output_v = [mech.joints[o].idx_v for o in self.outputs]

    # ---------------------------------------------------------------- expressions
    def _from_drives(self, X: Expr) -> Expr:
        """``C X``: the drives' rows of ``X`` as the motors' (``X`` itself without ``[motors]``)."""
        return X if self.mech.motor_map.identity else cs.DM(self.motor_matrix) @ X

    def _per_motor(self, X: Expr) -> Expr:
        """``X C⁻¹``: the columns per drive of ``X`` per motor (``X`` itself without ``[motors]``)."""
        return X if self.mech.motor_map.identity else X @ cs.DM(np.linalg.inv(self.motor_matrix))

    def _in_q(self, at: ActuatorTwin, expr: Expr) -> Expr:
        """An expression of ``at``'s configuration symbol in terms of :attr:`q`."""
        return cs.substitute(expr, at.tw.q, self.q) if at.tw.q is not self.q else expr

    def _newton(self, at: ActuatorTwin) -> cs.Function:
        """One closure Newton iteration of ``at``'s mechanism, its actuated joints held at ``target``:
        ``(q, target) -> (q_next, pivot)``. Without idle motions the step solves the twin's sparse LU of the passive
        columns (pivots fixed at the reference); with idle motions (a rod's spin) it is the least-norm step over
        every passive coordinate (homogenised: lengths in characteristic lengths), ``A⁺ r = Aᵀ (A Aᵀ)⁻¹ r`` by a
        Cholesky factorisation of ``A Aᵀ`` over the closure rows independent at the reference, as pkm's closure
        solver steps: holding an idle coordinate instead fails where the idle motion turns away from it (the
        Talos-like ankle's rods). A step longer than :data:`MAX_STEP` is shortened to it."""
        tw = at.tw
        mech = tw.mech
        scale = JacobianScales.of(mech).columns  # (a length in characteristic lengths)
        r = tw.rotate_rows(tw.closure_residual)
        if not at.idle:
            cols = list(at.passive)
            step = at.lu.solve(r) if at.lu is not None else cs.SX(0, 1)
            pivot = at.pivot
        else:
            cols = sorted(at.passive + at.idle)
            J = tw.closure_rows["jacobian"]
            rows = _independent_rows(tw.at_reference(J[:, cols]) * scale[cols])
            A = cs.horzcat(*[J[rows, c] * float(scale[c]) for c in cols])
            L, diag = cholesky(A @ A.T)
            step = cs.vertcat(*[float(scale[c]) for c in cols]) * (A.T @ cholesky_solve(L, r[rows]))
            ref = tw.at_reference(cs.vertcat(*diag)).ravel()
            pivot = cs.mmin(cs.vertcat(*[d * d / (x * x) for d, x in zip(diag, ref)]))
        dq = cs.SX.zeros(mech.nv)
        if cols:
            size = cs.mmax(cs.vertcat(*[cs.fabs(step[k]) / float(scale[c]) for k, c in enumerate(cols)]))
            factor = cs.fmin(1.0, MAX_STEP / size)  # (1 near the solution: the full Newton step)
            for k, c in enumerate(cols):
                dq[c] = -factor * step[k]
        q_next = tw.retract(dq)
        act = list(mech.act_q)
        q_next = cs.vertcat(*[tw.target[act.index(i)] if i in act else q_next[i] for i in range(mech.nq)])
        return cs.Function("newton", [tw.q, tw.target], [q_next, pivot])

    @functools.cache  # noqa: B019
    def step(self, twin: str) -> cs.Function:
        """One Newton iteration of the closure with the motors (``twin="m"``: ``fk``'s) or the outputs (``"o"``:
        ``ik``'s) held at ``target``: ``(q, qm or qo) -> (q_next, pivot)``, the held coordinates of ``q`` set to
        the target first (:meth:`_newton`), after CSE. The targets unroll it :attr:`iterations` times (the in-process
        C: :meth:`function`) or loop over it (the exported C, JAX, Warp: :meth:`looped`)."""
        at = {"m": self._twin_m, "o": self._twin_o}[twin]
        tw = at.tw
        q, target = cs.SX.sym("q", tw.mech.nq), cs.SX.sym("target", self.k)
        drives = self._per_motor(target.T).T if twin == "m" else target  # (the motors' u as the drives' C⁻¹ u)
        act = list(tw.mech.act_q)
        held = cs.vertcat(*[drives[act.index(i)] if i in act else q[i] for i in range(tw.mech.nq)])
        values = cs.cse([cs.densify(cs.SX(e)) for e in self._newton(at)(held, drives)])
        return cs.Function(f"{c_identifier(self.name)}_newton_{twin}", [q, target], values, ["q", f"q{twin}"],
                           ["q_next", "pivot"])  # (inputs named as the kernels': errors name them)

    @functools.cache  # noqa: B019
    def finish(self, kernel: str) -> cs.Function:
        """What a solve (:data:`SOLVES`) makes of the configuration its iterations of :meth:`step` reached and their
        smallest pivot: ``(q, pivot) -> outputs`` (:data:`KERNELS`' ``kernel`` outputs), after CSE: the residual,
        the status (:data:`STATUS`) and, for ``fk_j_dm``, ``J`` and ``ΔM`` there."""
        if kernel not in SOLVES:
            raise InvalidInputError("kernel", f"use one of {list(SOLVES)}", kernel)
        at = self._twin_o if kernel == "ik" else self._twin_m
        tw = at.tw
        q, pivot = cs.SX.sym("q", tw.mech.nq), cs.SX.sym("pivot")
        residual = cs.mmax(cs.fabs(cs.substitute(tw.closure_residual, tw.q, q)))
        lo, hi = stated_limits(tw.mech.model)
        outside = cs.SX(0.0)
        for i in np.flatnonzero(np.isfinite(lo) | np.isfinite(hi)):
            outside = outside + cs.if_else(q[int(i)] < lo[i] - LIMIT_TOL, 1.0, 0.0) \
                + cs.if_else(q[int(i)] > hi[i] + LIMIT_TOL, 1.0, 0.0)
        within = cs.if_else(outside > 0.0, float(STATUS.index("OUTSIDE_LIMITS")), 0.0)
        status = cs.if_else(pivot < PIVOT_FLOOR, 2.0, cs.if_else(residual <= self.tol, within, 1.0))
        y = (self._from_drives(cs.vertcat(*[q[i] for i in self.motor_q])) if kernel == "ik"
             else cs.vertcat(*[q[i] for i in self.output_q]))
        if kernel == "fk_j_dm":  # (J and ΔM at the solution; their solves' pivots under the floor: SINGULAR too)
            J, _, p_maps = self._maps
            dM, _, p_delta = self._delta
            at_q = [cs.substitute(e, self.q, q) for e in (J, dM, cs.fmin(p_maps, p_delta))]
            exprs = [q, y, at_q[0], at_q[1], cs.if_else(at_q[2] < PIVOT_FLOOR, 2.0, status)]
        else:
            exprs = [q, y, status, residual]
        values = cs.cse([cs.densify(cs.SX(e)) for e in exprs])
        return cs.Function(f"{c_identifier(self.name)}_{kernel}_finish", [q, pivot], values, ["q", "pivot"],
                           list(KERNELS[kernel][1]))

    @staticmethod
    def _rates(at: ActuatorTwin, rows: Sequence[int]) -> Expr:
        """The joint rates ``rows`` per actuated rate of ``at``'s mechanism (its symbol ``qd``), the idle rates zero:
        the closure's passive rates from the LU (rows that no idle motion moves: the outputs, the motors; the
        mass-orthogonal idle rates of the model, :attr:`ActuatorTwin.v`, would bring its mass matrix in)."""
        tw = at.tw
        act = [int(c) for c in tw.mech.act_v]
        v = cs.SX.zeros(tw.mech.nv)
        for k, c in enumerate(act):
            v[c] = tw.qd[k]
        if at.lu is not None:
            passive = -at.lu.solve(tw.closure_rows["jacobian"][:, act] @ tw.qd)
            for k, c in enumerate(at.passive):
                v[c] = passive[k]
        return cs.jacobian(cs.vertcat(*[v[r] for r in rows]), tw.qd)

    @functools.cached_property
    def _maps(self) -> tuple[Expr, Expr, Expr]:
        """``(J, J_inv, pivot)`` in :attr:`q`."""
        am, ao = self._twin_m, self._twin_o
        J = self._per_motor(self._rates(am, self.output_v))
        J_inv = self._from_drives(self._in_q(ao, self._rates(ao, self.motor_v)))
        pm = am.lu.smallest_relative_pivot() if am.lu is not None else cs.SX(1.0)
        po = self._in_q(ao, ao.lu.smallest_relative_pivot()) if ao.lu is not None else cs.SX(1.0)
        return J, J_inv, cs.fmin(pm, po)

    @classmethod
    def of(cls, transmission: Transmission, **options: int | float) -> TransmissionKernels:
        """The kernels of a :class:`~pkm.core.transmissions.transmission.Transmission` (:func:`pkm.transmissions`):
        its sub-mechanism, outputs and name (``options``: ``iterations``, ``tol``)."""
        return cls(transmission.mechanism, transmission.outputs, name=transmission.name,
                   **options)  # type: ignore[arg-type]

    @functools.cached_property
    def _delta(self) -> tuple[Expr, Expr, Expr]:
        """``(ΔM, Δh, pivot)`` in :attr:`q` and the symbol :attr:`qdo`."""
        ao = self._twin_o
        M_o, h_o = self._in_q(ao, ao.mass_matrix), self._in_q(ao, ao.bias)
        serial = Twin(self.mech)  # the serial-equivalent model: every joint but the outputs welded (serial_tree's)
        serial._inertia = lumped_inertias(self.mech.model, self.outputs, self.mech.q_reference)
        qdd_o = cs.SX.sym("qdd_o", self.k)
        v, a = cs.SX.zeros(self.mech.nv), cs.SX.zeros(self.mech.nv)
        for r, c in enumerate(self.output_v):
            v[c], a[c] = self.qdo[r], qdd_o[r]
        tau = cs.substitute(serial.rnea, cs.vertcat(serial.q, serial.v, serial.a), cs.vertcat(self.q, v, a))
        tau = cs.vertcat(*[tau[c] for c in self.output_v])
        M_s = cs.jacobian(tau, qdd_o)
        M_s = cs.tril(M_s) + cs.tril(M_s, False).T  # (exactly symmetric, as the twin's M_a)
        h_s = cs.substitute(tau, qdd_o, cs.DM.zeros(self.k))
        return M_o - M_s, h_o - h_s, self._in_q(ao, ao.pivot)

    @functools.cache  # noqa: B019  (one function per kernel for the life of the kernels)
    def function(self, kernel: str) -> cs.Function:
        """The CasADi SX function of ``kernel`` (:data:`KERNELS`), dense, after CSE; a solve's (:data:`SOLVES`) is its
        :meth:`step` unrolled :attr:`iterations` times and its :meth:`finish`, the parts the exported C, JAX and Warp
        (:meth:`looped`) loop over. Its name is ``<name>_<kernel>`` (C identifiers)."""
        if kernel not in KERNELS:
            raise InvalidInputError("kernel", f"use one of {sorted(KERNELS)}", kernel)
        if kernel in SOLVES:  # (iterations of the step unrolled: no branch, one instruction list)
            target = cs.SX.sym(KERNELS[kernel][0][1], self.k)
            step = self.step("o" if kernel == "ik" else "m")
            q, pivot = step(self.q, target)
            for _ in range(self.iterations - 1):
                q, p = step(q, target)
                pivot = cs.fmin(pivot, p)
            exprs: list[Expr] = list(self.finish(kernel).call([q, pivot]))
            sym: list[Expr] = [self.q, target]
        elif kernel == "maps":
            exprs, sym = list(self._maps), [self.q]
        else:
            exprs, sym = list(self._delta), [self.q, self.qdo]
        ins, outs = KERNELS[kernel]
        values = cs.cse([cs.densify(cs.SX(e)) for e in exprs])
        return cs.Function(f"{c_identifier(self.name)}_{kernel}", sym, values, list(ins), list(outs))

    @functools.cache  # noqa: B019
    def tangent(self, kernel: str) -> cs.Function:
        """The derivative of a solve's solution by the implicit function theorem (the closure's, at the solution,
        not through the Newton iterations), for ``kernel`` in :data:`SOLVES`: ``(q) -> (dq, dy)``, ``dq = ∂q_out/∂x``
        (nq x k, the configuration's coordinates per target coordinate, column-major) and ``dy = ∂y/∂x`` (k x k) for
        ``fk`` (``x = qm``, ``y = qo``: ``dy`` is ``maps``'s ``J``) and ``ik`` (``x = qo``, ``y = qm``: ``J_inv``); the
        idle motions' coordinates (a rod's spin, which the closure leaves free) held. ``fk_j_dm``'s is ``fk``'s.
        The warm start moves no solution: its derivative is zero."""
        if kernel not in SOLVES:
            raise InvalidInputError("kernel", f"use one of {list(SOLVES)}", kernel)
        at, rows = (self._twin_o, self.motor_q) if kernel == "ik" else (self._twin_m, self.output_q)
        tw = at.tw
        dv = cs.SX.sym("dv", tw.mech.nv)
        E = cs.substitute(cs.jacobian(tw.retract(dv), dv), dv, cs.DM.zeros(tw.mech.nv))  # (dq/dv: nq x nv)
        dq = self._in_q(at, E @ self._rates(at, range(tw.mech.nv)))
        if kernel == "ik":  # (x = qo; y = C q_a)
            dy = self._from_drives(cs.vertcat(*[dq[i, :] for i in rows]))
        else:  # (x = u = C q_a)
            dq = self._per_motor(dq)
            dy = cs.vertcat(*[dq[i, :] for i in rows])
        values = cs.cse([cs.densify(cs.SX(e)) for e in (dq, dy)])
        return cs.Function(f"{c_identifier(self.name)}_{kernel}_tangent", [self.q], values, ["q"], ["dq", "dy"])

    # ---------------------------------------------------------------- evaluation (the C batch, in process)
    @functools.cache  # noqa: B019
    def kernel(self, kernel: str) -> Callable[..., list[np.ndarray]]:
        """``kernel`` compiled (the twin's C batch driver, its vector driver from 256 samples): ``f(*arrays) ->
        outputs``, each an ``(n, nnz)`` array (numpy over samples without a C compiler)."""
        from pkm.core.twin.kernels import _Kernel

        return _Kernel(self.function(kernel), False, True, None, None)

    def run(self, kernel: str, *args: ArrayLike) -> list[np.ndarray]:
        """``kernel`` on a batch (each input ``(n, size)``, or 1-D: the same for every sample) or on one sample
        (every input 1-D): its outputs, ``(n, size)`` each or 1-D (matrices as their column-major nonzeros; a solve's
        status per sample, :data:`STATUS`).

        Raises:
            InvalidInputError: an input of the wrong size, or holding a NaN or an infinity.
        """
        fun = self.function(kernel)
        arrays = []
        for i, x in enumerate(args):
            a = as_array(x, fun.name_in(i))
            if a.ndim not in (1, 2) or a.shape[-1] != fun.nnz_in(i):
                raise InvalidInputError(fun.name_in(i), f"expected ({fun.nnz_in(i)},) or (n, {fun.nnz_in(i)})", x)
            if not np.isfinite(a).all():  # (the C target's INVALID_INPUT)
                raise InvalidInputError(fun.name_in(i), "holds non-finite values", x)
            arrays.append(np.ascontiguousarray(np.atleast_2d(a)))
        if len(arrays) != fun.n_in():
            raise InvalidInputError(kernel, f"takes {fun.n_in()} inputs {fun.name_in()}, got {len(arrays)}")
        outs = self.kernel(kernel)(*arrays)  # (a one-sample input among batches: the same for every sample)
        return [o[0] for o in outs] if all(np.ndim(x) == 1 for x in args) else outs

    def jax(self, kernel: str) -> Callable[..., tuple]:
        """``kernel`` as a jitted JAX function of one sample (:func:`pkm.core.twin.jaxgen.jax_function`; ``jax.vmap``
        for batches). A solve (:data:`SOLVES`) loops over its Newton :meth:`step` (``jax.lax.fori_loop``: XLA
        compiles one iteration, not :attr:`iterations`) and is differentiated by the implicit function theorem
        (:meth:`tangent`), never through its iterations (:data:`JAX_RUNTIME`): ``jax.jacfwd``, ``jax.grad``.

        Raises:
            MissingDependencyError: JAX is not installed (``pip install "pkm-robotics[jax]"``).
        """
        from pkm._optional import module
        from pkm.core.twin.jaxgen import jax_function

        if kernel not in SOLVES:
            return jax_function(self.function(kernel))
        self.function(kernel)  # (an unknown kernel refused; the tangent and the stages built once)
        jax = module("jax", extra="jax", what="TransmissionKernels.jax")
        namespace: dict = {}
        exec(compile(JAX_RUNTIME, "<pkm jax runtime>", "exec"), namespace)  # (the constant source below, no input)
        solve = namespace["newton_loop"](jax, jax.numpy, jax_function(self.step("o" if kernel == "ik" else "m")),
                                         jax_function(self.finish(kernel)), self.iterations)
        extra = [jax_function(self.function(k)) for k in ("maps", "delta")] if kernel == "fk_j_dm" else []
        f = namespace["implicit"](jax, jax.numpy, solve, jax_function(self.tangent(kernel)), *extra)
        ins = KERNELS[kernel][0]

        def run(*args: ArrayLike) -> tuple:
            if len(args) != len(ins):
                raise InvalidInputError(kernel, f"takes {len(ins)} inputs ({', '.join(ins)}), got {len(args)}")
            return f(*args)

        return jax.jit(run)

    def looped(self, kernel: str) -> cs.Function | Loop:
        """``kernel`` as Warp writes it: a solve (:data:`SOLVES`) as a :class:`~pkm.core.twin.warpgen.Loop` over its
        :meth:`step` then its :meth:`finish` (one copy of the step in the source: the battobot ankle's Warp module
        3x smaller: 1.94 -> 0.64 MB), the others their :meth:`function`. The same outputs as :meth:`function`'s, instruction for
        instruction."""
        fun = self.function(kernel)  # (an unknown kernel refused; the stages built once)
        if kernel not in SOLVES:
            return fun
        return Loop(fun.name(), self.step("o" if kernel == "ik" else "m"), self.finish(kernel), self.iterations)

    def warp(self, kernel: str, directory: str | os.PathLike[str] | None = None) -> object:
        """``kernel`` as a Warp kernel (:func:`pkm.core.twin.warpgen.warp_kernel` of :meth:`looped`: a solve loops
        over its Newton step).

        Raises:
            MissingDependencyError: Warp is not installed (``pip install "pkm-robotics[warp]"``).
        """
        from pkm.core.twin.warpgen import warp_kernel

        return warp_kernel(self.looped(kernel), directory)


#: The kernels that solve the closure (Newton from a warm start): :meth:`TransmissionKernels.step` iterated, then
#: :meth:`TransmissionKernels.finish`.
SOLVES = ("fk", "ik", "fk_j_dm")

#: Python source of the JAX side of a solve (:data:`SOLVES`), run by :meth:`TransmissionKernels.jax` and written into
#: the generated JAX module as it is: ``newton_loop(jax, jnp, step, finish, iterations)``, the solve
#: ``(q, x) -> outputs`` with its iterations in ``jax.lax.fori_loop`` (XLA compiles one: the battobot ankle's fk
#: unrolled took 74 s to compile, 10 s so), and ``implicit(jax, jnp, solve, tangent, maps=None, delta=None)``,
#: the solve with its derivative by the implicit function theorem (:meth:`TransmissionKernels.tangent`'s ``dq``,
#: ``dy`` at the solution) instead of through the iterations, which XLA took minutes and gigabytes to differentiate;
#: for ``fk_j_dm``, ``J`` and ``ΔM`` at the solution move with it (``maps``' and ``delta``'s derivative along
#: ``dq``). The warm start's derivative is zero, ``status``' and ``residual``'s too: the derivative is the converged
#: solution's, meaningless where ``status`` is not ``OK``.
JAX_RUNTIME = '''
def newton_loop(jax, jnp, step, finish, iterations):
    """The solve (q, x) -> outputs: step(q, x) -> (q, pivot) iterated, finish(q, smallest pivot) -> outputs."""

    def solve(q, x):
        q, pivot = step(q, x)

        def body(i, carry):
            q, p = step(carry[0], x)
            return q, jnp.fmin(carry[1], p)

        return finish(*jax.lax.fori_loop(1, iterations, body, (q, pivot)))

    return solve


def implicit(jax, jnp, solve, tangent, maps=None, delta=None):
    """solve(q, x) with its derivative by the implicit function theorem at the solution."""

    @jax.custom_jvp
    def f(q, x):
        return solve(q, x)

    @f.defjvp
    def f_jvp(primals, tangents):
        out = solve(*primals)
        dq_dx, dy_dx = tangent(out[0])
        n = jnp.shape(primals[1])[0]  # (the targets; matrices column-major)
        dq = dq_dx.reshape(n, -1).T @ tangents[1]
        dy = dy_dx.reshape(n, n).T @ tangents[1]
        rest = [jnp.zeros_like(o) for o in out[2:]]
        if maps is not None:  # (fk_j_dm: J and dM at the solution)
            rest[0] = jax.jvp(lambda z: maps(z)[0], (out[0],), (dq,))[1]
            rest[1] = jax.jvp(lambda z: delta(z, jnp.zeros(n, out[0].dtype))[0], (out[0],), (dq,))[1]
        return out, (dq, dy, *rest)

    return f
'''


def _independent_rows(A: np.ndarray, rtol: float = 1e-9) -> list[int]:
    """Rows of ``A`` independent (a greedy Gram-Schmidt, the largest remaining row first), in order."""
    rows, chosen = A.astype(float).copy(), list[int]()
    top = float(np.linalg.norm(A, axis=1).max(initial=0.0))
    for _ in range(min(A.shape)):
        norms = np.linalg.norm(rows, axis=1)
        norms[chosen] = -1.0
        i = int(np.argmax(norms))
        if norms[i] <= rtol * top:
            break
        chosen.append(i)
        u = rows[i] / norms[i]
        rows = rows - np.outer(rows @ u, u)
    return sorted(chosen)


def c_identifier(name: str) -> str:
    """``name`` as a C identifier (other characters as ``_``, a leading digit prefixed)."""
    out = "".join(c if c.isalnum() or c == "_" else "_" for c in name)
    return out if out and not out[0].isdigit() else f"t_{out}"


__all__ = ["ITERATIONS", "JAX_RUNTIME", "KERNELS", "MAX_STEP", "RTOL", "SOLVES", "STATUS", "TransmissionKernels", "c_identifier"]
