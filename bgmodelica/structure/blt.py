"""Block-lower-triangular ordering via Tarjan's strongly connected components (iterative)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from . import compiled
from .diagnosis import check_structurally_nonsingular
from .graph import gc_paused
from .matching import Matching


@dataclass
class Block:
    """One block of the BLT form: ``eqs[k]`` is matched to ``vars[k]``."""

    eqs: list[int]
    vars: list[int]

    @property
    def size(self) -> int:
        """Number of equations (and unknowns) in the block."""
        return len(self.eqs)


@gc_paused()
def block_lower_triangular(
    eq_vars: Sequence[Sequence[int]], n_unknowns: int, matching: Matching | None = None
) -> list[Block]:
    """Split a square system into blocks listed in solve order.

    ``eq_vars`` must list only unknowns (indices ``0..n_unknowns-1``). ``matching`` must be
    perfect; if missing or not perfect one is computed, raising
    :class:`~bgmodelica.structure.errors.StructurallySingular` if none exists. A block depends
    only on the unknowns of itself and of earlier blocks; within a block, equations are sorted.
    From :data:`~.compiled.LARGE` equations on the order is found by compiled code.
    """
    n = len(eq_vars)
    if matching is None or matching.size != n or n != n_unknowns:
        matching = check_structurally_nonsingular(eq_vars, n_unknowns, matching)
    var_to_eq, eq_to_var = matching.var_to_eq, matching.eq_to_var
    if n >= compiled.LARGE:
        groups = compiled.compiled_blocks(eq_vars, var_to_eq)
        if groups is not None:
            return [Block(g, [eq_to_var[e] for e in g]) for g in groups]

    index = [-1] * n
    low = [0] * n
    on_stack = [False] * n
    scc_stack: list[int] = []
    blocks: list[Block] = []
    counter = 0
    for root in range(n):
        if index[root] != -1:
            continue
        index[root] = low[root] = counter
        counter += 1
        scc_stack.append(root)
        on_stack[root] = True
        work = [(root, iter(eq_vars[root]))]
        while work:
            u, it = work[-1]
            for v in it:
                w = var_to_eq[v]
                if index[w] == -1:
                    index[w] = low[w] = counter
                    counter += 1
                    scc_stack.append(w)
                    on_stack[w] = True
                    work.append((w, iter(eq_vars[w])))
                    break
                if on_stack[w] and index[w] < low[u]:
                    low[u] = index[w]
            else:
                work.pop()
                lu = low[u]
                if lu == index[u]:
                    w = scc_stack.pop()
                    on_stack[w] = False
                    if w == u:
                        blocks.append(Block([u], [eq_to_var[u]]))
                    else:
                        comp = [w]
                        while w != u:
                            w = scc_stack.pop()
                            on_stack[w] = False
                            comp.append(w)
                        comp.sort()
                        blocks.append(Block(comp, [eq_to_var[e] for e in comp]))
                if work:
                    parent = work[-1][0]
                    if lu < low[parent]:
                        low[parent] = lu
    return blocks
