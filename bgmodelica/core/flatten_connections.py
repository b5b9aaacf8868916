"""Connection sets to equations, for the flattener (:mod:`.flatten`).

``connect`` statements join (connector, side) elements into sets: a connector is an *inside*
element in the context of the component that owns it, and an *outside* element in its own
component's ``connect`` statements. In each set potentials are equal and flows sum to zero,
inside flows counted positive and outside flows negative; a connector not connected as an
inside element gets ``flow = 0``. Two-symbol equations are lowered in one vectorized
operation, longer flow balances as one sparse matrix product.
"""

from __future__ import annotations

from typing import Any

import casadi as ca
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..errors import ConnectError
from .component import Component, Connector
from .expr import Leaf
from .flatmodel import FlatEquation
from .variables import KIND_FLOW, Symbol, lookup


class ConnectionLowering:
    """The flattener's connection methods. They read its tree (``connections``,
    ``elements``, ``paths``, ``parents``, ``full``, ``where``) and its bound symbols
    (``pos``, ``var_of``, ``all_sx``), and append to ``equations`` and ``columns``."""

    def _connection_equations(self) -> None:
        connectors = [e for e in self.elements if isinstance(e, Connector)]   # tree order
        index = {id(c): k for k, c in enumerate(connectors)}
        parents = self.parents
        heads: list[int] = []                 # node = 2*connector + side (1: outside)
        tails: list[int] = []
        signal_links: list[tuple[Any, Any, Component]] = []
        for conn, ctx in self.connections:
            a, b = conn.a, conn.b
            if a is b or (not isinstance(a, Connector) and _symbol(a) is _symbol(b)):
                end = self.paths.get(id(a)) if isinstance(a, Connector) \
                    else self.full.get(id(_symbol(a)), "?")
                raise ConnectError(f"{self.where(ctx)}: connect({end}, {end}) connects {end} "
                                   "to itself")
            nodes = []
            for end in (a, b):
                if isinstance(end, Connector):
                    k = index.get(id(end))
                    if k is None:
                        raise ConnectError(
                            f"{self.where(ctx)}: connect() uses a {type(end).__name__} that is "
                            "not part of the model (add its component to the model first)")
                    nodes.append(2 * k + (_owner(end, parents) is ctx))
            if len(nodes) == 2:
                heads.append(nodes[1])
                tails.append(nodes[0])
            else:
                signal_links.append((a, b, ctx))
        paths = [self.paths[id(c)] for c in connectors]
        pairs = _Pairs()
        for members in connection_sets(len(connectors), heads, tails, paths):
            self._one_set(members, connectors, paths, pairs)
        for a, b, ctx in signal_links:
            sa, sb = _symbol(a), _symbol(b)
            pairs.add(sa, sb, -1.0, f"connect in {self.where(ctx)}")
        self._emit_pairs(pairs)

    def _one_set(self, members: list[int], connectors: list[Connector], paths: list[str],
                 pairs: _Pairs) -> None:
        """The equations of one connection set; ``members``: its nodes (2*connector + side),
        in the order of their connectors' paths."""
        first = connectors[members[0] >> 1]
        if len(members) > 1:
            names = " -- ".join(paths[m >> 1] for m in members[:6])
            more = f" -- ... ({len(members)} connectors)" if len(members) > 6 else ""
            origin = f"connection set {{{names}{more}}}"
        else:
            origin = f"unconnected connector {paths[members[0] >> 1]}"
        for var_name, sym in first._symbols.items():
            syms = [connectors[m >> 1]._symbols[var_name] for m in members]
            if sym.decl.kind != KIND_FLOW:
                for other in syms[1:]:
                    pairs.add(syms[0], other, -1.0, origin)
                continue
            signs = [-1.0 if m & 1 else 1.0 for m in members]
            if len(syms) == 2:
                pairs.add(syms[0], syms[1], signs[0] * signs[1], origin)
            else:
                pairs.add_sum(syms, signs, origin)

    def _emit_pairs(self, pairs: _Pairs) -> None:
        """Residuals ``a + c*b`` of all two-symbol connection equations in one operation,
        then the flow sums of larger sets as one sparse matrix product."""
        if pairs.sums:
            pos = self.pos
            cols = [pos[id(sym)] for syms, _, _ in pairs.sums for sym in syms]
            vals = [sgn for _, signs, _ in pairs.sums for sgn in signs]
            rows = np.repeat(np.arange(len(pairs.sums)),
                             [len(syms) for syms, _, _ in pairs.sums]).tolist()
            # DM.triplet keeps each value with its (row, col); DM(Sparsity.triplet(...), vals)
            # would not (the sparsity is sorted column-major)
            sel = ca.DM.triplet(rows, cols, ca.DM(vals), len(pairs.sums), self.all_sx.numel())
            totals = ca.mtimes(sel, self.all_sx)
            self.equations.extend(FlatEquation(None, origin, terms=len(syms), at=(totals, k))
                                  for k, (syms, _, origin) in enumerate(pairs.sums))
            self.columns.append(totals)
        if not pairs.a:
            return
        pos, var_of = self.pos, self.var_of.get
        ia = [pos[id(s)] for s in pairs.a]
        ib = [pos[id(s)] for s in pairs.b]
        res = self.all_sx[ia] + self.all_sx[ib] * ca.DM(pairs.coef)
        va = [var_of(id(s)) for s in pairs.a]
        vb = [var_of(id(s)) for s in pairs.b]
        self.equations.extend(
            FlatEquation(None, origin, (a, b, -c) if a is not None and b is not None else None,
                         at=(res, k))
            for k, (origin, a, b, c) in enumerate(zip(pairs.origin, va, vb, pairs.coef,
                                                      strict=True)))
        self.columns.append(res)


