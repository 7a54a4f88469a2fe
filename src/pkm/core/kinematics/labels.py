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
        return tuple(_sign(S[np.ix_(r, c)]) * s for r, c, s in self.blocks)


#: A block whose smallest singular value is below this, relative to its largest, is singular: sign 0.
SINGULAR = 1e-8


def _sign(B: np.ndarray) -> int:
    """The sign of ``det(B)``, 0 where ``B`` is singular to :data:`SINGULAR` (there the sign is rounding)."""
    sv = np.linalg.svd(B, compute_uv=False)
    if not sv[-1] > SINGULAR * sv[0]:
        return 0
    return 1 if np.linalg.det(B) > 0 else -1


def _structure(mats: list[np.ndarray], cols: np.ndarray) -> _Blocks | None:
    """The blocks of ``mats[0]`` (the reference's matrix) on ``cols``, the sparsity from every matrix of ``mats``."""
    A = [M[:, cols] for M in mats]
    scale = max(float(np.abs(M).max()) for M in A) or 1.0
    nz = np.any([np.abs(M) > 1e-12 * scale for M in A], axis=0)
    rows = np.flatnonzero(nz.any(axis=1))
    n = len(cols)
    if len(rows) < n or n == 0:
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
    """The closure and the closure-and-task Jacobians at ``q``, homogenised (:mod:`pkm.core.model.scale`: positive
    row and column factors, so the determinants' signs are the raw matrices' and the singularity thresholds mean the
    same at any size)."""
    c = Configuration.compute(mech, q)
    J = np.array(c.closure_and_task_jacobian)
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
    fk, ik = _structures(mech)
    q = mech.check_q(q)
    if fk is None and ik is None:
        return ModeLabel()
    if np.array_equal(q, mech.q_reference):  # (the reference's own signs, by construction: no kinematics pass)
        return ModeLabel(() if fk is None else (1,) * len(fk.blocks), () if ik is None else (1,) * len(ik.blocks))
    fk_m, ik_m = _mats(mech, q)
    return ModeLabel(() if fk is None else fk.signs(fk_m), () if ik is None else ik.signs(ik_m))
