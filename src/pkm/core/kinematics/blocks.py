"""The block triangular form of a square sparsity pattern (Dulmage-Mendelsohn's fine decomposition): the one
structural routine behind the mode labels (the diagonal blocks of a Newton matrix, whose determinants' signs label
assembly and working modes: :mod:`pkm.core.kinematics.labels`, :mod:`pkm.core.export.model`) and the cascade of the
whole-mechanism polynomial systems (:mod:`pkm.core.modes.generic`: a block solved before the blocks that use its
unknowns).
"""

from __future__ import annotations

import numpy as np


def block_triangular(nz: np.ndarray, *, ordered: bool = False) -> list[tuple[tuple[int, ...], tuple[int, ...]]]:
    """The irreducible diagonal blocks ``(rows, cols)`` of the square boolean pattern ``nz`` (``nz[i, j]``: entry
    ``(i, j)`` may be nonzero); ``ordered``: in an order where a block's rows use only its own columns and those of
    the blocks before it (else in the order of scipy's strongly connected components, which the exported libraries'
    mode bits follow). A maximum matching puts a nonzero on every diagonal entry; the strongly connected components of the
    rows' graph are the blocks.

    Raises:
        ValueError: the pattern is structurally singular (no perfect matching).
    """
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components, maximum_bipartite_matching

    nz = np.asarray(nz, dtype=bool)
    n = nz.shape[0]
    if nz.shape != (n, n):
        raise ValueError(f"a {nz.shape} pattern is not square")
    match = maximum_bipartite_matching(csr_matrix(nz.astype(float)), perm_type="column")  # row i -> its column
    if (match < 0).any():
        raise ValueError("structurally singular")
    col_row = np.empty(n, dtype=int)
    col_row[match] = np.arange(n)
    G = np.zeros((n, n), dtype=bool)  # row i -> row r when row i uses r's column: r is solved first
    for i in range(n):
        for j in np.flatnonzero(nz[i]):
            G[i, col_row[j]] = True
    count, label = connected_components(csr_matrix(G.astype(float)), directed=True, connection="strong")
    after: list[set[int]] = [set() for _ in range(count)]  # the blocks each block needs first
    for i, r in zip(*np.nonzero(G)):
        if label[i] != label[r]:
            after[label[i]].add(int(label[r]))
    order: list[int] = [] if ordered else list(range(count))
    while len(order) < count:  # (a topological order of the condensation)
        ready = [k for k in range(count) if k not in order and after[k] <= set(order)]
        order.append(min(ready))
    return [(tuple(int(r) for r in np.flatnonzero(label == k)),
             tuple(int(match[r]) for r in np.flatnonzero(label == k))) for k in order]
