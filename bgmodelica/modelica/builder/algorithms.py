"""Modelica functions (specification chapter 12) evaluated by executing their algorithm.

A call binds the inputs (positional, named, defaults evaluated in the function's scope),
gives outputs and protected variables their bindings, then runs the statements on values:
numbers, strings, lists for arrays, and symbolic expressions for time-varying arguments.
With symbolic values the call is inlined: an ``if`` whose condition is symbolic runs both
branches and merges the assigned variables with ``if_else``; ``for`` ranges and ``while``
conditions must be known numbers (a loop over a time-varying bound is refused). Functions
with an ``external`` clause call the native re-implementation registered under the clause's
C name (:mod:`bgmodelica.modelica.externals`).
"""

from __future__ import annotations

import copy
from typing import Any

from ...core.expr import RELATIONS, Expr, Op
from .. import ast as A
from .. import scope as S
from .arith import _if_else
from .base import Ctx, NotConstant, fail, numeric_value

#: statements run per call before a loop is taken for endless
MAX_STEPS = 300_000


class _Return(Exception):
    pass


class _Break(Exception):
    pass


class FunctionDef:
    """A function class with its ``extends`` merged: inputs, outputs, protected variables
    (declaration order) and the algorithm or external clause."""

    __slots__ = ("scope", "inputs", "outputs", "locals", "algorithms", "external", "name",
                 "events")

    def __init__(self, scope: S.ClassScope) -> None:
        from .classes import class_view

        view = class_view(scope)
        self.scope = scope
        self.name = scope.full_name
        self.inputs: list[tuple[A.Component, S.ClassScope]] = []
        self.outputs: list[tuple[A.Component, S.ClassScope]] = []
        self.locals: list[tuple[A.Component, S.ClassScope]] = []
        for info in view.elements.values():
            comp = info.comp
            entry = (comp, info.lex, info)
            if "input" in comp.prefixes:
                self.inputs.append(entry)
            elif "output" in comp.prefixes:
                self.outputs.append(entry)
            else:
                self.locals.append(entry)
        self.algorithms: list[tuple[tuple, S.ClassScope]] = []
        self.external: tuple[A.External, S.ClassScope] | None = None
        for s in _bases(scope):
            for section in s.cdef.algorithms:
                self.algorithms.append((section, s))
            if s.cdef.external is not None and self.external is None:
                self.external = (s.cdef.external, s)
        #: ``annotation(GenerateEvents=true)``: relations in the body trigger events
        self.events = any(_flag(s.cdef.annotation, "GenerateEvents") for s in _bases(scope))


def _flag(annotation: A.Modification | None, name: str) -> bool:
    """Whether ``annotation`` sets ``name = true``."""
    if annotation is None:
        return False
    return any(isinstance(arg, A.ElementMod) and arg.name == name and arg.mod is not None
               and isinstance(arg.mod.binding, A.Bool) and arg.mod.binding.value
               for arg in annotation.args)


def _bases(scope: S.ClassScope) -> list[S.ClassScope]:
    """``scope`` and the classes it extends, bases first."""
    from .classes import resolve_class

    out: list[S.ClassScope] = []
    for el in scope.cdef.elements:
        if isinstance(el, A.Extends):
            base = resolve_class(scope, el.type_name, el.pos, scope, extends=True)
            if isinstance(base, S.ClassScope):
                out.extend(_bases(base))
    if scope.cdef.short is not None:
        base = resolve_class(scope.parent, scope.cdef.short[1], scope.cdef.pos, scope)
        if isinstance(base, S.ClassScope):
            out.extend(_bases(base))
    out.append(scope)
    return out


_DEFS: dict[int, FunctionDef] = {}


def function_def(scope: S.ClassScope) -> FunctionDef:
    hit = _DEFS.get(id(scope.cdef))
    if hit is None or hit.scope.cdef is not scope.cdef:
        hit = FunctionDef(scope)
        _DEFS[id(scope.cdef)] = hit
    return hit


def call_function(scope: S.ClassScope, node: A.Call, ctx: Ctx) -> Any:
    """The value of the call ``node`` of function ``scope`` (a tuple for several outputs
    when the caller asks for them through a tuple target; else the first output)."""
    from .evaluate import evaluate

    args = [evaluate(a, ctx) for a in node.args]
    kwargs = {k: evaluate(v, ctx) for k, v in node.kwargs.items()}
    return apply_function(scope, args, kwargs, ctx, node)


