"""Generated kernels of any mechanism: its twin's expressions as functions, compiled to C, run on one state, on numpy
batches and warm-started along paths.

:class:`Kernels` builds each kernel on first use from :class:`~pkm.core.twin.tree.Twin` (expressions after
common-subexpression elimination), compiles it with :func:`~pkm.core.twin.codegen.compile_library` when a C compiler
is present (:attr:`Kernels.how` says, per kernel, what runs it); otherwise batches run as numpy vectorised over
the samples (one numpy statement per instruction) and single samples on CasADi's virtual machine. Every kernel
takes and returns SI values in Pinocchio's conventions.

The linear solves use pivots fixed at the reference (:mod:`~pkm.core.twin.linear`). Where the smallest relative
pivot falls under :data:`PIVOT_FLOOR`, the kernel's answer for that sample is replaced by the generic core's
(:func:`pkm.inverse_dynamics`, :func:`pkm.close_loops`, :func:`pkm.solve_ik`) and the sample is listed in the
result's ``fallback``; a path sample that does not converge in the kernel is handed to the core the same way.

The actuator-space model (:mod:`pkm.core.dynamics.model`, expressions in :mod:`~pkm.core.twin.dynamics`):
:meth:`Kernels.mass_matrix` (``M_a``), :meth:`Kernels.bias` (``h_a``), :meth:`Kernels.gravity` (``g_a``),
:meth:`Kernels.mass_and_bias` (both from one fused kernel: what a simulation or a controller needs per state; 0.24 µs
a sample for the 3-PRS and 0.32 µs for the Delta in a C batch, ``pkm bench simulation_speed``) and
:meth:`Kernels.forward_dynamics` (``qdd_a``, the joints' viscous and Coulomb friction optional, Coulomb's sign
smoothed as ``tanh(v / COULOMB_VELOCITY)``); idle motions are handled as :func:`pkm.actuator_model` handles them,
reflected rotor inertias (Pinocchio's ``armature``) are in the twin's RNEA, and a sample under the pivot floor is
:func:`pkm.actuator_model`'s. The compiled simulation built on them is :mod:`~pkm.core.twin.simulation`.

Speed (issue 33): ``Kernels(mech, design=[...])`` takes joint origins and inertial parameters as every kernel's
last input (:mod:`~pkm.core.twin.design`; :meth:`Kernels.at` binds a design), so that one compiled library serves a
whole family of designs; compiled batches of :data:`VECTOR_SAMPLES` samples or more run on the vector units
(:mod:`~pkm.core.twin.simd`, bit for bit the scalar driver) and are split over ``threads`` cores;
:meth:`Kernels.jax` gives any kernel as a JAX function (:mod:`~pkm.core.twin.jaxgen`).
"""

from __future__ import annotations

import copy
import ctypes
import functools
import itertools
import os
import threading
import weakref
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import casadi as cs
import numpy as np
from numpy.typing import ArrayLike

from pkm.core.dynamics.model import COULOMB_VELOCITY
from pkm.core.model.mechanism import LimitViolation, Mechanism, check_mechanism
from pkm.core.model.plausibility import require_physical
from pkm.core.twin.codegen import C_INT as _I
from pkm.core.twin.codegen import C_REAL_P as _P
from pkm.core.twin.codegen import compile_library, numpy_function, pointers
from pkm.core.twin.dynamics import ActuatorTwin
from pkm.core.twin.task import TaskTwin
from pkm.core.twin.tree import Twin
from pkm.errors import InvalidInputError, NonFiniteError
from pkm.validation import as_array, as_count, as_scalar, as_tolerance, bounded

if TYPE_CHECKING:
    from pkm.core.kinematics.solve import SolveResult

#: Smallest relative pivot (:meth:`PivotedLU.smallest_relative_pivot`) at which a kernel's solve is trusted.
PIVOT_FLOOR = 1e-6
#: A compiled batch of at least twice this many samples runs on every core, in chunks (threads; the C is re-entrant).
THREAD_SAMPLES = 2048
#: A compiled batch of at least this many samples runs the kernel's vector driver (:mod:`~pkm.core.twin.simd`:
#: several samples a vector instruction, bit for bit the scalar driver's), compiled on the first such batch; a
#: smaller one the scalar driver (the vector library's compile is not worth it for a few samples).
VECTOR_SAMPLES = 256
#: By default (``vector=None``) only kernels of at most this many instructions take the vector driver: their vector
#: library compiles in under a second (the hexapod's efforts, 3,478: 0.6 s); a larger one's takes seconds to tens of
#: seconds (the Gough-Stewart's regressor, 9,322: 11 s), repaid only by batches of millions of samples (about 0.1 ns
#: saved an instruction a sample): ``vector=True`` asks for it.
VECTOR_INSTRUCTIONS = 4000



@dataclass(frozen=True)
class OperationCount:
    """The operations of one kernel's main output after common-subexpression elimination, counted as the papers
    and SYMORO count: ``*``, ``/``, squares and doublings as multiplications, ``+ -`` as additions, negations free;
    every other operation apart, in ``functions`` (``sin``, ``cos``, ``sqrt``, ``atan2``, ...).

    Attributes:
        kernel: Which kernel (:data:`KERNELS`).
        mul: Multiplications and divisions.
        add: Additions and subtractions.
        functions: Count per other operation.
        boundary: What the count covers, in words (:data:`BOUNDARIES`).
    """

    kernel: str
    mul: int
    add: int
    functions: dict
    boundary: str


