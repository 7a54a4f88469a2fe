"""The compiled simulation: :func:`pkm.simulate`'s fixed-step RK4 in generated C, the loops closed by Newton at every
stage, no Python per stage (see :mod:`pkm.core.dynamics.simulate` for the method and its events).

One library per mechanism (compiled on first use, cached as the kernels are) holds five functions of the twin and
the driver ``pkm_sim_run``:

* ``pkm_sim_close (q, q_a) -> q_next, residual, pivot, residual_0``: the loop closure's Newton iteration
  (:attr:`Twin.closure_newton`) with the residual at its starting point;
* ``pkm_sim_rates (q, qd, friction) -> M_a, h_a, f_a, v, pivot, J_p``: the actuator-space model
  (:class:`~pkm.core.twin.dynamics.ActuatorTwin`) and the passive columns of the closure rows (homogenised);
* ``pkm_sim_integrate (q, dv)``, ``pkm_sim_difference (q0, q1)``: Pinocchio's ``integrate`` (exact exponentials:
  the stages' seeds and the step's prediction are Pinocchio's) and ``difference`` on the configuration space;
* ``pkm_sim_samples (q, v, qdd) -> a, task, task velocity, task acceleration, potential energy, residual, pivot``:
  what a :class:`~pkm.core.dynamics.simulate.Simulation` holds per sample, run over every sample after the run.

Each stage does what the Python route does, in the same order and with the same floating-point expressions: the
actuated coordinates set in the seed, Newton to ``1e-12`` (lengths in the characteristic length, as the Python
route's :data:`~pkm.core.dynamics.simulate.CLOSURE_TOL`; at most 11 iterations), the model, the efforts (a torque
table interpolated as ``numpy.interp`` does and clipped to the actuators' peak efforts; or a Python controller,
called back through :mod:`ctypes` once per stage), ``M_a``'s Cholesky factorisation with
:func:`pkm.core.dynamics.model._solve_inertia`'s test. After each step the end is checked as
:class:`~pkm.core.dynamics.simulate.Simulation`'s events are (position and speed limits, the distance to a direct
singularity from the singular values of ``J_p``, homogenised by the mechanism's characteristic length as the Python
route's (:mod:`pkm.core.model.scale`), by one-sided Jacobi).

The driver hands a step back to Python (the return code says why) where the Python route could decide otherwise:
a step to be halved (the closed end more than half ``step_tol`` from the prediction), an end near an event
(within ``1e-11`` m or rad of a position limit, ``1e-9`` relative of a speed limit, ``1e-6`` relative of
``singular_tol``), an LU pivot under :data:`~pkm.core.twin.kernels.PIVOT_FLOOR`, a closure that does not converge,
``M_a`` failing its test, a non-finite state. Python then takes that one step (halving it, or stopping with the
event, exactly as the Python route) and gives the run back to C.
"""

from __future__ import annotations

import ctypes
import weakref
from collections.abc import Callable
from typing import TYPE_CHECKING

import casadi as cs
import numpy as np

from pkm.core.model.mechanism import Mechanism
from pkm.core.model.scale import JacobianScales
from pkm.core.twin.codegen import C_INT, C_REAL_P, compile_library, jacobi_sv, pointers, source
from pkm.core.twin.joint import _ONE_DOF
from pkm.core.twin.spatial import SE3, Expr, log3, log6, quat_matrix, rodrigues, zyx_angles
from pkm.core.twin.task import TaskTwin

if TYPE_CHECKING:
    from pkm.core.twin.kernels import Kernels
    from pkm.core.twin.tree import Twin

#: Why the driver stopped: the run is done, or it hands step ``last + 1`` to Python.
CODES = {0: "done", 1: "a compiled function failed", 2: "halve", 3: "near an event", 4: "pivot", 5: "no closure",
         6: "inertia", 7: "not finite", 8: "controller"}
CLOSURE_TOL = 1e-12  #: as :data:`pkm.core.dynamics.simulate.CLOSURE_TOL` (lengths in ``L``, angles in rad)
NEWTON_MAX = 11  # (the Python route accepts the 12th iterate at most, q_0 ... q_11)

#: ``int controller(t, q, v, tau)``: the Python controller called back from C (0: efforts written to ``tau``).
CONTROLLER = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, C_REAL_P, C_REAL_P, C_REAL_P)

