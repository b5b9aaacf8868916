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
        parent: dict[tuple[int, int], tuple[int, int]] = {}

        def find(x):
            parent.setdefault(x, x)
            root = x
            while parent[root] != root:
                root = parent[root]
            while parent[x] != root:
                parent[x], x = root, parent[x]
            return root

        connectors: dict[int, Connector] = {}
        signal_links: list[tuple[Any, Any, Component]] = []
        for conn, ctx in self.connections:
            if conn.a is conn.b or (not isinstance(conn.a, Connector)
                                    and _symbol(conn.a) is _symbol(conn.b)):
                end = self.paths.get(id(conn.a)) if isinstance(conn.a, Connector) \
                    else self.full.get(id(_symbol(conn.a)), "?")
                raise ConnectError(f"{self.where(ctx)}: connect({end}, {end}) connects {end} "
                                   "to itself")
            ends = []
            for end in (conn.a, conn.b):
                if isinstance(end, Connector):
                    if id(end) not in self.paths:
                        raise ConnectError(
                            f"{self.where(ctx)}: connect() uses a {type(end).__name__} that is "
                            "not part of the model (add its component to the model first)")
                    side = 1 if self.parents.get(id(end)) is ctx else 0   # 1 = outside
                    connectors[id(end)] = end
                    ends.append((id(end), side))
            if len(ends) == 2:
                parent[find(ends[0])] = find(ends[1])
            else:
                signal_links.append((conn.a, conn.b, ctx))
        for elem in self.elements:
            if isinstance(elem, Connector):
                connectors[id(elem)] = elem
                find((id(elem), 0))
        sets: dict[tuple[int, int], list[tuple[int, int]]] = {}
        for key in list(parent):
            sets.setdefault(find(key), []).append(key)
        pairs = _Pairs()
        for members in sets.values():
            self._one_set(members, connectors, pairs)
        for a, b, ctx in signal_links:
            sa, sb = _symbol(a), _symbol(b)
            pairs.add(sa, sb, -1.0, f"connect in {self.where(ctx)}")
        self._emit_pairs(pairs)

    def _one_set(self, members, connectors, pairs: _Pairs) -> None:
        members.sort(key=lambda m: self.paths[m[0]])
        first = connectors[members[0][0]]
        if len(members) > 1:
            names = " -- ".join(self.paths[m[0]] for m in members[:6])
            more = f" -- ... ({len(members)} connectors)" if len(members) > 6 else ""
            origin = f"connection set {{{names}{more}}}"
        else:
            origin = f"unconnected connector {self.paths[members[0][0]]}"
        for var_name, sym in first._symbols.items():
            syms = [connectors[cid]._symbols[var_name] for cid, _ in members]
            if sym.decl.kind != KIND_FLOW:
                for other in syms[1:]:
                    pairs.add(syms[0], other, -1.0, origin)
                continue
            signs = [-1.0 if side else 1.0 for _, side in members]
            if len(syms) == 2:
                pairs.add(syms[0], syms[1], signs[0] * signs[1], origin)
            else:
                pairs.add_sum(syms, signs, origin)

    def _emit_pairs(self, pairs: _Pairs) -> None:
        """Residuals ``a + c*b`` of all two-symbol connection equations in one operation,
        then the flow sums of larger sets as one sparse matrix product."""
        if pairs.sums:
            rows, cols, vals = [], [], []
            for k, (syms, signs, _) in enumerate(pairs.sums):
                for sym, sgn in zip(syms, signs, strict=True):
                    rows.append(k)
                    cols.append(self.pos[id(sym)])
                    vals.append(sgn)
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


def _symbol(x: Any) -> Symbol:
    if isinstance(x, Leaf) and isinstance(x.sym, Symbol):
        return x.sym
    sym = lookup(x) if isinstance(x, ca.SX) else None
    if sym is None:
        raise ConnectError(f"cannot connect {x!r}: not a signal variable")
    return sym