#: What each counted kernel covers.
BOUNDARIES = {
    "inverse_dynamics": (
        "in: a closed configuration q (nq numbers) and the actuated rates and accelerations (na each); out: the na "
        "actuator efforts. Included: every joint's placement, velocity and acceleration, the closure Jacobian and "
        "drift, the passive rates and accelerations (sparse LU, pivots fixed at the reference), RNEA with gravity "
        "and the projection (one transposed solve). Not included: the position-level loop closure (a Newton "
        "iteration is counted apart), an external wrench. Inertial parameters and geometry numeric (the model's)."),
    "closure_newton": (
        "in: q (nq) and the actuated coordinates (na); out: the next Newton iterate (nq). Included: forward "
        "kinematics, closure residual and Jacobian, the sparse LU and solve, the retraction; not the convergence test."),
}


@dataclass(frozen=True)
class PathResult:
    """A warm-started Newton solve along a path of targets.

    Attributes:
        q: The configurations (n x nq).
        residual: The largest closure residual (and task error, for the IK) at each (n), lengths counted in the
            characteristic length ``L`` and angles in rad (:attr:`pkm.core.kinematics.solve.SolveResult.relative_residual`,
            what ``tol`` bounds: the same iterations and verdicts for a copy scaled in size).
        iterations: Newton iterations per sample in the kernel (n).
        fallback: The samples solved by the generic core instead (pivot under :data:`PIVOT_FLOOR`, or no
            convergence in ``max_iter`` kernel iterations).
        how: What ran the kernel.
        outside_limits: Per joint that leaves the position limits the model states, the first sample outside and
            there its violation (:meth:`pkm.core.Mechanism.limits_along`; pkm's solvers report limits, they do not
            enforce them).
    """

    q: np.ndarray
    residual: np.ndarray
    iterations: np.ndarray
    fallback: tuple[int, ...] = field(default=())
    how: str = ""
    outside_limits: tuple[tuple[int, LimitViolation], ...] = ()


@functools.lru_cache(maxsize=1)
def _pool() -> ThreadPoolExecutor:
    """The threads compiled batches are split over (one a core, started once: starting them per call costs a
    millisecond, a third of a 100,000-sample batch of the 3-PRS on two cores); a forked child starts its own."""
    return ThreadPoolExecutor(_cores(), thread_name_prefix="pkm-kernels")


