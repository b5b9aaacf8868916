"""Algorithm statements (specification chapter 11) executed on values.

Statements run on numbers, strings, lists for arrays, and symbolic expressions for
time-varying values. An ``if`` whose condition is symbolic runs both branches and merges the
assigned variables with ``if_else`` (a ``return`` under such a condition guards the
assignments after it); ``for`` ranges and ``while`` conditions must be known numbers (a loop
over a time-varying bound is refused), and a step budget bounds every run. Function calls:
:mod:`.calls`; algorithm sections of models: :mod:`.sections`.
"""

from __future__ import annotations

from typing import Any

from ...core.expr import Expr
from .. import ast as A
from .arith import _if_else
from .base import Ctx, NotConstant, fail, numeric_value, varying
from .types import check_condition

#: statements run per call before a loop is taken for endless
MAX_STEPS = 300_000




class _Return(Exception):
    pass


class _Break(Exception):
    pass


class _State:
    __slots__ = ("steps", "whens", "leaves", "guard", "branching")

    def __init__(self) -> None:
        self.steps = 0
        #: inside branches of an ``if`` on a time-varying condition (run both)
        self.branching = 0
        #: True, or the time-varying condition under which no ``return`` has happened yet
        #: (assignments then keep the returned value where it is false)
        self.guard: Any = True
        self.whens: list | None = None        # collects when-statements in a model
        self.leaves: dict = {}                # the model variables a model's algorithm assigns


def _known(v: Any, ctx: Ctx) -> Any:
    """``v`` as a number when it depends on parameters only (they are known when the model
    is built), else ``v``."""
    if not _symbolic(v):
        return v
    try:
        return numeric_value(v, ctx.lex)
    except NotConstant:
        return v


def _symbolic(v: Any) -> bool:
    if isinstance(v, list):
        return any(_symbolic(x) for x in v)
    return isinstance(v, Expr)


def _run(stmts: tuple, ctx: Ctx, state: _State) -> None:
    from .evaluate import evaluate

    for st in stmts:
        state.steps += 1
        if state.steps > MAX_STEPS:
            raise fail(ctx.lex, st, f"algorithm did not finish after {MAX_STEPS} statements "
                       "(an endless loop?)")
        t = type(st)
        if t is A.Assign:
            _assign(st, ctx, state)
        elif t is A.StmtIf:
            _if(st, ctx, state)
        elif t is A.StmtFor:
            _for(st, ctx, state)
        elif t is A.StmtWhile:
            check_condition(st.condition, ctx, "a while-loop")
            while True:
                c = _known(evaluate(st.condition, ctx), ctx)
                if _symbolic(c):
                    raise varying(ctx.lex, st, "while-loop condition depends on time-varying "
                               "values (not supported)")
                if not c:
                    break
                try:
                    _run(st.body, ctx, state)
                except _Break:
                    break
                state.steps += 1
                if state.steps > MAX_STEPS:
                    raise fail(ctx.lex, st, f"while loop did not finish after {MAX_STEPS} "
                               "statements")
        elif t is A.StmtCall:
            _call_statement(st, ctx, state)
        elif t is A.Return:
            raise _Return()
        elif t is A.Break:
            raise _Break()
        elif t is A.StmtWhen:
            if state.whens is None:
                raise fail(ctx.lex, st, "a when-statement in a function")
            from .sections import _when_statement

            _when_statement(st, ctx, state)
        else:
            raise fail(ctx.lex, st, f"unsupported statement {t.__name__}")


