"""Modelica functions (specification chapter 12) evaluated by executing their algorithm.

A call binds the inputs (positional, named, defaults evaluated in the function's scope),
gives outputs and protected variables their bindings, then runs the statements
(:mod:`.algorithms`). With symbolic arguments the call is inlined. Functions with an
``external`` clause call the native re-implementation registered under the clause's C name
(:mod:`bgmodelica.modelica.externals`).
"""

from __future__ import annotations

from typing import Any

from ...core.expr import RELATIONS, Op
from .. import ast as A
from .. import scope as S
from .algorithms import _Break, _lists, _Return, _run, _State, _symbolic
from .base import Ctx, NotConstant, TimeVarying, fail, numeric_value, varying


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
    return _apply_or_defer(scope, args, kwargs, ctx, node, False)


def _apply_or_defer(scope: S.ClassScope, args: list, kwargs: dict, ctx: Ctx, node: Any,
                    all_outputs: bool) -> Any:
    """:func:`apply_function`; in a when-clause of a model, a call whose body cannot take
    its time-varying arguments symbolically runs on numbers at events instead
    (:mod:`.runtime`)."""
    from . import runtime

    try:
        return apply_function(scope, args, kwargs, ctx, node, all_outputs)
    except (TimeVarying, NotConstant):
        if not runtime.active(ctx) or not _symbolic([*args, *kwargs.values()]):
            raise
    return runtime.deferred(scope, args, kwargs, ctx, node, all_outputs)


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
        zero = [_lists(zero) for _ in range(n)]
    return zero


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
    return _apply_or_defer(scope, args, kwargs, ctx, call, True)


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
        if _symbolic(args):
            raise varying(ctx.lex, node, f"unsupported Modelica construct: external function "
                          f"{cname} (called by {fn.name}) on time-varying arguments (it runs on "
                          "values known when the model is built)") from None
        raise fail(ctx.lex, node, f"{fn.name}(): {err}") from None
    if len(out_names) == 1:
        local[out_names[0]] = _from_c(got)
    elif len(out_names) > 1:
        if not isinstance(got, tuple) or len(got) != len(out_names):
            raise fail(lex, ext, f"external {cname} returned {type(got).__name__}, expected "
                       f"{len(out_names)} outputs")
        for n, v in zip(out_names, got, strict=True):
            local[n] = _from_c(v)


def _from_c(v: Any) -> Any:
    """A numeric array result of a native implementation as the nested lists arrays are."""
    import numpy as np

    return v.tolist() if isinstance(v, np.ndarray) and v.dtype != object else v
