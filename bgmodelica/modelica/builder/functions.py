"""Modelica built-in functions and operators (``der``, ``pre``, ``sample``, ``size``, ``zeros``,
``min``/``max``/``sum``, ...) as evaluated by the builder.
"""

from __future__ import annotations

import math
from typing import Any

from ...core import expressions as X
from ...core import hybrid as H
from ...core.expr import Expr, Leaf, Op
from ...errors import ModelError
from .. import ast as A
from .. import scope as S
from .arith import _flatten, _num_or_expr, _shape, _sum
from .base import Ctx, NotConstant, check_array_size, fail, numeric_value
from .evaluate import _comprehension, evaluate
from .text import fn_string
from .types import check_der_argument


def _ev_call(node: A.Call, ctx: Ctx) -> Any:
    target = _function_target(node, ctx)
    if isinstance(target, S.ClassScope):
        from .calls import call_function

        return call_function(target, node, ctx)
    handler = _FUNCTIONS.get(target)
    if handler is None:
        raise fail(ctx.lex, node, f"{node.func.dotted}() is not supported here")
    return handler(node, ctx)


def resolve_function(node: A.Call, ctx: Ctx) -> S.ClassScope | None:
    """The Modelica function class a call names (None for a built-in function)."""
    target = _function_target(node, ctx)
    return target if isinstance(target, S.ClassScope) else None


def _function_target(node: A.Call, ctx: Ctx) -> Any:
    """A built-in function's name, or the ClassScope of a Modelica function."""
    ref = node.func
    parts = [p for p, _ in ref.parts]
    if len(parts) == 1:
        name = parts[0]
        if ref.global_:
            if name in _FUNCTIONS:
                return name
            found = S.lookup_top(ctx.lex.file, name) if ctx.lex is not None else None
        else:
            found = S.lookup(ctx.lex, name) if ctx.lex is not None else None
        if found is None or isinstance(found, S.Builtin):
            if name in _FUNCTIONS:
                return name
            raise fail(ctx.lex, node, f"unknown function {name}()")
        if isinstance(found, S.ClassScope):
            return _user_function(found, node, ctx)
        raise fail(ctx.lex, node, f"{name} is not a function")
    if ref.global_ and ctx.lex is not None:
        found = S.lookup_top(ctx.lex.file, parts[0])
    else:
        found = S.lookup(ctx.lex, parts[0]) if ctx.lex is not None else None
    got = S.walk(found, parts[1:]) if found is not None else None
    if isinstance(got, tuple) and got and got[0] == "function":
        return got[1]
    if isinstance(got, S.ClassScope):
        return _user_function(got, node, ctx)
    raise fail(ctx.lex, node, f"unknown function {ref.dotted}()")


def _user_function(found: S.ClassScope, node: A.Call, ctx: Ctx) -> Any:
    kind = found.cdef.kind
    if kind.endswith("function"):
        return found
    if found.cdef.short is not None and found.cdef.enum is None:
        from .classes import resolve_class

        base = resolve_class(found.parent, found.cdef.short[1], found.cdef.pos, found)
        if isinstance(base, S.ClassScope) and base.cdef.kind.endswith("function"):
            return found
    if kind == "record":
        raise fail(ctx.lex, node, f"unsupported Modelica construct: record constructor "
                   f"{found.full_name}()")
    if found.cdef.short is not None or found.cdef.enum is not None:
        name = found.cdef.name
        if name in ("Real", "Integer"):
            return name
    ctor = found.nested("constructor")
    if ctor is not None and ctor.cdef.kind.endswith("function"):
        return ctor                          # an ExternalObject: its constructor
    raise fail(ctx.lex, node, f"{found.full_name} is a {kind}, not a function")


