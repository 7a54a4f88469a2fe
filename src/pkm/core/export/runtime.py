"""The hand-written C of an exported library: the dense fallbacks, the Newton driver and the public functions'
bodies, as templates (``p_`` the library's prefix in lower case, ``P_`` in upper case; other upper-case words are
filled in by :mod:`pkm.core.export.library`). Strict C99, ``<math.h>`` only, no allocation, no state."""

HELPERS = r"""
/* ---------------------------------------------------------------- helpers */
static int p_finite(const double* x, int n) {
  int i;
  for (i = 0; i < n; ++i) if (!isfinite(x[i])) return 0;
  return 1;
}

/* coordinates (m, rad): finite and within P_ABSURD (pkm.validation.bounded's rule: beyond it refused, never wrapped) */
static int p_coordinates(const double* x, int n) {
  int i;
  for (i = 0; i < n; ++i) if (!isfinite(x[i]) || fabs(x[i]) > P_ABSURD) return 0;
  return 1;
}

static void p_copy(double* to, const double* from, int n) {
  int i;
  for (i = 0; i < n; ++i) to[i] = from[i];
}

static p_info* p_start(p_info* info, p_info* local) {
  p_info* out = info ? info : local;
  out->status = P_OK; out->iterations = 0; out->residual = 0.0; out->sigma_min = 0.0; out->pivot = 1.0;
  out->joint = -1; out->mode = 0;
  return out;
}

static int p_end(p_info* info, int status) {
  info->status = status;
  return status;
}

/* LU with partial pivoting of the column-major n x n A (destroyed); solves A x = b in place of b when b is not
   NULL. Returns the sign of det(A) (+1 or -1), 0 when a pivot is exactly zero. */
static int p_lu(int n, double* A, double* b) {
  int i, j, k, sign = 1;
  for (k = 0; k < n; ++k) {
    int r = k;
    double best = fabs(A[k * n + k]);
    for (i = k + 1; i < n; ++i) if (fabs(A[k * n + i]) > best) { best = fabs(A[k * n + i]); r = i; }
    if (best == 0.0) return 0;
    if (r != k) {
      for (j = 0; j < n; ++j) { double t = A[j * n + k]; A[j * n + k] = A[j * n + r]; A[j * n + r] = t; }
      if (b) { double t = b[k]; b[k] = b[r]; b[r] = t; }
      sign = -sign;
    }
    if (A[k * n + k] < 0.0) sign = -sign;
    for (i = k + 1; i < n; ++i) {
      double f = A[k * n + i] / A[k * n + k];
      A[k * n + i] = f;
      for (j = k + 1; j < n; ++j) A[j * n + i] -= f * A[j * n + k];
      if (b) b[i] -= f * b[k];
    }
  }
  if (b) for (i = n - 1; i >= 0; --i) {
    double s = b[i];
    for (j = i + 1; j < n; ++j) s -= A[j * n + i] * b[j];
    b[i] = s / A[i * n + i];
  }
  return sign;
}

JACOBI_SV
/* the smallest singular value relative to the largest of the column-major n x n A (kept) homogenised, row i times
   rows[i] and column j times cols[j] (a rotation row, an angular task row and a length column times the
   characteristic length: pkm.core.model.scale.JacobianScales), so that the singularity test judges the mechanism
   scaled in size alike; 0 where A is zero */
static double p_distance(int n, const double* A, const double* rows, const double* cols) {
  double W[P_NMAX * P_NMAX], s[P_NMAX];
  int i, j;
  for (j = 0; j < n; ++j) for (i = 0; i < n; ++i) W[j * n + i] = rows[i] * A[j * n + i] * cols[j];
  p_sv(n, n, W, s);
  return s[0] > 0.0 ? s[n - 1] / s[0] : 0.0;
}

/* the mode id from the blocks' determinants relative to the reference's: bit k set unless the k-th is positive */
static long p_mode(int nblocks, const double* det) {
  long mode = 0;
  int k;
  for (k = 0; k < nblocks; ++k) if (!(det[k] > 0.0)) mode |= 1L << k;
  return mode;
}

/* the first joint (index into p_limit_joint) outside its limits by more than P_LIMIT_TOL, or -1 */
static int p_outside(const double* q) {
  int k;
  for (k = 0; k < P_NLIMITS; ++k) {
    double x = q[p_limit_q[k]];
    if (x < p_limit_low[k] - P_LIMIT_TOL || x > p_limit_high[k] + P_LIMIT_TOL) return k;
  }
  return -1;
}
"""

