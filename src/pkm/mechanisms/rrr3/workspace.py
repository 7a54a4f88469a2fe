"""Planar 3-RRR: workspaces, condition-index maps and the global condition index, vectorised over grids.

Everything here evaluates the closed forms of :mod:`pkm.mechanisms.rrr3` on whole grids of
platform positions at once (numpy, no Python loop over nodes). Every choice the paper leaves
open is an explicit argument:

* **Matrix** — the condition index ``CI = 1/kappa`` (eqs. 22-23) is taken of the velocity map
  ``J = J_x^-1 J_q`` (equivalently of its inverse ``K = J_q^-1 J_x``, which has the same condition
  number and stays finite at direct singularities), with ``J_x`` homogenised as in
  :func:`pkm.mechanisms.rrr3.homogenized_jacobians`: moment column divided by ``L``.
* **L and moment point** — :class:`CiSettings` ``length`` (default the platform circumradius
  ``h / sqrt 3``) and ``reference`` (default the centroid ``G``, whose velocity is the task rate).
* **Kind** — :class:`CiSettings` ``kind``: ``"2"`` (spectral, ``sigma_min / sigma_max``) or ``"fro_normalized"``
  (``n / (||J||_F ||J^-1||_F)``), the names of :data:`pkm.core.differential.indices.KINDS` (:data:`KINDS`: those
  these maps compute).
* **Orientation and working mode** — ``phi`` (rad) and ``branch`` (1..8 or ``"mode1"``..``"mode8"``) of
  :class:`CiSettings`.
* **Grid** — :class:`Grid`: a square of nodes ``centre + step * (i, j)``, ``|i|, |j| <= n``,
  positions of the centroid ``G``.
* **Unreachable nodes** — they carry ``NaN`` in a map and are excluded from every mean
  (eq. 24's ``n`` counts workspace nodes only); :meth:`CiMap.gci` can count them as
  ``CI = 0`` instead, and returns an explicit empty result (``value=None``) when no node of
  the region is reachable.

The condition number of ``K`` (3 x 3) comes from the eigenvalues of ``M = K' K'^T`` with
``K' = (s_1 s_2 s_3) K = diag(s_2 s_3, s_1 s_3, s_1 s_2) J_x`` (``s_i = a sin psi_i``; the factor
cancels in a ratio and removes every division): the largest eigenvalue in closed form
(trigonometric solution of the characteristic cubic), the smallest from
``det M = det(K')^2`` so that it keeps its relative accuracy near singularities.

The reading that reproduces the paper's numbers (see :mod:`pkm.papers.rrr3`): spectral norm,
``L = h / sqrt 3``, moments about ``G``, ``Phi = 0``, mode 1 (mode 8 gives the mirror image),
the map square ``+-80 cm`` about the base centroid with 2 mm steps, unreachable nodes excluded.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from pkm._moved import renamed, renamed_fields
from pkm.core.differential.indices import inverse_condition
from pkm.errors import InvalidInputError, SingularityError, UnreachableError
from pkm.mechanisms import rrr3
from pkm.mechanisms._common import check_positive, real
from pkm.mechanisms.rrr3.kinematics import elbow_at, leg_reach
from pkm.validation import as_array, as_scalar, as_vector

#: The condition-index kinds these maps compute in closed form: a subset of
#: :data:`pkm.core.differential.indices.KINDS` (not its unnormalised ``"fro"``).
KINDS = ("2", "fro_normalized")
MAX_NODES_PER_AXIS = 20001  # a grid larger than this per axis is refused (memory)
MAX_NODES = 4001 ** 2  # a grid of more nodes in all is refused (memory: several float arrays of this size)
_CHUNK = 1 << 15  # nodes evaluated at once (fits the cache: faster than larger blocks)
_VERTEX_ANGLES = (7.0 * math.pi / 6.0, -math.pi / 6.0, math.pi / 2.0)  # directions G -> A, B, C at Phi = 0


@dataclass(frozen=True)
class Design:
    """Dimensions of a 3-RRR without a reference pose (any design, even one that cannot assemble).

    Attributes:
        a: Proximal link [m].
        b: Distal link [m].
        h: Platform side [m].
        H: Base side (actuator separation) [m].
    """

    a: float
    b: float
    h: float
    H: float

    def __post_init__(self):
        check_positive(self, "a", "b", "h", "H")

    @classmethod
    def of(cls, design) -> Design:
        """A :class:`Design` from anything with ``a, b, h, H`` (an :class:`~pkm.mechanisms.rrr3.Rrr3Params`)."""
        if isinstance(design, Design):
            return design
        try:
            return cls(design.a, design.b, design.h, design.H)
        except AttributeError:
            raise InvalidInputError("design", "needs attributes a, b, h, H (m)", design) from None

    @classmethod
    def similarity_law(cls, H: float) -> Design:
        """The paper's similarity law (eqs. 26-27): ``h = H / 10``, ``a = b = 0.4 H``."""
        return cls(0.4 * H, 0.4 * H, 0.1 * H, H)

    @property
    def base_centroid(self) -> np.ndarray:
        """Centroid of the base triangle [m]."""
        return np.array([self.H / 2.0, self.H / (2.0 * rrr3.SQRT3)])


