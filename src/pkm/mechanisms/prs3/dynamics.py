"""3-PRS inverse dynamics in closed form: Khalil's projection specialised, and its symbolic twin.

One algorithm, written once over a small set of operations, runs on three backends:

* **numpy** arrays of shape (N,): the vectorised batch route (:meth:`Prs3Dynamics.batch`);
* **CasADi SX** symbols: the symbolic twin, whose expression graph after common-subexpression
  elimination gives the operation count (:func:`operation_count`) and C code
  (:func:`generate_c`); its numeric ``Function`` serves single calls (:meth:`Prs3Dynamics.forces`);
* the reference route is not this code: :meth:`Prs3Dynamics.pinocchio` builds the state with the
  closed-form IK and the generic core, and projects Pinocchio's RNEA with
  :class:`pkm.core.dynamics.projection.KhalilProjection`. Tests hold the two together to 1e-9.

The pipeline, from the independent coordinates ``y = (z_p, beta, phi)`` and their first and second
time derivatives to the three actuator efforts (the boundary of the operation count):

1. platform orientation ``alpha`` (eq. 15), ``R = Rz(alpha) Ry(beta) Rx(phi)`` (eq. 1) and the parasitic
   position ``x_p = h (R00 - R11) / 2``, ``y_p = -h R10`` (eq. 15 corrected, see :mod:`pkm.mechanisms.prs3`);
2. platform angular velocity and acceleration in closed form: ``omega_x, omega_y`` from the
   Euler rates, ``omega_z (R00 + R11) = omega_x R20 + omega_y R21`` (the time derivative of the
   leg-plane condition ``R01 = R10``), and likewise for the accelerations;
3. per leg, the spherical-joint centre ``B_i``, its velocity and acceleration, the leg's inverse
   kinematics (eq. 10 with its square) and its joint rates and accelerations from
   ``dB = dd u1 + l dtheta (cos theta u1 - sin theta w)``;
4. per leg, recursive Newton-Euler of the slider-coupler chain (forces in the slider frame) with
   gravity as a base acceleration: ``h_d``, ``h_theta``;
5. the platform's Newton-Euler wrench (eq. 36, with the opposite sign: the wrench the legs must
   supply) minus an optional external wrench;
6. Khalil's projection (eq. 38): the passive joints' efforts become forces at ``B_i``
   (``G_2^T h_p``), and ``J_k^T`` is applied by solving the 6x6 wrench system whose columns are the
   actuated and constraint wrenches of the legs, by Gaussian elimination in a fixed order
   (constraint unknowns first) whose pivots stay away from zero off singularities.

Departures from the paper:

* eqs. (24)-(26) take the platform's linear velocity as independent and solve for ``omega``
  through ``J_r2``; at ``beta = phi = 0`` (where every trajectory of sec. 5 starts) ``J_r2`` is
  singular, because ``x_p, y_p`` are stationary there. Here ``(z_p, beta, phi)`` and their
  derivatives are independent and ``omega`` follows in closed form (step 2): no inversion, valid
  wherever the Euler angles are (``|beta| < pi/2`` and ``R00 + R11 != 0``).
* eqs. (32)-(33): the velocity-product term of the leg accelerations is
  ``ddB_w = -sigma ddtheta - c_w dtheta^2``, ``ddB_u = ddd + c_w ddtheta - sigma dtheta^2``
  (``sigma = l sin theta``, ``c_w = l cos theta``); the printed one has second derivatives
  where products of first derivatives belong.
* eq. (36) is the wrench the platform's inertia and weight exert; the projection uses the
  opposite (the wrench needed to move it), as Khalil does.

Inertial parameters follow Khalil's standard set per leg: ``m1`` (slider), ``m2``, ``MSa`` and
``MSp`` (first moments of the coupler along it and across it, in the leg plane: Table 2's
``m_x2``, ``m_y2``), ``ZZ2`` (coupler inertia about the knee axis through the knee: Table 2's
``I_zz2 + m2 (l/2)^2``); platform ``mp`` and its inertia about its centre of mass ``p`` in
platform axes. Gravity is ``G = 9.81 m/s^2`` along ``-Z`` (Pinocchio's default), a constant.
"""

from __future__ import annotations

import functools
import math
import pathlib
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from pkm.core.differential.velocity import inverse_accelerations, inverse_velocities
from pkm.core.dynamics.projection import KhalilProjection
from pkm.errors import InvalidInputError, NonFiniteError, SingularityError, UnreachableError
from pkm.mechanisms.prs3 import BRANCHES, PHI, Prs3Params, as_task, branch_names, build, configuration
from pkm.validation import as_array, as_count