#: The Newton driver of one solve (``$kind``: ``fk`` or ``ik``; ``$NX`` the unknowns, ``$NB`` the mode's blocks).
NEWTON = r"""
static int p_newton_$kind(const double* target, const double* q_prev, long mode, double tol, double* q, p_info* info) {
  double cur[P_NQ], next[P_NQ], det[$NB], r = 0.0, pv = 0.0;
  int it;
  p_copy(cur, q_prev, P_NQ);
  for (it = 1; it <= P_MAX_ITER; ++it) {
    p_k_$kind_step(cur, target, next, &r, &pv, det);
    info->iterations = it; info->residual = r; info->pivot = pv;
    if (!(pv >= P_PIVOT_FLOOR)) {  /* the fixed pivots fail: the same system, densely */
      double A[$NX * $NX], W[$NX * $NX], b[$NX];
      p_k_$kind_system(cur, target, A, b);
      info->sigma_min = p_distance($NX, A, p_$kind_row_scale, p_$kind_col_scale);
      if (!(info->sigma_min > P_SINGULAR_TOL)) { p_copy(q, q_prev, P_NQ); return p_end(info, P_SINGULAR); }
      p_copy(W, A, $NX * $NX);  /* (A kept for the mode's blocks) */
      p_lu($NX, W, b);
      p_k_$kind_retract(cur, b, target, next);
      if (r <= tol) {  /* the mode from the dense blocks */
        int k, i, j;
        for (k = 0; k < $KNBLOCKS; ++k) {
          double B[P_BMAX * P_BMAX];
          int m = p_$kind_block_start[k + 1] - p_$kind_block_start[k];
          const int* rows = p_$kind_block_rows + p_$kind_block_start[k];
          const int* cols = p_$kind_block_cols + p_$kind_block_start[k];
          for (j = 0; j < m; ++j) for (i = 0; i < m; ++i) B[j * m + i] = A[cols[j] * $NX + rows[i]];
          det[k] = p_lu(m, B, 0) * p_$kind_block_sign[k];
        }
      }
    }
    if (!p_finite(next, P_NQ) || !(r < INFINITY)) break;
    if (r <= tol) {  /* converged at cur; next is one step further */
      long found = p_mode($KNBLOCKS, det);
      int joint;
      p_copy(q, next, P_NQ);
      info->mode = found;
      if (mode >= 0 && found != mode) return p_end(info, P_LEFT_MODE);
      joint = p_outside(q);
      info->joint = joint;
      return p_end(info, joint >= 0 ? P_OUTSIDE_LIMITS : P_OK);
    }
    p_copy(cur, next, P_NQ);
  }
  p_copy(q, q_prev, P_NQ);
  return p_end(info, P_NOT_CONVERGED);
}
"""

