"""3-PRS robot (Diaz-Rodriguez, Carretero, Bautista-Quintero & Chacon, 2016): tree, closures, closed forms.

Geometry (paper eqs. 6-7, SI units): base frame O at the centre of the base, Z up. Leg ``i``
(``i = 1, 2, 3``) lies in the vertical plane spanned by ``e_r,i = (cos phi_i, sin phi_i, 0)`` and
``e_z``, ``phi_i = 0, 120, 240 deg``. Its rail (prismatic joint ``slider_i``) passes through
``a_i = g e_r,i`` with direction ``u_1,i = cos(gamma) e_r,i + sin(gamma) e_z``; the slider sits at
``S_i = a_i + d_i u_1,i``. A revolute ``knee_i`` of axis ``e_t,i = e_z x e_r,i`` (normal to the leg
plane) carries the coupler of length ``l`` to the spherical joint at the platform point
``B_i = p + R b_i``, ``b_i = h e_r,i`` in the platform frame. The platform (link ``platform_link``)
is a free body: URDF ``floating`` joint ``platform``, whose frame ``platform`` at ``p`` is the end
effector. Each spherical joint is a point closure ``coupler_i_tip`` == ``platform_ball_i``.

Rail inclination: ``gamma`` is the angle between the rail and the base plane, measured in the
leg plane from ``e_r,i`` (outward) towards ``e_z``: for ``gamma < pi/2`` the rail rises away from
the centre, for ``gamma > pi/2`` towards it. DH table 1 (``alpha_i1 = gamma_i``) does not fix
this direction without the paper's missing Fig. 2; the choice only matters for inclined rails
(Table 2 has ``gamma = pi/2``: vertical rails).

Joint conventions: ``slider_i`` is ``d_i``, the distance from ``a_i`` along ``u_1,i``. ``knee_i`` is
``theta_i``, with ``u_2,i = cos(theta_i) w_i + sin(theta_i) u_1,i`` the coupler direction and
``w_i = -sin(gamma) e_r,i + cos(gamma) e_z`` the inward normal to the rail in the leg plane:
``theta_i = 0`` when the coupler is perpendicular to the rail pointing inward, which is the double
root of eq. (10). Working modes (``Branch`` on the signs of ``knee_i``): ``slider_below`` (default,
the prototype of Fig. 1) has ``theta_i > 0``, the coupler pointing up the rail, the slider below the
spherical joint; ``slider_above`` has ``theta_i < 0``. (The other double root, coupler pointing
outward, is at ``theta_i = +-pi``, outside the useful workspace.)

Task: the paper's independent coordinates ``(z_p, beta, phi)`` with ``R = Rz(alpha) Ry(beta) Rx(phi)``
(eq. 1), i.e. pkm's task components ``["z", "pitch", "roll"]``. The parasitic motion
``x_p, y_p, alpha`` follows from the three spherical-joint centres staying in their leg planes
(eqs. 12-14, ``e_t,i . B_i = 0``): :func:`parasitic_motion`.

Actuation: ``"P"`` (sliders, Table 2 and sec. 5) or ``"R"`` (knees). With vertical rails and
``"R"`` the three passive sliders are parallel: the platform can rise with every knee locked, a
direct (type 2) singularity everywhere; :func:`pkm.core.diagnose` reports it. Knee actuation needs
inclined rails.

Departures from the paper (each covered by a test):

* Eq. (10) lacks a square: ``d_i = c_i.u_1,i -+ sqrt((c_i.u_1,i)^2 - c_i.c_i + l^2)`` with
  ``c_i = p + R b_i - a_i`` (as printed the radicand mixes m and m^2). ``slider_below`` takes the
  minus sign.
* Eq. (15) as printed does not hold for the layout of eqs. (6)-(7): its ``x_p`` and ``y_p`` are those
  of the layout rotated by 90 deg about Z (leg 1 on the +Y axis). For eqs. (6)-(7) the leg-plane
  conditions give ``R_01 = R_10`` (hence eq. 15's ``alpha``, which is right) and
  ``x_p = h (R_00 - R_11) / 2 = h/2 (c_a c_b - s_a s_b s_f - c_a c_f)``, ``y_p = -h R_10 = -h s_a c_b``:
  eq. (15)'s ``(x_p, y_p)`` is our ``(y_p, -x_p)``. Both vanish at ``beta = phi = 0`` and differ at
  second order in the angles. The printed form is kept as :func:`paper_parasitic_motion`.
* Eq. (7) labels ``a_i`` in frame p; it is in frame O.
* The paper has no forward-kinematics method: ``closed_form_fk`` is not offered (use
  :func:`pkm.core.close_loops`).

Masses and inertias: Table 2, read from ``dynamics/prs3_table2.toml`` (:func:`table2`). The slider
is a point mass at the revolute centre (it only translates, so its rotational inertia does no
work); the coupler's centre of mass is at ``l/2`` (Table 2's ``m_x2 = l m2 / 2``) with inertia
``m2 l^2 / 12`` about both transverse axes through it (Table 2's ``I_zz2`` about the revolute axis
direction) and 0 about its own axis.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np
import pinocchio as pin

from pkm.core.mechanism import Mechanism, as_array, check_mechanism, finite_result
from pkm.core.spec import Branch, Closure, ClosureSpec, TaskSpec, parse_toml, read_text_file
from pkm.core.task import zyx_matrix
from pkm.core.urdf import UrdfBuilder
from pkm.data import dynamics_path
from pkm.errors import InvalidInputError, InvalidParameterError, SpecError, UnreachableError
from pkm.mechanisms._common import (check_finite, check_nonnegative, check_params, check_positive, make_mechanism,
                                    rod_inertia, rot_y, rot_z, spec_parameters)

NAME = "prs3"
PHI = (0.0, 2.0 * math.pi / 3.0, 4.0 * math.pi / 3.0)
BRANCHES = {"slider_below": 1, "slider_above": -1}
DEFAULT_BRANCH = "slider_below"
ACTUATIONS = {"P": "slider", "R": "knee"}
TABLE2_FILE = "prs3_table2.toml"
TABLE2_FORMAT = "pkm.prs3_table2/1"
TABLE2_KEYS = {"kinematics": ("gamma", "l", "h", "g"),
               "dynamics": ("m1", "m2", "mp", "Izz2", "mx2", "my2", "Ixx3", "Iyy3", "Izz3", "Ixy3", "Ixz3", "Iyz3")}
_ROOT_TOL = 1e-12  # radicands of eq. (10) above -_ROOT_TOL l^2 count as the double root


# ---------------------------------------------------------------------- Table 2
@functools.cache
def table2() -> Mapping[str, float]:
    """Table 2 of the paper (SI), as stored in ``dynamics/prs3_table2.toml``.

    Returns:
        A read-only mapping with keys ``gamma l h g`` [rad, m] and ``m1 m2 mp`` [kg], ``Izz2`` [kg m^2],
        ``mx2 my2`` [kg m], ``Ixx3 Iyy3 Izz3 Ixy3 Ixz3 Iyz3`` [kg m^2].

    Raises:
        SpecError: The file is missing, not TOML, of another format, or lacks a key or a number.
    """
    path = dynamics_path(TABLE2_FILE)
    raw = parse_toml(read_text_file(path, "Table 2"), str(path))
    if raw.get("format") != TABLE2_FORMAT:
        raise SpecError(str(path), f"format {raw.get('format')!r}; this pkm reads {TABLE2_FORMAT!r}")
    out: dict[str, float] = {}
    for section, keys in TABLE2_KEYS.items():
        table = raw.get(section)
        if not isinstance(table, dict):
            raise SpecError(str(path), f"missing table [{section}]")
        for k in keys:
            v = table.get(k)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise SpecError(str(path), f"[{section}].{k} must be a finite number, got {v!r}")
            out[k] = float(v)
    return MappingProxyType(out)


def _from_table2(key: str):
    return field(default_factory=lambda: table2()[key])


# ---------------------------------------------------------------------- parameters
@dataclass(frozen=True)
class Prs3Params:
    """3-PRS design; defaults from the paper's Table 2 (``dynamics/prs3_table2.toml``).

    Attributes:
        gamma: Angle between each rail and the base plane, in the leg plane [rad], in (0, pi)
            (pi/2: vertical rails).
        l: Coupler length, revolute centre to spherical centre [m] (1 m).
        h: Platform radius, centre to spherical joints [m] (0.5 m).
        g: Base radius, centre to where the rails meet the base plane [m] (1 m).
        actuation: ``"P"`` (sliders driven, as in sec. 5) or ``"R"`` (knees driven).
        m_slider: Slider mass m1 [kg] (0.5 kg = 0.1 m_p).
        m_coupler: Coupler mass m2 [kg] (0.5 kg = 0.1 m_p).
        m_platform: Platform mass m_p [kg] (5 kg).
        Ixx3, Iyy3, Izz3: Platform principal inertias about its centre of mass [kg m^2]
            (m_p h^2/4, m_p h^2/4, m_p h^2/2).
        Ixy3, Ixz3, Iyz3: Platform inertia tensor products (URDF ``ixy ixz iyz``) [kg m^2] (0).
        reference: Reference independent coordinates ``(z_p [m], beta [rad], phi [rad])``: the start
            of the sec. 5 trajectories (eq. 41: z = 0.81 m, beta = phi = 0).
    """

    gamma: float = _from_table2("gamma")
    l: float = _from_table2("l")  # noqa: E741 (the paper's name)
    h: float = _from_table2("h")
    g: float = _from_table2("g")
    actuation: str = "P"
    m_slider: float = _from_table2("m1")
    m_coupler: float = _from_table2("m2")
    m_platform: float = _from_table2("mp")
    Ixx3: float = _from_table2("Ixx3")
    Iyy3: float = _from_table2("Iyy3")
    Izz3: float = _from_table2("Izz3")
    Ixy3: float = _from_table2("Ixy3")
    Ixz3: float = _from_table2("Ixz3")
    Iyz3: float = _from_table2("Iyz3")
    reference: tuple[float, float, float] = (0.81, 0.0, 0.0)

    def __post_init__(self):
        check_positive(self, "l", "h", "g", "m_platform")
        check_nonnegative(self, "m_slider", "m_coupler")
        check_finite(self, "gamma", "Ixx3", "Iyy3", "Izz3", "Ixy3", "Ixz3", "Iyz3")
        if not 0.0 < self.gamma < math.pi:
            raise InvalidParameterError("gamma", f"rail angle must lie in (0, pi) rad (pi/2: vertical rails), "
                                                 f"got {self.gamma!r}", self.gamma)
        if not isinstance(self.actuation, str) or self.actuation not in ACTUATIONS:
            raise InvalidParameterError("actuation", f"use 'P' (sliders) or 'R' (knees), got {self.actuation!r}",
                                        self.actuation)
        _check_inertia(self.platform_inertia)
        try:
            y = _task_vector(self.reference, "reference")
        except InvalidInputError as exc:
            raise InvalidParameterError("reference", str(exc), self.reference) from None
        object.__setattr__(self, "reference", tuple(float(v) for v in y))
        try:
            rad = _leg_vectors(self, y)[1]
        except UnreachableError as exc:
            raise InvalidParameterError(
                "reference", f"reference pose {self.reference} is unreachable with this design (leg {exc.leg} "
                             f"misses by {exc.excess:.4g} m); lengthen l, bring g and h closer, or choose another "
                             f"reference", self.reference) from None
        if np.min(rad) <= _ROOT_TOL * self.l**2:
            leg = int(np.argmin(rad)) + 1
            raise InvalidParameterError(
                "reference", f"at the reference pose {self.reference} the coupler of leg {leg} is perpendicular "
                             f"to its rail (double root of eq. 10, branches undefined); change l, g, h or the "
                             f"reference", self.reference)

    @property
    def platform_inertia(self) -> np.ndarray:
        """Platform inertia tensor about its centre of mass, platform axes [kg m^2]."""
        return np.array([[self.Ixx3, self.Ixy3, self.Ixz3],
                         [self.Ixy3, self.Iyy3, self.Iyz3],
                         [self.Ixz3, self.Iyz3, self.Izz3]])


def _check_inertia(I: np.ndarray) -> None:
    ev = np.linalg.eigvalsh(I)
    tol = 1e-12 * max(1.0, float(np.abs(ev).max()))
    if ev[0] < -tol or ev[0] + ev[1] < ev[2] - tol:
        raise InvalidParameterError("Ixx3", f"platform inertia (Ixx3 ... Iyz3) is not physical: principal moments "
                                            f"{ev.tolist()} must be >= 0 and obey the triangle inequality", I)


# ---------------------------------------------------------------------- closed forms
def _legs(params: Prs3Params) -> tuple[np.ndarray, ...]:
    """Per-leg vectors (rows i = 1..3, world axes): a_i, u_1,i, w_i, e_t,i, and b_i (platform axes)."""
    cg, sg = math.cos(params.gamma), math.sin(params.gamma)
    er = np.array([[math.cos(f), math.sin(f), 0.0] for f in PHI])
    ez = np.array([0.0, 0.0, 1.0])
    et = np.cross(ez, er)
    return params.g * er, cg * er + sg * ez, -sg * er + cg * ez, et, params.h * er


def _yaw(pitch: float, roll: float) -> tuple[float, tuple[float, ...]]:
    """``alpha = atan2(s_b s_f, c_f + c_b)`` (eq. 15) and ``(s_a, c_a, s_b, c_b, s_f, c_f)``."""
    sb, cb, sf, cf = math.sin(pitch), math.cos(pitch), math.sin(roll), math.cos(roll)
    alpha = math.atan2(sb * sf, cf + cb)
    return alpha, (math.sin(alpha), math.cos(alpha), sb, cb, sf, cf)


def parasitic_motion(h: float, pitch: float, roll: float) -> tuple[float, float, float]:
    """Dependent coordinates ``(x_p [m], y_p [m], alpha [rad])`` from ``beta``, ``phi`` (derived, eqs. 12-14).

    For the layout of eqs. (6)-(7), ``e_t,i . B_i = 0`` for the three legs gives ``R_01 = R_10``,
    ``x_p = h (R_00 - R_11) / 2`` and ``y_p = -h R_10`` (see the module doc for eq. 15). ``alpha`` is the
    root of ``s_a (c_b + c_f) = c_a s_b s_f`` given by ``atan2`` (0 at ``beta = phi = 0``).

    Args:
        h: Platform radius [m].
        pitch: beta [rad].
        roll: phi [rad].
    """
    alpha, (sa, ca, sb, cb, sf, cf) = _yaw(pitch, roll)
    return 0.5 * h * (ca * cb - sa * sb * sf - ca * cf), -h * sa * cb, alpha


def paper_parasitic_motion(h: float, pitch: float, roll: float) -> tuple[float, float, float]:
    """Eq. (15) as printed: ``(x_p [m], y_p [m], alpha [rad])`` from ``beta``, ``phi``.

    ``x_p = -h s_a c_b``, ``y_p = -h/2 (c_a c_b - s_a s_b s_f - c_a c_f)``,
    ``alpha = atan2(s_b s_f, c_f + c_b)``. It keeps the spherical joints in their leg planes for the
    layout rotated by 90 deg about Z (``phi_i = 90, 210, 330 deg``), not for eqs. (6)-(7), where
    :func:`parasitic_motion` holds; ``alpha`` is right for both.
    """
    alpha, (sa, ca, sb, cb, sf, cf) = _yaw(pitch, roll)
    return -h * sa * cb, -0.5 * h * (ca * cb - sa * sb * sf - ca * cf), alpha


def paper_constraint_jacobians(params: Prs3Params, y) -> tuple[np.ndarray, np.ndarray]:
    """``J_r1``, ``J_r2`` of eq. (25), ``J_r1 v_p = J_r2 omega_p`` (the leg-plane velocity conditions).

    Row ``i`` is eq. (24) for leg ``i``: ``e_t,i . v_p + (r_i x e_t,i) . omega_p = 0``, with ``e_t,i``
    the knee axis (third row of ``^{i,2}R_o``) and ``r_i = R b_i``. The paper solves it as
    ``omega_p = J_r2^-1 J_r1 v_p`` (eq. 26); at ``beta = phi = 0`` every ``r_i x e_t,i`` is ``h e_z``,
    so ``J_r2`` has rank 1 and eq. (26) cannot be evaluated where the sec. 5 trajectories start.
    :class:`pkm.mechanisms.prs3_dynamics.Prs3Dynamics` takes ``(z_p, beta, phi)`` as independent
    instead (its ``jacobian``).
    """
    params = check_params(params, Prs3Params)
    p, R = platform_pose(params, y)
    _, _, _, et, b = _legs(params)
    r = b @ R.T
    return et.copy(), -np.cross(r, et)


def platform_pose(params: Prs3Params, y) -> tuple[np.ndarray, np.ndarray]:
    """Platform position ``p`` [m] and rotation ``R`` for task vector ``y = (z_p, beta, phi)``."""
    params = check_params(params, Prs3Params)
    z, pitch, roll = _task_vector(y, "y")
    x, yp, alpha = parasitic_motion(params.h, pitch, roll)
    return np.array([x, yp, z]), zyx_matrix(roll, pitch, alpha)


def _leg_vectors(params: Prs3Params, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``c_i = B_i - a_i`` (rows, m) and the radicands ``l^2 - dist(B_i, rail_i)^2`` of eq. (10) [m^2].

    Raises:
        UnreachableError: The first leg with a negative radicand, by ``dist - l`` [m].
    """
    p, R = platform_pose(params, y)
    a, u1, _, _, b = _legs(params)
    c = p + b @ R.T - a
    cu = np.einsum("ij,ij->i", c, u1)
    with np.errstate(over="ignore", invalid="ignore"):  # a pose 1e155 m away: NaN, reported by inverse_kinematics
        rad = cu**2 - np.einsum("ij,ij->i", c, c) + params.l**2
    for i in range(3):
        if rad[i] < -_ROOT_TOL * params.l**2:
            dist = math.sqrt(params.l**2 - rad[i])
            raise UnreachableError(i + 1, dist - params.l, "m",
                                   f"leg {i + 1}: the spherical joint is farther than l from the rail")
    return c, np.maximum(rad, 0.0)