class _Pairs:
    """Two-symbol equations ``a + coef*b = 0`` collected for one vectorized lowering."""

    def __init__(self) -> None:
        self.a: list[Symbol] = []
        self.b: list[Symbol] = []
        self.coef: list[float] = []
        self.origin: list[str] = []
        self.sums: list[tuple[list[Symbol], list[float], str]] = []

    def add_sum(self, syms: list[Symbol], signs: list[float], origin: str) -> None:
        self.sums.append((syms, signs, origin))

    def add(self, a: Symbol, b: Symbol, coef: float, origin: str) -> None:
        self.a.append(a)
        self.b.append(b)
        self.coef.append(coef)
        self.origin.append(origin)


def connection_sets(n: int, heads: list[int], tails: list[int],
                    paths: list[str]) -> list[list[int]]:
    """The connection sets of ``n`` connectors joined by the links ``tails[k] -- heads[k]``
    between nodes ``2*connector + side`` (side 1: the connector seen from outside its
    component). Every connector's inside node is in a set, an outside node only if linked.
    Sets come in the order of their first node in the sequence ``heads[0], tails[0],
    heads[1], ...`` followed by the inside nodes; each set's nodes by their connectors'
    ``paths``, then in that sequence."""
    nodes, cuts = connection_set_arrays(n, heads, tails, paths)
    return [part.tolist() for part in np.split(nodes, cuts)] if n else []


def connection_set_arrays(n: int, heads: Any, tails: Any,
                          paths: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """:func:`connection_sets` as two arrays: the nodes of all sets one after the other,
    and where each set but the first starts."""
    if n == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    heads = np.asarray(heads, dtype=np.int64)
    tails = np.asarray(tails, dtype=np.int64)
    seq = np.concatenate((np.column_stack((heads, tails)).ravel(),
                          2 * np.arange(n, dtype=np.int64)))
    nodes, first = np.unique(seq, return_index=True)           # present nodes, first seen
    graph = sp.coo_matrix((np.ones(len(heads)), (heads, tails)), shape=(2 * n, 2 * n))
    _, label = connected_components(graph, directed=False)
    label = label[nodes]
    set_first = np.full(2 * n, len(seq), dtype=np.int64)
    np.minimum.at(set_first, label, first)                     # each set: its first node
    by_path = np.empty(n, dtype=np.int64)
    by_path[sorted(range(n), key=paths.__getitem__)] = np.arange(n)
    order = np.lexsort((first, by_path[nodes >> 1], set_first[label]))
    nodes, label = nodes[order], label[order]
    return nodes, np.flatnonzero(label[1:] != label[:-1]) + 1


def _owner(end: Connector, parents: dict) -> Any:
    """The component ``end`` belongs to: its parent, or the parent of the connector that
    holds it (a pin of a plug is an outside element in the plug owner's connects)."""
    owner = parents.get(id(end))
    while isinstance(owner, Connector):
        owner = parents.get(id(owner))
    return owner


def _symbol(x: Any) -> Symbol:
    if isinstance(x, Leaf) and isinstance(x.sym, Symbol):
        return x.sym
    sym = lookup(x) if isinstance(x, ca.SX) else None
    if sym is None:
        raise ConnectError(f"cannot connect {x!r}: not a signal variable")
    return sym