@renamed_fields(mode="branch", norm="kind")
@dataclass(frozen=True)
class CiSettings:
    """The choices behind a condition index (see the module doc).

    Attributes:
        phi: Platform orientation ``Phi`` [rad].
        branch: Working mode 1..8 (or ``"modeK"``); ``mode=`` is its deprecated former name.
        kind: Condition-index kind, one of :data:`KINDS`: ``"2"`` or ``"fro_normalized"``; ``norm=`` is its
            deprecated former name.
        length: Characteristic length ``L`` [m]; ``None``: the platform circumradius ``h / sqrt 3``.
        reference: Moment reference point, one of :data:`pkm.mechanisms.rrr3.REFERENCES`.
    """

    phi: float = 0.0
    branch: int | str = 1
    kind: str = "2"
    length: float | None = None
    reference: str = "centroid"

    def __post_init__(self):
        if real(self.phi) is None:
            raise InvalidInputError("phi", f"must be a finite angle in rad, got {self.phi!r}", self.phi)
        rrr3.branch_signs(self.branch)
        if not isinstance(self.kind, str) or self.kind not in KINDS:
            raise InvalidInputError("kind", f"use one of {KINDS}, got {self.kind!r}", self.kind)
        if self.length is not None and not (real(self.length) is not None and self.length > 0.0):
            raise InvalidInputError("length", f"must be finite and > 0 m (or None), got {self.length!r}", self.length)
        if not isinstance(self.reference, str) or self.reference not in rrr3.REFERENCES:
            raise InvalidInputError("reference", f"use one of {rrr3.REFERENCES}, got {self.reference!r}",
                                    self.reference)

    def length_for(self, design: Design) -> float:
        """``L`` [m] for ``design``."""
        return design.h / rrr3.SQRT3 if self.length is None else float(self.length)

    @property
    def mode(self) -> int | str:
        """Deprecated former name of :attr:`branch` (a :class:`DeprecationWarning`)."""
        renamed("CiSettings", "mode", "branch")
        return self.branch

    @property
    def norm(self) -> str:
        """Deprecated former name of :attr:`kind` (a :class:`DeprecationWarning`)."""
        renamed("CiSettings", "norm", "kind")
        return self.kind


@dataclass(frozen=True)
class Grid:
    """Square grid of centroid positions: nodes ``centre + step * (i, j)`` for ``|i|, |j| <= n``.

    Attributes:
        centre: Centre node ``(x, y)`` [m].
        n: Nodes on each side of the centre (``2 n + 1`` per axis).
        step: Node spacing [m].
    """

    centre: tuple[float, float]
    n: int
    step: float

    def __post_init__(self):
        c = self.centre
        if not (isinstance(c, (tuple, list)) and len(c) == 2 and all(real(v) is not None for v in c)):
            raise InvalidInputError("centre", "must be (x, y), finite, in m", c)
        if isinstance(self.n, bool) or not isinstance(self.n, (int, np.integer)) or self.n < 0:
            raise InvalidInputError("n", f"must be an integer >= 0, got {self.n!r}", self.n)
        if 2 * self.n + 1 > MAX_NODES_PER_AXIS:
            raise InvalidInputError("n", f"{2 * self.n + 1} nodes per axis exceeds {MAX_NODES_PER_AXIS}", self.n)
        if (2 * self.n + 1) ** 2 > MAX_NODES:
            raise InvalidInputError("n", f"{(2 * self.n + 1) ** 2} nodes exceed {MAX_NODES}; take a larger step",
                                    self.n)
        if real(self.step) is None or not self.step > 0.0:
            raise InvalidInputError("step", f"must be finite and > 0 m, got {self.step!r}", self.step)

    @classmethod
    def square(cls, centre, half_width: float, step: float) -> Grid:
        """The grid covering ``centre +- half_width`` [m] with spacing ``step`` [m] (``n = round(half_width / step)``)."""
        half_width = as_scalar(half_width, "half_width", low=0.0, unit="m")
        step = as_scalar(step, "step", low=0.0, strict_low=True, unit="m")
        c = as_vector(centre, 2, "centre")
        if half_width / step >= MAX_NODES_PER_AXIS:
            raise InvalidInputError("step", f"half_width / step = {half_width / step:.3g} exceeds {MAX_NODES_PER_AXIS} "
                                            "nodes per axis; take a larger step", step)
        n = round(half_width / step)
        if 2 * n + 1 > MAX_NODES_PER_AXIS:
            raise InvalidInputError("step", f"{2 * n + 1} nodes per axis exceeds {MAX_NODES_PER_AXIS}", step)
        return cls((float(c[0]), float(c[1])), int(n), float(step))

    @property
    def axis(self) -> np.ndarray:
        """Offsets of the nodes from the centre along either axis [m]."""
        return self.step * np.arange(-self.n, self.n + 1)

    @property
    def xs(self) -> np.ndarray:
        return self.centre[0] + self.axis

    @property
    def ys(self) -> np.ndarray:
        return self.centre[1] + self.axis

    @property
    def size(self) -> int:
        return (2 * self.n + 1) ** 2

    def square_mask(self, side: float, centre=None) -> np.ndarray:
        """Nodes (shape ``(ny, nx)``) inside the square of side ``side`` [m] about ``centre`` (default the grid's).

        Nodes on the square's edges count as inside (to 1e-9 of a step).
        """
        side = as_scalar(side, "side", low=0.0, strict_low=True, unit="m")
        c = self.centre if centre is None else as_vector(centre, 2, "centre")
        tol = side / 2.0 + 1e-9 * self.step
        inx = np.abs(self.xs - c[0]) <= tol
        iny = np.abs(self.ys - c[1]) <= tol
        return iny[:, None] & inx[None, :]


