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

from ..errors import SimulationError

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


class EventError(SimulationError):
    """Event handling failed: the event iteration did not converge, or events chatter."""


class Cycle:
    """Bookkeeping of relation values within one event iteration: the first values, the
    combinations seen, which relations moved, and which were settled by a search."""

    def __init__(self, n: int) -> None:
        self.first: np.ndarray | None = None
        self.seen: set[bytes] = set()
        self.free = np.zeros(n, dtype=bool)
        self.tolerant = np.zeros(n, dtype=bool)

    def moved(self, rel: np.ndarray, frozen: np.ndarray, g: np.ndarray, tol: float):
        """Relations whose value changes; a settled one changes only beyond ``tol``."""
        if self.first is None:
            self.first = rel.copy()
        return (rel != frozen) & ~(self.tolerant & (np.abs(g) <= tol))

    def closes(self, frozen: np.ndarray, rel: np.ndarray, moved: np.ndarray) -> bool:
        """Record a step from ``frozen`` to ``rel``; True when ``rel`` was seen before."""
        self.seen.add(frozen.tobytes())
        self.free |= moved
        return rel.tobytes() in self.seen

    def settled(self, rel: np.ndarray) -> None:
        self.tolerant |= self.free
        self.first = rel.copy()
        self.seen.clear()
        self.free[:] = False

    def reset(self) -> None:
        """The relations are stable: discrete changes may start a new cycle."""
        self.seen.clear()
        self.free[:] = False


class MixedSystemMixin:
    """The event loop's handling of mixed systems: a search when the event iteration
    cycles, and relations kept within the tolerance once settled (mixed into
    :class:`~.loop.HybridSimulator`)."""

    def _keep_settled(self, t: float, g: np.ndarray, dgdt: np.ndarray, before) -> None:
        """Relations at rounding level change again only once their indicator is past the
        tolerance: one left against the sign of its indicator (settled within the tolerance,
        e.g. a friction element sliding with zero relative acceleration), and one on
        algebraic variables whose crossing vanished when they were solved again at the event
        (the integrator's algebraic error made it)."""
        fn = self.fn
        value = self.p[fn.rel_slot]
        tol = self.opts.relation_tol
        keep = self._relation_values(t, g, dgdt) != value
        if before is not None:
            g_left, frozen = before
            vanished = (self._relation_values(t, g_left, dgdt) != frozen) & (value == frozen)
            keep |= vanished & (np.abs(g) <= tol) & (np.abs(g_left) <= tol) & self._on_z
        self.hysteresis = np.where(keep, tol, 0.0)

    def _settle(self, t: float, x, cycle: Cycle) -> np.ndarray:
        """Relation values of a mixed system whose event iteration cycles (see
        :mod:`.mixed`); raises :class:`EventError` when no combination is consistent.

        Under each combination the discrete variables defined by equations settle first
        (their pre() catches up, as in the event iteration with the relations frozen). A
        combination may be consistent only with the pre() values another one leads to (a
        friction element that keeps sliding once it started: ``pre(startForward)``), so
        the search is repeated from each of those."""
        fn = self.fn
        saved = self.p[fn.rel_slot].copy()
        pre_slot, lagging = fn.pre_slot, fn.pre_discrete
        saved_pre = self.p[pre_slot].copy()
        reached: dict[bytes, np.ndarray] = {}

        def evaluate(trial: np.ndarray):
            self.p[fn.rel_slot] = trial
            self.p[pre_slot] = start_pre
            for _ in range(self.opts.max_iterations):
                z = self._solve_z(t, x) if fn.alg_solver is not None else np.zeros(0)
                g, dgdt, *_, pre_src, _ = self._step(t, x, z)
                moved = lagging & (pre_src != self.p[pre_slot])
                if not moved.any():
                    break
                self.p[pre_slot] = np.where(lagging, pre_src, self.p[pre_slot])
            reached.setdefault(self.p[pre_slot].tobytes(), self.p[pre_slot].copy())
            return self._relation_values(t, g, dgdt), g

        free = list(np.nonzero(cycle.free)[0])
        names = ", ".join(dict.fromkeys(fn.relations[k].text for k in free[:6]))
        if len(free) > MAX_FREE:
            raise EventError(f"event iteration at t = {t:g} s cycles through {len(free)} "
                             f"relations ({names}, ...), too many to search", t)
        start_pre = saved_pre
        found, miss = search(evaluate, cycle.first, free, self.opts.relation_tol)
        for start_pre in list(reached.values()) if found is None else []:
            if np.array_equal(start_pre, saved_pre):
                continue
            found, other = search(evaluate, cycle.first, free, self.opts.relation_tol)
            miss = min(miss, other)
            if found is not None:
                break
        self.p[fn.rel_slot] = saved
        if found is None:
            self.p[pre_slot] = saved_pre
            raise EventError(f"event iteration at t = {t:g} s: no consistent values of "
                             f"{names} (the mixed system they close has no solution; the "
                             f"closest misses by {miss:.3g})", t)
        evaluate(found)                     # the pre() values the combination settles to
        self.p[fn.rel_slot] = saved
        cycle.settled(found)
        return found
