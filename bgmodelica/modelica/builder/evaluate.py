"""Evaluation of Modelica expressions to numbers, lists (arrays), elements and bgmodelica
expressions.
"""

from __future__ import annotations

import math
from typing import Any

from ...core import expressions as X
from ...core.component import Connector, Element
from ...core.expr import Expr
from .. import ast as A
from .. import scope as S
from .arith import (
    _arith,
    _flatten,
    _if_else,
    _neg,
    _relation,
)
from .base import Ctx, NotConstant, _Disabled, check_array_size, fail, numeric_value
from .classes import class_view, type_ref
from .env import Env, _category, sibling_parameter, static_env
from .expandable import Bus, declared_member
from .types import check_condition, check_number_operands


def evaluate(node: Any, ctx: Ctx) -> Any:
    """The value of an expression: a number, bool, string, enumeration value, expression
    (:class:`~bgmodelica.core.expr.Expr`), element, or a (nested) list for arrays."""
    fn = _EVAL.get(type(node))
    if fn is None:
        raise fail(ctx.lex, node, f"unsupported expression {type(node).__name__}")
    return fn(node, ctx)


def _ev_num(node: A.Num, ctx: Ctx) -> Any:
    return node.value


def _ev_str(node: A.Str, ctx: Ctx) -> Any:
    return node.value


def _ev_bool(node: A.Bool, ctx: Ctx) -> Any:
    return node.value


def _ev_ref(node: A.Ref, ctx: Ctx) -> Any:
    parts = node.parts
    name, subs = parts[0]
    env = ctx.env
    rest = 1
    if not ctx.numeric and env is not None and env.inst is not None and name not in ctx.loops:
        hit = env.inst.__dict__["_mo_members"].get(name)
        if hit is not None:
            val = hit
            if subs:
                val = _subscript(val, subs, ctx, node)
            for name, subs in parts[1:]:
                if isinstance(val, Element):
                    _check_public(val, name, ctx, node)
                    val = member(val, name, False, ctx.lex, node)
                elif isinstance(val, list):
                    val = _map_member(val, name, ctx, node)
                else:
                    raise fail(ctx.lex, node, f"{node.dotted}: cannot select {name!r} from a "
                               f"{type(val).__name__}")
                if subs:
                    val = _subscript(val, subs, ctx, node)
            return val
    if name in ctx.loops:
        val = ctx.loops[name]
    elif env is None and len(parts) == 1:
        # static evaluation (no instance): literals, constants and enumeration literals
        # found lexically (a function's imports) are known; any other bare name may be an
        # element of the instance
        found = S.lookup(ctx.lex, name) if ctx.lex is not None else None
        if not _is_value(found):
            raise NotConstant(name)
        val = _lexical_value(found, ctx, node)
    elif env is not None and name in env.view.elements and len(parts) > 1 \
            and (got := sibling_parameter(env, name, parts[1:])) is not None:
        tref = type_ref(env.view.elements[name])
        if tref.kind == "class" and tref.scope is not None:
            _check_public_in(class_view(tref.scope), parts[1][0], name, ctx.lex, node)
        return got[0]
    elif env is not None and name in env.view.elements:
        val = _env_member(env, name, ctx, node)
    elif env is not None and env.inst is not None and (
            name in env.inst._symbols or name in env.inst._children):
        val = member(env.inst, name, ctx.numeric)
    elif name == "time" and S.lookup(ctx.lex, "time") is None:
        if ctx.numeric:
            raise NotConstant("time")
        val = X.time
    else:
        found = S.lookup(ctx.lex, name) if ctx.lex is not None else None
        if found is None:
            raise fail(ctx.lex, node, f"unknown name {node.dotted!r}"
                       + (f" in {env.view.cdef.name}" if env is not None else ""))
        k = 1
        while k < len(parts) and not _is_value(found):
            if parts[k - 1][1]:
                raise fail(ctx.lex, node, f"subscripts on the class name {parts[k - 1][0]}")
            found = S.walk(found, [parts[k][0]])
            if found is None:
                raise fail(ctx.lex, node, f"unknown name {node.dotted!r}")
            k += 1
        val = _lexical_value(found, ctx, node)
        subs = parts[k - 1][1]
        rest = k
    if subs:
        val = _subscript(val, subs, ctx, node)
    for name, subs in parts[rest:]:
        if isinstance(val, Element):
            _check_public(val, name, ctx, node)
            val = member(val, name, ctx.numeric, ctx.lex, node)
        elif isinstance(val, list):
            val = _map_member(val, name, ctx, node)
        else:
            raise fail(ctx.lex, node, f"{node.dotted}: cannot select {name!r} from a "
                       f"{type(val).__name__}")
        if subs:
            val = _subscript(val, subs, ctx, node)
    return val