_DRIVER = r"""
/* pkm simulation driver: RK4 in the actuated coordinates, the loops closed by Newton at every stage */
#define NQ_ NQ
#define NV_ NV
#define NA_ NA
#define NP_ NP
#define NC_ NC
typedef int (*pkm_sim_controller)(casadi_real t, const casadi_real* q, const casadi_real* v, casadi_real* tau);

typedef struct {
  const casadi_real **ca, **ra, **ia, **da; casadi_real **cr, **rr, **ir, **dr;
  casadi_int *ciw, *riw, *iiw, *diw; casadi_real *cw, *rw, *iw, *dw;
  const casadi_real* set; const casadi_real* effort; const casadi_real* speed;
  casadi_int nlim; const casadi_int* lim_q; const casadi_real* lim_lo; const casadi_real* lim_hi;
  casadi_int ntab; const casadi_real* times; const casadi_real* table; pkm_sim_controller ctrl;
  const casadi_int* act_q; casadi_real fr[2];
} pkm_sim;

static casadi_real pkm_sim_interp(casadi_real x, casadi_int n, const casadi_real* xp, const casadi_real* fp,
                                  casadi_int stride) {
  /* numpy.interp of one value, its branches and expressions */
  if (n == 1 || x < xp[0]) return fp[0];
  if (x > xp[n - 1] || x == xp[n - 1]) return fp[(n - 1) * stride];
  casadi_int lo = 0, hi = n - 1;
  while (hi - lo > 1) { casadi_int mid = (lo + hi) / 2; if (xp[mid] <= x) lo = mid; else hi = mid; }
  if (xp[lo] == x) return fp[lo * stride];
  casadi_real a = fp[lo * stride], b = fp[(lo + 1) * stride];
  casadi_real slope = (b - a) / (xp[lo + 1] - xp[lo]);
  casadi_real r = slope * (x - xp[lo]) + a;
  if (r != r) { r = slope * (x - xp[lo + 1]) + b; if (r != r && a == b) r = a; }
  return r;
}

JACOBI_SV

static int pkm_sim_eval(pkm_sim* s, casadi_real t, const casadi_real* x, const casadi_real* seed, casadi_real* q,
                        casadi_real* k, casadi_real* v, casadi_real* tau, casadi_real* M, casadi_real* f,
                        casadi_real* Jp) {
  /* dx/dt at x = (q_a, qd), the loops closed from seed: as _Dynamics.rates */
  casadi_real cur[NQ_ + 1], next[NQ_ + 1], h[NA_ + 1], L[NA_ * NA_ + 1], y[NA_ + 1], rhs[NA_ + 1];
  casadi_real r = 0.0, r0 = 0.0, piv = 0.0;
  for (int i = 0; i < 2 * NA_; ++i) if (!isfinite(x[i])) return 7;
  memcpy(cur, seed, sizeof(casadi_real) * NQ_);
  for (int i = 0; i < NA_; ++i) cur[s->act_q[i]] = x[i];
  s->ca[0] = cur; s->ca[1] = x; s->cr[0] = next; s->cr[1] = &r; s->cr[2] = &piv; s->cr[3] = &r0;
  if (pkm_sim_close(s->ca, s->cr, s->ciw, s->cw, 0)) return 1;
  if (!(r0 <= CLOSURE_TOL_)) {
    int it = 0;
    for (;;) {
      if (!(piv >= PIVOT_FLOOR_)) return 4;
      memcpy(cur, next, sizeof(casadi_real) * NQ_);
      ++it;
      if (r <= CLOSURE_TOL_) break;
      if (it >= NEWTON_MAX_ || r != r) return 5;
      if (pkm_sim_close(s->ca, s->cr, s->ciw, s->cw, 0)) return 1;
    }
  }
  memcpy(q, cur, sizeof(casadi_real) * NQ_);
  s->ra[0] = q; s->ra[1] = x + NA_; s->ra[2] = s->fr;
  s->rr[0] = M; s->rr[1] = h; s->rr[2] = f; s->rr[3] = v; s->rr[4] = &piv; s->rr[5] = Jp;
  if (pkm_sim_rates(s->ra, s->rr, s->riw, s->rw, 0)) return 1;
  if (!(piv >= PIVOT_FLOOR_)) return 4;
  if (s->ctrl) {
    if (s->ctrl(t, q, v, tau)) return 8;
  } else {
    for (int i = 0; i < NA_; ++i) {
      casadi_real e = pkm_sim_interp(t, s->ntab, s->times, s->table + i, NA_);
      if (s->set[2] != 0.0) e = e < -s->effort[i] ? -s->effort[i] : (e > s->effort[i] ? s->effort[i] : e);
      tau[i] = e;
    }
  }
  for (int i = 0; i < NA_; ++i) rhs[i] = (tau[i] + (s->set[0] != 0.0 ? f[i] : 0.0)) - h[i];
  /* Cholesky of M (symmetric, column-major), the test of _solve_inertia (the diagonal homogenised) */
  static const casadi_real act_scale[NA_] = ACT_SCALE_;
  casadi_real dmin = INFINITY, dmax = 0.0;
  for (int j = 0; j < NA_; ++j) {
    casadi_real d = M[j * NA_ + j];
    for (int c = 0; c < j; ++c) d -= L[j * NA_ + c] * L[j * NA_ + c];
    if (!(d > 0.0)) return 6;
    d = sqrt(d); L[j * NA_ + j] = d;
    if (d * act_scale[j] < dmin) dmin = d * act_scale[j];
    if (d * act_scale[j] > dmax) dmax = d * act_scale[j];
    for (int i = j + 1; i < NA_; ++i) {
      casadi_real e = M[j * NA_ + i];
      for (int c = 0; c < j; ++c) e -= L[i * NA_ + c] * L[j * NA_ + c];
      L[i * NA_ + j] = e / d;
    }
  }
  if (!(dmin > INERTIA_FLOOR_ * dmax)) return 6;
  for (int i = 0; i < NA_; ++i) { casadi_real e = rhs[i]; for (int c = 0; c < i; ++c) e -= L[i * NA_ + c] * y[c]; y[i] = e / L[i * NA_ + i]; }
  for (int i = NA_ - 1; i >= 0; --i) {
    casadi_real e = y[i]; for (int c = i + 1; c < NA_; ++c) e -= L[c * NA_ + i] * k[NA_ + c]; k[NA_ + i] = e / L[i * NA_ + i];
  }
  for (int i = 0; i < NA_; ++i) { k[i] = x[NA_ + i]; if (!isfinite(k[NA_ + i])) return 7; }
  return 0;
}

static int pkm_sim_integrate_to(pkm_sim* s, const casadi_real* q, const casadi_real* dv, casadi_real* out) {
  s->ia[0] = q; s->ia[1] = dv; s->ir[0] = out;
  return pkm_sim_integrate(s->ia, s->ir, s->iiw, s->iw, 0);
}

static int pkm_sim_step(pkm_sim* s, casadi_real t, casadi_real h, const casadi_real* x, const casadi_real* k1,
                        const casadi_real* q, const casadi_real* v1, casadi_real* x_new, casadi_real* q_new,
                        casadi_real* k, casadi_real* v, casadi_real* tau, casadi_real* M, casadi_real* f,
                        casadi_real* Jp, casadi_real* moved) {
  /* one RK4 step of h: as _rk4_step without its halving */
  casadi_real xs[2 * NA_], seed[NQ_ + 1], qs[NQ_ + 1], dv[NV_ + 1], d[NV_ + 1], ts[NA_ + 1], Ms[NA_ * NA_ + 1], fs[NA_ + 1];
  casadi_real k2[2 * NA_], k3[2 * NA_], k4[2 * NA_], v2[NV_ + 1], v3[NV_ + 1], v4[NV_ + 1];
  int c;
  casadi_real half = 0.5 * h, sixth = h / 6.0;
  for (int i = 0; i < 2 * NA_; ++i) xs[i] = x[i] + half * k1[i];
  for (int i = 0; i < NV_; ++i) dv[i] = half * v1[i];
  if (pkm_sim_integrate_to(s, q, dv, seed)) return 1;
  if ((c = pkm_sim_eval(s, t + half, xs, seed, qs, k2, v2, ts, Ms, fs, 0))) return c;
  for (int i = 0; i < 2 * NA_; ++i) xs[i] = x[i] + half * k2[i];
  for (int i = 0; i < NV_; ++i) dv[i] = half * v2[i];
  if (pkm_sim_integrate_to(s, q, dv, seed)) return 1;
  if ((c = pkm_sim_eval(s, t + half, xs, seed, qs, k3, v3, ts, Ms, fs, 0))) return c;
  for (int i = 0; i < 2 * NA_; ++i) xs[i] = x[i] + h * k3[i];
  for (int i = 0; i < NV_; ++i) dv[i] = h * v3[i];
  if (pkm_sim_integrate_to(s, q, dv, seed)) return 1;
  if ((c = pkm_sim_eval(s, t + h, xs, seed, qs, k4, v4, ts, Ms, fs, 0))) return c;
  for (int i = 0; i < 2 * NA_; ++i) x_new[i] = x[i] + sixth * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
  for (int i = 0; i < NV_; ++i) dv[i] = sixth * (v1[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]);
  if (pkm_sim_integrate_to(s, q, dv, seed)) return 1;
  if ((c = pkm_sim_eval(s, t + h, x_new, seed, q_new, k, v, tau, M, f, Jp))) return c;
  s->da[0] = seed; s->da[1] = q_new; s->dr[0] = d;
  if (pkm_sim_difference(s->da, s->dr, s->diw, s->dw, 0)) return 1;
  *moved = 0.0;
  for (int i = 0; i < NV_; ++i) if (!(fabs(d[i]) <= *moved)) *moved = fabs(d[i]);
  return 0;
}

static int pkm_sim_near_event(pkm_sim* s, const casadi_real* x, const casadi_real* q, const casadi_real* Jp) {
  /* the end's checks (_Recorder.check), with margins: 1 where Python must decide */
  if (s->set[3] != 0.0) {
    for (casadi_int i = 0; i < s->nlim; ++i) {
      casadi_real a = q[s->lim_q[i]];
      if (!(s->lim_lo[i] - 1e-9 + 1e-11 <= a && a <= s->lim_hi[i] + 1e-9 - 1e-11)) return 1;
    }
    for (int i = 0; i < NA_; ++i) if (!(fabs(x[NA_ + i]) <= s->speed[i] * (1.0 - 1e-9))) return 1;
  }
  if (s->set[4] > 0.0 && NC_ >= NP_ && NP_ > 0) {
    casadi_real A[NC_ * NP_ + 1], sv[NP_ + 1];
    memcpy(A, Jp, sizeof(casadi_real) * NC_ * NP_);
    pkm_sim_sv(NC_, NP_, A, sv);
    if (sv[0] > 0.0 && sv[NP_ - 1] > 1e-9 * sv[0] && sv[NP_ - 1] < s->set[4] * sv[0] * (1.0 + 1e-6)) return 1;
  }
  return 0;
}

int pkm_sim_run(const casadi_real* set, const casadi_real* effort, const casadi_real* speed, casadi_int nlim,
                const casadi_int* lim_q, const casadi_real* lim_lo, const casadi_real* lim_hi, casadi_int ntab,
                const casadi_real* times, const casadi_real* table, pkm_sim_controller ctrl, const casadi_int* act_q,
                casadi_int first, casadi_int n_steps, casadi_real* X, casadi_real* Q, casadi_real* QDD,
                casadi_real* V, casadi_real* TAU, casadi_real* KIN, casadi_real* FQD, casadi_int* last) {
  /* steps first + 1 ... n_steps from the sample at row first (x, q, qdd, v given); set: the friction's factor, the
     Coulomb velocity, saturate, limits, singular_tol, step_tol, dt. Returns 0 (done) or why step *last + 1 is
     Python's (CODES). */
  pkm_sim s;
  casadi_real k1[2 * NA_], k[2 * NA_], x_new[2 * NA_], q_new[NQ_ + 1], v[NV_ + 1], tau[NA_ + 1], M[NA_ * NA_ + 1];
  casadi_real f[NA_ + 1], Jp[NC_ * NP_ + 1], moved = 0.0;
  int code = 0;
  *last = first;
  if (pkm_sim_close_pkm_alloc(&s.ca, &s.cr, &s.ciw, &s.cw)) return 1;
  if (pkm_sim_rates_pkm_alloc(&s.ra, &s.rr, &s.riw, &s.rw)) return 1;
  if (pkm_sim_integrate_pkm_alloc(&s.ia, &s.ir, &s.iiw, &s.iw)) return 1;
  if (pkm_sim_difference_pkm_alloc(&s.da, &s.dr, &s.diw, &s.dw)) return 1;
  s.set = set; s.effort = effort; s.speed = speed; s.nlim = nlim; s.lim_q = lim_q; s.lim_lo = lim_lo;
  s.lim_hi = lim_hi; s.ntab = ntab; s.times = times; s.table = table; s.ctrl = ctrl; s.act_q = act_q;
  s.fr[0] = 1.0; s.fr[1] = set[1];
  casadi_real dt = set[6], step_tol = set[5];
  for (casadi_int step = first + 1; step <= n_steps; ++step) {
    casadi_int p = step - 1;
    const casadi_real *x = X + p * 2 * NA_, *q = Q + p * NQ_;
    for (int i = 0; i < NA_; ++i) { k1[i] = x[NA_ + i]; k1[NA_ + i] = QDD[p * NA_ + i]; }
    code = pkm_sim_step(&s, (casadi_real) p * dt, dt, x, k1, q, V + p * NV_, x_new, q_new, k, v, tau, M, f, Jp, &moved);
    if (!code && !(moved <= 0.5 * step_tol)) code = 2;
    if (!code && pkm_sim_near_event(&s, x_new, q_new, Jp)) code = 3;
    if (code) break;
    memcpy(X + step * 2 * NA_, x_new, sizeof(casadi_real) * 2 * NA_);
    memcpy(Q + step * NQ_, q_new, sizeof(casadi_real) * NQ_);
    memcpy(QDD + step * NA_, k + NA_, sizeof(casadi_real) * NA_);
    memcpy(V + step * NV_, v, sizeof(casadi_real) * NV_);
    memcpy(TAU + step * NA_, tau, sizeof(casadi_real) * NA_);
    casadi_real kin = 0.0, fqd = 0.0;
    for (int j = 0; j < NA_; ++j) {
      casadi_real u = 0.0;
      for (int i = 0; i < NA_; ++i) u += 0.5 * x_new[NA_ + i] * M[j * NA_ + i];
      kin += u * x_new[NA_ + j];
      fqd += f[j] * x_new[NA_ + j];
    }
    KIN[step] = kin; FQD[step] = fqd;
    *last = step;
  }
  pkm_sim_close_pkm_free(s.ca, s.cr, s.ciw, s.cw); pkm_sim_rates_pkm_free(s.ra, s.rr, s.riw, s.rw);
  pkm_sim_integrate_pkm_free(s.ia, s.ir, s.iiw, s.iw); pkm_sim_difference_pkm_free(s.da, s.dr, s.diw, s.dw);
  return code;
}
"""