AREA_SIDE = 0.30  # m: default side of the square area of interest of area_gci (the GCI paper's 30 cm x 30 cm)


# ---------------------------------------------------------------------- vectorised closed forms
def _reach(d: Design, gx, gy, phi) -> tuple[np.ndarray, list]:
    """The nodes where every leg reaches (the broadcast shape of ``gx, gy, phi``) and per leg :func:`_vertices`'
    ``(i, vx, vy, tx, ty)`` and :func:`~pkm.mechanisms.rrr3.kinematics.leg_reach`'s ``(d2, dist)``."""
    reach = np.ones(np.broadcast_shapes(np.shape(gx), np.shape(gy), np.shape(phi)), dtype=bool)
    legs = []
    for i, vx, vy, tx, ty in _vertices(d, gx, gy, phi):
        d2, dist, reach_i = leg_reach(d.a, d.b, tx, ty)
        reach &= reach_i
        legs.append((i, vx, vy, tx, ty, d2, dist))
    return reach, legs


def _legs(d: Design, gx: np.ndarray, gy: np.ndarray, phi, signs, *, reachable_only: bool = False):
    """Per leg: reachable mask, platform vertex, unit distal direction and ``s = a sin psi`` (arrays like ``gx``;
    ``reachable_only``: the reachable nodes' only, in row-major order, the elbows placed on those alone).

    ``phi`` broadcasts against ``gx``. Same conventions as :func:`pkm.mechanisms.rrr3.inverse_kinematics`:
    ``psi_i`` has the sign of the working mode.
    """
    reach, legs = _reach(d, gx, gy, phi)
    out = []
    for i, vx, vy, tx, ty, d2, dist in legs:
        if reachable_only:
            vx, vy, tx, ty, d2, dist = (np.broadcast_to(v, reach.shape)[reach] for v in (vx, vy, tx, ty, d2, dist))
        Dx, Dy = elbow_at(d.a, d.b, tx, ty, signs[i], d2, dist)
        ux, uy = (tx - Dx) / d.b, (ty - Dy) / d.b
        s = Dx * uy - Dy * ux  # (D - O) x u = a sin psi
        out.append((vx, vy, ux, uy, s))
    return reach, out


def _vertices(d: Design, gx, gy, phi):
    """Per leg ``(i, vx, vy, tx, ty)``: the platform vertex, and relative to the leg's base vertex [m]."""
    base = np.array([[0.0, 0.0], [d.H, 0.0], [d.H / 2.0, d.H * rrr3.SQRT3 / 2.0]])
    rc = d.h / rrr3.SQRT3
    cphi, sphi = rc * np.cos(phi), rc * np.sin(phi)
    for i, ang in enumerate(_VERTEX_ANGLES):
        ca, sa = math.cos(ang), math.sin(ang)
        vx = gx + (cphi * ca - sphi * sa)  # G + rc (cos(phi + ang), sin(phi + ang))
        vy = gy + (sphi * ca + cphi * sa)
        yield i, vx, vy, vx - base[i, 0], vy - base[i, 1]


def reach_margin(design, gx, gy, phi: float = 0.0) -> np.ndarray:
    """How far inside the workspace the centroid ``(gx, gy)`` lies at orientation ``phi`` [m]: the least, over the
    legs, distance of ``|platform vertex - base vertex|`` to the ends of ``[|a - b|, a + b]``; positive inside,
    negative outside, 0 on the boundary (a leg stretched or folded). Continuous, so its zero contour draws the
    boundary without a grid's stair steps."""
    d = Design.of(design)
    lo, hi = abs(d.a - d.b), d.a + d.b
    margin = np.full(np.broadcast_shapes(np.shape(gx), np.shape(gy)), np.inf)
    for _, _, _, tx, ty in _vertices(d, np.asarray(gx, float), np.asarray(gy, float), phi):
        dist = np.hypot(tx, ty)
        margin = np.minimum(margin, np.minimum(dist - lo, hi - dist))
    return margin