def _map_member(val: list, name: str, ctx: Ctx, node: Any) -> list:
    for v in val[:1]:
        if isinstance(v, Element):
            _check_public(v, name, ctx, node)
    return [(_map_member(v, name, ctx, node) if isinstance(v, list)
             else member(v, name, ctx.numeric, ctx.lex, node)) for v in val]


def _check_public(elem: Element, name: str, ctx: Ctx, node: Any) -> None:
    """``a.name`` is refused when ``name`` is a protected element of ``a``'s class
    (specification 4.1: protected elements are not accessible by dot notation)."""
    env = elem.__dict__.get("_mo_env")
    if env is not None:
        _check_public_in(env.view, name, elem.name, ctx.lex, node)


def _check_public_in(view: Any, name: str, owner: str, lex: Any, node: Any) -> None:
    info = view.elements.get(name)
    if info is not None and name in info.lex.cdef.protected:
        raise fail(lex, node if node is not None else (0, 0),
                   f"{owner}.{name}: {name} is a protected element of {view.cdef.name} "
                   "(protected elements cannot be read from outside their class)")


def _is_value(found: Any) -> bool:
    return isinstance(found, (S.ConstRef, S.EnumValue))


def _lexical_value(found: Any, ctx: Ctx, node: Any) -> Any:
    if isinstance(found, S.EnumValue):
        return found
    if isinstance(found, S.ConstRef):
        return static_env(found.scope).numeric(found.name)
    raise fail(ctx.lex, node, f"{node.dotted} names a class, not a value")


def _env_member(env: Env, name: str, ctx: Ctx, node: Any) -> Any:
    info = env.view.elements[name]
    cat = _category(info, type_ref(info))
    if name in env.disabled:
        raise _Disabled(name)
    if cat in ("const", "string"):
        return env.numeric(name)
    if cat == "param" and type_ref(info).base in ("Boolean", "Integer", "enum"):
        return env.numeric(name)        # Boolean, Integer and enumeration parameters: fixed
                                        # when the model is built (they size and select)
    if ctx.numeric:
        if cat == "param":
            return env.numeric(name)
        if cat == "child" and env.inst is not None:
            return member(env.inst, name, True, ctx.lex, node)
        raise NotConstant(f"{name} is a variable")
    if env.inst is None:
        raise NotConstant(f"{name} (the instance does not exist yet)")
    return member(env.inst, name, False, ctx.lex, node)


def member(elem: Element, name: str, numeric: bool = False, lex: Any = None,
           node: Any = None) -> Any:
    """Element ``name`` of an instance: a leaf, a child, an array of them, or a constant."""
    d = elem.__dict__
    cache = d.get("_mo_members")
    if cache is None:
        cache = {}
        object.__setattr__(elem, "_mo_members", cache)
    if not numeric:
        hit = cache.get(name)
        if hit is not None:
            return hit
        val = _member(elem, name, False, lex, node)
        cache[name] = val
        return val
    return _member(elem, name, numeric, lex, node)


def _member(elem: Element, name: str, numeric: bool, lex: Any, node: Any) -> Any:
    env = elem.__dict__.get("_mo_env")
    if env is not None and name in env.view.elements:
        if name in env.disabled:
            raise _Disabled(name)
        info = env.view.elements[name]
        cat = _category(info, type_ref(info))
        if cat in ("const", "string") or (cat == "param" and (
                numeric or isinstance(elem, Connector))):
            return env.numeric(name)    # a connector's parameters have no symbol
    rename = elem.__dict__.get("_mo_rename")
    if rename:
        name = rename.get(name, name)
    sym = elem._symbols.get(name)
    if sym is not None:
        return numeric_value(sym.leaf, lex, node) if numeric else sym.leaf
    child = elem._children.get(name)
    if child is not None:
        return child
    arrays = elem.__dict__.get("_mo_arrays")
    if arrays and name in arrays:
        cache = elem.__dict__.setdefault("_mo_array_cache", {})
        val = cache.get(name)
        if val is None:
            val = _assemble(elem, name, arrays[name])
            cache[name] = val
        return numeric_value(val, lex, node) if numeric else val
    if isinstance(elem, Bus):
        made = declared_member(elem, name)
        if made is not None:
            return made
    where = f"{elem.name or type(elem).__name__}"
    have = [n for n in list(elem._symbols) + list(elem._children) if "[" not in n]
    have += list(arrays or ())
    raise fail(lex, node if node is not None else (0, 0),
               f"{where} ({type(elem).__name__}) has no element {name!r}; it has: "
               f"{', '.join(have) or 'none'}")