# ---------------------------------------------------------------------- configuration space
def _exp3_quat(w: Expr) -> tuple[Expr, Expr, Expr, Expr]:
    """The unit quaternion ``(x, y, z, w)`` of the rotation vector ``w`` (series near 0, as Pinocchio's)."""
    t2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2]
    small = t2 < 1e-8
    t = cs.sqrt(cs.if_else(small, 1.0, t2))
    c = cs.if_else(small, 1 - t2 / 8 + t2 * t2 / 384, cs.cos(t / 2))
    s = cs.if_else(small, 0.5 - t2 / 48 + t2 * t2 / 3840, cs.sin(t / 2) / t)
    return s * w[0], s * w[1], s * w[2], c


def _quat_mul(a: tuple, b: tuple) -> list[Expr]:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [aw * bx + bw * ax + ay * bz - az * by, aw * by + bw * ay + az * bx - ax * bz,
            aw * bz + bw * az + ax * by - ay * bx, aw * bw - ax * bx - ay * by - az * bz]


def _normalise(x: list[Expr]) -> list[Expr]:
    """Pinocchio's first-order normalisation, ``x (3 - |x|^2) / 2``."""
    n2 = sum((e * e for e in x[1:]), x[0] * x[0])
    return [e * ((3 - n2) / 2) for e in x]


