"""Expressions: ``der``, ``time``, math functions, and turning ``lhs == rhs`` into residuals."""

from __future__ import annotations

from typing import Any

import casadi as ca

from ..errors import EquationError
from .variables import KIND_PARAMETER, lookup, time

__all__ = ["der", "time", "residual_of", "signed_terms", "sin", "cos", "tan", "exp", "log",
           "sqrt", "atan2", "fabs", "tanh", "fmin", "fmax", "if_else", "sign"]

sin, cos, tan, exp, log, sqrt, tanh = ca.sin, ca.cos, ca.tan, ca.exp, ca.log, ca.sqrt, ca.tanh
atan2, fabs, fmin, fmax, sign = ca.atan2, ca.fabs, ca.fmin, ca.fmax, ca.sign


def if_else(condition: Any, then: Any, otherwise: Any) -> ca.SX:
    """Smooth-free selection ``then if condition else otherwise`` (no event handling)."""
    return ca.if_else(condition, then, otherwise)


def der(expr: Any) -> ca.SX:
    """Time derivative of a variable or of an expression of variables, parameters and time."""
    if isinstance(expr, (int, float)):
        return ca.SX(0)
    expr = ca.SX(expr)
    if expr.numel() != 1:
        return ca.vertcat(*[der(expr[i]) for i in range(expr.numel())])
    if expr.is_symbolic():
        return _der_symbol(expr)
    syms = ca.symvar(expr)
    if not syms:
        return ca.SX(0)
    rates = ca.vertcat(*[_der_symbol(s) for s in syms])
    return ca.jtimes(expr, ca.vertcat(*syms), rates)


def _der_symbol(sx: ca.SX) -> ca.SX:
    if ca.is_equal(sx, time):
        return ca.SX(1)
    sym = lookup(sx)
    if sym is None:
        raise EquationError(f"der({sx}): {sx} is not a declared variable")
    if sym.decl.kind == KIND_PARAMETER:
        return ca.SX(0)
    return sym.derivative().sx


def residual_of(eq: Any, where: str) -> list[ca.SX]:
    """Residuals ``lhs - rhs`` of an equation written as ``lhs == rhs`` (scalar or vector)."""
    if isinstance(eq, bool) or not isinstance(eq, (ca.SX, ca.MX, ca.DM)):
        raise EquationError(
            f"{where}: an equation must be written 'lhs == rhs' with at least one variable, "
            f"got {eq!r}")
    eq = ca.SX(eq)
    out = []
    for k in range(eq.numel()):
        e = eq[k]
        if not e.is_op(ca.OP_EQ):
            raise EquationError(f"{where}: '{e}' is not an equation; write it as 'lhs == rhs'")
        out.append(e.dep(0) - e.dep(1))
    return out


def signed_terms(expr: ca.SX, sign: float = 1.0, out: list | None = None,
                 depth: int = 0) -> list[tuple[float, ca.SX]] | None:
    """Split a sum of (possibly negated) symbols into ``[(sign, symbol), ...]``.

    Returns None when the expression is anything else (a product, a constant...). Used to
    find alias equations (``a = b``, ``a = -b``, ``a + b = 0``) without symbolic algebra.
    """
    out = [] if out is None else out
    if depth > 3 or len(out) > 2:
        return None
    if expr.is_symbolic():
        out.append((sign, expr))
        return out
    if expr.is_zero():
        return out
    if expr.is_op(ca.OP_ADD):
        if signed_terms(expr.dep(0), sign, out, depth + 1) is None:
            return None
        return signed_terms(expr.dep(1), sign, out, depth + 1)
    if expr.is_op(ca.OP_SUB):
        if signed_terms(expr.dep(0), sign, out, depth + 1) is None:
            return None
        return signed_terms(expr.dep(1), -sign, out, depth + 1)
    if expr.is_op(ca.OP_NEG):
        return signed_terms(expr.dep(0), -sign, out, depth + 1)
    return None