def apply_function(scope: S.ClassScope, args: list, kwargs: dict, ctx: Ctx, node: Any,
                   all_outputs: bool = False) -> Any:
    """Run function ``scope`` on evaluated arguments."""
    fn = function_def(scope)
    if len(args) > len(fn.inputs):
        raise fail(ctx.lex, node, f"{fn.name}() takes {len(fn.inputs)} input(s), got "
                   f"{len(args)}")
    local: dict[str, Any] = {}
    names = [c.name for c, _, _ in fn.inputs]
    for name in kwargs:
        if name not in names:
            raise fail(ctx.lex, node, f"{fn.name}() has no input {name!r}; it has: "
                       f"{', '.join(names) or 'none'}")
    for k, (comp, _, _) in enumerate(fn.inputs):
        if k < len(args):
            local[comp.name] = args[k]
            if comp.name in kwargs:
                raise fail(ctx.lex, node, f"{fn.name}(): input {comp.name} given twice")
        elif comp.name in kwargs:
            local[comp.name] = kwargs[comp.name]
    for comp, lex, info in fn.inputs:
        if comp.name not in local:
            binding = _binding(info)
            if binding is None:
                raise fail(ctx.lex, node, f"{fn.name}(): input {comp.name} has no value and "
                           "no default")
            local[comp.name] = _ev(binding, lex, local, info)
    for comp, lex, info in fn.outputs + fn.locals:
        if comp.name in local:
            continue
        binding = _binding(info)
        if binding is not None:
            local[comp.name] = _ev(binding, lex, local, info)
        else:
            local[comp.name] = _initial(comp, lex, local, info)
    if fn.external is not None and not fn.algorithms:
        _external(fn, local, ctx, node)
    else:
        state = _State()
        try:
            for section, lex in fn.algorithms:
                _run(section, Ctx(None, lex, local, False), state)
        except _Return:
            pass
        except _Break:
            raise fail(fn.scope, node, "break outside a loop") from None
        except RecursionError:
            raise fail(ctx.lex, node, f"{fn.name}(): recursion too deep") from None
    outs = [local.get(c.name) for c, _, _ in fn.outputs]
    for (c, _, _), v in zip(fn.outputs, outs, strict=True):
        if v is None:
            raise fail(ctx.lex, node, f"{fn.name}(): output {c.name} is never assigned")
    if not fn.events:
        given: set[int] = set()
        _nodes([*args, *kwargs.values()], given)
        memo: dict[int, Any] = {}
        outs = [_literal(v, given, memo) if c.type_name == "Real" else v
                for (c, _, _), v in zip(fn.outputs, outs, strict=True)]
    if all_outputs:
        return tuple(outs)
    if not outs:
        return None
    return outs[0]


def _nodes(value: Any, seen: set[int]) -> None:
    """Record in ``seen`` the ids of the expression nodes in ``value`` (arrays as lists)."""
    stack = [value]
    while stack:
        v = stack.pop()
        if isinstance(v, (list, tuple)):
            stack.extend(v)
        elif isinstance(v, Op) and id(v) not in seen:
            seen.add(id(v))
            stack.extend(v.args)


def _literal(value: Any, given: set[int], memo: dict[int, Any]) -> Any:
    """``value`` with the relations the function body made (not those of its arguments,
    ``given``) taken literally: relations in a function trigger no events (specification
    12.7, unless ``GenerateEvents=true``)."""
    if isinstance(value, (list, tuple)):
        return type(value)(_literal(v, given, memo) for v in value)
    stack = [value]
    while stack:                                  # post-order, without recursion
        v = stack[-1]
        if not isinstance(v, Op) or id(v) in memo:
            stack.pop()
            continue
        if id(v) in given or v.op == "noEvent":
            memo[id(v)] = v
        elif v.op in RELATIONS:
            memo[id(v)] = Op("noEvent", (v,))
        else:
            todo = [a for a in v.args if isinstance(a, Op) and id(a) not in memo]
            if todo:
                stack.extend(todo)
                continue
            args = tuple(memo.get(id(a), a) if isinstance(a, Op) else a for a in v.args)
            memo[id(v)] = v if all(x is y for x, y in zip(args, v.args, strict=True)) \
                else Op(v.op, args)
        stack.pop()
    return memo.get(id(value), value) if isinstance(value, Op) else value