def _assemble(elem: Element, name: str, dims: tuple[int, ...]) -> list:
    def build(prefix: tuple) -> Any:
        if len(prefix) == len(dims):
            key = f"{name}[{','.join(map(str, prefix))}]"
            sym = elem._symbols.get(key)
            return sym.leaf if sym is not None else elem._children[key]
        return [build(prefix + (i,)) for i in range(1, dims[len(prefix)] + 1)]

    return build(())


def _subscript(val: Any, subs: tuple, ctx: Ctx, node: Any) -> Any:
    idx = []
    for s in subs:
        if type(s) is A.Num and type(s.value) is int:
            idx.append(s.value)
            continue
        if type(s) is A.Ref and len(s.parts) == 1 and s.parts[0][1] is None \
                and s.parts[0][0] in ctx.loops:
            v = ctx.loops[s.parts[0][0]]
            if type(v) is int:
                idx.append(v)
                continue
        if isinstance(s, A.Colon):
            idx.append(None)
            continue
        try:
            v = evaluate(s, Ctx(ctx.env, ctx.lex, ctx.loops, True))
            v = numeric_value(v, ctx.lex, s)
        except NotConstant:
            if ctx.numeric:
                raise
            v = evaluate(s, ctx)        # a time-varying Integer index
            if isinstance(v, Expr):
                idx.append(v)
                continue
            v = numeric_value(v, ctx.lex, s)
        if isinstance(v, S.EnumValue):
            v = v.index
        if isinstance(v, list):
            idx.append([int(x) for x in _flatten(v)])
            continue
        if isinstance(v, bool) or not isinstance(v, (int, float)) or v != int(v):
            raise fail(ctx.lex, s, f"subscript of {node.dotted if hasattr(node, 'dotted') else ''}"
                       f" must be an Integer, got {v!r}")
        idx.append(int(v))

    def apply(v: Any, k: int) -> Any:
        if k == len(idx):
            return v
        if not isinstance(v, list):
            raise fail(ctx.lex, node, f"too many subscripts for {getattr(node, 'dotted', '')}")
        i = idx[k]
        if i is None:
            return [apply(x, k + 1) for x in v]
        if isinstance(i, list):
            return [apply(_at(v, j, ctx, node), k + 1) for j in i]
        if isinstance(i, Expr):
            return _select(i, [apply(x, k + 1) for x in v], ctx, node)
        return apply(_at(v, i, ctx, node), k + 1)

    return apply(val, 0)


def _select(i: Expr, items: list, ctx: Ctx, node: Any) -> Any:
    """``items[i]`` for a time-varying Integer ``i``: ``if i == 1 then items[1] elseif ...``
    (an index out of range takes the last element)."""
    if not items:
        raise fail(ctx.lex, node, f"index into the empty array {getattr(node, 'dotted', '')}")
    if any(isinstance(x, Element) for x in _flatten(items)):
        raise fail(ctx.lex, node, f"{getattr(node, 'dotted', 'expression')}: a component "
                   "selected by a time-varying index")
    out = items[-1]
    for k in range(len(items) - 1, 0, -1):
        out = _if_else(_relation("==", i, k, ctx, node), items[k - 1], out, ctx, node)
    return out


def _at(v: list, i: int, ctx: Ctx, node: Any) -> Any:
    if not 1 <= i <= len(v):
        raise fail(ctx.lex, node, f"index {i} out of range 1:{len(v)} in "
                   f"{getattr(node, 'dotted', 'expression')}")
    return v[i - 1]


def _ev_binop(node: A.BinOp, ctx: Ctx) -> Any:
    op = node.op
    if op == "and" or op == "or":
        a = evaluate(node.a, ctx)
        if isinstance(a, bool) or (isinstance(a, (int, float)) and not isinstance(a, Expr)):
            if op == "and" and not a:
                return False
            if op == "or" and a:
                return True
            b = evaluate(node.b, ctx)
            if isinstance(b, (bool, int, float)):
                return bool(b)
            return b
        b = evaluate(node.b, ctx)
        if isinstance(b, (bool, int, float)):
            if op == "and":
                return a if b else False
            return True if b else a
        return (a & b) if op == "and" else (a | b)
    a = evaluate(node.a, ctx)
    b = evaluate(node.b, ctx)
    if op in ("<", "<=", ">", ">=", "==", "<>"):
        return _relation(op, a, b, ctx, node)
    check_number_operands(node, ctx)
    return _arith(op, a, b, ctx, node)


def _ev_unary(node: A.Unary, ctx: Ctx) -> Any:
    a = evaluate(node.a, ctx)
    if node.op == "not":
        if isinstance(a, Expr):
            return ~a
        if isinstance(a, list):
            raise fail(ctx.lex, node, "'not' of an array")
        return not a
    if node.op == "+":
        return a
    check_number_operands(node, ctx)
    return _neg(a, ctx, node)


