"""Static types of expressions where the syntax tells them (literals, relations, declared
components): the checks that an operand, a condition or a ``der()`` argument has the type
the specification asks for, made on the source so that they name its position.
"""

from __future__ import annotations

from typing import Any

from .. import ast as A
from ..errors import ModelicaError
from .base import Ctx, fail

_RELATIONS = frozenset(("<", "<=", ">", ">=", "==", "<>", "and", "or"))
_ARITH = frozenset(("+", "-", "*", "/", "^", ".+", ".-", ".*", "./", ".^"))


def static_type(node: Any, ctx: Ctx) -> str | None:
    """``"Real"``, ``"Integer"``, ``"Boolean"`` or ``"String"`` when the expression's type
    is plain from its syntax and declarations, else None (not known: no check)."""
    t = type(node)
    if t is A.Bool:
        return "Boolean"
    if t is A.Num:
        return "Integer" if isinstance(node.value, int) else "Real"
    if t is A.Str:
        return "String"
    if t is A.BinOp:
        if node.op in _RELATIONS:
            return "Boolean"
        if node.op in _ARITH:
            a, b = static_type(node.a, ctx), static_type(node.b, ctx)
            if a in ("Real", "Integer") and b in ("Real", "Integer"):
                return "Integer" if a == b == "Integer" and node.op not in ("/", "./") \
                    else "Real"
        return None
    if t is A.Unary:
        return "Boolean" if node.op == "not" else static_type(node.a, ctx)
    if t is A.Ref:
        return _ref_type(node, ctx)
    return None


def _ref_type(node: A.Ref, ctx: Ctx) -> str | None:
    from .classes import type_ref

    if len(node.parts) != 1 or ctx.env is None:
        return None
    name = node.parts[0][0]
    info = ctx.env.view.elements.get(name)
    if info is None or name in ctx.loops:
        return None
    try:
        tref = type_ref(info)
    except ModelicaError:
        return None
    if tref.kind == "scalar" and tref.base in ("Real", "Integer", "Boolean", "String"):
        return tref.base
    return None


def check_number_operands(node: A.BinOp | A.Unary, ctx: Ctx) -> None:
    """The operands of an arithmetic operator are numbers (a Boolean is not: use
    ``if b then 1 else 0``)."""
    if node.op not in _ARITH and not (type(node) is A.Unary and node.op == "-"):
        return
    for side in ((node.a, node.b) if type(node) is A.BinOp else (node.a,)):
        kind = static_type(side, ctx)
        if kind in ("Boolean", "String") and not (kind == "String" and node.op == "+"):
            raise fail(ctx.lex, node, f"{_a(kind)} used as a number: operator "
                       f"'{node.op}' needs Real or Integer operands"
                       + (" (write 'if b then 1 else 0')" if kind == "Boolean" else ""))


def check_condition(cond: Any, ctx: Ctx, what: str) -> None:
    """An if- or while-condition is Boolean."""
    kind = static_type(cond, ctx)
    if kind is not None and kind != "Boolean":
        raise fail(ctx.lex, cond, f"the condition of {what} is {_a(kind)} expression, not a "
                   "Boolean one")


def check_der_argument(node: A.Call, ctx: Ctx) -> None:
    """``der()`` takes a Real expression (of a Real parameter or constant it is zero)."""
    if len(node.args) == 1:
        kind = static_type(node.args[0], ctx)
        if kind in ("Integer", "Boolean", "String"):
            raise fail(ctx.lex, node, f"der() of {_a(kind)} expression: der() takes a Real "
                       "expression")


def _a(kind: str) -> str:
    return ("an " if kind[0] in "AEIOU" else "a ") + kind
