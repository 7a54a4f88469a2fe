"""The state of one WebSocket stream: actuator samples in, forward kinematics, task rates and efforts out.

Each message is a map with ``qa`` (the actuated coordinates) and optionally ``qd`` (their rates) and ``qdd`` (their
accelerations), read as the HTTP queries read them (:func:`pkm.serve.queries._array`): numbers in SI or strings with
a unit of the entry's kind (``"10deg"``, ``"5mm"``; ``"-30deg/s"``, ``"300rpm"``), one sample; the answer has ``q``
and ``y`` (the configuration and the task value, the loops closed from the previous sample's configuration: a stream
stays on its assembly mode), the closure ``residual``, ``status`` (``"ok"``, or ``"outside_limits"`` where
``outside_limits``, the joints outside the position limits the model states with their values and limits, is not
empty), with ``qd`` the task rates ``yd``, with ``qd`` and ``qdd`` the actuator efforts ``tau`` (``M_a qdd + h_a``),
``compute_s`` and ``units`` (the unit of every quantity answered and given, as the HTTP answers carry them). A refused
message is answered ``{"error", "message"}``, the message naming the field and its units.

Where the mechanism's compiled kernels build (:class:`pkm.Kernels`: a C compiler, no idle motion), a sample is the
kernels' (the closure's Newton warm-started in C, the Jacobian and ``M_a``, ``h_a`` from their generated C), each
checked as the library checks it (a sample the kernels hand back goes to :func:`pkm.close_loops`); otherwise the
library's Python routes.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

import numpy as np

import pkm
from pkm.core.model.mechanism import Mechanism
from pkm.errors import InvalidInputError


class Stream:
    """One stream over ``mech``, warm-started from ``seed`` (default the reference configuration)."""

    def __init__(self, mech: Mechanism, seed: np.ndarray | None = None, kernels: Any = None):
        self.mech = mech
        self.q = mech.q_reference.copy() if seed is None else np.asarray(seed, dtype=float)
        self.kernels = kernels

    def _vector(self, sample: Mapping[str, Any], key: str) -> np.ndarray | None:
        """``sample[key]`` (one sample, units allowed) as the HTTP queries read it; None when absent."""
        from pkm.serve.queries import _input_units, _optional

        a = _optional(sample, key, self.mech.na, _input_units(self.mech, key))
        if a is not None and len(a) != 1:
            raise InvalidInputError(key, f"one sample ({self.mech.na} numbers) a message, not {len(a)}", len(a))
        return None if a is None else a[0]

    def units(self) -> dict[str, Any]:
        """The unit of every quantity of an answer and of a message (SI, per entry)."""
        from pkm.serve.queries import _actuated_units, _q_units, _rates, _task_units, _value_units

        return {"q": _q_units(self.mech), "y": _value_units(self.mech), "residual": "m or rad",
                "yd": _rates(list(_task_units(self.mech).values())), "tau": _actuated_units(self.mech, "effort"),
                "qa": _actuated_units(self.mech), "qd": _actuated_units(self.mech, "rate"),
                "qdd": _actuated_units(self.mech, "acceleration"), "compute_s": "s"}

    def step(self, sample: Any) -> dict[str, Any]:
        """The answer to one message (see the module doc).

        Raises:
            InvalidInputError: a malformed message; ConvergenceError and the other solve errors of
                :func:`pkm.close_loops` (the stream keeps its last configuration).
        """
        from pkm.core.differential.velocity import forward_jacobian
        from pkm.core.dynamics.model import actuator_model
        from pkm.core.kinematics import constraints
        from pkm.core.kinematics.solve import close_loops
        from pkm.core.twin.kernels import PIVOT_FLOOR

        if not isinstance(sample, Mapping):
            raise InvalidInputError("message", "a map with qa (and qd, qdd)", str(sample)[:100])
        t0 = time.perf_counter()
        qa = self._vector(sample, "qa")
        if qa is None:
            raise InvalidInputError("qa", f"missing: give {self.mech.na} numbers")
        qd, qdd = self._vector(sample, "qd"), self._vector(sample, "qdd")
        K = self.kernels
        q = residual = None
        if K is not None:  # (the kernels called directly: a stream's samples are checked here, one at a time)
            q_k, r_k, p_k, _ = K.kernel("closure_newton").follow(self.q, qa[None], 10, 1e-12)
            if r_k[0] <= 1e-12 and p_k[0] >= PIVOT_FLOOR and np.all(np.isfinite(q_k[0])):
                q, residual = q_k[0], float(constraints.largest(self.mech, q_k[0])[0])  # (m or rad, as close_loops')
        if q is None:
            r = close_loops(self.mech, qa, self.q)
            q, residual = r.q, r.residual
        self.q = q
        outside = [v._asdict() for v in self.mech.limit_violations(q)]
        out: dict[str, Any] = {"q": q, "y": pkm.TaskMap.of(self.mech).value(q), "residual": residual,
                               "status": "outside_limits" if outside else "ok", "outside_limits": outside}
        if qd is not None:
            if K is not None:
                J = K.kernel("forward_jacobian")(q[None])[0].reshape(-1, self.mech.na, order="F")
            else:
                J = forward_jacobian(self.mech, q)
            out["yd"] = J @ qd
            if qdd is not None:
                tau = None
                if K is not None and self.mech.base is None:  # (the kernels hold a floating base; the model frees it)
                    t_k, p_k = K.kernel("inverse_dynamics")(q[None], qd[None], qdd[None])
                    tau = t_k[0] if p_k[0, 0] >= PIVOT_FLOOR and np.all(np.isfinite(t_k[0])) else None
                if tau is None:
                    m = actuator_model(self.mech, q, qd)
                    tau = m.M @ qdd + m.h
                out["tau"] = tau
        out["compute_s"] = time.perf_counter() - t0
        out["units"] = self.units()
        return out


def kernels_for(mech: Mechanism) -> Any:
    """The compiled kernels a stream over ``mech`` uses, built and compiled now (None where they do not build: no
    C compiler, idle motions)."""
    from pkm.core.twin import Kernels
    from pkm.errors import PkmError

    try:
        K = Kernels(mech)
        for name in ("closure_newton", "forward_jacobian", "inverse_dynamics"):
            if K.kernel(name).lib is None:
                return None
        return K
    except PkmError:
        return None


__all__ = ["Stream", "kernels_for"]