G = 9.81
INERTIAL = ("m1", "m2", "MSa", "MSp", "ZZ2", "mp", "Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")
GEOMETRY = ("l", "h", "g", "cg", "sg")
PIVOT_TOL = 1e-9   # relative: |pivot| below this times the column scale is a direct singularity
SIGMA_TOL = 1e-7   # relative to l: |l sin theta| below this is an inverse (leg) singularity; the radicand's
                   # rounding (1e-16 l^2) alone puts 1e-8 l of noise on l sin theta


# ---------------------------------------------------------------------- parameters
def numeric_parameters(params: Prs3Params) -> dict[str, float]:
    """The algorithm's parameters (``GEOMETRY`` + ``INERTIAL``) for a design, SI.

    ``cos gamma`` and ``sin gamma`` within 1e-15 of 0 or +-1 are snapped to it (pi/2 is not a float).
    The coupler's centre of mass is at ``l/2`` and its inertia ``m2 l^2 / 12`` about it, as in the
    URDF: ``MSa = m2 l / 2``, ``MSp = 0``, ``ZZ2 = m2 l^2 / 3``.
    """
    def snap(x: float) -> float:
        for c in (0.0, 1.0, -1.0):
            if abs(x - c) < 1e-15:
                return c
        return x

    p = params
    I = p.platform_inertia
    return {"l": p.l, "h": p.h, "g": p.g, "cg": snap(math.cos(p.gamma)), "sg": snap(math.sin(p.gamma)),
            "m1": p.m_slider, "m2": p.m_coupler, "MSa": p.m_coupler * p.l / 2, "MSp": 0.0,
            "ZZ2": p.m_coupler * p.l**2 / 3, "mp": p.m_platform, "Ixx": I[0, 0], "Iyy": I[1, 1], "Izz": I[2, 2],
            "Ixy": I[0, 1], "Ixz": I[0, 2], "Iyz": I[1, 2]}


# ---------------------------------------------------------------------- the algorithm
def _is(x, c: float) -> bool:
    return isinstance(x, (int, float)) and x == c


def _mul(a, b):
    """``a * b`` folding exact Python constants 0 and +-1 (the layout's and the design's)."""
    if _is(a, 0) or _is(b, 0):
        return 0.0
    if _is(a, 1):
        return b
    if _is(b, 1):
        return a
    if _is(a, -1):
        return -b
    if _is(b, -1):
        return -a
    return a * b


def _add(*terms):
    out = 0.0
    for t in terms:
        if _is(t, 0):
            continue
        out = t if _is(out, 0) else out + t
    return out


def _sub(a, b):
    if _is(b, 0):
        return a
    return -b if _is(a, 0) else a - b


def _cross(a, b):
    return (_sub(_mul(a[1], b[2]), _mul(a[2], b[1])),
            _sub(_mul(a[2], b[0]), _mul(a[0], b[2])),
            _sub(_mul(a[0], b[1]), _mul(a[1], b[0])))


def _leg_axes(i: int, P: dict):
    """World components of ``e_r``, ``e_t`` (layout constants), ``u1`` and ``w`` of leg ``i``."""
    c, s = math.cos(PHI[i]), math.sin(PHI[i])
    c, s = (0.0 if abs(c) < 1e-15 else c), (0.0 if abs(s) < 1e-15 else s)
    er, et = (c, s, 0.0), (-s, c, 0.0)
    u1 = (_mul(P["cg"], c), _mul(P["cg"], s), P["sg"])
    w = (_mul(-1.0, _mul(P["sg"], c)), _mul(-1.0, _mul(P["sg"], s)), P["cg"])
    return er, et, u1, w


def _dot(a, b):
    return _add(*(_mul(x, y) for x, y in zip(a, b)))


