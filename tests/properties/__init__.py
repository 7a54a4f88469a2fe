"""Property-based tests (Hypothesis) of the four mechanisms, and the strategies they share.

The strategies draw *designs* (each mechanism's ``Params`` over ranges where it assembles, its
reference pose constructed so that it is reachable and regular, random masses and inertias),
*poses* (offsets about the reference, scaled per design) and *motions* (sums of sines). The
settings profiles are in ``conftest.py``: ``ci`` (default, derandomized, sized for ``make test``)
and ``long`` (``PKM_HYPOTHESIS_PROFILE=long``, 10 times the examples, random seeds, about 10 minutes).

:func:`record` keeps the worst value of each measured error; ``conftest.py`` prints the table at
the end of the run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from hypothesis import assume, settings
from hypothesis import strategies as st

import pkm
from pkm.errors import InvalidParameterError, PkmError
from pkm.mechanisms import definition, delta, hexapod, prs3, rrr3
from pkm.mechanisms._common import rot_y

#: The reference ``max_examples`` :func:`examples` scales every test's count from: ``@examples(n)`` runs ``n`` examples
#: where the profile's ``max_examples`` is this (the ``ci`` profile runs half of it, the ``long`` one ten times).
CI_EXAMPLES = 10

#: Worst value of each measured error over the run (key -> value).
WORST: dict[str, float] = {}


def examples(n: int) -> settings:
    """Settings running ``n`` examples at the reference count :data:`CI_EXAMPLES`, proportionally to the profile's
    ``max_examples`` (``ci``: ``n / 2``; ``long``: ``10 n``)."""
    return settings(max_examples=max(1, round(n * settings.default.max_examples / CI_EXAMPLES)))


def record(key: str, value: float) -> float:
    """Remember ``value`` if it is the largest seen under ``key``; returns it (for ``assert record(...) <= tol``)."""
    value = float(value)
    if not value <= WORST.get(key, -math.inf):
        WORST[key] = value
    return value


def floats(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


def unit_box(n: int) -> st.SearchStrategy[np.ndarray]:
    """Vectors of ``n`` numbers in [-1, 1] (offsets, scaled by the test)."""
    return st.lists(floats(-1.0, 1.0), min_size=n, max_size=n).map(np.array)


def wrap(a):
    return (np.asarray(a, dtype=float) + np.pi) % (2.0 * np.pi) - np.pi


# ---------------------------------------------------------------------- motions
@dataclass(frozen=True)
class Sines:
    """``x(t) = sum_k A_k sin(w_k t + phi_k)`` (vectors ``A_k``) with its first two derivatives."""

    amplitude: np.ndarray  # (K, n)
    omega: np.ndarray  # (K,) [rad/s]
    phase: np.ndarray  # (K,) [rad]
    t: float  # a time of interest [s]

    def at(self, t: float, scale) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(x, xd, xdd)`` at time ``t``, coordinate ``i`` multiplied by ``scale[i]``."""
        arg = self.omega * t + self.phase
        s, c, w = np.sin(arg), np.cos(arg), self.omega
        A = self.amplitude * np.asarray(scale, dtype=float)
        return s @ A, (w * c) @ A, (-w * w * s) @ A

    def through(self, y, scale):
        """The task motion ``t -> (y0 + x, xd, xdd)`` that passes through ``y`` at :attr:`t`."""
        y0 = np.asarray(y, dtype=float) - self.at(self.t, scale)[0]

        def motion_at(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            x, xd, xdd = self.at(t, scale)
            return y0 + x, xd, xdd

        return motion_at


def _moving(A: np.ndarray) -> np.ndarray:
    """Amplitudes with at least one of magnitude 0.1 or more: a motion, not a rest below rounding."""
    if np.abs(A).max() < 0.1:
        A = A.copy()
        A[0, 0] = 0.1
    return A


def sines(n: int, k: int = 2) -> st.SearchStrategy[Sines]:
    """Random sums of ``k`` sines in ``n`` coordinates, amplitudes in [-1, 1] (scaled by the test), not all
    below 0.1."""
    return st.builds(Sines, st.lists(unit_box(n), min_size=k, max_size=k).map(np.array).map(_moving),
                     st.lists(floats(0.5, 3.0), min_size=k, max_size=k).map(np.array),
                     st.lists(floats(0.0, 2.0 * math.pi), min_size=k, max_size=k).map(np.array),
                     floats(0.0, 3.0))


def rotation_path(angles: tuple[np.ndarray, np.ndarray, np.ndarray], R0: np.ndarray):
    """``R = exp(s_1 e_x) exp(s_2 e_y) exp(s_3 e_z) R0`` with its angular velocity and acceleration (world).

    Args:
        angles: ``(s, sd, sdd)``, each of shape (3,) [rad, rad/s, rad/s^2].
        R0: Constant right factor.

    Returns:
        ``(R, w, wd)``: with ``a_k`` the k-th axis carried by the factors before it,
        ``w = sum sd_k a_k`` and ``wd = sum sdd_k a_k + sd_k (w_{<k} x a_k)``.
    """
    s, sd, sdd = angles
    R = np.eye(3)
    w, wd = np.zeros(3), np.zeros(3)
    for k in range(3):
        a = R[:, k]  # R is the product of the factors before k: it carries e_k to a_k
        wd = wd + sdd[k] * a + sd[k] * np.cross(w, a)
        w = w + sd[k] * a
        R = R @ pin.exp3(s[k] * np.eye(3)[k])
    return R @ R0, w, wd


# ---------------------------------------------------------------------- singular paths
#: Path parameters s_max * 10^-k, k = 0..8, approaching a singular configuration at s = 0.
DECADES = 10.0 ** -np.arange(9)


def two_link_reach(l1: float, l2: float, s: float, x: float, *, lower: bool = True) -> tuple[float, float]:
    """Angle ``a`` of a first link and height ``y`` of the tip of two links turned by ``s`` from each other.

    ``l1 (cos a, sin a) + l2 (cos(a + s), sin(a + s)) = (x, y)``; of the two solutions, the one with
    the lower (``lower=True``) or higher tip.
    """
    z = l1 + l2 * complex(math.cos(s), math.sin(s))
    K, d = abs(z), math.atan2(z.imag, z.real)
    c = math.acos(max(-1.0, min(1.0, x / K)))
    sols = [(wrap(-d + sg * c).item(), K * math.sin(sg * c)) for sg in (1.0, -1.0)]
    return min(sols, key=lambda t: t[1]) if lower else max(sols, key=lambda t: t[1])


def assert_vanishes(index: np.ndarray, what: str, *, final: float = 1e-6) -> None:
    """``index`` (along ``DECADES``) decreases strictly, to at most ``final`` times its first value, and
    linearly in ``s`` at the end (each of the last three decades of ``s`` divides it by 5 to 20)."""
    index = np.asarray(index, dtype=float)
    rel_index = index / index[0]
    record(f"{what}: index at s = 1e-8 s_max / index at s_max", rel_index[-1])
    assert np.all(np.diff(index) < 0.0), (what, index)
    assert rel_index[-1] <= final, (what, index)
    ratios = index[-4:-1] / index[-3:]
    assert np.all((ratios > 5.0) & (ratios < 20.0)), (what, index)


# ---------------------------------------------------------------------- designs
def generic_case(name: str):
    """``(designs, pose, n, length)`` for a registered mechanism without strategies of its own (the toy five-bar):
    its default design, poses about the reference within the registry's task scale."""
    entry = definition(name)
    mod = entry.module()
    p0 = mod.Params()
    mech = mod.build(p0)
    task = pkm.TaskMap(mech)
    y_ref = task.value(mech.q_reference)
    scale = np.array(entry.tangent_scale(task.names))

    def pose(p, u: np.ndarray) -> np.ndarray:
        return task.retract(y_ref, scale * u)

    return st.just(p0), pose, task.size, lambda p: float(max(entry.task_scale))
@st.composite
def delta_designs(draw, offset: tuple[float, float] = (0.2, 1.0)) -> delta.DeltaParams:
    """A Delta whose reference pose is on the axis with the arms at a drawn angle (knee out); ``R - r``
    within ``offset`` arm lengths."""
    La = draw(floats(0.05, 0.3))
    Lb = La * draw(floats(2.2, 3.5))
    r = La * draw(floats(0.2, 0.8))
    R = r + La * draw(floats(*offset))
    th0 = draw(floats(-0.9, 0.2))  # arm angle at the reference [rad]
    z = La * math.sin(th0) - math.sqrt(Lb**2 - (R - r + La * math.cos(th0)) ** 2)
    return delta.DeltaParams(La=La, Lb=Lb, r=r, R=R, home=(0.0, 0.0, z), m_arm=draw(floats(0.02, 0.5)),
                             m_forearm=draw(floats(0.01, 0.3)), m_platform=draw(floats(0.05, 1.0)))


@st.composite
def rrr3_designs(draw, mode=None) -> rrr3.Rrr3Params:
    """A 3-RRR of random size, centred reference pose in a random (or the given) working mode, regular there."""
    H = draw(floats(0.5, 2.0))
    a, b, h = H * draw(floats(0.35, 0.6)), H * draw(floats(0.35, 0.6)), H * draw(floats(0.05, 0.25))
    mode = draw(st.integers(1, 8)) if mode is None else mode
    try:
        p = rrr3.Rrr3Params(a=a, b=b, h=h, H=H, branch=mode, home=(0.0, 0.0, 0.0), m_proximal=draw(floats(0.01, 1.0)),
                            m_distal=draw(floats(0.01, 1.0)), m_platform=draw(floats(0.01, 1.0)))
        rrr3.reference_pose(p)
    except InvalidParameterError:
        assume(False)
    assume(min(rrr3.singularity_measures(p, rrr3.reference_pose(p))) > 1e-2)
    return p


@st.composite
def platform_inertias(draw, mass: float, radius: float) -> dict[str, float]:
    """A physical inertia tensor about the centre of mass (``tr(S) I - S``, ``S`` a random second moment)."""
    s = mass * radius**2 * np.array([draw(floats(0.05, 0.5)) for _ in range(3)])
    Q = pin.exp3(np.array([draw(floats(-math.pi, math.pi)) for _ in range(3)]))
    S = Q @ np.diag(s) @ Q.T
    I = np.trace(S) * np.eye(3) - S
    return {"Ixx3": I[0, 0], "Iyy3": I[1, 1], "Izz3": I[2, 2], "Ixy3": I[0, 1], "Ixz3": I[0, 2], "Iyz3": I[1, 2]}


@st.composite
def prs3_designs(draw, actuation: str | None = None, inclined: bool = False) -> prs3.Prs3Params:
    """A 3-PRS whose couplers make a drawn angle ``theta_0`` with the rail normal at the reference (slider below).

    Actuation drawn when None. Rails from 69 to 112 deg (vertical included) when the sliders are driven;
    inclined (52-74 or 106-129 deg) when the knees are (vertical rails make knee actuation singular
    everywhere) or with ``inclined``.
    """
    actuation = draw(st.sampled_from(sorted(prs3.ACTUATIONS))) if actuation is None else actuation
    l = draw(floats(0.5, 1.5))
    h = l * draw(floats(0.4, 0.7))
    if actuation == "P" and not inclined:
        gamma = draw(floats(1.2, 1.95))
    else:
        gamma = draw(st.one_of(floats(0.9, 1.3), floats(1.85, 2.25)))
    th0 = draw(floats(0.35, 1.2))
    z = l * draw(floats(0.3, 1.0))
    # c . w = l cos(th0) with c = (h - g) e_r + z e_z and w = -sin(gamma) e_r + cos(gamma) e_z
    g = h + (l * math.cos(th0) - z * math.cos(gamma)) / math.sin(gamma)
    mp = draw(floats(1.0, 10.0))
    p = prs3.Prs3Params(gamma=gamma, l=l, h=h, g=g, actuation=actuation, m_slider=draw(floats(0.0, 2.0)),
                        m_coupler=draw(floats(0.0, 2.0)), m_platform=mp, reference=(z, 0.0, 0.0),
                        **draw(platform_inertias(mp, h)))
    return p


@st.composite
def hexapod_designs(draw, layout: str | None = None) -> hexapod.HexapodParams:
    """Table 1 scaled by a random factor (0.5..2), each length and angle perturbed, and a reference pose
    drawn in a well-conditioned region (platform turned 20-40 deg about Y, small tilt, beta within 0.3 rad)."""
    T = hexapod.HexapodParams()
    lam = draw(floats(0.5, 2.0))
    f = [draw(floats(0.9, 1.1)) for _ in range(8)]
    theta = tuple(t + math.radians(draw(floats(-5.0, 5.0))) for t in T.theta)
    layout = draw(st.sampled_from(sorted(hexapod.LAYOUTS))) if layout is None else layout
    tilt = pin.exp3(0.1 * draw(unit_box(3)))
    R = tilt @ rot_y(-math.radians(draw(floats(20.0, 40.0))))
    P = lam * np.array([0.02 * draw(floats(-1, 1)), draw(floats(-0.42, -0.3)), 0.02 * draw(floats(-1, 1))])
    try:
        p = hexapod.HexapodParams(Rf=lam * T.Rf * f[0], Rr=lam * T.Rr * f[1], R2=lam * T.R2 * f[2],
                                  H0=lam * T.H0 * f[3], LA=lam * T.LA * f[4], LB=lam * T.LB * f[5],
                                  h=lam * T.h * f[6], r=lam * T.r * f[7], theta=theta, layout=layout,
                                  home_rotation=tuple(R.ravel()), home_position=tuple(P),
                                  home_beta=draw(floats(-0.3, 0.3)), m_recon=draw(floats(0.05, 0.5)),
                                  m_arm=draw(floats(0.05, 0.5)), m_rod=draw(floats(0.05, 0.5)),
                                  m_platform=draw(floats(0.2, 2.0)))
        hexapod.reference_pose(p)
    except InvalidParameterError:
        assume(False)
    return p


# ---------------------------------------------------------------------- poses: offsets u in [-1, 1]^n
def delta_pose(p: delta.DeltaParams, u: np.ndarray) -> np.ndarray:
    """Platform centre ``home + 0.25 La u`` [m]."""
    return delta.reference_pose(p) + 0.25 * p.La * u


def rrr3_pose(p: rrr3.Rrr3Params, u: np.ndarray) -> np.ndarray:
    """Task ``home + (0.05 H, 0.05 H, 0.2 rad) u``."""
    return rrr3.reference_pose(p) + np.array([0.05 * p.H, 0.05 * p.H, 0.2]) * u


def prs3_pose(p: prs3.Prs3Params, u: np.ndarray) -> np.ndarray:
    """Task ``reference + (0.05 l, 0.15 rad, 0.15 rad) u``."""
    return prs3.reference_pose(p) + np.array([0.05 * p.l, 0.15, 0.15]) * u


def hexapod_pose(p: hexapod.HexapodParams, u: np.ndarray) -> np.ndarray:
    """Task vector of the reference moved by ``0.05 LA`` (position), 0.05 rad (rotation), 0.2 rad (beta)."""
    R, P, beta = hexapod.reference_pose(p)
    return hexapod.task_vector(pin.exp3(0.05 * u[3:6]) @ R, P + 0.05 * p.LA * u[:3], beta + 0.2 * u[6])


def regular(mech, q, margin: float = 1e-3) -> bool:
    """Whether the core classifies ``q`` regular with both singularity measures above ``margin`` (smallest
    singular values, in the units of the Jacobian columns: m per rad for revolute joints)."""
    d = pkm.diagnose(mech, q)
    return d.classification == "regular" and min(d.sigma_direct, d.sigma_inverse) > margin


def reachable(fn, *args, **kwargs):
    """``fn(*args, **kwargs)``, the example rejected when it raises a :class:`PkmError` (unreachable pose...)."""
    try:
        return fn(*args, **kwargs)
    except PkmError:
        assume(False)


# ---------------------------------------------------------------------- states along a motion
def path_state(mech, configuration, motion, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, v, a)`` at time ``t`` of the task motion ``motion(t) -> (y, yd, ydd)``: closed-form configuration,
    then the core's inverse velocities and accelerations."""
    y, yd, ydd = motion(t)
    q = configuration(y)
    v = pkm.inverse_velocities(mech, q, yd)
    return q, v, pkm.inverse_accelerations(mech, q, v, ydd)


def richardson2(diff, h: float) -> np.ndarray:
    """Central differences ``diff(h)`` extrapolated twice (``tests.fd.richardson`` at ``h/2`` and ``h``, then
    ``(16 R(h/2) - R(h)) / 15``): error O(h^6), so that a step large enough to keep rounding small (1e-3 s)
    stays accurate where the configuration changes fast (near the edge of the workspace)."""
    from tests.fd import richardson

    return (16.0 * richardson(diff, h / 2) - richardson(diff, h)) / 15.0


def derivative_error(x, x_fd, f, h: float) -> float:
    """``|x - x_fd|`` relative to ``|x_fd|``, or, when the motion is slow, to ``1e9 eps |f| / h``: the size of a
    difference quotient of ``f`` (step ``h``) of which rounding alone (about ``70 eps |f| / h`` after
    :func:`richardson2`, ``f`` itself computed to some ``10 eps``) makes up less than 1e-7."""
    scale = np.linalg.norm(x_fd) + 1e9 * np.finfo(float).eps * np.linalg.norm(f) / h
    return float(np.linalg.norm(np.asarray(x) - x_fd) / max(scale, 1e-300))


def path_derivative_errors(mech, state, t: float, h: float = 1e-3) -> tuple[float, float]:
    """Errors (:func:`derivative_error`) of ``v`` against differences of ``q`` and of ``a`` against differences of
    ``v`` at ``t``, for ``state(t) -> (q, v, a)`` (:func:`richardson2`; tangent differences of ``q`` wrapped, as
    revolute coordinates are kept in (-pi, pi])."""
    q, v, a = state(t)
    qd = richardson2(lambda hh: wrap(pin.difference(mech.model, state(t - hh)[0], state(t + hh)[0])) / (2 * hh), h)
    vd = richardson2(lambda hh: (state(t + hh)[1] - state(t - hh)[1]) / (2 * hh), h)
    return derivative_error(v, qd, q, h), derivative_error(a, vd, v, h)


def power_balance_error(mech, state, efforts, t: float, h: float = 1e-3) -> float:
    """``|sum tau_i qd_i - dE/dt|`` at time ``t``, relative to the gross power ``sum |tau_i qd_i|`` plus 1e9 times
    the error estimate of the differences (a motion nearly at rest at ``t`` has a power known only to that).

    ``efforts(q, v, a)`` gives ``tau`` in ``mech.actuated`` order; ``dE/dt`` (kinetic + potential, every body)
    comes from differences of the energy along the motion (:func:`richardson2` with steps ``h`` and ``h/2``:
    their difference estimates the error of the second, within a factor of a few when rounding dominates).
    """
    from pkm.core import dynamics

    q, v, a = state(t)
    tau = efforts(q, v, a)
    qd_a = v[mech.act_v]
    power = float(tau @ qd_a)

    def energy(tt):
        qq, vv, _ = state(tt)
        return sum(dynamics.energy(mech, qq, vv))

    def dE(hh):
        return float(richardson2(lambda k: np.array([(energy(t + k) - energy(t - k)) / (2 * k)]), hh)[0])

    coarse, fine = dE(h), dE(h / 2)
    scale = float(np.abs(tau) @ np.abs(qd_a)) + 1e9 * abs(coarse - fine)
    return abs(power - fine) / max(scale, 1e-300)  # 0 for a motion at rest


def seed_fraction(mech, q, length: float) -> float:
    """How far from ``q`` a seed may lie, as a fraction of a nominal offset: ``min(1, sigma_direct / (0.03 L))``.

    Near a direct singularity a second assembly mode lies close, at a distance proportional to the core's
    ``sigma_direct`` (at the hexapod's pose T, ``sigma_direct / LA = 0.03``, the other mode is 3 mm away);
    Newton's method from a seed nearer to it than to ``q`` rightly converges there.
    """
    return min(1.0, pkm.diagnose(mech, q).sigma_direct / (0.03 * length))


def forward_acceleration_errors(mech, q, seed: int) -> dict[str, float]:
    """``tests.fd.acceleration_errors`` along the same random actuated parabola with steps 1e-6 and 1e-5, the
    better of the two: rounding (the loop closure's) dominates the first, truncation the second where the
    configuration is near a fold of the actuated space; a wrong acceleration fails both."""
    from tests.fd import acceleration_errors

    runs = [acceleration_errors(mech, q, np.random.default_rng(seed), h=h) for h in (1e-6, 1e-5)]
    return min(runs, key=lambda e: max(e["joint"], e["task"]))


def round_trip_tolerance(mech, q, base: float = 1e-9, solver_tol: float = 1e-12) -> float:
    """What a position round trip can promise at ``q``: ``base``, or, near a singularity, ten times the error
    a residual of ``solver_tol`` (inf-norm, every closure) leaves in the coordinates,
    ``sqrt(n_c) solver_tol / sigma_min``, ``sigma_min`` the smaller of the core's two singularity measures."""
    d = pkm.diagnose(mech, q)
    return max(base, 10.0 * math.sqrt(mech.n_constraints) * solver_tol / min(d.sigma_direct, d.sigma_inverse))