def _if(st: A.StmtIf, ctx: Ctx, state: _State) -> None:
    from .evaluate import evaluate

    for k, (cond, body) in enumerate(st.branches):
        check_condition(cond, ctx, "an if-statement")
        c = _known(evaluate(cond, ctx), ctx)
        if not _symbolic(c):
            if c:
                _run(body, ctx, state)
                return
            continue
        # a symbolic condition: both sides, merged
        from . import runtime

        rest = A.StmtIf(st.branches[k + 1:], st.otherwise, st.pos) if st.branches[k + 1:] \
            else None
        then_vals = {n: _lists(v) for n, v in ctx.loops.items()}
        else_vals = {n: _lists(v) for n, v in ctx.loops.items()}
        g0 = state.guard
        then_done = else_done = False
        state.branching += 1
        try:
            with runtime.condition(c, ctx):
                _run(body, Ctx(ctx.env, ctx.lex, then_vals, False), state)
        except _Return:
            then_done = True
        except _Break:
            raise varying(ctx.lex, st, "break under a time-varying condition (not supported)") \
                from None
        finally:
            state.branching -= 1
        g_then, state.guard = state.guard, g0
        state.branching += 1
        try:
            with runtime.condition(runtime.negated(c), ctx):
                if rest is not None:
                    _if(rest, Ctx(ctx.env, ctx.lex, else_vals, False), state)
                else:
                    _run(st.otherwise, Ctx(ctx.env, ctx.lex, else_vals, False), state)
        except _Return:
            else_done = True
        except _Break:
            raise varying(ctx.lex, st, "break under a time-varying condition (not supported)") \
                from None
        finally:
            state.branching -= 1
        g_else = state.guard
        for name in set(then_vals) | set(else_vals):
            a, b = then_vals.get(name), else_vals.get(name)
            if a is b:
                ctx.loops[name] = a
            elif a is None or b is None:
                raise varying(ctx.lex, st, f"{name} is assigned in one branch only of an if "
                           "on a time-varying condition")
            else:
                ctx.loops[name] = _merge(c, a, b, ctx, st)
        if then_done and else_done:
            raise _Return()
        state.guard = _select(c, False if then_done else g_then, False if else_done else g_else,
                              ctx, st)
        return
    _run(st.otherwise, ctx, state)


def _lists(v: Any) -> Any:
    """A copy of the (nested) lists of ``v``; the values in them are shared (expressions
    are immutable, and copying them would copy whole expression graphs)."""
    return [_lists(x) for x in v] if isinstance(v, list) else v


def _select(c: Any, a: Any, b: Any, ctx: Ctx, node: Any) -> Any:
    """``if c then a else b`` for guards (True, False or a symbolic condition)."""
    if a is True and b is True:
        return True
    a = 1.0 if a is True else 0.0 if a is False else a
    b = 1.0 if b is True else 0.0 if b is False else b
    return _if_else(c, a, b, ctx, node) > 0.5


def _merge(c: Any, a: Any, b: Any, ctx: Ctx, node: Any) -> Any:
    if isinstance(a, list) and isinstance(b, list):
        return [_merge(c, x, y, ctx, node) for x, y in zip(a, b, strict=True)]
    if isinstance(a, str) or isinstance(b, str):
        if a == b:
            return a
        raise varying(ctx.lex, node, "a String depends on a time-varying condition")
    if _same(a, b):
        return a
    return _if_else(c, a, b, ctx, node)


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, Expr) or isinstance(b, Expr):
        return a is b
    try:
        return bool(a == b)
    except Exception:  # noqa: BLE001
        return False


def _for(st: A.StmtFor, ctx: Ctx, state: _State) -> None:
    from .evaluate import _iterate

    saved = {n: ctx.loops[n] for n, _ in st.indices if n in ctx.loops}
    try:
        for loops in _iterate(st.indices, ctx, st):
            for n, v in loops.items():
                if n in dict(st.indices):
                    ctx.loops[n] = v
            try:
                _run(st.body, ctx, state)
            except _Break:
                break
    finally:
        for n, _ in st.indices:
            ctx.loops.pop(n, None)
        ctx.loops.update(saved)