def algorithm(y, yd, ydd, wrench, P: dict, X, *, actuation: str = "P", signs=(1, 1, 1)) -> dict:
    """The whole pipeline (module doc) on any backend.

    Args:
        y, yd, ydd: ``(z_p, beta, phi)`` [m, rad], their rates and accelerations; each entry a
            scalar of the backend (float, numpy array of samples, CasADi SX).
        wrench: ``None`` or 6 backend scalars: external force [N] and moment [N m] on the
            platform, world axes, moment about ``p``.
        P: Parameters (``GEOMETRY`` + ``INERTIAL``), numbers or symbols.
        X: The backend's ``sin, cos, sqrt, atan2``.
        actuation: ``"P"`` or ``"R"``.
        signs: Per leg, +1 for ``slider_below``, -1 for ``slider_above``.

    Returns:
        ``tau`` (3 actuator efforts), ``qa``/``qa_d``/``qa_dd`` (actuated coordinates, rates and
        accelerations), the
        singularity measures ``sigma`` (``l sin theta_i`` per leg), ``radicand`` (per leg) and
        ``pivots`` (of the 6x6 elimination, with their column scales).
    """
    z, beta, phi = y
    _, bd, fd = yd
    zdd, bdd, fdd = ydd
    h, l = P["h"], P["l"]
    # 1. orientation (eq. 15: alpha), rotation (eq. 1), parasitic position (eq. 15 corrected)
    sb, cb, sf, cf = X.sin(beta), X.cos(beta), X.sin(phi), X.cos(phi)
    sbsf, sbcf = sb * sf, sb * cf
    alpha = X.atan2(sbsf, cf + cb)
    sa, ca = X.sin(alpha), X.cos(alpha)
    R00, R10, R20 = ca * cb, sa * cb, -sb
    R01, R11, R21 = ca * sbsf - sa * cf, sa * sbsf + ca * cf, cb * sf
    R02, R12, R22 = ca * sbcf + sa * sf, sa * sbcf - ca * sf, cb * cf
    R = ((R00, R01, R02), (R10, R11, R12), (R20, R21, R22))
    hh = _mul(0.5, h)
    p = (_mul(hh, R00 - R11), _mul(-1.0, _mul(h, R10)), z)
    # 2. angular velocity, its effect on R, linear velocity
    S = R00 + R11
    inv_S = 1.0 / S
    wx = R00 * fd - sa * bd
    wy = R10 * fd + ca * bd
    wz = (wx * R20 + wy * R21) * inv_S
    om = (wx, wy, wz)
    Rd00, Rd10, Rd20 = wy * R20 - wz * R10, wz * R00 - wx * R20, wx * R10 - wy * R00
    Rd01, Rd11, Rd21 = wy * R21 - wz * R11, wz * R01 - wx * R21, wx * R11 - wy * R01
    v = (_mul(hh, Rd00 - Rd11), _mul(-1.0, _mul(h, Rd10)), yd[0])
    # angular acceleration: Euler-rate terms, then omega_z from the second derivative of R01 = R10
    ad = wz - R20 * fd  # d alpha / dt
    wxd = R00 * fdd + Rd00 * fd - sa * bdd - ca * ad * bd
    wyd = R10 * fdd + Rd10 * fd + ca * bdd - sa * ad * bd
    wzd = (wxd * R20 + wyd * R21 + wy * Rd21 - wz * (Rd11 + Rd00) + wx * Rd20) * inv_S
    omd = (wxd, wyd, wzd)
    Rdd00 = wyd * R20 - wzd * R10 + wy * Rd20 - wz * Rd10
    Rdd11 = wzd * R01 - wxd * R21 + wz * Rd01 - wx * Rd21
    Rdd10 = wzd * R00 - wxd * R20 + wz * Rd00 - wx * Rd20
    acc = (_mul(hh, Rdd00 - Rdd11), _mul(-1.0, _mul(h, Rdd10)), zdd)

    # 5. platform Newton-Euler (body axes for the inertia), minus the external wrench
    mp = P["mp"]
    I = ((P["Ixx"], P["Ixy"], P["Ixz"]), (P["Ixy"], P["Iyy"], P["Iyz"]), (P["Ixz"], P["Iyz"], P["Izz"]))
    wb = tuple(_dot((R[0][j], R[1][j], R[2][j]), om) for j in range(3))
    wdb = tuple(_dot((R[0][j], R[1][j], R[2][j]), omd) for j in range(3))
    Iw = tuple(_dot(I[j], wb) for j in range(3))
    nb = tuple(_dot(I[j], wdb) + c for j, c in enumerate(_cross(wb, Iw)))
    F = [_mul(mp, acc[0]), _mul(mp, acc[1]), _mul(mp, acc[2] + G)]
    M = [_dot(R[j], nb) for j in range(3)]
    if wrench is not None:
        F = [_sub(F[j], wrench[j]) for j in range(3)]
        M = [_sub(M[j], wrench[3 + j]) for j in range(3)]

    # 3-4. legs: kinematics, recursive Newton-Euler, passive efforts as forces at B_i
    cols_c, cols_a, tau_leg, qa, qa_d, qa_dd, sigmas, rads = [], [], [], [], [], [], [], []
    aSw = _mul(G, P["cg"])  # gravity as base acceleration, w component (constant)
    for i in range(3):
        er, et, u1, w = _leg_axes(i, P)
        r = tuple(_mul(h, _add(_mul(R[j][0], er[0]), _mul(R[j][1], er[1]))) for j in range(3))
        wr = _cross(om, r)
        Bd = tuple(v[j] + wr[j] for j in range(3))
        Bdd = tuple(acc[j] + c1 + c2 for j, (c1, c2) in enumerate(zip(_cross(omd, r), _cross(om, wr))))
        c = (p[0] + r[0] - _mul(P["g"], er[0]), p[1] + r[1] - _mul(P["g"], er[1]), z + r[2])
        cu, cw = _dot(c, u1), _dot(c, w)
        rad = l * l - cw * cw
        sigma = _mul(float(signs[i]), X.sqrt(rad))
        inv_sigma = 1.0 / sigma
        Bdu, Bdw = _dot(Bd, u1), _dot(Bd, w)
        Bddu, Bddw = _dot(Bdd, u1), _dot(Bdd, w)
        td = -Bdw * inv_sigma
        td2 = td * td
        dd = Bdu - cw * td
        tdd = -(Bddw + cw * td2) * inv_sigma
        ddd = Bddu - cw * tdd + sigma * td2
        # Newton-Euler of slider + coupler, in the slider frame (u1, e_t, w)
        st, ct = sigma / l, cw / l
        MSu = _add(_mul(P["MSa"], st), _mul(P["MSp"], ct))
        MSw = _sub(_mul(P["MSa"], ct), _mul(P["MSp"], st))
        aSu = ddd + _mul(G, P["sg"])
        hd = _sub(_add(_mul(_add(P["m1"], P["m2"]), aSu), _mul(tdd, MSw)), _mul(td2, MSu))
        ht = _sub(_add(_mul(P["ZZ2"], tdd), _mul(MSw, aSu)), _mul(MSu, aSw))
        if actuation == "P":
            k = cw * inv_sigma
            act_dir = tuple(_add(u1[j], _mul(k, w[j])) for j in range(3))   # dd = act_dir . dB
            fpass = tuple(_mul(-(ht * inv_sigma), w[j]) for j in range(3))   # h_theta dtheta as a force
            tau_leg.append(hd)
            qa.append(cu - sigma)
            qa_d.append(dd)
            qa_dd.append(ddd)
        else:
            act_dir = w                                                     # dtheta = -(w . dB) / sigma
            fpass = tuple(_mul(hd, _add(u1[j], _mul(cw * inv_sigma, w[j]))) for j in range(3))
            tau_leg.append(ht)
            qa.append(X.atan2(sigma, cw))
            qa_d.append(td)
            qa_dd.append(tdd)
        for j, m in enumerate(_cross(r, fpass)):
            F[j] = _add(F[j], fpass[j])
            M[j] = _add(M[j], m)
        cols_c.append((*et, *_cross(r, et)))
        cols_a.append((*act_dir, *_cross(r, act_dir)))
        sigmas.append(sigma)
        rads.append(rad)

    # 6. J_k^T by elimination: unknowns (lambda_1..3, f_1..3), equations (Fy, Fx, Mz, Fz, Mx, My);
    #    leg 1's constraint direction e_t,1 = (0, 1, 0) makes Fy its pivot
    order = (1, 0, 5, 2, 3, 4)
    cols = cols_c + cols_a
    A = [[cols[k][e] for k in range(6)] for e in order]
    b = [(F + M)[e] for e in order]
    f, pivots = _solve_last3(A, b)
    if actuation == "P":
        tau = [tau_leg[i] + f[i] for i in range(3)]
    else:
        tau = [tau_leg[i] - sigmas[i] * f[i] for i in range(3)]
    return {"tau": tau, "qa": qa, "qa_d": qa_d, "qa_dd": qa_dd, "sigma": sigmas, "radicand": rads,
            "pivots": pivots}


