"""Expressions in equations: ``der``, ``time`` and math functions (see :mod:`.expr`)."""

from __future__ import annotations

from typing import Any

import casadi as ca
import numpy as np

from ..errors import EquationError
from .expr import (
    ArrayBase,
    Expr,
    Leaf,
    Number,
    acos,
    asin,
    atan,
    atan2,
    cos,
    cosh,
    differentiate,
    exp,
    fabs,
    fmax,
    fmin,
    if_else,
    log,
    sign,
    sin,
    sinh,
    sqrt,
    tan,
    tanh,
)
from .variables import KIND_PARAMETER, TIME, lookup, time

__all__ = ["der", "time", "sin", "cos", "tan", "exp", "log", "sqrt", "asin", "acos", "atan",
           "sinh", "cosh", "tanh", "atan2", "fabs", "sign", "fmin", "fmax", "if_else"]


def der(expr: Any) -> Any:
    """Time derivative of a variable or of an expression of variables, parameters and time."""
    if isinstance(expr, Number):
        return 0.0
    if isinstance(expr, ArrayBase):
        rates = _leaf_rates(expr)
        return rates if rates is not None else expr.map(der)
    if isinstance(expr, Expr):
        return differentiate(expr, _rate)
    if isinstance(expr, (ca.SX, ca.MX)):
        return _der_sx(ca.SX(expr))
    raise EquationError(f"der() of {expr!r}: not an expression")


def _leaf_rates(expr: ArrayBase) -> Any:
    """``der`` of a stored array of declared scalars (``der(v[:-1])``), element by element
    without the general differentiation; None for any other array."""
    from .array_marks import has_one_unit, is_declared, mark_leaves
    from .arrays import ArrayExpr, _wrap

    if not isinstance(expr, ArrayExpr) or expr.node is not None:
        return None
    items = expr.items
    if not all(issubclass(t, Leaf) for t in set(map(type, items.flat))):
        return None
    out = np.empty(items.size, dtype=object)
    out[:] = [_rate(leaf.sym) for leaf in items.flat]
    if out.size and is_declared(items) and isinstance(out[0], Leaf):
        mark_leaves(out, has_one_unit(items))  # one declaration: all variables, or none
    return _wrap(out.reshape(items.shape))


def _rate(sym: Any) -> Any:
    if sym is TIME:
        return 1.0
    if sym.decl.kind == KIND_PARAMETER:
        return 0.0
    return sym.derivative().leaf


def _der_sx(expr: ca.SX) -> ca.SX:
    if expr.numel() != 1:
        return ca.vertcat(*[_der_sx(expr[i]) for i in range(expr.numel())])
    syms = ca.symvar(expr)
    if not syms:
        return ca.SX(0)
    rates = []
    for s in syms:
        if ca.is_equal(s, TIME.sx):
            rates.append(ca.SX(1))
            continue
        sym = lookup(s)
        if sym is None:
            raise EquationError(f"der({expr}): {s} is not a declared variable")
        rate = _rate(sym)
        rates.append(rate.sym.sx if isinstance(rate, Leaf) else ca.SX(rate))
    return ca.jtimes(expr, ca.vertcat(*syms), ca.vertcat(*rates))