def _args(node: A.Call, ctx: Ctx, n: int | tuple[int, ...], name: str) -> list:
    if node.iterator is not None:
        raise fail(ctx.lex, node, f"{name}() does not take an iterator")
    counts = (n,) if isinstance(n, int) else n
    if len(node.args) not in counts or node.kwargs:
        raise fail(ctx.lex, node, f"{name}() takes {' or '.join(map(str, counts))} "
                   f"positional argument(s), got {len(node.args)}"
                   + (f" and named {', '.join(node.kwargs)}" if node.kwargs else ""))
    return [evaluate(a, ctx) for a in node.args]


def _elementwise(fn):
    def apply(x):
        if isinstance(x, list):
            return [apply(v) for v in x]
        if isinstance(x, S.EnumValue):
            x = x.index
        return fn(x)
    return apply


def _unary_fn(name: str, fn):
    def handler(node: A.Call, ctx: Ctx) -> Any:
        (x,) = _args(node, ctx, 1, name)
        try:
            return _elementwise(fn)(x)
        except (ValueError, OverflowError) as err:
            raise fail(ctx.lex, node, f"{name}({x!r}): {err}") from None
    return handler


def _log10(x: Any) -> Any:
    if isinstance(x, Expr):
        return X.log(x) / math.log(10.0)
    return math.log10(x)


def _floor(x: Any) -> Any:
    if isinstance(x, Expr):
        return Op("floor", (x,))
    return math.floor(x)


def _ceil(x: Any) -> Any:
    if isinstance(x, Expr):
        return Op("ceil", (x,))
    return math.ceil(x)


def _symbolic(ctx: Ctx, node: Any, name: str) -> None:
    if ctx.numeric:
        raise NotConstant(f"{name}()")


def _fn_der(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "der")
    check_der_argument(node, ctx)
    (x,) = _args(node, ctx, 1, "der")
    try:
        return _elementwise(X.der)(x)
    except ModelError as err:
        raise fail(ctx.lex, node, str(err)) from None


def _leaf_arg(x: Any, ctx: Ctx, node: Any, name: str) -> Any:
    if isinstance(x, list):
        return [_leaf_arg(v, ctx, node, name) for v in x]
    if not isinstance(x, Leaf):
        raise fail(ctx.lex, node, f"{name}() takes a variable, got {x!r}")
    return x


def _variables_ctx(ctx: Ctx) -> Ctx:
    """``ctx`` where names refer to the model's variables, not to the values an algorithm
    section has assigned them so far (``pre(n)`` after ``n := ...``); loop indices stay."""
    if ctx.env is None or not ctx.loops:
        return ctx
    loops = {k: v for k, v in ctx.loops.items()
             if isinstance(v, (int, S.EnumValue)) and not isinstance(v, bool)}
    return Ctx(ctx.env, ctx.lex, loops, ctx.numeric)


def _fn_pre(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "pre")
    ctx = _variables_ctx(ctx)
    (x,) = _args(node, ctx, 1, "pre")
    x = _leaf_arg(x, ctx, node, "pre")
    return _elementwise(H.pre)(x)


def _fn_edge(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "edge")
    ctx = _variables_ctx(ctx)
    (x,) = _args(node, ctx, 1, "edge")
    return _elementwise(H.edge)(_leaf_arg(x, ctx, node, "edge"))


def _fn_change(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "change")
    ctx = _variables_ctx(ctx)
    (x,) = _args(node, ctx, 1, "change")
    return _elementwise(H.change)(_leaf_arg(x, ctx, node, "change"))


def _fn_initial(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "initial")
    _args(node, ctx, 0, "initial")
    return H.initial()


def _fn_terminal(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "terminal")
    _args(node, ctx, 0, "terminal")
    return H.terminal()