def _exp3_matrix(w: Expr) -> Expr:
    x, y, z, c = _exp3_quat(w)
    return quat_matrix(x, y, z, c)


def _exp6_translation(v: Expr, w: Expr) -> Expr:
    """``V(w) v``, the translation of SE(3)'s exponential of the twist ``[v; w]``."""
    t2 = cs.dot(w, w)
    small = t2 < 1e-8
    t = cs.sqrt(cs.if_else(small, 1.0, t2))
    a = cs.if_else(small, 0.5 - t2 / 24, (1 - cs.cos(t)) / cs.if_else(small, 1.0, t2))
    b = cs.if_else(small, 1.0 / 6 - t2 / 120, (t - cs.sin(t)) / cs.if_else(small, 1.0, t2 * t))
    wxv = cs.vertcat(w[1] * v[2] - w[2] * v[1], w[2] * v[0] - w[0] * v[2], w[0] * v[1] - w[1] * v[0])
    wxwxv = cs.vertcat(w[1] * wxv[2] - w[2] * wxv[1], w[2] * wxv[0] - w[0] * wxv[2], w[0] * wxv[1] - w[1] * wxv[0])
    return v + a * wxv + b * wxwxv


def integrate(twin: Twin, q: Expr, dv: Expr) -> Expr:
    """Pinocchio's ``integrate(q, dv)`` on the twin's configuration space (exact exponentials, Pinocchio's
    first-order renormalisation of unit blocks)."""
    out = [q[i] for i in range(twin.mech.model.nq)]
    for J in twin.joints[1:]:
        k, i = J.kind, J.idx_q
        d = [dv[c] for c in J.cols]
        if k == "mimic":
            continue
        if k in _ONE_DOF or k == "Universal":
            for r, e in enumerate(d):
                out[i + r] = q[i + r] + e
        elif k in ("RUBX", "RUBY", "RUBZ"):
            c, s = q[i], q[i + 1]
            new = _normalise([cs.cos(d[0]) * c - cs.sin(d[0]) * s, cs.sin(d[0]) * c + cs.cos(d[0]) * s])
            out[i], out[i + 1] = new
        elif k == "Spherical":
            new = _normalise(_quat_mul(tuple(q[i + r] for r in range(4)), _exp3_quat(cs.vertcat(*d))))
            out[i:i + 4] = new
        elif k == "FreeFlyer":
            quat = tuple(q[i + 3 + r] for r in range(4))
            R0 = quat_matrix(*quat)
            p = cs.vertcat(q[i], q[i + 1], q[i + 2]) + R0 @ _exp6_translation(cs.vertcat(*d[:3]), cs.vertcat(*d[3:]))
            out[i:i + 3] = [p[0], p[1], p[2]]
            out[i + 3:i + 7] = _normalise(_quat_mul(quat, _exp3_quat(cs.vertcat(*d[3:]))))
        else:  # planar: SE(2)
            c, s, th = q[i + 2], q[i + 3], d[2]
            small = th * th < 1e-8
            sa = cs.if_else(small, 1 - th * th / 6, cs.sin(th) / cs.if_else(small, 1.0, th))
            ca = cs.if_else(small, th / 2 - th * th * th / 24, (1 - cs.cos(th)) / cs.if_else(small, 1.0, th))
            tx, ty = sa * d[0] - ca * d[1], ca * d[0] + sa * d[1]
            out[i], out[i + 1] = q[i] + c * tx - s * ty, q[i + 1] + s * tx + c * ty
            ct, st = cs.cos(th), cs.sin(th)
            out[i + 2], out[i + 3] = c * ct - s * st, s * ct + c * st
    return cs.vertcat(*out)