def _moment_point(d: Design, gx, gy, phi, reference: str):
    if reference == "centroid":
        return gx, gy
    if reference == "A":
        rc = d.h / rrr3.SQRT3
        return gx + rc * np.cos(phi + _VERTEX_ANGLES[0]), gy + rc * np.sin(phi + _VERTEX_ANGLES[0])
    return 0.0, 0.0  # "origin"


def inverse_jacobian_stack(design, gx, gy, settings: CiSettings = CiSettings()) -> tuple[np.ndarray, np.ndarray]:
    """``K = J_q^-1 J_x`` (homogenised) at many centroid positions: motor rates from ``(v_P, L Phi_dot)``.

    Args:
        design: Anything with ``a, b, h, H`` [m].
        gx, gy: Centroid coordinates [m], same shape ``S``.
        settings: Orientation, working mode, ``L`` and moment point (``kind`` unused).

    Returns:
        ``(K, reachable)``: ``K`` of shape ``S + (3, 3)`` [1/m] (``inf``/``nan`` rows where a leg is
        stretched, folded or out of reach), ``reachable`` of shape ``S``.
    """
    d = Design.of(design)
    gx, gy = np.asarray(gx, dtype=float), np.asarray(gy, dtype=float)
    reach, legs = _legs(d, gx, gy, settings.phi, rrr3.branch_signs(settings.branch))
    L = settings.length_for(d)
    px, py = _moment_point(d, gx, gy, settings.phi, settings.reference)
    K = np.empty(gx.shape + (3, 3))
    with np.errstate(divide="ignore", invalid="ignore"):
        for i, (vx, vy, ux, uy, s) in enumerate(legs):
            K[..., i, 0] = ux / s
            K[..., i, 1] = uy / s
            K[..., i, 2] = ((vx - px) * uy - (vy - py) * ux) / (L * s)
    return K, reach


def _condition_index(rows, s, kind: str) -> np.ndarray:
    """``1 / kappa`` of ``K = diag(1/s) R`` (``R`` rows ``rows[i] = (r_x, r_y, r_m)``), by the eigenvalues of ``K' K'^T``."""
    w = (s[1] * s[2], s[0] * s[2], s[0] * s[1])  # K' = (s1 s2 s3) K = diag(w) R
    kr = [[w[i] * rows[i][j] for j in range(3)] for i in range(3)]

    def dot(i, j):
        return kr[i][0] * kr[j][0] + kr[i][1] * kr[j][1] + kr[i][2] * kr[j][2]

    m00, m11, m22, m01, m02, m12 = dot(0, 0), dot(1, 1), dot(2, 2), dot(0, 1), dot(0, 2), dot(1, 2)
    detk = (kr[0][0] * (kr[1][1] * kr[2][2] - kr[1][2] * kr[2][1])
            - kr[0][1] * (kr[1][0] * kr[2][2] - kr[1][2] * kr[2][0])
            + kr[0][2] * (kr[1][0] * kr[2][1] - kr[1][1] * kr[2][0]))
    p3 = detk * detk  # det M
    tr = m00 + m11 + m22
    p2 = m00 * m11 - m01 * m01 + m00 * m22 - m02 * m02 + m11 * m22 - m12 * m12
    with np.errstate(divide="ignore", invalid="ignore"):
        if kind == "fro_normalized":  # kappa_F / 3 = sqrt(tr M tr M^-1) / 3, tr M^-1 = p2 / p3
            ci = np.where(p3 > 0.0, 3.0 * np.sqrt(p3 / (tr * p2)), 0.0)
        else:
            q = tr / 3.0
            off = m01 * m01 + m02 * m02 + m12 * m12
            pp = np.sqrt(((m00 - q) ** 2 + (m11 - q) ** 2 + (m22 - q) ** 2 + 2.0 * off) / 6.0)
            ps = np.where(pp > 0.0, pp, 1.0)
            b00, b11, b22 = (m00 - q) / ps, (m11 - q) / ps, (m22 - q) / ps
            b01, b02, b12 = m01 / ps, m02 / ps, m12 / ps
            detb = b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02) + b02 * (b01 * b12 - b11 * b02)
            ang = np.arccos(np.clip(detb / 2.0, -1.0, 1.0)) / 3.0
            lmax = np.where(pp > 0.0, q + 2.0 * pp * np.cos(ang), q)
            half = (tr - lmax) / 2.0  # (lambda_mid + lambda_min) / 2
            prod = p3 / np.where(lmax > 0.0, lmax, 1.0)  # lambda_mid * lambda_min
            # At a node exactly on an inverse singularity M has rank 1 and half cancels to +-1e-17: a denominator
            # <= 0 means lambda_min = 0 (it gave CI = 1 there before issue 15, found by the generic route)
            den = half + np.sqrt(np.clip(half * half - prod, 0.0, None))
            lmin = np.where(den > 0.0, prod / np.where(den > 0.0, den, 1.0), 0.0)
            ci = np.where((lmax > 0.0) & (p3 > 0.0), np.sqrt(np.clip(lmin / lmax, 0.0, 1.0)), 0.0)
    return np.clip(np.nan_to_num(ci, nan=0.0), 0.0, 1.0)