def _fn_sample(node: A.Call, ctx: Ctx) -> Any:
    _symbolic(ctx, node, "sample")
    if node.kwargs:
        args = [evaluate(node.kwargs.get("start", A.Num(0)), ctx),
                evaluate(node.kwargs["interval"], ctx)] if "interval" in node.kwargs else []
    else:
        args = _args(node, ctx, 2, "sample")
    if len(args) != 2:
        raise fail(ctx.lex, node, "sample(start, interval) takes two arguments")
    start, interval = (a.index if isinstance(a, S.EnumValue) else a for a in args)
    try:
        return H.sample(start, interval)
    except ModelError as err:
        raise fail(ctx.lex, node, str(err)) from None


def _fn_noevent(node: A.Call, ctx: Ctx) -> Any:
    (x,) = _args(node, ctx, 1, "noEvent")
    return _elementwise(H.no_event)(x)


def _fn_smooth(node: A.Call, ctx: Ctx) -> Any:
    _, x = _args(node, ctx, 2, "smooth")
    return x


def _fn_homotopy(node: A.Call, ctx: Ctx) -> Any:
    if node.kwargs:
        if "actual" not in node.kwargs:
            raise fail(ctx.lex, node, "homotopy() needs actual=")
        return evaluate(node.kwargs["actual"], ctx)
    actual, _ = _args(node, ctx, 2, "homotopy")
    return actual


def _minmax(name: str):
    pick2 = X.fmin if name == "min" else X.fmax

    def handler(node: A.Call, ctx: Ctx) -> Any:
        if node.iterator is not None:
            items = _comprehension(node.iterator[0], node.iterator[1], ctx, node)
            items = _flatten(items)
        else:
            args = _args(node, ctx, (1, 2), name)
            items = _flatten(args[0]) if len(args) == 1 else args
            if len(args) == 2 and (isinstance(args[0], list) or isinstance(args[1], list)):
                raise fail(ctx.lex, node, f"{name}(a, b) of arrays: use {name}(array)")
        if not items:
            raise fail(ctx.lex, node, f"{name}() of an empty array")
        items = [_num_or_expr(v, ctx, node) for v in items]
        out = items[0]
        for v in items[1:]:
            out = pick2(out, v)
        return out
    return handler


def _reduction(name: str):
    def handler(node: A.Call, ctx: Ctx) -> Any:
        if node.iterator is not None:
            items = _flatten(_comprehension(node.iterator[0], node.iterator[1], ctx, node))
        else:
            (a,) = _args(node, ctx, 1, name)
            items = _flatten(a)
        if name == "sum":
            return _sum(items)
        out: Any = 1
        for v in items:
            out = out * v
        return out
    return handler


def _fn_abs(x: Any) -> Any:
    return X.fabs(x) if isinstance(x, Expr) else abs(x)


def _fn_sign(x: Any) -> Any:
    return X.sign(x) if isinstance(x, Expr) else (x > 0) - (x < 0)


def _fn_atan2(node: A.Call, ctx: Ctx) -> Any:
    y, x = _args(node, ctx, 2, "atan2")
    return X.atan2(y, x)


def _fn_mod(node: A.Call, ctx: Ctx) -> Any:
    x, y = _args(node, ctx, 2, "mod")
    if isinstance(x, Expr) or isinstance(y, Expr):
        return x - _floor(x / y) * y
    return x - math.floor(x / y) * y


def _fn_rem(node: A.Call, ctx: Ctx) -> Any:
    x, y = _args(node, ctx, 2, "rem")
    if isinstance(x, Expr) or isinstance(y, Expr):
        q = x / y
        return x - X.if_else(q < 0, _ceil(q), _floor(q)) * y
    return math.fmod(x, y)


def _fn_div(node: A.Call, ctx: Ctx) -> Any:
    x, y = _args(node, ctx, 2, "div")
    if isinstance(x, Expr) or isinstance(y, Expr):
        q = x / y
        return X.if_else(q < 0, _ceil(q), _floor(q))
    q = x / y
    return math.trunc(q)