def difference(twin: Twin, q0: Expr, q1: Expr) -> Expr:
    """Pinocchio's ``difference(q0, q1)`` (nv) on the twin's configuration space (the planar joint's through SE(3))."""
    out = cs.SX.zeros(twin.mech.nv)
    for J in twin.joints[1:]:
        k, i, cols = J.kind, J.idx_q, J.cols
        if k == "mimic":
            continue
        if k in _ONE_DOF or k == "Universal":
            for r, c in enumerate(cols):
                out[c] = q1[i + r] - q0[i + r]
        elif k in ("RUBX", "RUBY", "RUBZ"):
            out[cols[0]] = cs.atan2(q0[i] * q1[i + 1] - q0[i + 1] * q1[i], q0[i] * q1[i] + q0[i + 1] * q1[i + 1])
        elif k == "Spherical":
            R0 = quat_matrix(*(q0[i + r] for r in range(4)))
            R1 = quat_matrix(*(q1[i + r] for r in range(4)))
            w = log3(R0.T @ R1)
            for r, c in enumerate(cols):
                out[c] = w[r]
        else:
            if k == "FreeFlyer":
                M0 = SE3(quat_matrix(*(q0[i + 3 + r] for r in range(4))), cs.vertcat(q0[i], q0[i + 1], q0[i + 2]))
                M1 = SE3(quat_matrix(*(q1[i + 3 + r] for r in range(4))), cs.vertcat(q1[i], q1[i + 1], q1[i + 2]))
                rows: tuple[int, ...] = (0, 1, 2, 3, 4, 5)
            else:
                z = np.array([0.0, 0.0, 1.0])
                M0 = SE3(rodrigues(z, q0[i + 2], q0[i + 3]), cs.vertcat(q0[i], q0[i + 1], 0))
                M1 = SE3(rodrigues(z, q1[i + 2], q1[i + 3]), cs.vertcat(q1[i], q1[i + 1], 0))
                rows = (0, 1, 5)
            xi = log6(M0.inverse() * M1)
            for c, r in zip(cols, rows):
                out[c] = xi[r]
    return out