def condition_index(design, gx, gy, settings: CiSettings = CiSettings()) -> tuple[np.ndarray, np.ndarray]:
    """``CI = 1/kappa`` (eq. 23) at many centroid positions; ``NaN`` where unreachable.

    Args:
        design: Anything with ``a, b, h, H`` [m].
        gx, gy: Centroid coordinates [m] (broadcast together; ``settings.phi`` may instead be given
            per node through :func:`condition_index_phi`).
        settings: See :class:`CiSettings`.

    Returns:
        ``(ci, reachable)`` of the broadcast shape; ``ci`` in [0, 1], 0 at a singularity.
    """
    gx, gy = _broadcast(("gx", gx), ("gy", gy))
    return condition_index_phi(design, gx, gy, _settings(settings).phi, settings)


def condition_index_phi(design, gx, gy, phi, settings: CiSettings = CiSettings()) -> tuple[np.ndarray, np.ndarray]:
    """As :func:`condition_index` with the orientation ``phi`` [rad] given per node (broadcast with ``gx``)."""
    d = Design.of(design)
    settings = _settings(settings)
    gx, gy, phi = _broadcast(("gx", gx), ("gy", gy), ("phi", phi))
    if gx.size > MAX_NODES:
        raise InvalidInputError("gx", f"{gx.size} nodes exceed {MAX_NODES}; evaluate in parts", gx.shape)
    if not (np.all(np.isfinite(gx)) and np.all(np.isfinite(gy)) and np.all(np.isfinite(phi))):
        raise InvalidInputError("gx, gy, phi", "must be finite (m, m, rad)")
    shape = gx.shape
    gx, gy, phi = gx.ravel(), gy.ravel(), phi.ravel()
    constant = phi.size > 0 and bool(np.all(phi == phi[0]))
    ci = np.full(gx.size, np.nan)
    reach = np.zeros(gx.size, dtype=bool)
    signs = rrr3.branch_signs(settings.branch)
    L = settings.length_for(d)
    for start in range(0, gx.size, _CHUNK):
        sl = slice(start, start + _CHUNK)
        x, y, p = gx[sl], gy[sl], (phi[:1] if constant else phi[sl])
        ok, legs = _legs(d, x, y, p, signs, reachable_only=True)
        if not np.any(ok):
            continue
        x, y, p = x[ok], y[ok], (p if constant else p[ok])
        px, py = _moment_point(d, x, y, p, settings.reference)
        rows = [(ux, uy, ((vx - px) * uy - (vy - py) * ux) / L) for vx, vy, ux, uy, _ in legs]
        idx = np.flatnonzero(ok) + start
        ci[idx] = _condition_index(rows, [leg[4] for leg in legs], settings.kind)
        reach[idx] = True
    return ci.reshape(shape), reach.reshape(shape)


# ---------------------------------------------------------------------- results
@dataclass(frozen=True)
class Gci:
    """A global condition index (eq. 24) over a region.

    Attributes:
        value: Mean CI over the counted nodes; ``None`` when no node is counted (empty workspace).
        nodes: Nodes of the region.
        reachable: Reachable nodes of the region.
        counted: Nodes in the mean (``reachable``, or ``nodes`` when unreachable ones count as 0).
    """

    value: float | None
    nodes: int
    reachable: int
    counted: int

    @property
    def empty(self) -> bool:
        return self.value is None