def _fn_size(node: A.Call, ctx: Ctx) -> Any:
    if ctx.numeric and node.args:
        # the size of a variable array is known when built even if its values are not
        try:
            first = evaluate(node.args[0], ctx)
        except NotConstant:
            shape = _declared_shape(node.args[0], ctx)
            first = evaluate(node.args[0], Ctx(ctx.env, ctx.lex, ctx.loops, False)) \
                if shape is None else shape
        rest = _args(A.Call(node.func, node.args[1:], node.kwargs, node.pos), ctx, (0, 1),
                     "size")
        args = [first, *rest]
    else:
        args = _args(node, ctx, (1, 2), "size")
    shape = args[0] if isinstance(args[0], tuple) else _shape(args[0])
    if len(args) == 1:
        return list(shape)
    k = numeric_value(args[1], ctx.lex, node)
    if not 1 <= k <= len(shape):
        raise fail(ctx.lex, node, f"size(a, {k}): a has {len(shape)} dimension(s)")
    return shape[int(k) - 1]


def _declared_shape(arg: Any, ctx: Ctx) -> tuple | None:
    """The declared dimensions of the variable ``arg`` names, when its instance is not built
    yet (a size the model's other declarations take from it); else None."""
    from .env import _dims

    env = ctx.env
    if env is None or env.inst is not None or not isinstance(arg, A.Ref) \
            or len(arg.parts) != 1 or arg.parts[0][1]:
        return None
    info = env.view.elements.get(arg.parts[0][0])
    return None if info is None else _dims(info, env)


def _sizes(node: A.Call, ctx: Ctx, name: str, first: int = 0) -> tuple[list, list[int]]:
    if node.kwargs or node.iterator is not None:
        raise fail(ctx.lex, node, f"{name}() takes positional arguments")
    vals = [evaluate(a, ctx) for a in node.args]
    dims = []
    for v in vals[first:]:
        v = numeric_value(v, ctx.lex, node)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or v != int(v) or v < 0:
            raise fail(ctx.lex, node, f"{name}(): sizes must be non-negative Integers")
        dims.append(int(v))
    check_array_size(math.prod(dims), ctx.lex, node, f"{name}()")
    return vals, dims


def _filled(value: Any, dims: list[int]) -> Any:
    if not dims:
        return value
    return [_filled(value, dims[1:]) for _ in range(dims[0])]


def _fn_zeros(node: A.Call, ctx: Ctx) -> Any:
    return _filled(0, _sizes(node, ctx, "zeros")[1])


def _fn_ones(node: A.Call, ctx: Ctx) -> Any:
    return _filled(1, _sizes(node, ctx, "ones")[1])


def _fn_fill(node: A.Call, ctx: Ctx) -> Any:
    vals, dims = _sizes(node, ctx, "fill", 1)
    return _filled(vals[0], dims)


def _fn_identity(node: A.Call, ctx: Ctx) -> Any:
    _, (n,) = _sizes(node, ctx, "identity")
    return [[1 if i == j else 0 for j in range(n)] for i in range(n)]


def _fn_linspace(node: A.Call, ctx: Ctx) -> Any:
    a, b, n = _args(node, ctx, 3, "linspace")
    n = int(numeric_value(n, ctx.lex, node))
    if n < 2:
        raise fail(ctx.lex, node, "linspace(x1, x2, n) needs n >= 2")
    return [a + (b - a) * k / (n - 1) for k in range(n)]


def _fn_transpose(node: A.Call, ctx: Ctx) -> Any:
    (m,) = _args(node, ctx, 1, "transpose")
    if len(_shape(m)) != 2:
        raise fail(ctx.lex, node, "transpose() of a matrix")
    return [list(r) for r in zip(*m, strict=True)]


def _fn_vector(node: A.Call, ctx: Ctx) -> Any:
    (m,) = _args(node, ctx, 1, "vector")
    return _flatten(m)


