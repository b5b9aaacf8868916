"""Array equations lowered as blocks (see :mod:`.arrays`).

An array equation becomes one residual column: its arrays of declared scalars are slices of
the model's symbol vector (by position), every operator is one CasADi operation on whole
vectors, and numpy broadcasting is an index map. ``a == b``, ``a == -b``, ``a + b == 0``
between two arrays of variables are alias links, element by element.
"""

from __future__ import annotations

from collections.abc import Callable
from operator import attrgetter
from typing import Any

import casadi as ca
import numpy as np

from ..errors import EquationError
from .arrays import ArrayEquation, ArrayExpr
from .expr import Expr, alias_signs, apply_op, shape_of, to_sx

#: ``alien(symbol, equation, where)``: the error for a symbol that is not part of the model
Alien = Callable[[Any, Any, str], EquationError]


def residual(eq: ArrayEquation, where: str, pos: dict[int, int], symbols: ca.SX,
             alien: Alien, memo: dict[int, Any] | None = None) -> tuple[ca.SX, int]:
    """``lhs - rhs`` of ``eq`` as one column of its scalar equations (C order) and their
    number; ``pos`` maps ``id(symbol)`` to its row in ``symbols``; ``memo`` (one per
    flattening) keeps the rows of each declared array for the next equation using it."""
    shape = eq.shape
    size = int(np.prod(shape))
    lowering = _Lowering(eq, where, pos, symbols, alien, {} if memo is None else memo)
    res = ca.SX(lowering.lower(eq.lhs, shape) - lowering.lower(eq.rhs, shape))
    if not lowering.found:
        raise EquationError(f"{where}: equation {eq!r} has no variables")
    if res.numel() != size:
        res = ca.repmat(res, size, 1)
    return res, size


class _Lowering:
    """One array equation's operands as SX columns. A class rather than a recursive closure:
    a closure that calls itself is a reference cycle, which would keep the flattener it
    reports through (and every symbol entry it holds) alive until the cyclic collector runs."""

    def __init__(self, eq: ArrayEquation, where: str, pos: dict[int, int], symbols: ca.SX,
                 alien: Alien, memo: dict[int, Any]) -> None:
        self.eq, self.where, self.pos, self.symbols = eq, where, pos, symbols
        self.alien, self.memo = alien, memo
        self.found = False

    def lower(self, x: Any, want: tuple[int, ...]) -> Any:
        pos = self.pos
        if isinstance(x, ArrayExpr):
            if x.node is None:
                try:
                    idx = _rows(x.items, pos, self.memo)
                except KeyError:
                    items = x.items.ravel()
                    sym = next(leaf.sym for leaf in items if id(leaf.sym) not in pos)
                    raise self.alien(sym, self.eq, self.where) from None
                self.found = True
                col = self.symbols[idx]
            else:
                op, args = x.node
                col = apply_op(op, [self.lower(a, x.shape) for a in args])
            return _broadcast(col, x.shape, want)
        if isinstance(x, np.ndarray):
            return ca.DM(np.broadcast_to(x.astype(float), want).ravel())
        if isinstance(x, Expr):
            leaves: list = []
            shape_of(x, leaves, [])
            for sym in leaves:
                if id(sym) not in pos:
                    raise self.alien(sym, self.eq, self.where)
            self.found = self.found or bool(leaves)
            return to_sx(x)
        return float(x)


_SYM = attrgetter("sym")


def _rows(items: np.ndarray, pos: dict[int, int], memo: dict[int, Any]) -> list[int]:
    """Rows of an array of declared scalars (C order). A declared array's rows are read
    once; a slice or transpose of it (a numpy view) takes its rows by the same offset and
    strides (object and int64 elements are both 8 bytes)."""
    base = items
    while isinstance(base.base, np.ndarray):
        base = base.base
    if base is items and items.size < 64 or not base.flags.c_contiguous \
            or base.itemsize != 8:
        return [pos[id(leaf.sym)] for leaf in items.ravel()]
    hit = memo.get(id(base))
    if hit is None:
        try:
            rows = np.fromiter(map(pos.__getitem__, map(id, map(_SYM, base.ravel()))),
                               np.int64, base.size)
        except (KeyError, AttributeError):        # not all of the base is declared scalars
            rows = None
        hit = memo[id(base)] = (base, rows)       # holding base keeps its id unique
    if hit[1] is None:
        return [pos[id(leaf.sym)] for leaf in items.ravel()]
    offset = (items.__array_interface__["data"][0]
              - base.__array_interface__["data"][0]) // 8
    view = np.lib.stride_tricks.as_strided(hit[1][offset:], shape=items.shape,
                                           strides=items.strides, writeable=False)
    return view.ravel().tolist()


def alias_form(eq: ArrayEquation) -> tuple[float, float, list[ArrayExpr]] | None:
    """For ``sa*a + sb*b = 0`` between two arrays of declared scalars (after moving all to
    one side): ``(sa, sb, [a, b])``, the two arrays as written; None for any other form."""
    leaves: list = []
    consts: list = []
    signs = alias_signs(_signature(eq.lhs, leaves, consts), _signature(eq.rhs, leaves, consts))
    if not signs or any(np.any(np.asarray(c) != 0.0) for c in consts):
        return None
    return signs[0], signs[1], leaves


def alias_pairs(eq: ArrayEquation) -> tuple[float, float, np.ndarray, np.ndarray] | None:
    """:func:`alias_form` with the leaves of ``a`` and ``b`` broadcast to the equation's
    shape and flattened: ``(sa, sb, leaves of a, leaves of b)``."""
    form = alias_form(eq)
    if form is None:
        return None
    sa, sb, arrays = form
    shape = eq.shape
    a, b = (np.broadcast_to(arr.items, shape).ravel() for arr in arrays)
    return sa, sb, a, b


def _signature(x: Any, leaves: list, consts: list) -> Any:
    """The shape of an array expression for :func:`~.expr.alias_signs`: stored arrays are
    leaves ``"L"``, numbers and numeric arrays constants ``"C"``, scalar expressions
    ``"X"``."""
    if isinstance(x, ArrayExpr):
        if x.node is None:
            leaves.append(x)
            return "L"
        return (x.node[0], *[_signature(a, leaves, consts) for a in x.node[1]])
    if isinstance(x, Expr):
        return "X"
    consts.append(x)
    return "C"


def _broadcast(col: Any, have: tuple[int, ...], want: tuple[int, ...]) -> Any:
    """A column of shape ``have`` (C order) repeated to ``want`` by numpy broadcasting."""
    if have == want or int(np.prod(have)) == 1:
        return col
    idx = np.broadcast_to(np.arange(int(np.prod(have))).reshape(have), want).ravel()
    return col[idx.tolist()]