def _binding(info: Any) -> Any:
    m = info.mod
    if m is not None and m.has_binding:
        return m.binding
    mod = info.comp.mod
    return mod.binding if mod is not None else None


def _ev(expr: Any, lex: S.ClassScope, local: dict, info: Any) -> Any:
    from .evaluate import evaluate

    return evaluate(expr, Ctx(None, lex, local, False))


def _initial(comp: A.Component, lex: S.ClassScope, local: dict, info: Any) -> Any:
    """An unbound output or protected variable: zeros of its declared size (sizes ``:`` are
    fixed by the first assignment)."""
    from .evaluate import evaluate

    dims = []
    for d in comp.dims:
        if isinstance(d, A.Colon):
            return None
        v = numeric_value(evaluate(d, Ctx(None, lex, local, True)), lex, d)
        dims.append(int(v))
    zero: Any = "" if comp.type_name == "String" else (
        False if comp.type_name == "Boolean" else 0)
    for n in reversed(dims):
        zero = [copy.deepcopy(zero) for _ in range(n)]
    return zero


class _State:
    __slots__ = ("steps", "whens", "leaves", "guard")

    def __init__(self) -> None:
        self.steps = 0
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
            while True:
                c = _known(evaluate(st.condition, ctx), ctx)
                if _symbolic(c):
                    raise fail(ctx.lex, st, "while-loop condition depends on time-varying "
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
            _call_statement(st, ctx)
        elif t is A.Return:
            raise _Return()
        elif t is A.Break:
            raise _Break()
        elif t is A.StmtWhen:
            if state.whens is None:
                raise fail(ctx.lex, st, "a when-statement in a function")
            _when_statement(st, ctx, state)
        else:
            raise fail(ctx.lex, st, f"unsupported statement {t.__name__}")


def _if(st: A.StmtIf, ctx: Ctx, state: _State) -> None:
    from .evaluate import evaluate

    for k, (cond, body) in enumerate(st.branches):
        c = _known(evaluate(cond, ctx), ctx)
        if not _symbolic(c):
            if c:
                _run(body, ctx, state)
                return
            continue
        # a symbolic condition: both sides, merged
        rest = A.StmtIf(st.branches[k + 1:], st.otherwise, st.pos) if st.branches[k + 1:] \
            else None
        then_vals = {n: copy.copy(v) for n, v in ctx.loops.items()}
        else_vals = {n: copy.copy(v) for n, v in ctx.loops.items()}
        g0 = state.guard
        then_done = else_done = False
        try:
            _run(body, Ctx(ctx.env, ctx.lex, then_vals, False), state)
        except _Return:
            then_done = True
        except _Break:
            raise fail(ctx.lex, st, "break under a time-varying condition (not supported)") \
                from None
        g_then, state.guard = state.guard, g0
        try:
            if rest is not None:
                _if(rest, Ctx(ctx.env, ctx.lex, else_vals, False), state)
            else:
                _run(st.otherwise, Ctx(ctx.env, ctx.lex, else_vals, False), state)
        except _Return:
            else_done = True
        except _Break:
            raise fail(ctx.lex, st, "break under a time-varying condition (not supported)") \
                from None
        g_else = state.guard
        for name in set(then_vals) | set(else_vals):
            a, b = then_vals.get(name), else_vals.get(name)
            if a is b:
                ctx.loops[name] = a
            elif a is None or b is None:
                raise fail(ctx.lex, st, f"{name} is assigned in one branch only of an if "
                           "on a time-varying condition")
            else:
                ctx.loops[name] = _merge(c, a, b, ctx, st)
        if then_done and else_done:
            raise _Return()
        state.guard = _select(c, False if then_done else g_then, False if else_done else g_else,
                              ctx, st)
        return
    _run(st.otherwise, ctx, state)


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
        raise fail(ctx.lex, node, "a String depends on a time-varying condition")
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


def call_outputs(call: A.Call, ctx: Ctx) -> tuple:
    """All outputs of a function call (for tuple assignments and equations)."""
    from .evaluate import evaluate
    from .functions import resolve_function

    scope = resolve_function(call, ctx)
    if scope is None:
        raise fail(ctx.lex, call, f"{call.func.dotted}() returns one value; a tuple target "
                   "needs a Modelica function with several outputs")
    args = [evaluate(a, ctx) for a in call.args]
    kwargs = {k: evaluate(v, ctx) for k, v in call.kwargs.items()}
    return apply_function(scope, args, kwargs, ctx, call, all_outputs=True)


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
        ctx.loops[name] = _copy_lists(value)
        return
    cur = ctx.loops[name]
    num = Ctx(ctx.env, ctx.lex, ctx.loops, False)
    idx = []
    for s in subs:
        if isinstance(s, A.Colon):
            idx.append(None)
            continue
        v = _known(evaluate(s, num), ctx)
        if _symbolic(v):
            raise fail(ctx.lex, node, f"subscript of {name} depends on time-varying values")
        idx.append(v)
    ctx.loops[name] = _set(cur, idx, value, ctx, node, name)


def _copy_lists(value: Any) -> Any:
    """``value`` with its (nested) lists copied and their elements shared: expressions
    are never changed in place, and copying one would copy the variables it names."""
    return [_copy_lists(v) for v in value] if isinstance(value, list) else value


def _set(cur: Any, idx: list, value: Any, ctx: Ctx, node: Any, name: str) -> Any:
    if not idx:
        return value
    if not isinstance(cur, list):
        raise fail(ctx.lex, node, f"{name}: too many subscripts")
    head, rest = idx[0], idx[1:]
    cur = list(cur)
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


def _call_statement(st: A.StmtCall, ctx: Ctx) -> None:
    from .evaluate import evaluate

    call = st.call
    name = call.func.dotted
    if name == "assert":
        cond = evaluate(call.args[0], ctx)
        if _symbolic(cond):
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


def _c_value(v: Any) -> Any:
    """An argument as the native implementations take it: enumerations as their index,
    numeric arrays as numpy arrays."""
    import numpy as np

    if isinstance(v, S.EnumValue):
        return v.index
    if isinstance(v, list):
        items = [_c_value(x) for x in v]
        if not _symbolic(items) and not any(isinstance(x, str) for x in items):
            try:
                return np.asarray(items, dtype=float)
            except (TypeError, ValueError):
                return items
        return items
    return v


def _external(fn: FunctionDef, local: dict, ctx: Ctx, node: Any) -> None:
    from .evaluate import evaluate

    ext, lex = fn.external  # type: ignore[misc]
    try:
        from ..externals import IMPLEMENTATIONS
    except ImportError:
        IMPLEMENTATIONS = {}
    cname = ext.function or fn.scope.cdef.name
    impl = IMPLEMENTATIONS.get(cname)
    if impl is None:
        raise fail(lex, ext, f"unsupported Modelica construct: external function {cname} "
                   f"(called by {fn.name}) is not implemented")
    ectx = Ctx(None, lex, local, False)
    if ext.function is None:
        arg_nodes = [A.Ref(((c.name, None),)) for c, _, _ in fn.inputs]
        out_names = [c.name for c, _, _ in fn.outputs]
        args = [local[c.name] for c, _, _ in fn.inputs]
    else:
        arg_nodes = list(ext.args)
        args = [evaluate(a, ectx) for a in arg_nodes]
        out_names = []
        if ext.output is not None:
            out_names.append(ext.output.parts[0][0])
        outputs = {c.name for c, _, _ in fn.outputs}
        for a in arg_nodes:
            if isinstance(a, A.Ref) and len(a.parts) == 1 and a.parts[0][0] in outputs:
                out_names.append(a.parts[0][0])
    args = [_c_value(a) for a in args]
    try:
        got = impl(*args)
    except NotConstant:
        raise
    except Exception as err:  # noqa: BLE001 -- one line naming the function
        raise fail(ctx.lex, node, f"{fn.name}(): {err}") from None
    if len(out_names) == 1:
        local[out_names[0]] = got
    elif len(out_names) > 1:
        if not isinstance(got, tuple) or len(got) != len(out_names):
            raise fail(lex, ext, f"external {cname} returned {type(got).__name__}, expected "
                       f"{len(out_names)} outputs")
        for n, v in zip(out_names, got, strict=True):
            local[n] = v


# -- algorithm sections of models -----------------------------------------------------------


def section_equations(stmts: A.Statements, ctx: Ctx, out: list, initial: bool) -> None:
    """The equations of an algorithm section of a model (specification 11.1): the section is
    run symbolically; each variable it assigns outside ``when`` becomes ``v = value``, each
    ``when``-statement a when-equation of the variables its branches assign (starting from
    their ``pre`` values). In an initial algorithm the assignments become initial
    equations."""
    from .equations import _discrete_start, _equation, _parameter_value
    from .evaluate import evaluate

    names = _targets(stmts)
    leaves = {n: evaluate(A.Ref(((n, None),), stmts.pos), ctx) for n in names}
    local = dict(ctx.loops)
    for n in names:
        local[n] = _pre(leaves[n]) if not initial else None
    state = _State()
    state.whens = []
    state.leaves = leaves
    try:
        _run(tuple(stmts), Ctx(ctx.env, ctx.lex, local, False), state)
    except _Return:
        pass
    in_when: set[str] = set()
    for branches in state.whens:
        for _, assigned in branches:
            in_when |= set(assigned)
    for n in names:
        if n in in_when:
            continue
        if local.get(n) is None:
            raise fail(ctx.lex, stmts, f"{n} is not assigned on every path of the algorithm")
        if initial and (_discrete_start(leaves[n], local[n], ctx, stmts)
                        or _parameter_value(leaves[n], local[n], ctx, stmts)):
            continue
        _equation(leaves[n], local[n], ctx, stmts, out)
    for branches in state.whens:
        out.append(_when_of(branches, leaves, ctx, stmts))


def _when_of(branches: list, leaves: dict, ctx: Ctx, node: Any) -> Any:
    from ...core import hybrid as H
    from .equations import _equation

    union: list[str] = []
    for _, assigned in branches:
        union += [n for n in assigned if n not in union]
    result = None
    for cond, assigned in branches:
        eqs: list = []
        for n in union:
            _equation(leaves[n], assigned.get(n, _pre(leaves[n])), ctx, node, eqs)
        result = H.when(cond, *eqs) if result is None else result.elsewhen(cond, *eqs)
    return result


def _pre(v: Any) -> Any:
    from ...core import hybrid as H

    if isinstance(v, list):
        return [_pre(x) for x in v]
    try:
        return H.pre(v)
    except Exception:  # noqa: BLE001 -- not a variable: its value
        return v


def _targets(stmts: Any) -> list[str]:
    """The names assigned anywhere in ``stmts`` (first part of each target), in order."""
    out: list[str] = []

    def add(ref: Any) -> None:
        if isinstance(ref, A.Ref):
            n = ref.parts[0][0]
            if n not in out:
                out.append(n)

    def walk(items: Any) -> None:
        for st in items:
            if isinstance(st, A.Assign):
                if isinstance(st.target, A.TupleExpr):
                    for item in st.target.items:
                        add(item)
                else:
                    add(st.target)
            elif isinstance(st, (A.StmtIf, A.StmtWhen)):
                for _, body in st.branches:
                    walk(body)
                walk(getattr(st, "otherwise", ()))
            elif isinstance(st, (A.StmtFor, A.StmtWhile)):
                walk(st.body)

    walk(stmts)
    return out


def _when_statement(st: A.StmtWhen, ctx: Ctx, state: _State) -> None:
    """A when-statement of a model's algorithm: each branch run from the ``pre`` values of
    what it assigns; collected for :func:`section_equations`."""
    from .evaluate import evaluate

    branches = []
    for cond, body in st.branches:
        c = evaluate(cond, ctx)
        names = _targets(body)
        local = dict(ctx.loops)
        for n in names:
            local[n] = _pre(state.leaves[n]) if n in state.leaves else None
        _run(body, Ctx(ctx.env, ctx.lex, local, False), state)
        branches.append((c, {n: local[n] for n in names}))
    state.whens.append(branches)