def _cores() -> int:
    """The cores this process may run on (its affinity, where the system tells it)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


if hasattr(os, "register_at_fork"):  # (a fork's child has none of the parent's threads: its pool would hang)
    os.register_at_fork(after_in_child=_pool.cache_clear)


def _steps_driver(lib: ctypes.CDLL, name: str) -> Callable[..., int]:
    """A driver ``(n, in, out, steps)`` of ``lib`` (:mod:`~pkm.core.twin.codegen`, :mod:`~pkm.core.twin.simd`)."""
    driver = getattr(lib, name)
    driver.argtypes = [_I, ctypes.POINTER(_P), ctypes.POINTER(_P), ctypes.POINTER(_I)]
    driver.restype = ctypes.c_int
    return driver


class _Kernel:
    """One function, compiled (``lib``) or not; ``__call__`` takes sample-major arrays (n x size) and returns a list
    of sample-major outputs: the C batch driver when compiled (the vector driver from :data:`VECTOR_SAMPLES`
    samples when ``vector``; split over ``threads`` cores, default all, from ``2 THREAD_SAMPLES``), else numpy
    vectorised over the samples (:func:`~pkm.core.twin.codegen.numpy_function`; CasADi's virtual machine for one
    sample)."""

    def __init__(self, fun: cs.Function, follow: bool, compiled: bool, directory: str | os.PathLike[str] | None,
                 vector: bool | None = None, threads: int | None = None):
        self.fun, self.directory, self.threads = fun, directory, threads
        self.vector = vector if vector is not None else fun.n_instructions() <= VECTOR_INSTRUCTIONS
        self._simd: Callable[..., int] | None = None
        self._simd_lock = threading.Lock()
        self.lib, self.how = compile_library(fun, follow=follow, directory=directory) if compiled else (
            None, "compiled=False")
        self.in_size = [fun.nnz_in(i) for i in range(fun.n_in())]
        self.out_size = [fun.nnz_out(i) for i in range(fun.n_out())]
        if self.lib is None:
            self.how = f"numpy over samples, CasADi's virtual machine for one ({self.how})"
            self._numpy = numpy_function(fun)
            return
        self._batch = getattr(self.lib, f"{fun.name()}_batch")
        self._batch.argtypes = [_I, ctypes.POINTER(_P), ctypes.POINTER(_P)]
        self._batch.restype = ctypes.c_int
        self._batch_steps = _steps_driver(self.lib, f"{fun.name()}_batch_steps")
        if follow:
            self._follow = getattr(self.lib, f"{fun.name()}_follow")
            self._follow.argtypes = [_I, _P, _P, _P, _P, _P, ctypes.POINTER(_I), _I, ctypes.c_double, _P]
            self._follow.restype = ctypes.c_int
        self._one = threading.local()  # (one sample: each thread's buffers, the C call releasing the GIL)

    def _buffers(self) -> tuple[list[np.ndarray], list[np.ndarray], object, object]:
        """This thread's fixed buffers and pointer arrays for one sample, so that a call costs a copy in and out."""
        one = self._one
        if not hasattr(one, "bufs"):
            ins, outs = [np.zeros(n) for n in self.in_size], [np.zeros(n) for n in self.out_size]
            one.bufs = (ins, outs, pointers(ins), pointers(outs))
        return one.bufs

    def __call__(self, *arrays: np.ndarray) -> list[np.ndarray]:
        """The kernel on ``n`` samples; an input of one row among inputs of ``n`` is the same for every sample (a
        design: read in place, not copied ``n`` times)."""
        n = max(a.shape[0] for a in arrays)
        if self.lib is None:
            if n > 1:
                arrays = tuple(np.broadcast_to(a, (n, a.shape[1])) for a in arrays)
            if n == 1:
                outs = self.fun(*[a[0] for a in arrays])
                outs = outs if isinstance(outs, tuple) else (outs,)
                return [np.array(o).reshape(1, -1, order="F") for o in outs]
            return self._numpy(*arrays)
        if n == 1:
            ins1, outs1, in_p1, out_p1 = self._buffers()
            for buf, a in zip(ins1, arrays):
                buf[:] = a[0]
            if self._batch(1, in_p1, out_p1):
                raise RuntimeError(f"the compiled kernel {self.fun.name()} failed")
            return [o[None].copy() for o in outs1]
        ins = [np.ascontiguousarray(a, dtype=float) for a in arrays]
        constant = [a.shape[0] == 1 for a in ins]
        steps = np.array([0 if c else size for c, size in zip(constant, self.in_size)], dtype=np.int64)
        steps_p = steps.ctypes.data_as(ctypes.POINTER(_I))
        outs = [np.empty((n, s)) for s in self.out_size]
        workers = min(self.threads or _cores(), n // THREAD_SAMPLES)
        bounds = np.linspace(0, n, max(workers, 1) + 1).astype(int)
        driver = self._vector_driver() if self.vector and n >= VECTOR_SAMPLES else self._batch_steps

        def part(lo: int, hi: int) -> int:  # (ctypes releases the GIL: the chunks run on as many cores)
            in_p = pointers(a if c else a[lo:] for a, c in zip(ins, constant))
            return int(driver(hi - lo, in_p, pointers(o[lo:] for o in outs), steps_p))

        if workers > 1:  # (the last chunk on this thread)
            others = [_pool().submit(part, lo, hi) for lo, hi in itertools.pairwise(bounds[:-1])]
            failed = bool(part(bounds[-2], bounds[-1])) | any(f.result() for f in others)
        else:
            failed = bool(part(0, n))
        if failed:
            raise RuntimeError(f"the compiled kernel {self.fun.name()} failed")
        return outs

    def _vector_driver(self) -> Callable[..., int]:
        """The vector driver (:func:`~pkm.core.twin.simd.simd_library`, compiled on first use), or the scalar one
        where it does not compile (:attr:`how` says why)."""
        if self._simd is not None:
            return self._simd
        with self._simd_lock:  # (compiled once, whichever thread asks first)
            if self._simd is None:
                from pkm.core.twin.simd import simd_library

                lib, how = simd_library(self.fun, self.directory)
                self.how += f"; batches of {VECTOR_SAMPLES} or more: " + (
                    f"the vector driver ({how})" if lib is not None else f"scalar (no vector driver: {how})")
                self._simd = self._batch_steps if lib is None else _steps_driver(lib, f"{self.fun.name()}_simd_steps")
            return self._simd

    def follow(self, q0: np.ndarray, targets: np.ndarray, max_iter: int, tol: float,
               design: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        n, nq = targets.shape[0], q0.shape[0]
        extra = () if design is None else (design,)
        if self.lib is None:
            q, out = q0.copy(), (np.empty((n, nq)), np.empty(n), np.empty(n), np.zeros(n, dtype=np.int64))
            for k in range(n):
                it = 0
                while True:
                    nxt, r, p = self.fun(q, targets[k], *extra)
                    q, it = np.array(nxt).ravel(), it + 1
                    if float(r) <= tol or it >= max_iter or not np.isfinite(float(r)):
                        break
                out[0][k], out[1][k], out[2][k], out[3][k] = q, float(r), float(p), it
            return out
        q_out, res, piv = np.empty((n, nq)), np.empty(n), np.empty(n)
        its = np.zeros(n, dtype=np.int64)
        t = np.ascontiguousarray(targets, dtype=float)
        q0 = np.ascontiguousarray(q0, dtype=float)
        flag = self._follow(n, q0.ctypes.data_as(_P), t.ctypes.data_as(_P), q_out.ctypes.data_as(_P),
                            res.ctypes.data_as(_P), piv.ctypes.data_as(_P), its.ctypes.data_as(ctypes.POINTER(_I)),
                            max_iter, tol, None if design is None else np.ascontiguousarray(design, dtype=float
                                                                                            ).ctypes.data_as(_P))
        if flag:
            raise RuntimeError(f"the compiled kernel {self.fun.name()} failed")
        return q_out, res, piv, its


class Kernels:
    """The generated kernels of ``mech`` (see the module doc).

    Args:
        mech: Any mechanism pkm loads, without idle motions for the kernels of the passive solve (``velocities``,
            ``accelerations``, ``inverse_dynamics``, ``closure_newton``...); the actuator-space model's take them, and
            so do the task's (``ik_newton``, ``inverse_jacobian``, ``inverse_rates``, the maps'), one coordinate per
            idle motion held (:func:`~pkm.core.twin.dynamics.idle_columns`, as the exported C holds it).
        design: Design parameters taken as kernel inputs (:mod:`~pkm.core.twin.design`: ``JOINT.x`` ...
            ``JOINT.yaw``, ``BODY.m`` ... ``BODY.Izz``): every kernel takes a last input ``design`` and one compiled
            library serves every design; :meth:`at` binds a design. Default none: the file's numbers are constants.
        compiled: Compile to C when a C compiler is present (default); False runs numpy (batches) and CasADi's
            virtual machine (one sample).
        directory: Where compiled libraries go (default :func:`pkm.core.twin.codegen.cache_dir`).
        vector: Run compiled batches of :data:`VECTOR_SAMPLES` or more on the vector units
            (:mod:`~pkm.core.twin.simd`; bit for bit the scalar driver's): True for every kernel, None (default)
            for kernels of at most :data:`VECTOR_INSTRUCTIONS` instructions, False never.
        threads: Cores a compiled batch of ``2 THREAD_SAMPLES`` or more is split over (default: every core).

    Raises:
        SpecError: ``mech`` has idle motions (on the first kernel that needs the passive solve).
        UnknownNameError: a design parameter ``mech`` does not have (the error lists those it has).

    Examples:
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> K = pkm.Kernels(delta)
        >>> q = pkm.solve_ik(delta, [0.02, 0.0, -0.36]).q
        >>> np.allclose(K.forward_jacobian(q), pkm.forward_jacobian(delta, q))
        True
    """

    def __init__(self, mech: Mechanism, *, design: Sequence[str] | None = None, compiled: bool = True,
                 directory: str | os.PathLike[str] | None = None, vector: bool | None = None,
                 threads: int | None = None):
        self.mech = check_mechanism(mech)
        self.twin = Twin(self.mech, design)
        #: The design parameters (:class:`~pkm.core.twin.design.Design`; empty: none).
        self.design = self.twin.design
        self.compiled, self.directory = compiled, directory
        if vector is not None and not isinstance(vector, (bool, np.bool_)):
            raise InvalidInputError("vector", "expected True, False or None", vector)
        self.vector = None if vector is None else bool(vector)
        self.threads = None if threads is None else as_count(threads, "threads", high=1024)
        self._kernels: dict[str, _Kernel] = {}
        self._shared: dict[object, object] = {}
        self._lock = threading.RLock()  # (the kernels and what they share, built once whichever thread asks first)
        self._p = self.design.base

    def at(self, design: Mapping[str, float] | ArrayLike, mech: Mechanism | None = None) -> Kernels:
        """These kernels (the same compiled libraries) evaluated at one design: ``design`` by name (the others at
        the file's values) or as the whole vector of :attr:`design`'s parameters. ``mech`` is that design's
        mechanism, which the fallbacks (samples under the pivot floor) and the paths' default start use; default
        :func:`~pkm.core.twin.design.design_mechanism` (built here: a URDF read and an assembly). The view shares
        the compiled kernels: each thread may call its own views."""
        if not len(self.design):
            raise InvalidInputError("design", "these kernels take no design inputs: build them with "
                                              "Kernels(mech, design=[names])", design)
        view = copy.copy(self)
        view._p = self.design.vector(design)
        if mech is None:
            from pkm.core.twin.design import design_mechanism

            mech = design_mechanism(self.mech, dict(zip(self.design.names, view._p)))
        view.mech = check_mechanism(mech)
        return view

    @property
    def design_values(self) -> np.ndarray:
        """The design the kernels are evaluated at (:meth:`at`; the file's by default)."""
        return self._p.copy()

    def inputs(self, name: str) -> tuple[str, ...]:
        """The inputs of kernel ``name`` (:data:`KERNELS`, then ``design`` when the kernels take one: all but the
        regressor's)."""
        return KERNELS[name][0] + (("design",) if len(self.design) and name != "regressor" else ())

    # ---------------------------------------------------------------- kernels
    def function(self, name: str) -> cs.Function:
        """The CasADi function of a kernel (:data:`KERNELS`), inputs and outputs dense, after CSE: built once per
        mechanism and design parameters, whichever of its :class:`Kernels` asks (compiled or not, any ``threads``)."""
        if not isinstance(name, str) or name not in KERNELS:
            raise InvalidInputError("kernel", f"use one of {sorted(KERNELS)}", name)
        built = _FUNCTIONS.setdefault(self.twin.mech, {})  # (a design view's: the twin's, shared)
        key = (tuple(self.design.names), name)
        if key not in built:
            built[key] = self._function(name)
        return built[key]

    def _function(self, name: str) -> cs.Function:
        tw, tk = self.twin, TaskTwin.of(self.twin)
        if name == "regressor":  # (a twin of its own: the bodies' parameters as symbols)
            from pkm.core.twin.regressor import regressor_function

            if len(self.design):
                raise InvalidInputError("kernel", "the regressor is linear in the inertial parameters already; "
                                                  "take it from Kernels(mech) of each design", name)
            return regressor_function(self.mech)
        inputs, outputs = KERNELS[name]
        exprs = {"inverse_dynamics": lambda: {"tau": tw.inverse_dynamics,
                                              "pivot": tw.passive_lu.smallest_relative_pivot()},
                 "inverse_dynamics_derivatives": lambda: {"tau": tw.inverse_dynamics,
                                                          **tw.inverse_dynamics_derivatives},
                 "velocities": lambda: {"v": tw.velocities},
                 "accelerations": lambda: {"a": tw.accelerations},
                 "forward_jacobian": lambda: {"J": tk.forward_jacobian},
                 "inverse_jacobian": lambda: {"J": tk.inverse_jacobian},
                 "inverse_rates": lambda: tk.inverse_rates,
                 "closure_newton": lambda: tw.closure_newton, "ik_newton": lambda: tk.ik_newton,
                 "map_newton": lambda: tk.map_newton, "map_newton_qr": lambda: tk.map_newton_qr,
                 "map_indices": lambda: tk.map_indices,
                 "mass_matrix": lambda: {"M": self.dynamics.mass_matrix, "pivot": self.dynamics.pivot},
                 "bias": lambda: {"h": self.dynamics.bias, "pivot": self.dynamics.pivot},
                 "gravity": lambda: {"g": self.dynamics.gravity, "pivot": self.dynamics.pivot},
                 "mass_and_bias": lambda: {"M": self.dynamics.mass_matrix, "h": self.dynamics.bias,
                                           "pivot": self.dynamics.pivot},
                 "forward_dynamics": lambda: self.dynamics.forward_dynamics,
                 }[name]()
        assert tuple(exprs) == outputs
        sym = {"q": tw.q, "v": tw.v, "qd": tw.qd, "qdd": tw.qdd, "target": tw.target, "y": tk.task_target,
               "scale": tk.scale, "design": tw.p}
        if name == "inverse_rates":
            sym.update(zip(("yd", "ydd"), tk.task_rates))
        inputs = self.inputs(name)
        if name in _DYNAMICS:
            sym.update(tau=self.dynamics.tau, friction=self.dynamics.friction)
        values = cs.cse([cs.densify(cs.SX(e)) for e in exprs.values()])
        fun_name = f"pkm_{name}" + ("_design" if len(self.design) else "")
        return cs.Function(fun_name, [sym[i] for i in inputs], values, list(inputs), list(outputs))

    def jax(self, name: str, *, x64: bool = True) -> Callable[..., tuple]:
        """Kernel ``name`` as a jitted JAX function of one sample (:mod:`pkm.core.twin.jaxgen`, pkm's own
        translation of the twin; built once per kernel): inputs as :meth:`inputs` names them (the design last,
        where the kernels take one: pass :attr:`design_values` or any design, a JAX array like the others), each a
        1-D array of nonzeros, outputs likewise (column-major); ``jax.vmap`` maps it over a batch,
        ``jax.grad`` and ``jax.jacfwd`` differentiate it, on whatever device JAX runs (a GPU where it has one).
        Equal to the compiled C to 1e-12 in double precision (``x64``: JAX's 64-bit mode turned on, process-wide).
        The samples under the pivot floor are not redone here: the kernels that solve return the pivot (the last
        output); mask on it.

        Raises:
            MissingDependencyError: JAX is not installed (``pip install "pkm-robotics[jax]"``).
        """
        from pkm.core.twin.jaxgen import jax_function

        if not isinstance(name, str) or name not in KERNELS:
            raise InvalidInputError("kernel", f"use one of {sorted(KERNELS)}", name)
        return self.cached(("jax", name, x64), lambda: jax_function(self.function(name), x64=x64))  # type: ignore

    @functools.cached_property
    def dynamics(self) -> ActuatorTwin:
        """The actuator-space model's expressions (:class:`~pkm.core.twin.dynamics.ActuatorTwin`; idle motions
        handled)."""
        return ActuatorTwin(self.twin)

    def kernel(self, name: str) -> _Kernel:
        """The kernel ``name`` (built, and compiled, on first use)."""
        if name not in self._kernels:
            with self._lock:
                if name not in self._kernels:
                    self._kernels[name] = _Kernel(self.function(name), name in _PATHS, self.compiled,
                                                  self.directory, self.vector, self.threads)
        return self._kernels[name]

    def cached(self, key: object, make: Callable[[], object]) -> object:
        """``make()`` once for these kernels and every design bound to them (:meth:`at`): a compiled library of
        several kernels (the maps' grid driver)."""
        if key not in self._shared:
            with self._lock:
                if key not in self._shared:
                    self._shared[key] = make()
        return self._shared[key]

    @property
    def how(self) -> dict[str, str]:
        """What runs each kernel built so far."""
        return {k: v.how for k, v in self._kernels.items()}

    def operation_count(self, name: str = "inverse_dynamics") -> OperationCount:
        """The operations of the kernel's main output (``tau``, ``q_next``) after CSE: see :class:`OperationCount`."""
        from pkm.core.twin.codegen import paper_counts

        if not isinstance(name, str) or name not in BOUNDARIES:
            raise InvalidInputError("kernel", f"operation counts are stated for {sorted(BOUNDARIES)}", name)
        fun = self.function(name)
        args = fun.sx_in()
        mul, add, counts = paper_counts(cs.Function("count", args, cs.cse([fun.call(args)[0]])))
        return OperationCount(name, mul, add, counts, BOUNDARIES[name])

    # ---------------------------------------------------------------- evaluation
    def _run(self, name: str, *args: ArrayLike, pivoted: bool = False) -> tuple[list[np.ndarray], bool]:
        """The kernel on one sample (each input 1-D) or a batch (each 2-D, the same length); a non-finite output
        is diagnosed: non-finite input (:class:`InvalidInputError`) or a failed evaluation (:class:`NonFiniteError`;
        with ``pivoted``, only at samples whose pivot, the last output, is above the floor: the others are the
        caller's to redo)."""
        if name in _DYNAMICS or name.startswith("inverse_dynamics"):  # (a design's own inertias: Kernels.at)
            require_physical(self.mech, f"the compiled {name.replace('_', ' ')}")
        kernel = self._kernels.get(name) or self.kernel(name)
        arrays = []
        for what, size, x in zip(KERNELS[name][0], kernel.in_size, args):
            a = x if type(x) is np.ndarray and x.dtype == np.float64 else as_array(x, what)
            if a.ndim not in (1, 2) or a.shape[-1] != size:
                raise InvalidInputError(what, f"expected ({size},) or (n, {size})", x)
            arrays.append(bounded(a, what, x) if what == "q" else a)  # (a configuration: the coordinates' rule)
        single = arrays[0].ndim == 1
        if any((a.ndim == 1) != single for a in arrays):
            raise InvalidInputError(name, "give every input as one sample or every input as a batch")
        if single:
            arrays = [a[None] for a in arrays]
        elif len({a.shape[0] for a in arrays}) > 1:
            raise InvalidInputError(name, f"batches of different lengths {[a.shape[0] for a in arrays]}")
        if len(self.design):
            arrays.append(self._p[None])  # (one row: the same design for every sample, read in place)
        outs = kernel(*arrays)
        if not np.isfinite(outs[0]).all():
            for what, a in zip(KERNELS[name][0], arrays):
                if not np.isfinite(a).all():
                    raise InvalidInputError(what, "holds non-finite values")
            if pivoted and np.isfinite(outs[0][outs[-1][:, 0] >= PIVOT_FLOOR]).all():
                return outs, single
            raise NonFiniteError(f"kernel {name}", outs[0], "non-finite values at finite inputs (a singular state?)")
        return outs, single

    def _shaped(self, name: str, outs: list[np.ndarray], single: bool) -> list[np.ndarray]:
        fun = self.kernel(name).fun
        shaped = []
        for i, o in enumerate(outs):
            r, c = fun.size_out(i)
            x = o.reshape(-1, c, r).transpose(0, 2, 1) if c > 1 else o
            shaped.append(x[0] if single else x)
        return shaped

    def inverse_dynamics(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> np.ndarray:
        """Actuator efforts (na, or n x na) at closed configurations ``q`` (nq or n x nq) for actuated rates and
        accelerations ``qd, qdd`` (na or n x na) [N, N m]: :attr:`Twin.inverse_dynamics`, samples under the pivot
        floor recomputed by :func:`pkm.inverse_dynamics`. Under redundant actuation (the efforts not unique) the same
        distribution as :func:`pkm.inverse_dynamics`: ``Gᵀ h`` with the core's homogenised pseudo-inverse, the
        closure multipliers of least norm (:attr:`Twin.passive_solve`)."""
        (tau, pivot), single = self._run("inverse_dynamics", q, qd, qdd, pivoted=True)
        if not pivot.min() >= PIVOT_FLOOR:
            bad = np.flatnonzero(~(pivot[:, 0] >= PIVOT_FLOOR))
            from pkm.core.differential.velocity import accelerations, velocities
            from pkm.core.dynamics.projection import inverse_dynamics

            Q, QD, QDD = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, qd, qdd))
            for k in bad:
                v = velocities(self.mech, Q[k], QD[k])
                tau[k] = inverse_dynamics(self.mech, Q[k], v, accelerations(self.mech, Q[k], v, QDD[k]))
        return tau[0] if single else tau

    def regressor(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike,
                  fallback: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray] | None = None) -> np.ndarray:
        """The regressor ``Y_a`` (na x p, or n x na x p) at closed configurations ``q`` for actuated rates and
        accelerations (:mod:`pkm.core.twin.regressor`; columns as :func:`pkm.regressor`'s); samples under the pivot
        floor are recomputed by ``fallback(q, qd, qdd)`` (:func:`pkm.regressor`, as :func:`pkm.regressor_batch`
        passes it), or are NaN without one."""
        (Yt, pivot), single = self._run("regressor", q, qd, qdd, pivoted=True)
        Y = Yt.reshape(len(Yt), self.mech.na, -1)  # (Yt's column-major nonzeros: Y row-major, no copy)
        Y = Y[0] if single else Y
        if not pivot.min() >= PIVOT_FLOOR:
            Q, QD, QDD = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, qd, qdd))
            Yb = Y[None] if single else Y
            for k in np.flatnonzero(~(pivot[:, 0] >= PIVOT_FLOOR)):
                Yb[k] = np.nan if fallback is None else fallback(Q[k], QD[k], QDD[k])
        return Y

    def inverse_dynamics_derivatives(self, q: ArrayLike, qd: ArrayLike, qdd: ArrayLike) -> dict[str, np.ndarray]:
        """``tau`` and its derivatives ``dtau_dqa`` (along the closure), ``dtau_dqd``, ``dtau_dqdd`` (na x na each, or
        n x na x na) at closed configurations (see :attr:`Twin.inverse_dynamics_derivatives`)."""
        outs, single = self._run("inverse_dynamics_derivatives", q, qd, qdd)
        return dict(zip(KERNELS["inverse_dynamics_derivatives"][1], self._shaped("inverse_dynamics_derivatives",
                                                                                 outs, single)))

    def velocities(self, q: ArrayLike, qd: ArrayLike) -> np.ndarray:
        """All joint rates (nv) for actuated rates ``qd`` at closed configurations ``q``."""
        outs, single = self._run("velocities", q, qd)
        return outs[0][0] if single else outs[0]

    def accelerations(self, q: ArrayLike, v: ArrayLike, qdd: ArrayLike) -> np.ndarray:
        """All joint accelerations (nv) at ``(q, v)`` for actuated accelerations ``qdd``."""
        outs, single = self._run("accelerations", q, v, qdd)
        return outs[0][0] if single else outs[0]

    def forward_jacobian(self, q: ArrayLike) -> np.ndarray:
        """Task rates per actuated rate (task size x na) at closed configurations."""
        outs, single = self._run("forward_jacobian", q)
        return self._shaped("forward_jacobian", outs, single)[0]

    def inverse_jacobian(self, q: ArrayLike) -> np.ndarray:
        """Actuated rates per task rate (na x task size) at closed configurations."""
        outs, single = self._run("inverse_jacobian", q)
        return self._shaped("inverse_jacobian", outs, single)[0]

    def inverse_rates(self, q: ArrayLike, yd: ArrayLike, ydd: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """The joint rates ``v`` (nv, or n x nv) and the actuated accelerations (na, or n x na) for task rates and
        accelerations ``yd, ydd`` (task size, or n x task size) at closed configurations ``q``: the actuated entries
        as :func:`pkm.inverse_velocities` and :func:`pkm.inverse_accelerations` give them, exactly
        (:attr:`~pkm.core.twin.task.TaskTwin.inverse_rates`); the idle coordinates (one per idle motion) at zero
        rate, where the core's carry no idle motion in the mass metric. Samples under the pivot floor are the
        core's (then ``v`` in the core's convention)."""
        (v, qdd, pivot), single = self._run("inverse_rates", q, yd, ydd, pivoted=True)
        if not pivot.min() >= PIVOT_FLOOR:
            from pkm.core.differential.velocity import inverse_accelerations, inverse_velocities

            Q, YD, YDD = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, yd, ydd))
            for k in np.flatnonzero(~(pivot[:, 0] >= PIVOT_FLOOR)):
                v[k] = inverse_velocities(self.mech, Q[k], YD[k])
                qdd[k] = inverse_accelerations(self.mech, Q[k], v[k], YDD[k])[self.mech.act_v]
        return (v[0], qdd[0]) if single else (v, qdd)

    # ---------------------------------------------------------------- the actuator-space model
    def _model_run(self, name: str, *args: ArrayLike) -> tuple[list[np.ndarray], bool]:
        """:meth:`_run` of a kernel of the actuator-space model, the samples under the pivot floor recomputed by
        :func:`pkm.actuator_model` (``args``: ``q``, then ``qd`` when the kernel takes it, then ``tau``)."""
        outs, single = self._run(name, *args, pivoted=True)
        pivot = outs[-1][:, 0]
        if not pivot.min() >= PIVOT_FLOOR:
            from pkm.core.dynamics.model import actuator_model

            cols = [np.atleast_2d(np.asarray(x, dtype=float)) for x in args]
            for k in np.flatnonzero(~(pivot >= PIVOT_FLOOR)):
                if name == "forward_dynamics":
                    friction = cols[3][k]
                    m = actuator_model(self.mech, cols[0][k], cols[1][k], coulomb_velocity=float(friction[1]))
                    outs[0][k] = m.accelerations(cols[2][k], friction=bool(friction[0]))
                    continue
                m = actuator_model(self.mech, cols[0][k], cols[1][k] if len(cols) > 1 else None)
                values = {"mass_matrix": (m.M,), "bias": (m.h,), "gravity": (m.g,), "mass_and_bias": (m.M, m.h)}[name]
                for o, x in zip(outs, values):
                    o[k] = x.ravel(order="F")
        return outs, single

    def mass_matrix(self, q: ArrayLike) -> np.ndarray:
        """``M_a`` (na x na, or n x na x na) [kg m^2, kg] at closed configurations ``q`` (nq or n x nq), as
        :func:`pkm.mass_matrix` (reflected rotor inertias in, idle motions mass-orthogonal)."""
        outs, single = self._model_run("mass_matrix", q)
        return self._shaped("mass_matrix", outs, single)[0]

    def bias(self, q: ArrayLike, qd: ArrayLike) -> np.ndarray:
        """``h_a`` (na, or n x na) [N m, N] at closed configurations ``q`` and actuated rates ``qd`` (na or n x na):
        Coriolis, centrifugal, gravity and closure-drift efforts, as :func:`pkm.bias_efforts`."""
        outs, single = self._model_run("bias", q, qd)
        return outs[0][0] if single else outs[0]

    def gravity(self, q: ArrayLike) -> np.ndarray:
        """``g_a`` (na, or n x na) [N m, N]: the efforts that hold the mechanism still, as :func:`pkm.gravity_efforts`."""
        outs, single = self._model_run("gravity", q)
        return outs[0][0] if single else outs[0]

    def mass_and_bias(self, q: ArrayLike, qd: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """``(M_a, h_a)`` from one fused kernel (common subexpressions computed once): :meth:`mass_matrix` and
        :meth:`bias` together."""
        outs, single = self._model_run("mass_and_bias", q, qd)
        M, h, _ = self._shaped("mass_and_bias", outs, single)
        return M, h

    def forward_dynamics(self, q: ArrayLike, qd: ArrayLike, tau: ArrayLike, *, friction: bool = False,
                         coulomb_velocity: float = COULOMB_VELOCITY) -> np.ndarray:
        """Actuated accelerations ``qdd = M_a⁻¹ (τ_a + f_a - h_a)`` (na, or n x na) for efforts ``tau`` (na or n x na)
        [N m, N] at closed states ``(q, qd)``: the actuated entries of :func:`pkm.forward_dynamics`, with the joints'
        viscous and Coulomb friction ``f_a`` when ``friction`` (off by default, as there; Coulomb's sign smoothed as
        ``tanh(v / coulomb_velocity)``, as :func:`pkm.actuator_model`).

        Raises:
            SingularityError: ``M_a`` is singular (:func:`pkm.actuator_model`'s test), or a direct singularity.
        """
        if not isinstance(friction, (bool, np.bool_)):
            raise InvalidInputError("friction", "expected True or False", friction)
        cv = as_scalar(coulomb_velocity, "coulomb_velocity", low=1e-12)
        n = np.shape(q)[0] if np.ndim(q) == 2 else None
        settings = np.array([1.0 if friction else 0.0, cv])
        outs, single = self._model_run("forward_dynamics", q, qd, tau,
                                       settings if n is None else np.tile(settings, (n, 1)))
        return outs[0][0] if single else outs[0]

    # ---------------------------------------------------------------- paths
    def close_loops_path(self, q_actuated: ArrayLike, q0: ArrayLike | None = None, *, tol: float = 1e-12, max_iter: int = 10) -> PathResult:
        """The loop closure along a path of actuated coordinates (n x na), each solve warm-started from the previous
        solution (the first from ``q0``, default the reference), as :func:`pkm.close_loops` per sample (``tol`` as
        its: the largest residual with lengths in the characteristic length, angles in rad)."""
        from pkm.core.kinematics.solve import close_loops

        return self._path("closure_newton", q_actuated, q0, tol, max_iter,
                          lambda q, t: close_loops(self.mech, t, q, tol=tol))

    def ik_path(self, targets: ArrayLike, q0: ArrayLike | None = None, *, tol: float = 1e-12, max_iter: int = 10) -> PathResult:
        """The inverse kinematics along a path of task values (n x task value size, laid out as
        :meth:`pkm.core.kinematics.task.TaskMap.value`), warm-started, as :func:`pkm.solve_ik` per sample (``tol`` as
        its, scale-free)."""
        from pkm.core.kinematics.solve import solve_ik

        return self._path("ik_newton", targets, q0, tol, max_iter, lambda q, t: solve_ik(self.mech, t, q, tol=tol))

    def _path(self, name: str, targets: ArrayLike, q0: ArrayLike | None, tol: float, max_iter: int,
              core: Callable[[np.ndarray, np.ndarray], SolveResult]) -> PathResult:
        tol, max_iter = as_tolerance(tol, "tol"), as_count(max_iter, "max_iter", high=1000)
        kernel = self.kernel(name)
        t = np.atleast_2d(as_array(targets, "targets"))
        if t.shape[1] != kernel.in_size[1] or not np.all(np.isfinite(t)):
            raise InvalidInputError("targets", f"expected finite values of shape (n, {kernel.in_size[1]})", targets)
        bounded(t, "targets", targets)
        prev = self.mech.q_reference.copy() if q0 is None else self.mech.check_q(q0, "q0")
        n = len(t)
        Q, res, its = np.empty((n, len(prev))), np.empty(n), np.zeros(n, dtype=np.int64)
        fallback, start = [], 0
        while start < n:
            q_k, r_k, p_k, i_k = kernel.follow(prev, t[start:], max_iter, tol, self._p if len(self.design) else None)
            bad = np.flatnonzero(~((r_k <= tol) & (p_k >= PIVOT_FLOOR)))
            end = start + (int(bad[0]) if bad.size else len(q_k))
            Q[start:end], res[start:end], its[start:end] = q_k[:end - start], r_k[:end - start], i_k[:end - start]
            if end == n:
                break
            solved = core(prev if end == start else Q[end - 1], t[end])  # the core, from the last good sample
            Q[end], res[end], its[end] = solved.q, solved.relative_residual, 0
            fallback.append(end)
            prev, start = solved.q, end + 1
        return PathResult(Q, res, its, tuple(fallback), kernel.how, self.mech.limits_along(Q))


_PATHS = ("closure_newton", "ik_newton")  # the kernels with the path driver
#: mechanism -> {(design parameters, kernel): its CasADi function} (:meth:`Kernels.function`)
_FUNCTIONS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_DYNAMICS = ("mass_matrix", "bias", "gravity", "mass_and_bias", "forward_dynamics")  # the actuator-space model's

#: Each kernel's inputs and outputs.
KERNELS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "inverse_dynamics": (("q", "qd", "qdd"), ("tau", "pivot")),
    "inverse_dynamics_derivatives": (("q", "qd", "qdd"), ("tau", "dtau_dqa", "dtau_dqd", "dtau_dqdd")),
    "velocities": (("q", "qd"), ("v",)),
    "accelerations": (("q", "v", "qdd"), ("a",)),
    "forward_jacobian": (("q",), ("J",)),
    "inverse_jacobian": (("q",), ("J",)),
    "inverse_rates": (("q", "yd", "ydd"), ("v", "qdd", "pivot")),
    "closure_newton": (("q", "target"), ("q_next", "residual", "pivot")),
    "ik_newton": (("q", "y"), ("q_next", "residual", "pivot")),
    "map_newton": (("q", "y"), ("q_next", "step", "pivot")),
    "map_newton_qr": (("q", "y"), ("q_next", "step")),
    "map_indices": (("q", "y", "scale"), ("K", "residual", "branch")),
    "mass_matrix": (("q",), ("M", "pivot")),
    "bias": (("q", "qd"), ("h", "pivot")),
    "gravity": (("q",), ("g", "pivot")),
    "mass_and_bias": (("q", "qd"), ("M", "h", "pivot")),
    "forward_dynamics": (("q", "qd", "tau", "friction"), ("qdd", "pivot")),
    "regressor": (("q", "qd", "qdd"), ("Yt", "pivot")),
}

__all__ = ["KERNELS", "PIVOT_FLOOR", "Kernels", "PathResult"]
