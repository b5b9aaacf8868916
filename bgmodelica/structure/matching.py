"""Bipartite matching between equations and variables (all iterative).

* :func:`maximum_matching` - Hopcroft-Karp, optionally warm-started from a given matching.
* :func:`augment` - one augmenting-path search from a single equation.
* :func:`preferred_column_matching` - greedy on the transversal matroid: columns are taken in
  a preference order and a column joins iff an augmenting path reaches it, which yields the
  lexicographically best set of matchable columns.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from . import compiled
from .graph import gc_paused

_INF = 1 << 60


@dataclass
class Matching:
    """A matching: ``eq_to_var[i]`` / ``var_to_eq[j]`` with -1 for unmatched vertices."""

    eq_to_var: list[int]
    var_to_eq: list[int]

    @classmethod
    def empty(cls, n_eqs: int, n_vars: int) -> Matching:
        """The empty matching."""
        return cls([-1] * n_eqs, [-1] * n_vars)

    @property
    def size(self) -> int:
        """Number of matched pairs."""
        return sum(1 for v in self.eq_to_var if v != -1)

    def pairs(self) -> list[tuple[int, int]]:
        """Matched ``(eq, var)`` pairs in equation order."""
        return [(i, v) for i, v in enumerate(self.eq_to_var) if v != -1]

    def copy(self) -> Matching:
        """Copy of the matching."""
        return Matching(list(self.eq_to_var), list(self.var_to_eq))


def _filtered_adjacency(
    eq_vars: Sequence[Sequence[int]],
    var_allowed: Sequence[bool] | None,
    eq_allowed: Sequence[bool] | None,
) -> Sequence[Sequence[int]]:
    if var_allowed is None:
        if eq_allowed is None:
            return eq_vars
        adj: list[Sequence[int]] = list(eq_vars)
    else:
        adj = [[v for v in vs if var_allowed[v]] for vs in eq_vars]
    if eq_allowed is not None:
        for i, ok in enumerate(eq_allowed):
            if not ok:
                adj[i] = ()
    return adj


def _warm_start(
    adj: Sequence[Sequence[int]], n_vars: int, initial: Matching
) -> tuple[list[int], list[int]]:
    """Copy the valid pairs of ``initial`` (edge present, both ends allowed)."""
    n_eqs = len(adj)
    eq_to_var = [-1] * n_eqs
    var_to_eq = [-1] * n_vars
    for i, v in enumerate(initial.eq_to_var[:n_eqs]):
        if v == -1 or v >= n_vars:
            continue
        if v < len(initial.var_to_eq) and initial.var_to_eq[v] != i:
            raise ValueError(f"inconsistent initial matching at equation {i} / variable {v}")
        if var_to_eq[v] == -1 and v in adj[i]:
            eq_to_var[i] = v
            var_to_eq[v] = i
    return eq_to_var, var_to_eq


def _greedy(adj: Sequence[Sequence[int]], eq_to_var: list[int], var_to_eq: list[int]) -> None:
    for i, vs in enumerate(adj):
        if eq_to_var[i] == -1:
            for v in vs:
                if var_to_eq[v] == -1:
                    eq_to_var[i] = v
                    var_to_eq[v] = i
                    break


def _hopcroft_karp(
    adj: Sequence[Sequence[int]], eq_to_var: list[int], var_to_eq: list[int]
) -> None:
    """Extend ``eq_to_var``/``var_to_eq`` in place to a maximum matching."""
    n_eqs = len(adj)
    while True:
        free = [i for i in range(n_eqs) if eq_to_var[i] == -1 and adj[i]]
        if not free:
            return
        # BFS: layer the equations by alternating distance from the free ones.
        dist = [_INF] * n_eqs
        for i in free:
            dist[i] = 0
        queue = list(free)
        limit = _INF
        qi = 0
        while qi < len(queue):
            u = queue[qi]
            qi += 1
            du = dist[u]
            if du >= limit:
                continue
            for v in adj[u]:
                w = var_to_eq[v]
                if w == -1:
                    if limit == _INF:
                        limit = du + 1
                elif dist[w] == _INF:
                    dist[w] = du + 1
                    queue.append(w)
        if limit == _INF:
            return
        # DFS along the layers: vertex-disjoint shortest augmenting paths.
        ptr = [0] * n_eqs
        for root in free:
            us = [root]
            vs: list[int] = []
            while us:
                u = us[-1]
                au = adj[u]
                i = ptr[u]
                nd = dist[u] + 1
                nxt = -1
                while i < len(au):
                    v = au[i]
                    i += 1
                    w = var_to_eq[v]
                    if w == -1:
                        vs.append(v)
                        nxt = -2
                        break
                    if dist[w] == nd:
                        vs.append(v)
                        nxt = w
                        break
                ptr[u] = i
                if nxt == -2:
                    for k, uu in enumerate(us):
                        vv = vs[k]
                        eq_to_var[uu] = vv
                        var_to_eq[vv] = uu
                        dist[uu] = _INF
                    break
                if nxt >= 0:
                    us.append(nxt)
                else:
                    dist[u] = _INF
                    us.pop()
                    if vs:
                        vs.pop()


@gc_paused()
def maximum_matching(
    eq_vars: Sequence[Sequence[int]],
    n_vars: int,
    var_allowed: Sequence[bool] | None = None,
    *,
    eq_allowed: Sequence[bool] | None = None,
    initial: Matching | None = None,
) -> Matching:
    """Maximum matching of equations to variables (Hopcroft-Karp, iterative).

    Only variables with ``var_allowed[j]`` and equations with ``eq_allowed[i]`` take part
    (all by default). ``initial`` warm-starts the search: its pairs whose edge exists and whose
    ends are allowed are kept, the rest dropped; it may be shorter than the current graph.
    Without ``initial``, from :data:`~.compiled.LARGE` equations on, compiled code searches.
    """
    adj = _filtered_adjacency(eq_vars, var_allowed, eq_allowed)
    if initial is None and len(adj) >= compiled.LARGE:
        return Matching(*compiled.compiled_matching(adj, n_vars))
    if initial is None:
        eq_to_var = [-1] * len(adj)
        var_to_eq = [-1] * n_vars
    else:
        eq_to_var, var_to_eq = _warm_start(adj, n_vars, initial)
    _greedy(adj, eq_to_var, var_to_eq)
    _hopcroft_karp(adj, eq_to_var, var_to_eq)
    return Matching(eq_to_var, var_to_eq)


def augment(
    eq: int,
    eq_vars: Sequence[Sequence[int]],
    matching: Matching,
    var_allowed: Sequence[bool] | None = None,
) -> bool:
    """Search one augmenting path from the unmatched equation ``eq`` (iterative DFS).

    On success ``matching`` is updated in place and True returned; otherwise it is unchanged.
    """
    eq_to_var, var_to_eq = matching.eq_to_var, matching.var_to_eq
    if eq_to_var[eq] != -1:
        return True
    seen: set[int] = set()
    us = [eq]
    vs: list[int] = []
    ptr = {eq: 0}
    while us:
        u = us[-1]
        au = eq_vars[u]
        i = ptr[u]
        nxt = -1
        while i < len(au):
            v = au[i]
            i += 1
            if v in seen or (var_allowed is not None and not var_allowed[v]):
                continue
            seen.add(v)
            w = var_to_eq[v]
            vs.append(v)
            if w == -1:
                for k, uu in enumerate(us):
                    eq_to_var[uu] = vs[k]
                    var_to_eq[vs[k]] = uu
                return True
            nxt = w
            break
        ptr[u] = i
        if nxt >= 0:
            ptr[nxt] = 0
            us.append(nxt)
        else:
            us.pop()
            if vs:
                vs.pop()
    return False


@gc_paused()
def preferred_column_matching(
    eq_vars: Sequence[Sequence[int]], n_vars: int, preference: Sequence[int]
) -> Matching:
    """Match equations (rows) to variables (columns) taking columns in ``preference`` order.

    A column joins the matched set iff an augmenting path from it exists (greedy on the
    transversal matroid), so the matched column set is the lexicographically best basis.
    Columns absent from ``preference`` are never used. Stops once every row is matched.
    """
    n_rows = len(eq_vars)
    col_rows: dict[int, list[int]] = {c: [] for c in preference}
    for r, vs in enumerate(eq_vars):
        for c in vs:
            rows = col_rows.get(c)
            if rows is not None:
                rows.append(r)
    row_to_col = [-1] * n_rows
    col_to_row = [-1] * n_vars
    stamp = [0] * n_rows
    cur = 1
    matched = 0
    ptr: dict[int, int] = {}
    for c0 in preference:
        if matched == n_rows:
            break
        if col_to_row[c0] != -1:
            continue
        cs = [c0]
        via: list[int] = []
        ptr[c0] = 0
        found = False
        while cs:
            c = cs[-1]
            rows = col_rows[c]
            i = ptr[c]
            nxt = -1
            while i < len(rows):
                r = rows[i]
                i += 1
                if stamp[r] == cur:
                    continue
                stamp[r] = cur
                m = row_to_col[r]
                via.append(r)
                if m == -1:
                    found = True
                    break
                nxt = m
                break
            ptr[c] = i
            if found:
                for k, cc in enumerate(cs):
                    row_to_col[via[k]] = cc
                    col_to_row[cc] = via[k]
                break
            if nxt >= 0:
                ptr[nxt] = 0
                cs.append(nxt)
            else:
                cs.pop()
                if via:
                    via.pop()
        if found:
            matched += 1
            cur += 1  # rows seen by failed searches stay dead until the matching changes
    return Matching(row_to_col, col_to_row)