#: The public functions (``p_`` prefix); declarations in :data:`HEADER_FUNCTIONS`.
PUBLIC = r"""
/* The forward kinematics from q_prev to the actuated coordinates qa as pkm.close_loops solves it: along the straight
   path in actuated coordinates (a revolute one the short way round), in steps of at most P_FK_STEP per actuator (in
   rad, or in characteristic lengths: p_actuated_unit) and P_MAX_STEPS steps at most, each corrected by Newton from
   the last (to P_PATH_TOL on the way, P_TOL at qa), so that a solution far from q_prev (a first one, from
   p_q_reference) stays in q_prev's assembly mode where a single Newton jump would leave it or fail. A step that does
   not converge ends the path: P_NOT_CONVERGED, q_prev kept. info->iterations counts every step's iterations. */
static int p_follow_fk(const double* qa, const double* q_prev, long mode, double* q, p_info* info) {
  double start[P_NA], d[P_NA], sub[P_NA], cur[P_NQ], first[P_NQ];  /* (q may be q_prev's buffer) */
  int k, s, n = 1, total = 0, status;
  p_copy(first, q_prev, P_NQ);
  for (k = 0; k < P_NA; ++k) {
    double steps;
    start[k] = q_prev[p_actuated_q[k]];
    d[k] = qa[k] - start[k];
    if (p_actuated_revolute[k]) d[k] = atan2(sin(d[k]), cos(d[k]));
    steps = ceil(fabs(d[k]) / (P_FK_STEP * p_actuated_unit[k]));
    if (!(steps <= P_MAX_STEPS)) steps = P_MAX_STEPS;
    if (steps > n) n = (int) steps;
  }
  p_copy(cur, first, P_NQ);
  for (s = 1; s < n; ++s) {
    for (k = 0; k < P_NA; ++k) sub[k] = start[k] + d[k] * ((double) s / n);
    status = p_newton_fk(sub, cur, -1, P_PATH_TOL, q, info);
    total += info->iterations;
    if (status != P_OK && status != P_OUTSIDE_LIMITS) {
      info->iterations = total;
      p_copy(q, first, P_NQ);
      return status;
    }
    p_copy(cur, q, P_NQ);
  }
  info->joint = -1;
  status = p_newton_fk(qa, cur, mode, P_TOL, q, info);
  info->iterations += total;
  if (status == P_NOT_CONVERGED || status == P_SINGULAR) p_copy(q, first, P_NQ);
  return status;
}

/* ---------------------------------------------------------------- public functions */
int p_fk(const double qa[P_NA], const double q_prev[P_NQ], long mode, double q[P_NQ], double y[P_NY], p_info* info) {
  p_info local;
  int status;
  info = p_start(info, &local);
  if (!p_coordinates(qa, P_NA) || !p_coordinates(q_prev, P_NQ)) return p_end(info, P_INVALID_INPUT);
  status = p_follow_fk(qa, q_prev, mode, q, info);
  p_k_task_value(q, y);
  return status;
}

int p_ik(const double y[P_NY], const double q_prev[P_NQ], long mode, double q[P_NQ], double qa[P_NA], p_info* info) {
  p_info local;
  int status, k;
  info = p_start(info, &local);
  if (!p_coordinates(y, P_NY) || !p_coordinates(q_prev, P_NQ)) return p_end(info, P_INVALID_INPUT);
  status = p_newton_ik(y, q_prev, mode, P_TOL, q, info);
  for (k = 0; k < P_NA; ++k) qa[k] = q[p_actuated_q[k]];
  return status;
}

int p_fk_mode(const double q[P_NQ], long* mode) {
  double qa[P_NA], next[P_NQ], det[FKB], r, pv;
  int k;
  if (!p_coordinates(q, P_NQ)) return P_INVALID_INPUT;
  for (k = 0; k < P_NA; ++k) qa[k] = q[p_actuated_q[k]];
  p_k_fk_step(q, qa, next, &r, &pv, det);
  *mode = p_mode(FK_NBLOCKS, det);
  return P_OK;
}

int p_ik_mode(const double q[P_NQ], long* mode) {
  double y[P_NY], next[P_NQ], det[IKB], r, pv;
  if (!p_coordinates(q, P_NQ)) return P_INVALID_INPUT;
  p_k_task_value(q, y);
  p_k_ik_step(q, y, next, &r, &pv, det);
  *mode = p_mode(IK_NBLOCKS, det);
  return P_OK;
}

int p_task_value(const double q[P_NQ], double y[P_NY]) {
  if (!p_coordinates(q, P_NQ)) return P_INVALID_INPUT;
  p_k_task_value(q, y);
  return P_OK;
}

int p_fk_distance(const double q[P_NQ], double* distance) {
  double qa[P_NA], A[FKN * FKN], b[FKN];
  int k;
  if (!p_coordinates(q, P_NQ)) return P_INVALID_INPUT;
  for (k = 0; k < P_NA; ++k) qa[k] = q[p_actuated_q[k]];
  p_k_fk_system(q, qa, A, b);
  *distance = p_distance(FKN, A, p_fk_row_scale, p_fk_col_scale);
  return P_OK;
}

/* a kernel's pivot under the floor: singular (the homogenised passive closure Jacobian's relative smallest singular
   value) or not */
static int p_pivot_failed(const double* q, p_info* info) {
  p_fk_distance(q, &info->sigma_min);
  return p_end(info, info->sigma_min > P_SINGULAR_TOL ? P_PIVOT_ORDER : P_SINGULAR);
}

int p_jacobians(const double q[P_NQ], double J[P_NX * P_NA], double K[P_NA * P_NX], p_info* info) {
  p_info local;
  info = p_start(info, &local);
  if (!p_coordinates(q, P_NQ)) return p_end(info, P_INVALID_INPUT);
  p_k_jacobians(q, J, K, &info->pivot);
  if (!(info->pivot >= P_PIVOT_FLOOR)) return p_pivot_failed(q, info);
  return P_OK;
}

/* out = M x (transpose: M^T x), M the forward Jacobian J (which 0: P_NX x P_NA) or the inverse K (which 1:
   P_NA x P_NX) at q, column-major */
static int p_map(const double* q, const double* x, int which, int transpose, double* out, p_info* info) {
  double J[P_NX * P_NA], K[P_NA * P_NX];
  const double* M = which ? K : J;
  int rows = which ? P_NA : P_NX, cols = which ? P_NX : P_NA, a, b, status;
  if (!p_finite(x, transpose ? rows : cols)) { p_info local; return p_end(p_start(info, &local), P_INVALID_INPUT); }
  status = p_jacobians(q, J, K, info);
  if (status != P_OK) return status;
  if (!transpose) {
    for (a = 0; a < rows; ++a) { out[a] = 0.0; for (b = 0; b < cols; ++b) out[a] += M[b * rows + a] * x[b]; }
  } else {
    for (b = 0; b < cols; ++b) { out[b] = 0.0; for (a = 0; a < rows; ++a) out[b] += M[b * rows + a] * x[a]; }
  }
  return P_OK;
}

int p_task_velocity(const double q[P_NQ], const double qd[P_NA], double xd[P_NX], p_info* info) {
  return p_map(q, qd, 0, 0, xd, info);  /* xd = J qd */
}

int p_actuator_velocity(const double q[P_NQ], const double xd[P_NX], double qd[P_NA], p_info* info) {
  return p_map(q, xd, 1, 0, qd, info);  /* qd = K xd */
}

int p_task_effort(const double q[P_NQ], const double tau[P_NA], double w[P_NX], p_info* info) {
  return p_map(q, tau, 1, 1, w, info);  /* w = K^T tau */
}

int p_actuator_effort(const double q[P_NQ], const double w[P_NX], double tau[P_NA], p_info* info) {
  return p_map(q, w, 0, 1, tau, info);  /* tau = J^T w */
}

int p_jdot_qdot(const double q[P_NQ], const double qd[P_NA], double c[P_NX], p_info* info) {
  p_info local;
  info = p_start(info, &local);
  if (!p_coordinates(q, P_NQ) || !p_finite(qd, P_NA)) return p_end(info, P_INVALID_INPUT);
  p_k_jdot_qdot(q, qd, c, &info->pivot);
  if (!(info->pivot >= P_PIVOT_FLOOR)) return p_pivot_failed(q, info);
  return P_OK;
}

int p_inverse_dynamics(const double q[P_NQ], const double qd[P_NA], const double qdd[P_NA], double tau[P_NA],
                       p_info* info) {
  p_info local;
  info = p_start(info, &local);
  if (!p_coordinates(q, P_NQ) || !p_finite(qd, P_NA) || !p_finite(qdd, P_NA)) return p_end(info, P_INVALID_INPUT);
  p_k_inverse_dynamics(q, qd, qdd, tau, &info->pivot);
  if (!(info->pivot >= P_PIVOT_FLOOR)) return p_pivot_failed(q, info);
  return P_OK;
}

int p_mass_matrix(const double q[P_NQ], double M[P_NA * P_NA], p_info* info) {
  p_info local;
  info = p_start(info, &local);
  if (!p_coordinates(q, P_NQ)) return p_end(info, P_INVALID_INPUT);
  p_k_mass_matrix(q, M, &info->pivot);
  if (!(info->pivot >= P_PIVOT_FLOOR)) return p_pivot_failed(q, info);
  return P_OK;
}

int p_gravity(const double q[P_NQ], double g[P_NA], p_info* info) {
  p_info local;
  info = p_start(info, &local);
  if (!p_coordinates(q, P_NQ)) return p_end(info, P_INVALID_INPUT);
  p_k_gravity(q, g, &info->pivot);
  if (!(info->pivot >= P_PIVOT_FLOOR)) return p_pivot_failed(q, info);
  return P_OK;
}
"""

