"""``String(...)`` (specification 3.7.1.2): the text of a Boolean, Integer, Real or
enumeration value known when it is evaluated (a time-varying one: in a when-clause the call
around it runs at events, :mod:`.runtime`)."""

from __future__ import annotations

from typing import Any

from .. import ast as A
from .. import scope as S
from .base import Ctx, fail, numeric_value, varying

_NAMES = ("significantDigits", "minimumLength", "leftJustified", "format")


def fn_string(node: A.Call, ctx: Ctx) -> Any:
    """``String(x, significantDigits=6, minimumLength=0, leftJustified=true)``,
    ``String(x, format=...)`` (a C format without ``%``)."""
    from .evaluate import evaluate

    if not node.args or node.iterator is not None:
        raise fail(ctx.lex, node, "String() takes a value to convert")
    names = list(_NAMES if len(node.args) <= 1 else _NAMES[1:])
    opts: dict[str, Any] = {}
    for a in node.args[1:]:
        if not names:
            raise fail(ctx.lex, node, "String(): too many arguments")
        opts[names.pop(0)] = evaluate(a, ctx)
    for k, v in node.kwargs.items():
        if k not in _NAMES:
            raise fail(ctx.lex, node, f"String() has no argument {k!r}")
        opts[k] = evaluate(v, ctx)
    x = evaluate(node.args[0], ctx)
    if not isinstance(x, (bool, int, float, str, S.EnumValue)):
        try:
            x = numeric_value(x, ctx.lex, node)
        except Exception:  # noqa: BLE001 -- a value known only while simulating
            raise varying(ctx.lex, node, "String() of a time-varying value") from None
    return _text(x, opts)


def _text(x: Any, opts: dict) -> str:
    if isinstance(x, S.EnumValue):
        out = x.literal
    elif isinstance(x, bool):
        out = "true" if x else "false"
    elif "format" in opts:
        fmt = str(opts["format"])
        out = ("%" + fmt) % (int(x) if fmt[-1:] in "dioxXc" else x)
    elif isinstance(x, int):
        out = str(x)
    else:
        out = f"{float(x):.{int(opts.get('significantDigits', 6))}g}"
    width = int(opts.get("minimumLength", 0))
    return out.ljust(width) if opts.get("leftJustified", True) else out.rjust(width)