def inverse_kinematics(params: Prs3Params, y, branch: str | tuple[str, str, str] | None = None
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Slider positions ``d_i`` [m] and knee angles ``theta_i`` [rad] for ``y = (z_p, beta, phi)`` (eqs. 8-11).

    ``d_i = c_i.u_1,i -+ sqrt((c_i.u_1,i)^2 - c_i.c_i + l^2)`` (eq. 10 with its missing square), the minus
    sign for ``slider_below``; ``theta_i = atan2((c_i - d_i u_1,i).u_1,i, (c_i - d_i u_1,i).w_i)`` (eq. 8).

    Args:
        params: The design.
        y: ``(z_p [m], beta [rad], phi [rad])``, shape (3,), ``|beta| < pi/2``.
        branch: ``"slider_below"`` (default) / ``"slider_above"`` for all legs, or one per leg.

    Raises:
        UnreachableError: The first leg whose spherical joint is farther than ``l`` from its rail,
            with the excess distance [m].
        InvalidInputError: Bad ``y`` or branch.
    """
    params = check_params(params, Prs3Params)
    signs = np.array([BRANCHES[b] for b in _branches(branch)], dtype=float)
    y = _task_vector(y, "y")
    c, rad = _leg_vectors(params, y)
    _, u1, w, _, _ = _legs(params)
    cu = np.einsum("ij,ij->i", c, u1)
    d = cu - signs * np.sqrt(rad)
    theta = np.arctan2(cu - d, np.einsum("ij,ij->i", c, w))
    finite_result((d, theta), "slider positions and knee angles", f"y = {y.tolist()} is too far out (overflow)")
    return d, theta


def joint_values(params: Prs3Params, y, branch: str | tuple[str, str, str] | None = None) -> dict[str, list[float]]:
    """Every joint coordinate of the tree (closed form) for ``y = (z_p, beta, phi)``."""
    params = check_params(params, Prs3Params)
    d, theta = inverse_kinematics(params, y, branch)
    p, R = platform_pose(params, y)
    # "+ 0.0" turns the -0.0 of the closed forms into 0.0
    out: dict[str, list[float]] = {"platform": [float(v) + 0.0 for v in (*p, *pin.Quaternion(R).coeffs())]}
    for i in range(3):
        out[f"slider_{i + 1}"] = [float(d[i]) + 0.0]
        out[f"knee_{i + 1}"] = [float(theta[i]) + 0.0]
    return out


def configuration(mech: Mechanism, y, branch: str | tuple[str, str, str] | None = None) -> np.ndarray:
    """Full configuration vector ``q`` of ``mech`` for ``y = (z_p, beta, phi)`` (closed form)."""
    mech = check_mechanism(mech)
    return mech.q_from_dict(joint_values(mech.params, y, branch))


# ---------------------------------------------------------------------- uniform interface
def closed_form_ik(params: Prs3Params, y, branch: str | None = None) -> np.ndarray:
    """Actuated coordinates for ``y = (z, pitch, roll)``: ``d_i`` [m] (actuation P) or ``theta_i`` [rad] (R)."""
    params = check_params(params, Prs3Params)
    d, theta = inverse_kinematics(params, y, branch)
    return d if params.actuation == "P" else theta


def closed_form_configuration(mech: Mechanism, y, branch: str | None = None) -> np.ndarray:
    """Every joint coordinate for task vector ``y`` (closed form)."""
    return configuration(mech, y, branch)


# ---------------------------------------------------------------------- tree and spec
def urdf_xml(params: Prs3Params) -> str:
    """The URDF tree: free platform, and per leg base -> slider -> coupler (see the module doc)."""
    params = check_params(params, Prs3Params)
    b = UrdfBuilder(NAME)
    b.link("base")
    reach = 2.0 * (params.g + params.h + params.l + abs(params.reference[0]))
    a, _, _, _, bp = _legs(params)
    for i in range(3):
        n = i + 1
        # slider frame: x along the rail u_1, y along e_t (knee axis), z along w (coupler at theta = 0)
        b.link(f"slider_link_{n}", params.m_slider)
        b.joint(f"slider_{n}", "prismatic", "base", f"slider_link_{n}", a[i], rot_z(PHI[i]) @ rot_y(-params.gamma),
                axis=(1.0, 0.0, 0.0), limits=(-reach, reach))
        b.link(f"coupler_{n}", params.m_coupler, (0.0, 0.0, params.l / 2), rod_inertia(params.m_coupler, params.l, 2))
        b.joint(f"knee_{n}", "revolute", f"slider_link_{n}", f"coupler_{n}", axis=(0.0, 1.0, 0.0))
        b.frame(f"coupler_{n}_tip", f"coupler_{n}", (0.0, 0.0, params.l))
    # link "platform_link": Pinocchio 4.1 refuses a name shared by a body frame and a joint frame
    b.link("platform_link", params.m_platform, inertia=params.platform_inertia)
    b.joint("platform", "floating", "base", "platform_link")
    for i in range(3):
        b.frame(f"platform_ball_{i + 1}", "platform_link", bp[i])
    return b.to_xml()


def closure_spec(params: Prs3Params) -> ClosureSpec:
    """Closures, actuation (``params.actuation``), task, branches and the reference configuration."""
    params = check_params(params, Prs3Params)
    reference = {k: tuple(v) for k, v in joint_values(params, params.reference).items()}
    joint = ACTUATIONS[params.actuation]
    return ClosureSpec(
        mechanism=NAME,
        description=f"3-PRS (Diaz-Rodriguez et al. 2016), actuated in the {params.actuation} joints; spherical "
                    "joints as point closures, free platform",
        urdf=f"{NAME}.urdf",
        end_effector="platform",
        actuated=tuple(f"{joint}_{n}" for n in (1, 2, 3)),
        closures=tuple(Closure(f"ball_{n}", "point", f"coupler_{n}_tip", f"platform_ball_{n}") for n in (1, 2, 3)),
        task=TaskSpec(("z", "pitch", "roll")),
        reference=reference,
        branches={name: Branch(name, {f"knee_{n}": s for n in (1, 2, 3)},
                               f"every slider {name.split('_')[1]} its spherical joint "
                               f"(knee_i {'>' if s > 0 else '<'} 0)") for name, s in BRANCHES.items()},
        default_branch=DEFAULT_BRANCH,
        parameters=spec_parameters(params),
    )


Params = Prs3Params


def build(params: Prs3Params | None = None) -> Mechanism:
    """The 3-PRS as a :class:`~pkm.core.Mechanism` (Table 2 design when ``params`` is None)."""
    params = Prs3Params() if params is None else params
    return make_mechanism(urdf_xml(params), closure_spec(params), params)


# ---------------------------------------------------------------------- input checks
def _task_vector(y, name: str) -> np.ndarray:
    arr = as_array(y, name, "3 numbers (z_p [m], beta [rad], phi [rad])")
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise InvalidInputError(name, f"expected 3 finite numbers (z_p, beta, phi), got shape {arr.shape}", y)
    if abs(arr[1]) >= math.pi / 2:
        raise InvalidInputError(name, f"pitch beta = {arr[1]!r} rad: Z-Y-X angles need |beta| < pi/2", y)
    return arr


def _branches(branch: str | tuple[str, str, str] | None) -> tuple[str, str, str]:
    branch = DEFAULT_BRANCH if branch is None else branch
    out = (branch,) * 3 if isinstance(branch, str) else tuple(branch) if isinstance(branch, (tuple, list)) else ()
    if len(out) != 3 or any(not isinstance(b, str) or b not in BRANCHES for b in out):
        raise InvalidInputError("branch", f"use {list(BRANCHES)} or a tuple of three, got {branch!r}", branch)
    return out