#: The closed-form inverse kinematics of the actuated coordinates (mechanisms of crank legs: see
#: :attr:`pkm.core.export.model.ExportModel.closed_form`).
CLOSED_FORM = r"""
int p_ik_actuators(const double y[P_NY], long mode, double qa[P_NA], p_info* info) {
  p_info local;
  double signs[P_NA], margin[P_NA];
  int k;
  info = p_start(info, &local);
  if (!p_coordinates(y, P_NY)) return p_end(info, P_INVALID_INPUT);
  if (mode < 0) mode = 0;
  for (k = 0; k < P_NA; ++k) signs[k] = ((mode >> k) & 1L) ? -p_closed_sign[k] : p_closed_sign[k];
  p_k_ik_closed(y, signs, qa, margin);
  info->mode = mode; info->iterations = 0; info->sigma_min = margin[0];
  for (k = 0; k < P_NA; ++k) {
    if (margin[k] < info->sigma_min) info->sigma_min = margin[k];
    if (!(margin[k] >= 0.0) && -margin[k] > info->residual) info->residual = -margin[k];
  }
  if (!p_finite(qa, P_NA)) return p_end(info, P_SINGULAR);
  if (info->residual > 0.0) return p_end(info, P_NOT_CONVERGED);
  for (k = 0; k < P_NY; ++k) {  /* (the task's joints: y is their values) */
    int l = p_task_limit[k];
    if (l >= 0 && (y[k] < p_limit_low[l] - P_LIMIT_TOL || y[k] > p_limit_high[l] + P_LIMIT_TOL)) {
      info->joint = l;
      return p_end(info, P_OUTSIDE_LIMITS);
    }
  }
  for (k = 0; k < P_NA; ++k) {
    int l = p_actuated_limit[k];
    if (l >= 0 && (qa[k] < p_limit_low[l] - P_LIMIT_TOL || qa[k] > p_limit_high[l] + P_LIMIT_TOL)) {
      info->joint = l;
      return p_end(info, P_OUTSIDE_LIMITS);
    }
  }
  return P_OK;
}
"""

