"""Mixed systems at an event: relation values that depend on algebraic variables whose
equations depend on those relations (ideal diodes, the stuck/sliding logic of friction).

The event loop first iterates such relations to a fixed point. When the iteration cycles
(the relation values come back to a combination seen before), the relations that moved are
searched combination by combination, nearest first, for one that reproduces itself: the
relation values computed from the algebraic solution under that combination equal the
combination. A relation whose indicator lies within ``tol`` of zero may keep either value
(both sides agree up to rounding).
"""

from __future__ import annotations

from collections.abc import Callable
from itertools import combinations

import numpy as np

#: at most this many relations are searched (2**n combinations)
MAX_FREE = 12


def mismatch(assumed: np.ndarray, values: np.ndarray, g: np.ndarray, tol: float) -> float:
    """How far the relation values computed from a solution miss the assumed ones: the largest
    ``|g|`` of a relation that disagrees (0 when all agree); ``tol`` and below count as 0."""
    off = np.abs(g[values != assumed])
    worst = float(off.max()) if off.size else 0.0
    return 0.0 if worst <= tol else worst


def search(evaluate: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
           start: np.ndarray, free: list[int], tol: float) -> tuple[np.ndarray | None, float]:
    """Relation values consistent with the algebraic solution they give.

    evaluate(r): the relation values and indicators computed after solving with relation
    values ``r``. Combinations differ from ``start`` in the relations ``free`` only, the
    nearest (fewest flips) first. Returns the first consistent combination, or (None, the
    smallest mismatch found) when there is none."""
    best = np.inf
    for n_flip in range(len(free) + 1):
        for flip in combinations(free, n_flip):
            trial = start.copy()
            trial[list(flip)] = 1.0 - trial[list(flip)]
            values, g = evaluate(trial)
            miss = mismatch(trial, values, g, tol)
            if miss == 0.0:
                return trial, 0.0
            best = min(best, miss)
    return None, best