def _solve_last3(A, b):
    """Gaussian elimination without pivoting on 6x6 ``A x = b``; returns ``x[3:]`` and the pivots."""
    A = [list(row) for row in A]
    b = list(b)
    inv, pivots = [], []
    for k in range(6):
        ik = 1.0 / A[k][k]
        inv.append(ik)
        pivots.append(A[k][k])
        for i in range(k + 1, 6):
            if _is(A[i][k], 0):
                continue
            fct = A[i][k] * ik
            for j in range(k + 1, 6):
                A[i][j] = _sub(A[i][j], _mul(fct, A[k][j]))
            b[i] = _sub(b[i], _mul(fct, b[k]))
    x = [None] * 6
    for k in (5, 4, 3):
        s = b[k]
        for j in range(k + 1, 6):
            s = _sub(s, _mul(A[k][j], x[j]))
        x[k] = _mul(s, inv[k])
    return x[3:], pivots


NUMPY = SimpleNamespace(sin=np.sin, cos=np.cos, sqrt=np.sqrt, atan2=np.arctan2)
CASADI_OPS = None  # filled on first use: casadi is imported lazily (it is slow to import)


def _casadi():
    global CASADI_OPS
    import casadi as ca

    if CASADI_OPS is None:
        CASADI_OPS = SimpleNamespace(sin=ca.sin, cos=ca.cos, sqrt=ca.sqrt, atan2=ca.atan2)
    return ca, CASADI_OPS


