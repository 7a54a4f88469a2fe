"""Which assembly and working mode a configuration is in: the signs of the diagonal blocks' determinants of the
solvers' Newton matrices, relative to the reference configuration's (the labels the exported libraries give,
:mod:`pkm.core.export.model`, here on the numeric Jacobians).

* assembly (forward kinematics): the closure Jacobian on the passive coordinates;
* working (inverse kinematics): the closure and task Jacobian on every coordinate but a floating base's.

Each matrix's block triangular form (:func:`~pkm.core.kinematics.blocks.block_triangular`, from its sparsity: entries
nonzero at the reference or at two seeded configurations near it) has one block per independent part (the inverse
kinematics of independent legs: one per leg). A block's determinant changes sign only where the block is singular, so
two configurations whose signs differ are in different modes, joined by no path that avoids the singularity; equal
signs do not prove the same mode (the hexapod's assembly modes share signs). Rows that vanish everywhere (a planar
mechanism's normal rows) are dropped, and of more rows than columns those a pivoted QR picks at the reference;
blocks whose entries never change are left out. Where the matrix is rank deficient at the reference (an idle motion,
a reference on a singularity) the label is empty: no mode is told.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import scipy.linalg
from numpy.typing import ArrayLike

from pkm.core.kinematics.blocks import block_triangular
from pkm.core.kinematics.configuration import Configuration
from pkm.core.model.mechanism import Mechanism
from pkm.core.model.scale import JacobianScales


@dataclass(frozen=True)
class ModeLabel:
    """The signs of the blocks' determinants at a configuration, relative to the reference's (+1 the reference's
    sign, -1 the opposite, 0 a singular block).

    Attributes:
        assembly: Per block of the forward kinematics' matrix (the closure Jacobian on the passive coordinates).
        working: Per block of the inverse kinematics' matrix (closure and task Jacobian).
    """

    assembly: tuple[int, ...] = ()
    working: tuple[int, ...] = ()

    @property
    def assembly_id(self) -> int:
        """Bit ``k`` set where assembly block ``k`` has the reference's opposite sign (0: the reference's mode)."""
        return sum(1 << k for k, s in enumerate(self.assembly) if s < 0)

    @property
    def working_id(self) -> int:
        """Bit ``k`` set where working block ``k`` has the reference's opposite sign (0: the reference's mode)."""
        return sum(1 << k for k, s in enumerate(self.working) if s < 0)

    def differs(self, other: ModeLabel) -> tuple[str, ...]:
        """``"assembly"`` and/or ``"working"`` where a block has opposite nonzero signs in the two labels."""
        out = []
        for kind in ("assembly", "working"):
            a, b = getattr(self, kind), getattr(other, kind)
            if len(a) == len(b) and any(x * y < 0 for x, y in zip(a, b)):
                out.append(kind)
        return tuple(out)

    def as_dict(self) -> dict[str, object]:
        """``{"assembly": [...], "working": [...], "assembly_id": int, "working_id": int}`` (JSON)."""
        return {"assembly": list(self.assembly), "working": list(self.working), "assembly_id": self.assembly_id,
                "working_id": self.working_id}


@dataclass(frozen=True)
class _Blocks:
    rows: np.ndarray  # the rows kept (indices into the full matrix)
    cols: np.ndarray  # the columns (velocity indices)
    blocks: tuple[tuple[tuple[int, ...], tuple[int, ...], int], ...]  # (rows, cols, reference sign), square indices

    def signs(self, A: np.ndarray) -> tuple[int, ...]:
        S = A[np.ix_(self.rows, self.cols)]
        out = [0] * len(self.blocks)
        for which, r, c in self.stacks:  # (the blocks of one size as one stack: one LAPACK call for them all)
            for k, sign in zip(which, _signs(S[r[:, :, None], c[:, None, :]])):
                out[k] = sign * self.blocks[k][2]
        return tuple(out)

    @functools.cached_property
    def stacks(self) -> tuple[tuple[tuple[int, ...], np.ndarray, np.ndarray], ...]:
        """The blocks grouped by size: ``(their indices, their rows (b x n), their columns (b x n))`` per size."""
        sizes: dict[int, list[int]] = {}
        for k, (r, _, _) in enumerate(self.blocks):
            sizes.setdefault(len(r), []).append(k)
        return tuple((tuple(ks), np.array([self.blocks[k][0] for k in ks], dtype=int).reshape(len(ks), n),
                      np.array([self.blocks[k][1] for k in ks], dtype=int).reshape(len(ks), n))
                     for n, ks in sizes.items())


#: A block whose smallest singular value is below this, relative to its largest, is singular: sign 0.
SINGULAR = 1e-8


def _sign(B: np.ndarray) -> int:
    """The sign of ``det(B)``, 0 where ``B`` is singular to :data:`SINGULAR` (there the sign is rounding)."""
    sv = np.linalg.svd(B, compute_uv=False)
    if not sv[-1] > SINGULAR * sv[0]:
        return 0
    return 1 if np.linalg.det(B) > 0 else -1


def _signs(B: np.ndarray) -> list[int]:
    """:func:`_sign` of each matrix of the stack ``B`` (b x n x n), by the same LAPACK routines on each. The SVD is
    skipped where the determinant proves the matrix regular: ``|det| > 10 SINGULAR ‖B‖_F^n`` gives, as ``|det|`` is
    the product of the singular values and ``‖B‖_F`` bounds the largest, a smallest above ``10 SINGULAR`` of the
    largest (LU's rounding of ``det``, ``n eps`` of ``‖B‖^n``, far below the margin)."""
    det = np.linalg.det(B)
    n = B.shape[-1]
    regular = np.abs(det) > 10.0 * SINGULAR * np.linalg.norm(B, axis=(-2, -1)) ** n
    if not regular.all():
        sv = np.linalg.svd(B[~regular], compute_uv=False)
        regular[~regular] = sv[:, -1] > SINGULAR * sv[:, 0]
    return [0 if not r else (1 if d > 0 else -1) for r, d in zip(regular, det)]


def _structure(mats: list[np.ndarray], cols: np.ndarray) -> _Blocks | None:
    """The blocks of ``mats[0]`` (the reference's matrix) on ``cols``, the sparsity from every matrix of ``mats``."""
    n = len(cols)
    if n == 0:  # (no coordinate to label: every joint actuated, or a floating base alone)
        return None
    A = [M[:, cols] for M in mats]
    scale = max(float(np.abs(M).max(initial=0.0)) for M in A) or 1.0
    nz = np.any([np.abs(M) > 1e-12 * scale for M in A], axis=0)
    rows = np.flatnonzero(nz.any(axis=1))
    if len(rows) < n:
        return None
    if len(rows) > n:
        _, _, piv = scipy.linalg.qr(A[0][rows].T, pivoting=True)
        rows = np.sort(rows[piv[:n]])
    ref = A[0][rows]
    if np.linalg.matrix_rank(ref, tol=1e-9 * scale) < n:
        return None
    pattern = nz[rows]
    constant = np.all([np.abs(M[rows] - ref) <= 1e-12 * scale for M in A], axis=0)
    try:
        found = block_triangular(pattern)
    except ValueError:
        return None
    signs = [(r, c, _sign(ref[np.ix_(r, c)])) for r, c in found if not constant[np.ix_(r, c)].all()]
    blocks = tuple(b for b in signs if b[2] != 0)  # (a block singular at the reference labels nothing)
    return _Blocks(rows, cols, blocks)


def _mats(mech: Mechanism, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The closure and the closure-and-task Jacobians at ``q``, homogenised (:func:`_scaled`)."""
    return _scaled(mech, Configuration.compute(mech, q).closure_and_task_jacobian)


def _scaled(mech: Mechanism, J: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The closure and the closure-and-task Jacobians from ``J``, the closure-and-task Jacobian, homogenised
    (:mod:`pkm.core.model.scale`: positive row and column factors, so the determinants' signs are the raw matrices'
    and the singularity thresholds mean the same at any size)."""
    J = np.asarray(J, dtype=float)
    scales = JacobianScales.of(mech)
    Jc = scales.constraint(J[:mech.n_constraints])
    return Jc, np.vstack([Jc, scales.task(J[mech.n_constraints:])])


def _structures(mech: Mechanism) -> tuple[_Blocks | None, _Blocks | None]:
    key = mech.q_reference.tobytes()  # (relative to the reference: found again where the reference changes)
    cached = mech.__dict__.get("_mode_blocks")
    if cached is None or cached[0] != key:
        rng = np.random.default_rng(0)
        qs = [mech.q_reference] + [pin.integrate(mech.model, mech.q_reference, 0.3 * rng.standard_normal(mech.nv))
                                   for _ in range(2)]
        fk, ik = zip(*(_mats(mech, q) for q in qs))
        free = np.arange(mech.nv) if mech.free_v is None else mech.free_v
        cached = (key, _structure(list(fk), mech.passive_v), _structure(list(ik), free))
        mech.__dict__["_mode_blocks"] = cached
    return cached[1], cached[2]


def mode_label(mech: Mechanism, q: ArrayLike) -> ModeLabel:
    """The assembly and working mode labels of the configuration ``q`` (module doc); one kinematics pass (the
    blocks are found once per mechanism).

    Examples:
        >>> import pkm
        >>> delta = pkm.load("delta")
        >>> pkm.mode_label(delta, delta.q_reference)
        ModeLabel(assembly=(1,), working=(1, 1, 1, 1))
        >>> q = pkm.branch_seed(delta, "knee_in")
        >>> pkm.mode_label(delta, q).working
        (1, -1, -1, -1)
    """
    return _label(mech, mech.check_q(q))


def mode_label_at(mech: Mechanism, q: np.ndarray, jacobian: np.ndarray | None = None, *,
                  result: bool = False) -> ModeLabel:
    """:func:`mode_label` of the checked configuration ``q`` from ``jacobian``, the raw closure-and-task Jacobian
    at ``q`` (:attr:`~pkm.core.kinematics.configuration.Configuration.closure_and_task_jacobian`, ``nv`` columns):
    the solvers' own Newton matrix, so that the label costs no kinematics pass (the same numbers); None: computed
    at ``q``. ``result``: ``q`` is a solve's result, whose label is kept (the last one, per mechanism and thread):
    a solve seeded with the last solve's result (a path followed step by step) finds its seed's label there."""
    return _label(mech, q, jacobian, result)


def _label(mech: Mechanism, q: np.ndarray, jacobian: np.ndarray | None = None, keep: bool = False) -> ModeLabel:
    """The label of ``q`` from ``jacobian`` (None: computed at ``q``), the one kept where it is ``q``'s; ``keep``:
    kept (:func:`mode_label_at`)."""
    fk, ik = _structures(mech)
    if fk is None and ik is None:
        return ModeLabel()
    if np.array_equal(q, mech.q_reference):  # (the reference's own signs, by construction: no kinematics pass)
        return ModeLabel(() if fk is None else (1,) * len(fk.blocks), () if ik is None else (1,) * len(ik.blocks))
    key = (q.tobytes(), mech.q_reference.tobytes())
    last = getattr(mech._local, "mode_label", None)
    if last is not None and last[0] == key:
        return last[1]
    fk_m, ik_m = _mats(mech, q) if jacobian is None else _scaled(mech, jacobian)
    label = ModeLabel(() if fk is None else fk.signs(fk_m), () if ik is None else ik.signs(ik_m))
    if keep:
        mech._local.mode_label = (key, label)
    return label