def _fn_scalar(node: A.Call, ctx: Ctx) -> Any:
    (m,) = _args(node, ctx, 1, "scalar")
    flat = _flatten(m)
    if len(flat) != 1:
        raise fail(ctx.lex, node, "scalar() of an array with more than one element")
    return flat[0]


def _fn_integer(node: A.Call, ctx: Ctx) -> Any:
    (x,) = _args(node, ctx, 1, "integer")
    if isinstance(x, S.EnumValue):
        return x.index
    return _floor(x) if isinstance(x, Expr) else int(math.floor(x))


def _fn_real(node: A.Call, ctx: Ctx) -> Any:
    (x,) = _args(node, ctx, 1, "Real")
    return float(x) if isinstance(x, (int, float)) else x


def _fn_cross(node: A.Call, ctx: Ctx) -> Any:
    a, b = _args(node, ctx, 2, "cross")
    if _shape(a) != (3,) or _shape(b) != (3,):
        raise fail(ctx.lex, node, "cross() of two 3-vectors")
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _fn_unsupported(name: str, what: str):
    def handler(node: A.Call, ctx: Ctx) -> Any:
        raise fail(ctx.lex, node, f"unsupported Modelica construct: {what}")
    return handler


def _fn_statement(name: str):
    def handler(node: A.Call, ctx: Ctx) -> Any:
        raise fail(ctx.lex, node, f"{name}() is a statement of an equation section, not an "
                   "expression")
    return handler


_FUNCTIONS: dict[str, Any] = {
    "der": _fn_der, "pre": _fn_pre, "edge": _fn_edge, "change": _fn_change,
    "initial": _fn_initial, "terminal": _fn_terminal, "sample": _fn_sample,
    "noEvent": _fn_noevent, "smooth": _fn_smooth, "homotopy": _fn_homotopy,
    "abs": _unary_fn("abs", _fn_abs), "sign": _unary_fn("sign", _fn_sign),
    "sqrt": _unary_fn("sqrt", X.sqrt), "sin": _unary_fn("sin", X.sin),
    "cos": _unary_fn("cos", X.cos), "tan": _unary_fn("tan", X.tan),
    "asin": _unary_fn("asin", X.asin), "acos": _unary_fn("acos", X.acos),
    "atan": _unary_fn("atan", X.atan), "sinh": _unary_fn("sinh", X.sinh),
    "cosh": _unary_fn("cosh", X.cosh), "tanh": _unary_fn("tanh", X.tanh),
    "exp": _unary_fn("exp", X.exp), "log": _unary_fn("log", X.log),
    "log10": _unary_fn("log10", _log10), "floor": _unary_fn("floor", _floor),
    "ceil": _unary_fn("ceil", _ceil), "atan2": _fn_atan2,
    "min": _minmax("min"), "max": _minmax("max"), "sum": _reduction("sum"),
    "product": _reduction("product"), "mod": _fn_mod, "rem": _fn_rem, "div": _fn_div,
    "size": _fn_size, "zeros": _fn_zeros, "ones": _fn_ones, "fill": _fn_fill,
    "identity": _fn_identity, "linspace": _fn_linspace, "transpose": _fn_transpose,
    "vector": _fn_vector, "scalar": _fn_scalar, "integer": _fn_integer,
    "Integer": _fn_integer, "Real": _fn_real, "cross": _fn_cross,
    "delay": _fn_unsupported("delay", "delay() (time delays)"),
    "spatialDistribution": _fn_unsupported("spatialDistribution", "spatialDistribution()"),
    "cardinality": _fn_unsupported("cardinality", "cardinality()"),
    "inStream": _fn_unsupported("inStream", "stream connectors (inStream)"),
    "actualStream": _fn_unsupported("actualStream", "stream connectors (actualStream)"),
    "String": fn_string,
    "connect": _fn_statement("connect"), "reinit": _fn_statement("reinit"),
    "assert": _fn_statement("assert"), "terminate": _fn_statement("terminate"),
}