# ---------------------------------------------------------------------- symbolic twin
@dataclass(frozen=True)
class OpCount:
    """Operations of the symbolic twin after common-subexpression elimination.

    Counted as SYMORO and the papers count: ``*``, ``/`` and squares as multiplications, ``+``
    and ``-`` as additions, negations free; transcendental functions apart.

    Attributes:
        mode: ``"symbolic"`` (geometry and inertia symbols), ``"inertial"`` (geometry numeric,
            inertial parameters symbols) or ``"numeric"`` (everything numeric, Table 2).
        actuation: ``"P"`` or ``"R"``.
        mul: Multiplications and divisions.
        add: Additions and subtractions.
        functions: Count per transcendental function (``sin cos sqrt atan2``).
        boundary: What the count covers, in words.
    """

    mode: str
    actuation: str
    mul: int
    add: int
    functions: dict
    boundary: str


BOUNDARY = ("in: z_p, beta, phi and their first and second time derivatives (9 numbers); out: the 3 actuator "
            "efforts. Included: parasitic motion, platform velocity and acceleration, leg inverse kinematics of "
            "position, velocity and acceleration, leg recursive Newton-Euler with gravity, platform Newton-Euler, "
            "Khalil's projection (passive efforts and J_k^T by elimination). No external wrench.")
MODES = ("symbolic", "inertial", "numeric")
_ZERO6 = np.zeros(6)
_HALF_PI = math.pi / 2


def twin(params: Prs3Params | None = None, *, mode: str = "numeric", outputs: str = "tau", wrench: bool = False,
         branch=None):
    """The symbolic twin as a CasADi ``Function`` (expressions after ``casadi.cse``).

    Args:
        params: The design (Table 2 when None); its numbers stay numbers unless ``mode`` makes them symbols.
        mode: One of :data:`MODES` (see :class:`OpCount`).
        outputs: ``"tau"`` (the efforts only: the counted function) or ``"all"`` (also actuated
            coordinates and rates, and the singularity measures: the numeric single-call route).
        wrench: Add a 6-vector input for an external platform wrench.
        branch: Working mode per leg (``slider_below`` default).

    Returns:
        A ``casadi.Function`` with inputs ``y, yd, ydd`` (3 each), then ``wrench`` (6) if asked,
        then the symbolic parameters in order (``INERTIAL`` then ``GEOMETRY`` as the mode asks);
        outputs ``tau`` (3) and, for ``"all"``, ``qa``, ``qa_d``, ``checks`` (``radicand``
        3, ``sigma`` 3, ``pivots`` 6).
    """
    if mode not in MODES:
        raise InvalidInputError("mode", f"use one of {MODES}", mode)
    ca, ops = _casadi()
    params = Prs3Params() if params is None else params
    P = numeric_parameters(params)
    keys = {"symbolic": INERTIAL + GEOMETRY, "inertial": INERTIAL, "numeric": ()}[mode]
    syms = []
    for k in keys:
        P[k] = ca.SX.sym(k)
        syms.append(P[k])
    y, yd, ydd = ca.SX.sym("y", 3), ca.SX.sym("yd", 3), ca.SX.sym("ydd", 3)
    w = ca.SX.sym("wrench", 6) if wrench else None
    signs = [BRANCHES[b] for b in branch_names(branch)]
    out = algorithm([y[i] for i in range(3)], [yd[i] for i in range(3)], [ydd[i] for i in range(3)],
                    None if w is None else [w[i] for i in range(6)], P, ops, actuation=params.actuation, signs=signs)
    res = [ca.vertcat(*out["tau"])]
    names = ["tau"]
    if outputs == "all":
        res += [ca.vertcat(*out["qa"]), ca.vertcat(*out["qa_d"]),
                ca.vertcat(*out["radicand"], *out["sigma"], *out["pivots"])]
        names += ["qa", "qa_d", "checks"]
    res = ca.cse(res)
    inputs = [y, yd, ydd] + ([w] if wrench else []) + syms
    in_names = ["y", "yd", "ydd"] + (["wrench"] if wrench else []) + [str(s) for s in syms]
    return ca.Function(f"prs3_id_{params.actuation}", inputs, res, in_names, names)


def operation_count(params: Prs3Params | None = None, *, mode: str = "inertial") -> OpCount:
    """Count the twin's operations (see :class:`OpCount`, :data:`BOUNDARY`)."""
    from pkm.core.twin.codegen import count_operations

    params = Prs3Params() if params is None else params
    counts = count_operations(twin(params, mode=mode))
    known = {"mul", "div", "sq", "add", "sub", "neg", "sin", "cos", "sqrt", "atan2", "input", "output", "const"}
    if set(counts) - known:
        raise RuntimeError(f"operations the counter does not classify: {sorted(set(counts) - known)}")
    return OpCount(mode, params.actuation, counts.get("mul", 0) + counts.get("div", 0) + counts.get("sq", 0),
                   counts.get("add", 0) + counts.get("sub", 0),
                   {k: counts.get(k, 0) for k in ("sin", "cos", "sqrt", "atan2")}, BOUNDARY)