@dataclass(frozen=True, eq=False)
class CiMap:
    """A condition-index map over a grid at one orientation and working mode.

    Attributes:
        design: The dimensions.
        settings: The choices (see :class:`CiSettings`).
        grid: The grid of centroid positions.
        ci: CI per node, shape ``(ny, nx)`` (rows along ``y``), ``NaN`` where unreachable.
        reachable: Reachable nodes, same shape.
    """

    design: Design
    settings: CiSettings
    grid: Grid
    ci: np.ndarray = field(repr=False)
    reachable: np.ndarray = field(repr=False)

    def gci(self, region: np.ndarray | None = None, *, unreachable: str = "exclude") -> Gci:
        """Eq. (24) over ``region`` (a node mask, default all nodes).

        Args:
            region: Boolean mask of shape ``(ny, nx)``.
            unreachable: ``"exclude"`` (the paper's reading: ``n`` counts workspace nodes) or
                ``"zero"`` (unreachable nodes of the region count with CI = 0).
        """
        mask = np.ones(self.ci.shape, dtype=bool) if region is None else np.asarray(region, dtype=bool)
        if mask.shape != self.ci.shape:
            raise InvalidInputError("region", f"mask shape {mask.shape} is not the grid's {self.ci.shape}")
        if unreachable not in ("exclude", "zero"):
            raise InvalidInputError("unreachable", f"use 'exclude' or 'zero', got {unreachable!r}", unreachable)
        inside = mask & self.reachable
        nodes, reach = int(mask.sum()), int(inside.sum())
        counted = reach if unreachable == "exclude" else nodes
        value = float(np.sum(self.ci[inside]) / counted) if counted and reach else (0.0 if counted else None)
        return Gci(value, nodes, reach, counted)

    def area_gci(self, side: float = AREA_SIDE, *, unreachable: str = "exclude") -> Gci:
        """GCI over the square area of interest of side ``side`` [m] about the base centroid."""
        return self.gci(self.grid.square_mask(side, self.design.base_centroid), unreachable=unreachable)


def ci_map(design, grid: Grid | None = None, settings: CiSettings = CiSettings()) -> CiMap:
    """The CI map of ``design`` over ``grid`` (default :func:`workspace_grid`: every reachable centroid)."""
    d = Design.of(design)
    g = workspace_grid(d) if grid is None else _grid(grid)
    rows, cols = _reach_box(d, g, _settings(settings).phi)
    ci, reach = np.full((g.ys.size, g.xs.size), np.nan), np.zeros((g.ys.size, g.xs.size), dtype=bool)
    if rows.stop > rows.start and cols.stop > cols.start:
        ci[rows, cols], reach[rows, cols] = condition_index(d, g.xs[None, cols], g.ys[rows, None], settings)
    return CiMap(d, settings, g, ci, reach)


def _reach_box(d: Design, g: Grid, phi: float) -> tuple[slice, slice]:
    """The rows and columns of ``g`` outside which no node is reachable at orientation ``phi``: leg ``i`` reaches
    only where ``G`` lies within ``(a + b)(1 + REACH_TOL)`` of its base vertex less the platform vertex's offset, so
    each leg bounds a box; their intersection, widened by a step (rounding: the nodes outside are unreachable by far
    more than that). A map evaluates the nodes inside only (those outside are NaN, unreachable, as evaluated)."""
    reach = (d.a + d.b) * (1.0 + rrr3.REACH_TOL) + g.step
    x_lo = y_lo = -math.inf
    x_hi = y_hi = math.inf
    for _, _, _, tx, ty in _vertices(d, 0.0, 0.0, phi):  # (G = 0: t = offset - base, the disc's centre is -t)
        x_lo, x_hi = max(x_lo, -float(tx) - reach), min(x_hi, -float(tx) + reach)
        y_lo, y_hi = max(y_lo, -float(ty) - reach), min(y_hi, -float(ty) + reach)
    xs, ys = g.xs, g.ys
    cols = slice(int(np.searchsorted(xs, x_lo)), int(np.searchsorted(xs, x_hi, side="right")))
    rows = slice(int(np.searchsorted(ys, y_lo)), int(np.searchsorted(ys, y_hi, side="right")))
    return rows, cols


@dataclass(frozen=True, eq=False)
class Workspace:
    """The constant-orientation workspace of the centroid on a grid.

    Attributes:
        design: The dimensions.
        phi: Orientation [rad].
        grid: The grid.
        reachable: Reachable nodes, shape ``(ny, nx)`` (every working mode reaches the same set).
    """

    design: Design
    phi: float
    grid: Grid
    reachable: np.ndarray = field(repr=False)

    @property
    def nodes(self) -> int:
        return int(self.reachable.sum())

    @property
    def empty(self) -> bool:
        return self.nodes == 0

    @property
    def area(self) -> float:
        """Area estimate [m^2]: reachable nodes times ``step^2``."""
        return self.nodes * self.grid.step ** 2

    @property
    def touches_edge(self) -> bool:
        """Whether a reachable node lies on the grid's border (the grid may then cut the workspace)."""
        r = self.reachable
        return bool(r[0].any() or r[-1].any() or r[:, 0].any() or r[:, -1].any())


def workspace(design, phi: float = 0.0, grid: Grid | None = None) -> Workspace:
    """Reachable centroid positions at orientation ``phi`` [rad] (eq. 9 real on every leg), Fig. 3."""
    d = Design.of(design)
    phi = as_scalar(phi, "phi", unit="rad")
    g = workspace_grid(d) if grid is None else _grid(grid)
    reach, _ = _reach(d, g.xs[None, :], g.ys[:, None], phi)
    return Workspace(d, phi, g, reach)


def workspace_grid(design, step: float | None = None) -> Grid:
    """A grid that contains every reachable centroid: base centroid ``+- (a + b + H / sqrt 3)``; default 201 x 201."""
    d = Design.of(design)
    half = d.a + d.b + d.H / rrr3.SQRT3
    return Grid.square(d.base_centroid, half, half / 100.0 if step is None else step)


