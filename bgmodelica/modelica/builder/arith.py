"""Arithmetic, relations and shapes of evaluated Modelica values: numbers, bgmodelica
expressions and (nested) lists for arrays, elementwise with Modelica's array rules.
"""

from __future__ import annotations

from typing import Any

from ...core import expressions as X
from ...core import hybrid as H
from ...core.component import Element
from ...core.expr import Expr
from .. import scope as S
from .base import Ctx, fail


def _flatten(v: Any) -> list:
    if isinstance(v, list):
        out = []
        for x in v:
            out.extend(_flatten(x))
        return out
    return [v]


def _num_or_expr(v: Any, ctx: Ctx, node: Any) -> Any:
    if isinstance(v, S.EnumValue):
        return v.index
    if isinstance(v, (Element, str)) and not ctx.numeric:
        raise fail(ctx.lex, node, f"{v!r} cannot be used in arithmetic")
    return v


def _arith(op: str, a: Any, b: Any, ctx: Ctx, node: Any) -> Any:
    if isinstance(a, list) or isinstance(b, list):
        return _array_arith(op, a, b, ctx, node)
    if isinstance(a, str) and isinstance(b, str) and op == "+":
        return a + b
    a = _num_or_expr(a, ctx, node)
    b = _num_or_expr(b, ctx, node)
    try:
        if op in ("+", ".+"):
            return a + b
        if op in ("-", ".-"):
            return a - b
        if op in ("*", ".*"):
            return a * b
        if op in ("/", "./"):
            if not isinstance(b, Expr) and not isinstance(a, Expr) and b == 0:
                raise fail(ctx.lex, node, "division by zero")
            return a / b
        if op in ("^", ".^"):
            if isinstance(a, (int, float)) and isinstance(b, (int, float)):
                return a ** b if not (isinstance(a, int) and isinstance(b, int) and b < 0) \
                    else float(a) ** b
            return a ** b
    except TypeError:
        raise fail(ctx.lex, node, f"cannot apply {op!r} to {a!r} and {b!r}") from None
    raise fail(ctx.lex, node, f"unknown operator {op}")


def _shape(v: Any) -> tuple:
    out = []
    while isinstance(v, list):
        out.append(len(v))
        v = v[0] if v else None
    return tuple(out)


def _array_arith(op: str, a: Any, b: Any, ctx: Ctx, node: Any) -> Any:
    la, lb = isinstance(a, list), isinstance(b, list)
    if op == "*" and la and lb:
        sa, sb = _shape(a), _shape(b)
        if len(sa) == 1 and len(sb) == 1:              # scalar product
            if sa != sb:
                raise fail(ctx.lex, node, f"vector sizes {sa[0]} and {sb[0]} differ")
            return _sum([_arith("*", x, y, ctx, node) for x, y in zip(a, b, strict=True)])
        if len(sa) == 2 and len(sb) == 1:
            return [_arith("*", row, b, ctx, node) for row in a]
        if len(sa) == 1 and len(sb) == 2:
            cols = [[r[j] for r in b] for j in range(sb[1])]
            return [_arith("*", a, c, ctx, node) for c in cols]
        if len(sa) == 2 and len(sb) == 2:
            cols = [[r[j] for r in b] for j in range(sb[1])]
            return [[_arith("*", row, c, ctx, node) for c in cols] for row in a]
        raise fail(ctx.lex, node, "unsupported array product")
    if op in ("+", "-", ".+", ".-", ".*", "./", ".^") and la and lb:
        if len(a) != len(b):
            raise fail(ctx.lex, node, f"array sizes {len(a)} and {len(b)} differ")
        return [_arith(op, x, y, ctx, node) for x, y in zip(a, b, strict=True)]
    if la and lb:
        raise fail(ctx.lex, node, f"operator {op} on two arrays is not supported")
    if op in ("+", "-") and not (op in ("+", "-") and (la and lb)):
        # Modelica forbids array + scalar; accept it elementwise
        pass
    if la:
        return [_arith(op, x, b, ctx, node) for x in a]
    return [_arith(op, a, y, ctx, node) for y in b]


def _sum(items: list) -> Any:
    if not items:
        return 0
    out = items[0]
    for x in items[1:]:
        out = out + x
    return out


def _relation(op: str, a: Any, b: Any, ctx: Ctx, node: Any) -> Any:
    if isinstance(a, S.EnumValue) and isinstance(b, S.EnumValue):
        if op == "==":
            return a == b
        if op == "<>":
            return not a == b
        a, b = a.index, b.index
    if isinstance(a, str) and isinstance(b, str):
        return {"==": a == b, "<>": a != b, "<": a < b, "<=": a <= b, ">": a > b,
                ">=": a >= b}[op]
    a = _num_or_expr(a, ctx, node)
    b = _num_or_expr(b, ctx, node)
    if isinstance(a, list) or isinstance(b, list):
        raise fail(ctx.lex, node, "relations compare scalars, not arrays")
    if isinstance(a, Expr) or isinstance(b, Expr):
        if op == "==":
            return H.eq(a, b)
        if op == "<>":
            if not isinstance(a, Expr):
                a, b = b, a
            return a != b
        if op == "<":
            return a < b if isinstance(a, Expr) else b > a
        if op == "<=":
            return a <= b if isinstance(a, Expr) else b >= a
        if op == ">":
            return a > b if isinstance(a, Expr) else b < a
        return a >= b if isinstance(a, Expr) else b <= a
    return {"==": a == b, "<>": a != b, "<": a < b, "<=": a <= b, ">": a > b,
            ">=": a >= b}[op]


def _neg(a: Any, ctx: Ctx, node: Any) -> Any:
    if isinstance(a, list):
        return [_neg(x, ctx, node) for x in a]
    a = _num_or_expr(a, ctx, node)
    return -a


def _if_else(c: Any, a: Any, b: Any, ctx: Ctx, node: Any) -> Any:
    if isinstance(a, list) or isinstance(b, list):
        if not (isinstance(a, list) and isinstance(b, list) and len(a) == len(b)):
            raise fail(ctx.lex, node, "if-expression branches of different sizes")
        return [_if_else(c, x, y, ctx, node) for x, y in zip(a, b, strict=True)]
    return X.if_else(c, _num_or_expr(a, ctx, node), _num_or_expr(b, ctx, node))
