"""Order of equation blocks that solve explicitly, one scalar at a time (no CasADi).

A square system of scalar equations, grouped into consecutive *blocks* (the rows of one
array equation), solves explicitly block by block when

- it has a perfect matching of equations to unknowns (each equation solved for one unknown);
- its block-lower-triangular form has only 1x1 blocks (no algebraic loop);
- no equation uses an unknown solved by another equation of its own block (a block is then
  one whole-vector operation: ``i[2:n] = (v[1:n-1] - v[2:n]) / R[2:n]``, not a recurrence);
- the blocks depend on each other without a cycle.

A system with only 1x1 blocks has a single perfect matching, so the answer does not depend on
the matching found. The work is done on sparse integer arrays (scipy's compiled matching and
strongly connected components), in time linear in the number of incidences.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass
class ExplicitOrder:
    """``unknown_of[r]``: the unknown equation ``r`` is solved for; ``blocks``: the block
    indices in solve order (each after the blocks whose unknowns it uses)."""

    unknown_of: np.ndarray
    blocks: list[int]


def explicit_order(n: int, rows: np.ndarray, cols: np.ndarray,
                   block_sizes: Sequence[int]) -> ExplicitOrder | str:
    """The explicit solve order of ``n`` equations in ``n`` unknowns, or why there is none.

    rows, cols: the incidence pairs (equation ``rows[k]`` uses unknown ``cols[k]``;
    duplicates allowed); block_sizes: the number of equations of each block, in row order.
    """
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components, maximum_bipartite_matching

    rows = np.asarray(rows, dtype=np.int64)
    cols = np.asarray(cols, dtype=np.int64)
    if sum(block_sizes) != n:
        return f"the blocks hold {sum(block_sizes)} equations, not {n}"
    if n == 0:
        return ExplicitOrder(np.zeros(0, dtype=np.int64), list(range(len(block_sizes))))
    ones = np.ones(rows.size, dtype=np.int8)
    incidence = csr_matrix((ones, (rows, cols)), shape=(n, n))
    unknown_of = maximum_bipartite_matching(incidence, perm_type="column")
    if (unknown_of < 0).any():
        return "no perfect matching of equations to unknowns"
    eq_of = np.empty(n, dtype=np.int64)
    eq_of[unknown_of] = np.arange(n)
    source = eq_of[cols]                       # the equation that solves what row r uses
    depends = csr_matrix((ones, (rows, source)), shape=(n, n))
    n_scc, _ = connected_components(depends, directed=True, connection="strong")
    if n_scc != n:
        return f"{n - n_scc} more unknowns than 1x1 blocks: an algebraic loop"
    block_of = np.repeat(np.arange(len(block_sizes)), block_sizes)
    b_row, b_src = block_of[rows], block_of[source]
    if ((b_row == b_src) & (rows != source)).any():
        return "an equation uses an unknown solved by another row of its own block"
    cross = b_row != b_src
    n_blocks = len(block_sizes)
    edges = np.unique(b_src[cross] * n_blocks + b_row[cross])
    order = _topological(n_blocks, edges // n_blocks, edges % n_blocks)
    if order is None:
        return "the blocks depend on each other in a cycle"
    return ExplicitOrder(unknown_of.astype(np.int64), order)


def _topological(n: int, before: np.ndarray, after: np.ndarray) -> list[int] | None:
    """Kahn's order of ``n`` nodes with edges ``before[k] -> after[k]`` (None on a cycle);
    ready nodes are taken lowest index first, so the order follows the model text."""
    import heapq

    indegree = np.bincount(after, minlength=n).tolist()
    succ: list[list[int]] = [[] for _ in range(n)]
    for a, b in zip(before.tolist(), after.tolist(), strict=True):
        succ[a].append(b)
    ready = [k for k in range(n) if indegree[k] == 0]
    heapq.heapify(ready)
    out: list[int] = []
    while ready:
        k = heapq.heappop(ready)
        out.append(k)
        for m in succ[k]:
            indegree[m] -= 1
            if indegree[m] == 0:
                heapq.heappush(ready, m)
    return out if len(out) == n else None