def _assign(st: A.Assign, ctx: Ctx, state: _State | None = None) -> None:
    from .evaluate import evaluate

    target = st.target
    if isinstance(target, A.TupleExpr):
        call = st.value
        if not isinstance(call, A.Call):
            raise fail(ctx.lex, st, "a tuple assignment needs a function call on the right")
        from .calls import call_outputs

        values = call_outputs(call, ctx)
        for item, v in zip(target.items, values, strict=False):
            if item is not None:
                _store(item, v, ctx, st)
        return
    value = evaluate(st.value, ctx)
    if state is not None and state.guard is not True and isinstance(target, A.Ref) \
            and len(target.parts) == 1 and not target.parts[0][1] \
            and ctx.loops.get(target.parts[0][0]) is not None:
        value = _merge(state.guard, value, ctx.loops[target.parts[0][0]], ctx, st)
    _store(target, value, ctx, st)


def _store(ref: Any, value: Any, ctx: Ctx, node: Any) -> None:
    from .evaluate import evaluate

    if not isinstance(ref, A.Ref) or len(ref.parts) != 1:
        raise fail(ctx.lex, node, "assignment to a record field or a non-variable is not "
                   "supported")
    name, subs = ref.parts[0]
    if name not in ctx.loops:
        raise fail(ctx.lex, node, f"assignment to {name!r}, which is not a variable of the "
                   "function")
    if not subs:
        ctx.loops[name] = _lists(value)
        return
    cur = ctx.loops[name]
    num = Ctx(ctx.env, ctx.lex, ctx.loops, False)
    idx = []
    for s in subs:
        if isinstance(s, A.Colon):
            idx.append(None)
            continue
        v = _known(evaluate(s, num), ctx)
        if isinstance(v, list) and _symbolic(v):
            raise varying(ctx.lex, node, f"subscript of {name} depends on time-varying values")
        idx.append(v)
    ctx.loops[name] = _set(cur, idx, value, ctx, node, name)


def _set(cur: Any, idx: list, value: Any, ctx: Ctx, node: Any, name: str) -> Any:
    if not idx:
        return value
    if not isinstance(cur, list):
        raise fail(ctx.lex, node, f"{name}: too many subscripts")
    head, rest = idx[0], idx[1:]
    cur = list(cur)
    if isinstance(head, Expr):
        # a time-varying index: each element keeps its value unless the index names it
        from .arith import _relation

        return [_merge(_relation("==", head, p + 1, ctx, node),
                       _set(x, rest, value, ctx, node, name), x, ctx, node)
                for p, x in enumerate(cur)]
    if head is None:
        positions = list(range(len(cur)))
        vals = value if isinstance(value, list) else [value] * len(cur)
    elif isinstance(head, list):
        positions = [int(i) - 1 for i in head]
        vals = value if isinstance(value, list) else [value] * len(positions)
    else:
        positions = [int(head) - 1]
        vals = [value]
    if len(vals) != len(positions):
        raise fail(ctx.lex, node, f"{name}: {len(vals)} values for {len(positions)} elements")
    for p, v in zip(positions, vals, strict=True):
        if not 0 <= p < len(cur):
            raise fail(ctx.lex, node, f"{name}[{p + 1}]: index out of range 1..{len(cur)}")
        cur[p] = _set(cur[p], rest, v, ctx, node, name)
    return cur


def _call_statement(st: A.StmtCall, ctx: Ctx, state: _State) -> None:
    from .evaluate import evaluate

    call = st.call
    name = call.func.dotted
    if name == "assert":
        cond = evaluate(call.args[0], ctx)
        if _symbolic(cond) or state.branching:
            return                  # checked while simulating only for model equations
        if not cond:
            msg = evaluate(call.args[1], ctx) if len(call.args) > 1 else "assertion failed"
            level = call.kwargs.get("level") or (call.args[2] if len(call.args) > 2 else None)
            if level is not None and "warning" in getattr(level, "dotted", ""):
                return
            raise fail(ctx.lex, st, f"assert failed: {msg}")
        return
    if name == "terminate":
        raise fail(ctx.lex, st, "terminate() in a function")
    evaluate(call, ctx)