def _ev_if(node: A.IfExpr, ctx: Ctx) -> Any:
    conds = []
    for cond, val in node.branches:
        check_condition(cond, ctx, "an if-expression")
        c = evaluate(cond, ctx)
        if isinstance(c, (bool, int, float)) and not isinstance(c, Expr):
            if c:
                if not conds:
                    return evaluate(val, ctx)
                conds.append((True, val))
                break
            continue
        conds.append((c, val))
    else:
        conds.append((True, node.otherwise))
    out = evaluate(conds[-1][1], ctx)
    for c, val in reversed(conds[:-1]):
        out = _if_else(c, evaluate(val, ctx), out, ctx, node)
    return out


def _ev_range(node: A.Range, ctx: Ctx) -> Any:
    num = Ctx(ctx.env, ctx.lex, ctx.loops, True)
    start = numeric_value(evaluate(node.start, num), ctx.lex, node)
    stop = numeric_value(evaluate(node.stop, num), ctx.lex, node)
    step = 1 if node.step is None else numeric_value(evaluate(node.step, num), ctx.lex, node)
    if isinstance(start, S.EnumValue):
        raise fail(ctx.lex, node, "ranges of enumerations are not supported")
    if all(isinstance(v, int) and not isinstance(v, bool) for v in (start, stop, step)):
        if step == 0:
            raise fail(ctx.lex, node, "range step is zero")
        out = range(start, stop + (1 if step > 0 else -1), step)
        check_array_size(len(out), ctx.lex, node, "the range")
        return list(out)
    if step == 0:
        raise fail(ctx.lex, node, "range step is zero")
    n = int(math.floor((stop - start) / step + 1e-12)) + 1
    check_array_size(n, ctx.lex, node, "the range")
    return [start + k * step for k in range(max(n, 0))]


def _ev_array(node: A.ArrayLit, ctx: Ctx) -> Any:
    return [evaluate(x, ctx) for x in node.items]


def _ev_matrix(node: A.Matrix, ctx: Ctx) -> Any:
    rows = []
    for row in node.rows:
        vals = [evaluate(x, ctx) for x in row]
        if all(isinstance(v, list) for v in vals):      # [A, B] of column blocks
            rows.extend([sum((v[i] if isinstance(v[i], list) else [v[i]] for v in vals), [])
                         for i in range(len(vals[0]))])
        else:
            rows.append(vals)
    return rows


def _iterate(indices: tuple, ctx: Ctx, node: Any):
    """Yield loop dictionaries for ``for i in r, j in s``."""
    def rec(k: int, loops: dict):
        if k == len(indices):
            yield loops
            return
        name, rng = indices[k]
        if rng is None:
            raise fail(ctx.lex, node, f"for {name}: an iteration range is needed (implicit "
                       "ranges are not supported)")
        vals = evaluate(rng, Ctx(ctx.env, ctx.lex, loops, True))
        vals = numeric_value(vals, ctx.lex, rng)
        if not isinstance(vals, list):
            vals = [vals]
        for v in vals:
            inner = dict(loops)
            inner[name] = v
            yield from rec(k + 1, inner)

    return rec(0, ctx.loops)


def _ev_comp(node: A.ArrayComp, ctx: Ctx) -> Any:
    return _comprehension(node.expr, node.indices, ctx, node)


def _comprehension(expr: Any, indices: tuple, ctx: Ctx, node: Any) -> list:
    if len(indices) > 1:
        # {e for i in r, j in s}: the last iterator is the outermost
        outer = indices[-1]
        out = []
        for loops in _iterate((outer,), ctx, node):
            out.append(_comprehension(expr, indices[:-1],
                                      Ctx(ctx.env, ctx.lex, loops, ctx.numeric), node))
        return out
    return [evaluate(expr, Ctx(ctx.env, ctx.lex, loops, ctx.numeric))
            for loops in _iterate(indices, ctx, node)]


def _ev_call(node: A.Call, ctx: Ctx) -> Any:
    from .functions import _ev_call as call

    return call(node, ctx)


_EVAL: dict[type, Any] = {
    A.Num: _ev_num, A.Str: _ev_str, A.Bool: _ev_bool, A.Ref: _ev_ref, A.BinOp: _ev_binop,
    A.Unary: _ev_unary, A.IfExpr: _ev_if, A.Range: _ev_range, A.ArrayLit: _ev_array,
    A.ArrayComp: _ev_comp, A.Matrix: _ev_matrix, A.Call: _ev_call,
}
