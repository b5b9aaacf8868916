"""Order of equation blocks that solve explicitly, one scalar at a time (no CasADi).

A square system of scalar equations, grouped into consecutive *blocks* (the rows of one
array equation), solves explicitly block by block when

- it has a perfect matching of equations to unknowns (each equation solved for one unknown);
- its block-lower-triangular form has only 1x1 blocks (no algebraic loop);
- the blocks depend on each other without a cycle.

A block is solved as whole-vector operations: ``i[2:n] = (v[1:n-1] - v[2:n]) / R[2:n]`` is
one. Equations are taken by *level*: those using no unknown first, then those using only
these, and so on; a block whose equations sit at several levels (a sum of currents using the
currents of the other nodes, a class of component used in two roles) is solved in parts,
level by level. A system deeper than :data:`MAX_LEVELS` levels is ordered block by block
instead, with levels inside each block only (a recurrence deeper than that is refused).

A system with only 1x1 blocks has a single perfect matching, so the answer does not depend on
the matching found. The work is done on sparse integer arrays (scipy's compiled matching and
strongly connected components), in time linear in the number of incidences.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

#: a block is split into at most this many levels (each is one vector operation)
MAX_LEVELS = 64


@dataclass
class ExplicitOrder:
    """``unknown_of[r]``: the unknown equation ``r`` is solved for; ``blocks``: the block
    indices in solve order (each after the blocks whose unknowns it uses); ``rows[k]``: the
    rows of ``blocks[k]`` solved at that step (offsets in the block), None for all of them
    (a block split into levels comes once per level)."""

    unknown_of: np.ndarray
    blocks: list[int]
    rows: list[np.ndarray | None] | None = None

    def steps(self) -> list[tuple[int, np.ndarray | None]]:
        """``(block, rows)`` in solve order."""
        return list(zip(self.blocks, self.rows or [None] * len(self.blocks), strict=True))


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
    n_blocks = len(block_sizes)
    uses = rows != source
    level = _levels(n, rows[uses], source[uses])
    if level is not None:
        # levels of the whole system: a row comes after every row it uses, so steps taken
        # by level (then block, as written) are in order
        step_of = level * n_blocks + block_of
        steps, step_of = np.unique(step_of, return_inverse=True)
        order = list(range(steps.size))
        step_block = steps % n_blocks
    else:
        # a deep system: levels inside each block only, blocks ordered by their dependences
        inner = uses & (block_of[rows] == block_of[source])
        level = _levels(n, rows[inner], source[inner])
        if level is None:
            return (f"an equation uses an unknown solved by another row of its own block, "
                    f"over more than {MAX_LEVELS} levels (a recurrence)")
        n_levels = int(level.max()) + 1
        steps, step_of = np.unique(block_of * n_levels + level, return_inverse=True)
        b_row, b_src = step_of[rows], step_of[source]
        cross = b_row != b_src
        edges = np.unique(b_src[cross] * steps.size + b_row[cross])
        found = _topological(steps.size, edges // steps.size, edges % steps.size)
        if found is None:
            return "the blocks depend on each other in a cycle"
        order = found
        step_block = steps // n_levels
    blocks = step_block[order].tolist()
    split = np.bincount(step_block, minlength=n_blocks) > 1
    if not split.any():
        return ExplicitOrder(unknown_of.astype(np.int64), blocks)
    starts = np.concatenate(([0], np.cumsum(block_sizes)))
    parts = [np.flatnonzero(step_of[starts[b]:starts[b + 1]] == step) if split[b] else None
             for step, b in zip(order, blocks, strict=True)]
    return ExplicitOrder(unknown_of.astype(np.int64), blocks, parts)


def _levels(n: int, rows: np.ndarray, sources: np.ndarray) -> np.ndarray | None:
    """The level of each of ``n`` equations along the edges ``sources[k] -> rows[k]`` (an
    acyclic graph): 0 without incoming edge, else one more than its highest source; None
    past :data:`MAX_LEVELS`."""
    level = np.zeros(n, dtype=np.int64)
    for _ in range(MAX_LEVELS):
        if not rows.size:
            return level
        want = np.zeros(n, dtype=np.int64)
        np.maximum.at(want, rows, level[sources] + 1)
        if (want <= level).all():
            return level
        level = np.maximum(level, want)
    return None


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