HEADER_CLOSED_FORM = r"""
/* The actuated coordinates qa (P_NA) for the task value y (P_NY) in closed form, no iteration: each crank leg's
   circle-sphere intersection. mode: bit k set puts actuator k's leg on the branch opposite to the reference's
   (negative: 0; its own numbering, per actuator: not a P_IK_MODE_* id, which numbers p_ik's blocks).
   NOT_CONVERGED: a leg cannot reach (info->residual: by how much, as 1 - |C| / rho); info->sigma_min: the smallest
   leg margin 1 - |C| / rho (0 at a leg's inverse singularity); OUTSIDE_LIMITS: a task joint's or an actuator's limit
   (info->joint). */
int p_ik_actuators(const double y[P_NY], long mode, double qa[P_NA], p_info* info);
"""

HEADER_FUNCTIONS = r"""
/* Every function returns a status (P_OK or one of the codes above) and fills *info when info is not NULL. None
   allocates, prints or keeps state: any number of threads may call them at once. Arrays are column-major. */

/* Forward kinematics: the configuration q (P_NQ) and task value y (P_NY) for the actuated coordinates qa (P_NA),
   by Newton from the caller's previous solution q_prev (P_MAX_ITER iterations at most), along a path of steps of at
   most P_FK_STEP per actuator where qa is farther (P_MAX_STEPS at most): a first solution from p_q_reference (mode
   P_FK_MODE_REFERENCE) to any qa the reference's assembly mode reaches without crossing a singularity. mode: the
   assembly mode the solution must be in (a P_FK_MODE_* id; negative: any). q may be q_prev's buffer. q and y hold the solution for P_OK, P_LEFT_MODE
   and P_OUTSIDE_LIMITS, else q_prev (nothing is written for P_INVALID_INPUT). */
int p_fk(const double qa[P_NA], const double q_prev[P_NQ], long mode, double q[P_NQ], double y[P_NY], p_info* info);

/* Inverse kinematics: q (P_NQ) and the actuated coordinates qa (P_NA) for the task value y (P_NY), by Newton
   from q_prev; mode: the working mode (a P_IK_MODE_* id; negative: any). Outputs as p_fk's. */
int p_ik(const double y[P_NY], const double q_prev[P_NQ], long mode, double q[P_NQ], double qa[P_NA], p_info* info);

/* The assembly (forward kinematics) and working (inverse kinematics) mode ids of a closed configuration. */
int p_fk_mode(const double q[P_NQ], long* mode);
int p_ik_mode(const double q[P_NQ], long* mode);

/* The distance of a closed configuration q from a direct singularity: the smallest singular value of the forward
   kinematics' Newton matrix (the closure Jacobian on the passive coordinates) relative to its largest, the matrix
   homogenised by the characteristic length (pkm.diagnose's direct_distance: the same for the mechanism scaled in
   size); SINGULAR below P_SINGULAR_TOL. */
int p_fk_distance(const double q[P_NQ], double* distance);

/* The task value of a configuration (P_NY: see p_task_names). */
int p_task_value(const double q[P_NQ], double y[P_NY]);

/* At a closed configuration q: the forward Jacobian J (task rates per actuated rate, P_NX x P_NA) and the
   inverse K (P_NA x P_NX). */
int p_jacobians(const double q[P_NQ], double J[P_NX * P_NA], double K[P_NA * P_NX], p_info* info);

/* Rate and effort maps at a closed configuration: xd = J qd, qd = K xd, w = K^T tau (the task effort the
   actuator efforts balance), tau = J^T w (the actuator efforts that balance the task effort w). */
int p_task_velocity(const double q[P_NQ], const double qd[P_NA], double xd[P_NX], p_info* info);
int p_actuator_velocity(const double q[P_NQ], const double xd[P_NX], double qd[P_NA], p_info* info);
int p_task_effort(const double q[P_NQ], const double tau[P_NA], double w[P_NX], p_info* info);
int p_actuator_effort(const double q[P_NQ], const double w[P_NX], double tau[P_NA], p_info* info);

/* dJ/dt qd: the task acceleration at zero actuated acceleration (P_NX). */
int p_jdot_qdot(const double q[P_NQ], const double qd[P_NA], double c[P_NX], p_info* info);

/* Inverse dynamics: the actuator efforts tau (P_NA) [N m, N] at a closed configuration for the actuated rates qd
   and accelerations qdd, under gravity (reflected rotor inertias included). */
int p_inverse_dynamics(const double q[P_NQ], const double qd[P_NA], const double qdd[P_NA], double tau[P_NA],
                       p_info* info);

/* The actuator-space mass matrix M_a (P_NA x P_NA) and the gravity efforts g_a (P_NA). */
int p_mass_matrix(const double q[P_NQ], double M[P_NA * P_NA], p_info* info);
int p_gravity(const double q[P_NQ], double g[P_NA], p_info* info);
"""