# ---------------------------------------------------------------------- per-sample outputs
def quaternion(R: Expr) -> list[Expr]:
    """``(x, y, z, w)`` of the rotation ``R``, Eigen's algorithm (``pin.Quaternion(R)``: the same branches and signs;
    every branch finite)."""
    t = R[0, 0] + R[1, 1] + R[2, 2]
    positive = t > 0
    s = cs.sqrt(cs.fmax(t + 1.0, 1e-300))
    first = [(R[2, 1] - R[1, 2]) * (0.5 / s), (R[0, 2] - R[2, 0]) * (0.5 / s), (R[1, 0] - R[0, 1]) * (0.5 / s), 0.5 * s]
    i1 = R[1, 1] > R[0, 0]
    i2 = R[2, 2] > cs.if_else(i1, R[1, 1], R[0, 0])
    out = first
    for i, cond in ((0, cs.logic_and(cs.logic_not(i1), cs.logic_not(i2))), (1, cs.logic_and(i1, cs.logic_not(i2))),
                    (2, i2)):
        j, k = (i + 1) % 3, (i + 2) % 3
        si = cs.sqrt(cs.fmax(R[i, i] - R[j, j] - R[k, k] + 1.0, 1e-300))
        b: list = [0, 0, 0, 0]
        b[i] = 0.5 * si
        b[3] = (R[k, j] - R[j, k]) * (0.5 / si)
        b[j] = (R[j, i] + R[i, j]) * (0.5 / si)
        b[k] = (R[k, i] + R[i, k]) * (0.5 / si)
        take = cs.logic_and(cs.logic_not(positive), cond)
        out = [cs.if_else(take, bb, o) for bb, o in zip(b, out)]
    return out