@dataclass(frozen=True, eq=False)
class OrientationSweep:
    """Workspace and CI over a 3-D grid (positions x orientations), as in the paper's Fig. 3 count.

    Attributes:
        phis: Orientations [rad].
        reachable_nodes: Reachable nodes per orientation.
        ci_sum: Sum of CI over the reachable nodes per orientation.
        nodes: Every node evaluated (positions x orientations).
        step: Position grid step [m] (``area = reachable_nodes * step^2``).
    """

    phis: np.ndarray
    reachable_nodes: np.ndarray
    ci_sum: np.ndarray
    nodes: int
    step: float

    @property
    def areas(self) -> np.ndarray:
        return self.reachable_nodes * self.step ** 2

    @property
    def gci(self) -> np.ma.MaskedArray:
        """GCI per orientation, masked where the workspace is empty (no average is taken there)."""
        empty = self.reachable_nodes == 0
        return np.ma.masked_array(self.ci_sum / np.where(empty, 1, self.reachable_nodes), mask=empty)


def orientation_sweep(design, xs: ArrayLike, ys: ArrayLike, phis: ArrayLike,
                      settings: CiSettings = CiSettings()) -> OrientationSweep:
    """Reachability and CI on every node of ``xs x ys x phis`` (m, m, rad); ``settings.phi`` is ignored.

    ``xs`` must be evenly spaced (its step sets the node area).
    """
    gx, gy, gphi = (np.asarray(v, dtype=float).ravel() for v in (xs, ys, phis))
    if min(gx.size, gy.size, gphi.size) == 0:
        raise InvalidInputError("xs, ys, phis", "each needs at least one value")
    step = float(gx[1] - gx[0]) if gx.size > 1 else 0.0
    per = max(1, _CHUNK // (gx.size * gy.size))
    reach_n, ci_sum = np.zeros(gphi.size, dtype=np.int64), np.zeros(gphi.size)
    X, Y = np.meshgrid(gx, gy)
    for k in range(0, gphi.size, per):
        ph = gphi[k:k + per]
        ci, reach = condition_index_phi(design, X[None], Y[None], ph[:, None, None], settings)
        reach_n[k:k + per] = reach.sum(axis=(1, 2))
        ci_sum[k:k + per] = np.where(reach, ci, 0.0).sum(axis=(1, 2))
    return OrientationSweep(gphi, reach_n, ci_sum, gx.size * gy.size * gphi.size, step)


# ---------------------------------------------------------------------- singularities inside a region
def direct_singularity_crossings(design, grid: Grid, settings: CiSettings = CiSettings(),
                                 region: np.ndarray | None = None) -> int:
    """Neighbouring reachable node pairs of ``region`` between which ``det J_x`` changes sign.

    A direct-singularity curve (``det J_x = 0``) crossing the region shows as such pairs; 0 means the
    region is free of direct singularities at the grid's resolution.
    """
    d = Design.of(design)
    grid, settings = _grid(grid), _settings(settings)
    if region is not None and np.shape(region) != (grid.ys.size, grid.xs.size):
        raise InvalidInputError("region", f"mask shape {np.shape(region)} is not the grid's "
                                          f"{(grid.ys.size, grid.xs.size)}", np.shape(region))
    rows, cols = _reach_box(d, grid, settings.phi)  # (outside, no node is reachable: no pair counts)
    if rows.stop <= rows.start or cols.stop <= cols.start:
        return 0
    X, Y = grid.xs[None, cols], grid.ys[rows, None]
    reach, legs = _legs(d, X, Y, settings.phi, rrr3.branch_signs(settings.branch), reachable_only=True)
    X, Y = (np.broadcast_to(v, reach.shape)[reach] for v in (X, Y))
    (ax, ay), (bx, by), (cx, cy) = [(ux, uy) for _, _, ux, uy, _ in legs]
    mx = [((vx - X) * uy - (vy - Y) * ux) for vx, vy, ux, uy, _ in legs]
    ok = reach if region is None else reach & np.asarray(region, dtype=bool)[rows, cols]
    sgn = np.zeros(reach.shape)  # (unreachable nodes: never counted)
    sgn[reach] = np.sign(ax * (by * mx[2] - mx[1] * cy) - ay * (bx * mx[2] - mx[1] * cx) + mx[0] * (bx * cy - by * cx))
    h = ok[:, 1:] & ok[:, :-1] & (sgn[:, 1:] * sgn[:, :-1] <= 0)
    v = ok[1:, :] & ok[:-1, :] & (sgn[1:, :] * sgn[:-1, :] <= 0)
    return int(h.sum() + v.sum())


# ---------------------------------------------------------------------- designs
@dataclass(frozen=True, eq=False)
class SweepResult:
    """Quality of many designs (one row per design).

    Attributes:
        designs: The designs.
        gci: Overall GCI, masked where the workspace is empty (no average taken).
        area_gci: GCI over the reachable nodes of the area of interest, masked where there are none.
        coverage: Fraction of the area of interest that is reachable.
        min_area_ci: Smallest CI over the reachable nodes of the area, masked where there are none.
    """

    designs: tuple[Design, ...]
    gci: np.ma.MaskedArray
    area_gci: np.ma.MaskedArray
    coverage: np.ndarray
    min_area_ci: np.ma.MaskedArray

    def best(self, min_coverage: float = 1.0) -> int | None:
        """Index of the design with the highest area GCI among those covering ``min_coverage`` of the area."""
        ok = (self.coverage >= min_coverage - 1e-12) & ~np.ma.getmaskarray(self.area_gci)
        return int(np.flatnonzero(ok)[np.argmax(self.area_gci.data[ok])]) if ok.any() else None


def sweep(designs: Iterable, *, step: float = 0.01, side: float = AREA_SIDE, settings: CiSettings = CiSettings(),
          progress: bool = True) -> SweepResult:
    """Overall and area GCI of every design (a :func:`workspace_grid` box at ``step`` [m]), with a tqdm bar."""
    designs = tuple(Design.of(d) for d in designs)
    if not designs:
        raise InvalidInputError("designs", "needs at least one design")
    out = np.full((len(designs), 4), np.nan)
    iterator = designs
    if progress:
        from tqdm import tqdm
        iterator = tqdm(designs, desc="3-RRR designs", unit="design", disable=None)
    for k, d in enumerate(iterator):
        m = ci_map(d, workspace_grid(d, step), settings)
        overall, area = m.gci(), m.area_gci(side)
        region = m.grid.square_mask(side, d.base_centroid) & m.reachable
        out[k] = [overall.value if not overall.empty else np.nan, area.value if not area.empty else np.nan,
                  area.reachable / area.nodes, float(np.min(m.ci[region])) if region.any() else np.nan]
    masked = [np.ma.masked_invalid(out[:, k]) for k in (0, 1, 3)]
    return SweepResult(designs, masked[0], masked[1], out[:, 2], masked[2])


def naive_condition_index(design, y, settings: CiSettings = CiSettings()) -> float:
    """One node the slow way (baseline and cross-check): per-pose Jacobians and an SVD. ``NaN`` if unreachable."""
    d = Design.of(design)
    params = _LooseParams(d.a, d.b, d.h, d.H)
    try:
        Jx, Jq = rrr3.homogenized_jacobians(params, y, settings.branch, length=settings.length_for(d),
                                            reference=settings.reference)
    except UnreachableError:
        return float("nan")
    except SingularityError:
        return 0.0
    if np.min(np.abs(np.diag(Jq))) == 0.0:
        return 0.0
    return float(inverse_condition(Jx / np.diag(Jq)[:, None], settings.kind))


def _broadcast(*named) -> tuple[np.ndarray, ...]:
    """The named arrays as floats broadcast together; InvalidInputError naming them otherwise."""
    arrays = [as_array(v, n, "coordinates (m) or angles (rad)") for n, v in named]
    try:
        return tuple(np.broadcast_arrays(*arrays))
    except ValueError:
        raise InvalidInputError(", ".join(n for n, _ in named), "shapes " + ", ".join(str(a.shape) for a in arrays)
                                + " do not broadcast together; pass arrays of one shape") from None


def _settings(settings) -> CiSettings:
    if not isinstance(settings, CiSettings):
        raise InvalidInputError("settings", f"expected a CiSettings, got {type(settings).__name__}", settings)
    return settings


def _grid(grid) -> Grid:
    if not isinstance(grid, Grid):
        raise InvalidInputError("grid", f"expected a Grid (Grid.square(centre, half_width, step)), got "
                                        f"{type(grid).__name__}", grid)
    return grid


@dataclass(frozen=True)
class _LooseParams(rrr3.Rrr3Params):
    """The four lengths the closed forms read, without Rrr3Params' reference-pose checks."""

    def __post_init__(self):
        check_positive(self, "a", "b", "h", "H")


def __getattr__(name: str) -> tuple[str, ...]:
    if name == "NORMS":  # (deprecated since 0.2.0)
        renamed("pkm.mechanisms.rrr3.workspace", "NORMS", "KINDS")
        return KINDS
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "AREA_SIDE",
    "KINDS",
    "CiMap",
    "CiSettings",
    "Design",
    "Gci",
    "Grid",
    "OrientationSweep",
    "SweepResult",
    "Workspace",
    "ci_map",
    "condition_index",
    "condition_index_phi",
    "direct_singularity_crossings",
    "inverse_jacobian_stack",
    "naive_condition_index",
    "orientation_sweep",
    "reach_margin",
    "sweep",
    "workspace",
    "workspace_grid",
]
