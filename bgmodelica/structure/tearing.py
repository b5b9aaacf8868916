"""Tearing of algebraic loops: greedy choice of tearing variables and residual equations.

Heuristic (in the spirit of Cellier & Kofman): causalize every equation that has exactly one
unknown left and can be solved explicitly for it; when stuck, tear the unknown that occurs in
the most not-yet-used equations and continue. Equations left with no unknown become residuals.
"""

from __future__ import annotations

import heapq
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from .graph import gc_paused


@dataclass
class Tearing:
    """``causal`` lists ``(eq, var)`` assignments in evaluation order given ``tear_vars``;
    ``residual_eqs`` must vanish; ``len(residual_eqs) == len(tear_vars)``."""

    tear_vars: list[int]
    residual_eqs: list[int]
    causal: list[tuple[int, int]]


@gc_paused()
def tear(
    block_eqs: Sequence[int],
    block_vars: Sequence[int],
    eq_vars: Sequence[Sequence[int]],
    solvable: Callable[[int, int], bool] | None = None,
) -> Tearing:
    """Tear the algebraic loop ``block_eqs`` x ``block_vars`` (square, e.g. one BLT block).

    ``eq_vars[e]`` is the incidence of equation ``e`` (global indices; variables outside
    ``block_vars`` count as known). ``solvable(eq, var)`` says whether ``eq`` can be solved
    explicitly for ``var`` (e.g. it occurs linearly with a non-zero constant coefficient);
    ``None`` means always.
    """
    if len(block_eqs) != len(block_vars):
        raise ValueError(f"block is not square: {len(block_eqs)} equations, "
                         f"{len(block_vars)} variables")
    unknowns = set(block_vars)
    evars: dict[int, list[int]] = {}
    var_eqs: dict[int, list[int]] = {v: [] for v in block_vars}
    left: dict[int, int] = {}
    for e in block_eqs:
        vs = [v for v in dict.fromkeys(eq_vars[e]) if v in unknowns]
        evars[e] = vs
        left[e] = len(vs)
        for v in vs:
            var_eqs[v].append(e)
    known: set[int] = set()
    used: set[int] = set()
    causal: list[tuple[int, int]] = []
    tear_vars: list[int] = []
    residual: list[int] = []
    # occurrences of each unknown in equations not yet used (for the tearing heuristic)
    occ = {v: len(es) for v, es in var_eqs.items()}
    queue: deque[int] = deque()
    for e in block_eqs:
        if left[e] == 1:
            queue.append(e)
        elif left[e] == 0:
            used.add(e)
            residual.append(e)

    def use(e: int) -> None:
        used.add(e)
        for v in evars[e]:
            occ[v] -= 1

    def make_known(v: int) -> None:
        known.add(v)
        for e in var_eqs[v]:
            if e in used:
                continue
            left[e] -= 1
            if left[e] == 1:
                queue.append(e)
            elif left[e] == 0:
                use(e)
                residual.append(e)

    heap = [(-occ[v], v) for v in block_vars]
    heapq.heapify(heap)
    while len(known) < len(unknowns):
        while queue:
            e = queue.popleft()
            if e in used or left[e] != 1:
                continue
            v = next(u for u in evars[e] if u not in known)
            if solvable is None or solvable(e, v):
                use(e)
                causal.append((e, v))
                make_known(v)
        if len(known) == len(unknowns):
            break
        while True:
            negc, v = heapq.heappop(heap)
            if v in known:
                continue
            if -negc != occ[v]:
                heapq.heappush(heap, (-occ[v], v))
                continue
            break
        tear_vars.append(v)
        make_known(v)
    return Tearing(tear_vars, residual, causal)