def generate_c(path, params: Prs3Params | None = None, *, mode: str = "numeric") -> str:
    """Write the twin (efforts only) as self-contained C to ``path``; returns the function's name.

    The generated function has CasADi's calling convention
    (``int NAME(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem)``).
    """
    ca, _ = _casadi()
    f = twin(params, mode=mode)
    path = pathlib.Path(path)
    gen = ca.CodeGenerator(path.name, {"with_header": True})
    gen.add(f)
    gen.generate(str(path.parent) + "/")
    return f.name()


# ---------------------------------------------------------------------- numeric API
@dataclass(frozen=True)
class DynamicsResult:
    """Actuator efforts along samples of a motion (arrays of shape (N, 3), or (3,) for one).

    Attributes:
        tau: Efforts [N] (sliders) or [N m] (knees).
        q_actuated: Actuated coordinates ``d_i`` [m] or ``theta_i`` [rad].
        qd_actuated: Their rates [m/s] or [rad/s].
        qdd_actuated: Their accelerations [m/s^2] or [rad/s^2] (batch results only, else None).
        power: ``tau * qd_actuated`` [W].
    """

    tau: np.ndarray
    q_actuated: np.ndarray
    qd_actuated: np.ndarray
    qdd_actuated: np.ndarray | None = None

    @property
    def power(self) -> np.ndarray:
        return self.tau * self.qd_actuated


