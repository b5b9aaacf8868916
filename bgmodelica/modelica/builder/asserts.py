"""``assert`` in a model's equations: refused when built if false then, else kept as a
check made while simulating (:mod:`bgmodelica.asserts`)."""

from __future__ import annotations

from typing import Any

from ...core import hybrid as H
from ...core.expr import Expr
from .. import ast as A
from .base import Ctx, NotConstant, fail, numeric_value
from .evaluate import evaluate


def assert_equation(call: A.Call, ctx: Ctx, out: list, initial: bool) -> None:
    """``assert(condition, message, level)``: false when built: an error now; time-varying:
    checked while simulating (:mod:`bgmodelica.asserts`)."""
    if not call.args:
        raise fail(ctx.lex, call, "assert(condition, message) needs a condition")
    level_node = call.kwargs.get("level") or (call.args[2] if len(call.args) > 2 else None)
    level = "warning" if level_node is not None and "warning" in getattr(
        level_node, "dotted", "") else "error"
    cond = evaluate(call.args[0], ctx)
    message = _assert_message(call, ctx)
    if isinstance(cond, Expr):
        try:
            cond = numeric_value(cond, ctx.lex, call)      # parameters only: known now
        except NotConstant:
            pass
    if not isinstance(cond, Expr):
        if not cond and level == "error":
            raise fail(ctx.lex, call, f"assert failed: {message}")
        return
    if not initial:
        out.append(H.assert_(cond, f"{message} ({_where_text(ctx, call)})", level))


def _assert_message(call: A.Call, ctx: Ctx) -> str:
    if len(call.args) < 2 and "message" not in call.kwargs:
        return "assertion"
    node = call.args[1] if len(call.args) > 1 else call.kwargs["message"]
    try:
        msg = evaluate(node, ctx)
    except Exception:  # noqa: BLE001 -- a message built from time-varying values: its text
        msg = None
    if isinstance(msg, str):
        return " ".join(msg.split())
    parts = []

    def strings(n: Any) -> None:
        if isinstance(n, A.Str):
            parts.append(n.value)
        elif isinstance(n, A.BinOp):
            strings(n.a)
            strings(n.b)

    strings(node)
    return " ".join(" ".join(parts).split()) or "assertion"


def _where_text(ctx: Ctx, node: Any) -> str:
    from .base import _where

    return _where(ctx.lex, node.pos)