def task_value(twin: Twin) -> Expr:
    """The task value at :attr:`Twin.q`, laid out as :meth:`pkm.core.kinematics.task.TaskMap.value`."""
    tk = TaskTwin.of(twin)
    out: list = []
    for fid, comps in tk._task_groups():
        M = twin.frame_placement(fid)
        if comps == ("pose",):
            out += [M.p[0], M.p[1], M.p[2], *quaternion(M.R)]
            continue
        rpy = zyx_angles(M.R)
        out += [M.p["xyz".index(c)] if c in ("x", "y", "z") else rpy[("roll", "pitch", "yaw").index(c)] for c in comps]
    out += [twin.q[j.idx_q] for j in twin.mech.task_joints]
    return cs.vertcat(*out)


# ---------------------------------------------------------------------- the library
class Simulator:
    """The compiled simulation of ``kernels``' mechanism (see the module doc); :attr:`lib` is None, and :attr:`how`
    says why, where it cannot run (no C compiler, ``compiled=False``)."""

    def __init__(self, kernels: Kernels):
        tw = kernels.twin
        mech = tw.mech
        self.mech = mech
        dyn = kernels.dynamics
        close = tw.closure_newton
        r0 = tw.with_actuated(cs.mmax(cs.fabs(tw.relative_closure_residual))) if mech.n_constraints else cs.SX(0.0)
        passive = [int(c) for c in mech.passive_v]
        scales = JacobianScales.of(mech)  # (J_p homogenised, as the Python route's check: the same for any size)
        Jp = cs.diag(cs.DM(scales.constraint_rows)) @ tw.closure_rows["jacobian"][:, passive] \
            @ cs.diag(cs.DM(scales.columns[passive])) if mech.n_constraints else cs.SX(0, len(passive))
        self.shape_jp = Jp.shape
        dq = cs.SX.sym("dv", mech.nv)
        q1 = cs.SX.sym("q1", mech.model.nq)
        qdd = tw.qdd
        a = tw.accelerations
        Jt = TaskTwin.of(tw).task_jacobian
        ta = Jt @ a + cs.jtimes(Jt @ tw.v, tw.q, tw.tangent @ tw.v)
        resid = cs.mmax(cs.fabs(tw.closure_residual)) if mech.n_constraints else cs.SX(0.0)

        def fn(name: str, ins: list, outs: list) -> cs.Function:
            return cs.Function(name, ins, cs.cse([cs.densify(cs.SX(e)) for e in outs]))

        self.functions = [
            fn("pkm_sim_close", [tw.q, tw.target], [close["q_next"], close["residual"], close["pivot"], r0]),
            fn("pkm_sim_rates", [tw.q, tw.qd, dyn.friction],
               [dyn.mass_matrix, dyn.bias, dyn.friction_efforts, dyn.v, dyn.pivot, Jp]),
            fn("pkm_sim_integrate", [tw.q, dq], [integrate(tw, tw.q, dq)]),
            fn("pkm_sim_difference", [tw.q, q1], [difference(tw, tw.q, q1)]),
            fn("pkm_sim_samples", [tw.q, tw.v, qdd],
               [a, task_value(tw), Jt @ tw.v, ta, tw.potential_energy, resid, tw.passive_lu.smallest_relative_pivot()
                if mech.n_constraints else cs.SX(1.0)]),
        ]
        self.lib: ctypes.CDLL | None = None
        if not kernels.compiled:
            self.how = "compiled=False"
            return
        from pkm.core.twin.dynamics import INERTIA_FLOOR
        from pkm.core.twin.kernels import PIVOT_FLOOR

        sizes = {"NQ": mech.model.nq, "NV": mech.nv, "NA": mech.na, "NP": Jp.shape[1], "NC": Jp.shape[0]}
        driver = _DRIVER
        for key, value in sizes.items():
            driver = driver.replace(f" {key}\n", f" {value}\n")
        driver = (driver.replace("JACOBI_SV\n", jacobi_sv("pkm_sim_sv", 1e-15, 1e-15)).replace("CLOSURE_TOL_", repr(CLOSURE_TOL)).replace("PIVOT_FLOOR_", repr(float(PIVOT_FLOOR)))
                  .replace("NEWTON_MAX_", str(NEWTON_MAX)).replace("INERTIA_FLOOR_", repr(INERTIA_FLOOR))
                  .replace("ACT_SCALE_", "{" + ", ".join(repr(float(x)) for x in JacobianScales.of(mech).actuated)
                           + "}"))
        self.lib, self.how = compile_library(self.functions, directory=kernels.directory,
                                             text=source(self.functions) + driver)
        if self.lib is None:
            return
        run = self.lib.pkm_sim_run
        P, IP = C_REAL_P, ctypes.POINTER(C_INT)
        run.argtypes = [P, P, P, C_INT, IP, P, P, C_INT, P, P, CONTROLLER, IP, C_INT, C_INT, P, P, P, P, P, P, P, IP]
        run.restype = ctypes.c_int
        self._run = run
        self._samples = self.lib.pkm_sim_samples_batch
        self._samples.argtypes = [C_INT, ctypes.POINTER(P), ctypes.POINTER(P)]
        self._samples.restype = ctypes.c_int
        self.out_sizes = [self.functions[4].nnz_out(i) for i in range(self.functions[4].n_out())]

    def run(self, settings: np.ndarray, effort: np.ndarray, speed: np.ndarray, limits: tuple[np.ndarray, ...],
            table: tuple[np.ndarray, np.ndarray] | None, controller: Callable | None, first: int, n_steps: int,
            rows: dict[str, np.ndarray]) -> tuple[int, int]:
        """Steps ``first + 1 ... n_steps`` into ``rows`` (``X, Q, QDD, V, TAU, KIN, FQD``, C-contiguous, row
        ``first`` given); returns ``(last, code)``: the last row written and why it stopped (:data:`CODES`)."""
        P = C_REAL_P
        p = lambda a: a.ctypes.data_as(P)
        lim_q, lim_lo, lim_hi = limits
        times, values = table if table is not None else (np.zeros(1), np.zeros((1, self.mech.na)))
        act_q = np.ascontiguousarray(self.mech.act_q, dtype=np.int64)
        last = C_INT(0)
        ctrl = CONTROLLER(controller) if controller is not None else CONTROLLER()
        code = self._run(p(settings), p(effort), p(speed), len(lim_q), lim_q.ctypes.data_as(ctypes.POINTER(C_INT)),
                         p(lim_lo), p(lim_hi), len(times), p(times), p(values), ctrl,
                         act_q.ctypes.data_as(ctypes.POINTER(C_INT)), first, n_steps, *(p(rows[k]) for k in
                         ("X", "Q", "QDD", "V", "TAU", "KIN", "FQD")), ctypes.byref(last))
        return int(last.value), int(code)

    def samples(self, Q: np.ndarray, V: np.ndarray, QDD: np.ndarray) -> list[np.ndarray]:
        """``a, task, task_velocity, task_acceleration, potential, residual, pivot`` at every sample (n x size)."""
        n = Q.shape[0]
        ins = [np.ascontiguousarray(a, dtype=float) for a in (Q, V, QDD)]
        outs = [np.empty((n, s)) for s in self.out_sizes]
        if self._samples(n, pointers(ins), pointers(outs)):
            from pkm.errors import CompilerError

            raise CompilerError("the compiled simulation's samples", "the generated code failed")
        return outs


_SIMULATORS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def simulator(mech: Mechanism) -> Simulator:
    """The compiled simulation of ``mech``, built once per mechanism object (its library compiled once per machine).

    Raises:
        SpecError: ``mech`` has idle motions (the twin's loop closure needs a unique solution).
    """
    sim = _SIMULATORS.get(mech)
    if sim is None:
        from pkm.core.twin.kernels import Kernels

        sim = _SIMULATORS[mech] = Simulator(Kernels(mech))
    return sim


__all__ = ["CODES", "CONTROLLER", "Simulator", "difference", "integrate", "quaternion", "simulator", "task_value"]