class Prs3Dynamics:
    """Inverse dynamics of a 3-PRS for platform motions given in ``(z_p, beta, phi)``.

    Args:
        params: The design (Table 2, P-actuated, when None).
        branch: Working mode, ``"slider_below"`` (default) or ``"slider_above"``, or one per leg.

    Example::

        dyn = Prs3Dynamics()
        tau = dyn.forces([0.81, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])  # [N], ~26.2 each
    """

    def __init__(self, params: Prs3Params | None = None, branch=None):
        self.params = Prs3Params() if params is None else params
        self.branch = branch_names(branch)
        self.signs = tuple(BRANCHES[b] for b in self.branch)
        self.P = numeric_parameters(self.params)

    @functools.cached_property
    def _function(self):
        """The twin with one packed input ``(y, yd, ydd, wrench)`` (15) and one packed output
        ``(tau, qa, qa_d, radicand, sigma, pivots)`` (21), evaluated in place on numpy buffers
        (CasADi's ``Function.buffer``: no conversion per call; one object per thread)."""
        ca, _ = _casadi()
        f = twin(self.params, mode="numeric", outputs="all", wrench=True, branch=self.branch)
        x = ca.SX.sym("x", 15)
        packed = ca.Function("prs3_id_packed", [x], [ca.vertcat(*f(x[0:3], x[3:6], x[6:9], x[9:15]))])
        buf, run = packed.buffer()
        arg, res = np.zeros(15), np.zeros(21)
        buf.set_arg(0, memoryview(arg))
        buf.set_res(0, memoryview(res))
        return packed, buf, run, arg, res

    def forces(self, y, yd, ydd, wrench=None) -> np.ndarray:
        """Actuator efforts (3,) for one sample, through the twin's expression graph.

        Args:
            y: ``(z_p [m], beta [rad], phi [rad])``.
            yd: Their rates [m/s, rad/s].
            ydd: Their accelerations [m/s^2, rad/s^2].
            wrench: Optional external wrench on the platform: force [N] and moment about ``p``
                [N m], world axes.

        Raises:
            InvalidInputError: Mis-shaped or non-finite input, ``|beta| >= pi/2``.
            UnreachableError: A leg cannot reach (which, and by how much).
            SingularityError: An inverse (leg) or direct singularity at this configuration.
        """
        return self._evaluate(y, yd, ydd, wrench)[0:3]

    def evaluate(self, y, yd, ydd, wrench=None) -> DynamicsResult:
        """Efforts, actuated coordinates and rates for one sample (see :meth:`forces`)."""
        r = self._evaluate(y, yd, ydd, wrench)
        return DynamicsResult(r[0:3], r[3:6], r[6:9])

    def _evaluate(self, y, yd, ydd, wrench) -> np.ndarray:
        try:
            x = np.concatenate((y, yd, ydd, _ZERO6 if wrench is None else wrench), dtype=float)
            ok = x.shape == (15,) and abs(x[1]) < _HALF_PI and np.isfinite(x).all()
        except (TypeError, ValueError, OverflowError):
            ok = False
        if not ok:  # the slow path names what is wrong
            x = np.concatenate(self._sample(y, yd, ydd, wrench))
        _, _, run, arg, res = self._function
        arg[:] = x
        run()
        r = res.copy()
        c = r[9:]
        if not (c[0:3].min() >= 0.0 and np.abs(c[3:6]).min() > SIGMA_TOL * self.params.l
                and np.abs(c[6:12]).min() > PIVOT_TOL * max(1.0, self.params.h)):
            self._check(c.reshape(1, -1), None)
        if not np.all(np.isfinite(r[:9])):
            raise NonFiniteError("actuator efforts", r[:9], "the rates or accelerations are too large (overflow); "
                                                           "check the units (m/s, rad/s)")
        return r

    def batch(self, Y, Yd, Ydd, wrench=None, *, t=None, chunk: int = 16384) -> DynamicsResult:
        """Efforts along N samples at once (vectorised numpy, the same algorithm as the twin).

        Args:
            Y, Yd, Ydd: Arrays (N, 3) of ``(z_p, beta, phi)`` and their derivatives.
            wrench: None, one wrench (6,) for every sample, or (N, 6).
            t: Optional sample times [s] (N,), used in error messages.
            chunk: Samples per vectorised pass (bounds the memory of the temporaries).

        Raises:
            InvalidInputError, UnreachableError, SingularityError: as :meth:`forces`, naming the first
                offending sample (and its time when ``t`` is given).
        """
        Y, Yd, Ydd = (_samples(a, 3, n) for a, n in ((Y, "Y"), (Yd, "Yd"), (Ydd, "Ydd")))
        N = len(Y)
        if len(Yd) != N or len(Ydd) != N:
            raise InvalidInputError("Yd", f"Y, Yd and Ydd need the same number of samples, got {N}, {len(Yd)}, "
                                          f"{len(Ydd)}")
        chunk = as_count(chunk, "chunk", low=1, high=10**7)
        W = None
        if wrench is not None:
            W = as_array(wrench, "wrench", "a wrench (6,) or (N, 6) [N, N m]")
            W = np.broadcast_to(_samples(W[None], 6, "wrench")[0], (N, 6)) if W.shape == (6,) else \
                _samples(W, 6, "wrench")
            if len(W) != N:
                raise InvalidInputError("wrench", f"expected (6,) or ({N}, 6), got {W.shape}")
        if t is not None:
            t = _samples(as_array(t, "t", "sample times (N,) [s]").reshape(-1, 1), 1, "t").ravel()
            if len(t) != N:
                raise InvalidInputError("t", f"expected {N} sample times, got {len(t)}", t)
        bad = np.nonzero(np.abs(Y[:, 1]) >= math.pi / 2)[0]
        if len(bad):
            raise InvalidInputError("Y", f"{_where(bad[0], t)}: pitch beta = {Y[bad[0], 1]!r} rad; Z-Y-X angles "
                                         "need |beta| < pi/2", Y[bad[0]])
        tau, qa, qad, qadd = (np.empty((N, 3)) for _ in range(4))
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):  # overflow is reported below
            for s in range(0, N, chunk):
                sl = slice(s, s + chunk)
                out = algorithm(Y[sl].T, Yd[sl].T, Ydd[sl].T, None if W is None else W[sl].T, self.P, NUMPY,
                                actuation=self.params.actuation, signs=self.signs)
                n = len(Y[sl])
                checks = _columns([*out["radicand"], *out["sigma"], *out["pivots"]], n)
                self._check(checks, None if t is None else t[sl], offset=s)
                tau[sl], qa[sl], qad[sl], qadd[sl] = (_columns(out[k], n) for k in ("tau", "qa", "qa_d", "qa_dd"))
        for name, arr in (("tau", tau), ("q_actuated", qa), ("qd_actuated", qad), ("qdd_actuated", qadd)):
            if not np.all(np.isfinite(arr)):
                k = int(np.argmax(~np.isfinite(arr).all(axis=1)))
                raise NonFiniteError(f"{name} at {_where(k, t)}", arr[k], "the rates or accelerations are too large "
                                     "(overflow); check the units (m/s, rad/s)")
        return DynamicsResult(tau, qa, qad, qadd)

    def jacobian(self, y) -> np.ndarray:
        """``J = d q_a / d y`` (3x3) at ``y = (z_p, beta, phi)``: ``qd_a = J yd`` (closed form).

        Column ``k`` is the actuated rate for ``yd = e_k``; it is defined wherever the Euler angles
        are and no leg is singular, ``beta = phi = 0`` included (see the module doc on eq. 26).
        """
        y = self._sample(y, np.zeros(3), np.zeros(3), None)[0]
        return self.batch(np.tile(y, (3, 1)), np.eye(3), np.zeros((3, 3))).qd_actuated.T

    def homogeneous_jacobian(self, y) -> np.ndarray:
        """The Jacobian in dimensionally homogeneous form, its characteristic lengths explicit.

        Inputs ``(zd_p, h beta_d, h phi_d)`` (m/s: the platform radius ``h`` turns rates of
        rotation into speeds of the spherical joints), outputs ``dd_i`` (m/s, P-actuated) or
        ``l theta_d_i`` (m/s, R-actuated: the coupler length ``l``). Its condition number does not
        depend on the unit of length.
        """
        J = self.jacobian(y) / np.array([1.0, self.params.h, self.params.h])
        return J * self.params.l if self.params.actuation == "R" else J

    def pinocchio(self, y, yd, ydd, wrench=None) -> np.ndarray:
        """The reference route: closed-form IK, the generic core's velocities and accelerations,
        Pinocchio's RNEA and :class:`~pkm.core.dynamics.projection.KhalilProjection` on the URDF model."""
        q, v, a = self.state(y, yd, ydd)
        return self._projection.inverse_dynamics(q, v, a, wrench)

    def state(self, y, yd, ydd) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Joint configuration, velocities and accelerations of the tree model for a sample."""
        y, yd, ydd, _ = self._sample(y, yd, ydd, None)
        q = configuration(self.mechanism, y, self.branch)
        v = inverse_velocities(self.mechanism, q, yd)
        return q, v, inverse_accelerations(self.mechanism, q, v, ydd)

    @functools.cached_property
    def mechanism(self):
        """The Pinocchio model of the same design."""
        return build(self.params)

    @functools.cached_property
    def _projection(self):
        return KhalilProjection(self.mechanism)

    # -------------------------------------------------------------- checks
    @staticmethod
    def _sample(y, yd, ydd, wrench):
        y = as_task(y, "y")
        yd, ydd = (_samples(as_array(a, n, "3 rates").reshape(1, -1), 3, n)[0] for a, n in ((yd, "yd"),
                                                                                           (ydd, "ydd")))
        w = np.zeros(6) if wrench is None else _samples(as_array(wrench, "wrench", "a wrench (6,)").reshape(1, -1), 6,
                                                        "wrench")[0]
        return y, yd, ydd, w

    def _check(self, checks: np.ndarray, t, offset: int = 0) -> None:
        """Raise for the first sample whose leg cannot reach or whose configuration is singular."""
        l, h = self.params.l, self.params.h
        rad, sigma, piv = checks[:, 0:3], checks[:, 3:6], checks[:, 6:12]
        bad_rad = rad < -1e-12 * l * l
        bad_sig = ~(np.abs(sigma) > SIGMA_TOL * l)
        bad_piv = ~(np.abs(piv) > PIVOT_TOL * max(1.0, h))
        bad = bad_rad.any(axis=1) | bad_sig.any(axis=1) | bad_piv.any(axis=1)
        if not bad.any():
            return
        k = int(np.argmax(bad))
        where = _where(k + offset, None if t is None else t[k:k + 1], local=True)
        if bad_rad[k].any():  # a radicand rounded to within -1e-12 l^2 of 0 (NaN sigma) is the double root
            leg = int(np.argmax(bad_rad[k]))
            excess = math.sqrt(max(l * l - rad[k, leg], 0.0)) - l
            raise UnreachableError(leg + 1, excess, "m", f"{where}: the spherical joint is farther than l from "
                                                          "the rail")
        if bad_sig[k].any():
            leg = int(np.argmax(bad_sig[k]))
            raise SingularityError("inverse", float(np.nan_to_num(abs(sigma[k, leg]))),
                                   f"{where}: leg {leg + 1}'s coupler is perpendicular to its rail")
        raise SingularityError("direct", float(np.min(np.abs(piv[k]))),
                               f"{where}: the legs' actuation and constraint wrenches are dependent")


def _columns(values, n: int) -> np.ndarray:
    """Stack per-sample results as columns, broadcasting the ones that came out constant."""
    return np.column_stack([np.broadcast_to(np.asarray(x, dtype=float), (n,)) for x in values])


def _samples(a, n: int, name: str) -> np.ndarray:
    arr = as_array(a, name, f"an array of shape (N, {n}) of numbers")
    if arr.ndim != 2 or arr.shape[1] != n or arr.shape[0] == 0:
        raise InvalidInputError(name, f"expected shape (N, {n}) with N >= 1, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        k = int(np.argmax(~np.isfinite(arr).all(axis=1)))
        raise InvalidInputError(name, f"sample {k} is not finite: {arr[k].tolist()}")
    return arr


def _where(k: int, t, *, local: bool = False) -> str:
    if t is None:
        return f"sample {k}"
    return f"sample {k} (t = {float(t[0] if local else t[k]):.6g} s)"


__all__ = [
    "BOUNDARY",
    "GEOMETRY",
    "INERTIAL",
    "MODES",
    "DynamicsResult",
    "OpCount",
    "Prs3Dynamics",
    "algorithm",
    "generate_c",
    "numeric_parameters",
    "operation_count",
    "twin",
]
