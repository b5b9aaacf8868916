"""Modelica equations (plain, ``connect``, ``for``, ``if``, ``when``) evaluated into bgmodelica
equations for one instance.
"""

from __future__ import annotations

from typing import Any

from ...core import hybrid as H
from ...core.component import Connector, Element, connect
from ...core.expr import Equation, Expr
from ...errors import ConnectError, DeclarationError, EquationError, ModelError
from .. import ast as A
from .. import scope as S
from ..errors import ModelicaError
from .base import (
    INTERNAL_ERRORS,
    Ctx,
    NotConstant,
    _Disabled,
    _is_number,
    describe_internal,
    fail,
    numeric_value,
)
from .env import Env
from .evaluate import _iterate, evaluate
from .expandable import Missing, connect_bus, connect_end, resolve
from .types import check_condition


def _equation(a: Any, b: Any, ctx: Ctx, node: Any, out: list) -> None:
    if isinstance(a, list) or isinstance(b, list):
        if not (isinstance(a, list) and isinstance(b, list)):
            if isinstance(a, list) and _is_number(b) or isinstance(b, list) and _is_number(a):
                raise fail(ctx.lex, node, "array equation with a scalar side")
            raise fail(ctx.lex, node, "array equation with a scalar side")
        if len(a) != len(b):
            raise fail(ctx.lex, node, f"array equation of sizes {len(a)} and {len(b)}")
        for x, y in zip(a, b, strict=True):
            _equation(x, y, ctx, node, out)
        return
    a = a.index if isinstance(a, S.EnumValue) else a
    b = b.index if isinstance(b, S.EnumValue) else b
    if isinstance(a, Element) or isinstance(b, Element):
        raise fail(ctx.lex, node, "an equation between components: use connect(a, b)")
    if isinstance(a, Expr):
        out.append(Equation(a, b))
    elif isinstance(b, Expr):
        out.append(Equation(b, a))
    else:
        raise fail(ctx.lex, node, f"equation {a!r} = {b!r} has no variables")


def equations_of(env: Env, eqs: list, initial: bool = False) -> list:
    """The bgmodelica equations of the Modelica equations ``eqs`` for instance ``env``."""
    out: list = []
    for eq, lex in eqs:
        _eval_equation(eq, Ctx(env, lex, {}, False), out, initial)
    return out


def _eval_equation(eq: Any, ctx: Ctx, out: list, initial: bool) -> None:
    try:
        if isinstance(eq, A.Statements):
            from .sections import section_equations

            section_equations(eq, ctx, out, initial)
        elif isinstance(eq, A.EqSimple) and isinstance(eq.lhs, A.TupleExpr):
            _tuple_equation(eq, ctx, out, initial)
        elif isinstance(eq, A.EqSimple):
            try:
                a = evaluate(eq.lhs, ctx)
                b = evaluate(eq.rhs, ctx)
            except NotConstant as err:
                raise fail(ctx.lex, eq, f"cannot evaluate: {err.what}") from None
            if initial and (_discrete_start(a, b, ctx, eq) or _parameter_value(a, b, ctx, eq)):
                return
            _equation(a, b, ctx, eq, out)
        elif isinstance(eq, A.EqCall):
            _eval_call_equation(eq, ctx, out, initial)
        elif isinstance(eq, A.EqFor):
            for loops in _iterate(eq.indices, ctx, eq):
                inner = Ctx(ctx.env, ctx.lex, loops, False)
                for sub in eq.body:
                    _eval_equation(sub, inner, out, initial)
        elif isinstance(eq, A.EqIf):
            _eval_if_equation(eq, ctx, out, initial)
        elif isinstance(eq, A.EqWhen):
            if initial:
                raise fail(ctx.lex, eq, "when-equations are not allowed in initial equations")
            out.append(_eval_when(eq, ctx))
        elif isinstance(eq, A.Unsupported):
            raise fail(ctx.lex, eq, f"unsupported Modelica construct: {eq.what}")
        else:
            raise fail(ctx.lex, eq, f"unsupported equation {type(eq).__name__}")
    except _Disabled:
        if isinstance(eq, A.EqCall) and eq.call.func.dotted == "connect":
            return
        raise fail(ctx.lex, eq, "the equation uses a conditional component that is switched "
                   "off") from None
    except (ConnectError, EquationError, DeclarationError) as err:
        if isinstance(err, ModelicaError):
            raise
        raise fail(ctx.lex, eq, str(err)) from None
    except NotConstant as err:
        raise fail(ctx.lex, eq, f"cannot evaluate when the model is built: {err.what}") \
            from None
    except INTERNAL_ERRORS as err:
        raise fail(ctx.lex, eq, f"cannot build this equation: {describe_internal(err)}") \
            from None


#: the time at which initial equations of discrete variables are evaluated when the model is
#: built [s]
INITIAL_TIME = 0.0


def _discrete_start(a: Any, b: Any, ctx: Ctx, node: Any) -> bool:
    """An initial equation ``d = value`` of a discrete variable (or an Integer, Boolean or
    enumeration output) whose value is known when the model is built sets its start value
    (its value before the first event)."""
    from ...core.variables import KIND_DISCRETE, KIND_OUTPUT

    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        if all(_discrete_start(x, y, ctx, node) for x, y in zip(a, b, strict=True)):
            return True
        return False
    sym = getattr(a, "sym", None) if isinstance(a, Expr) else None
    decl = getattr(sym, "decl", None)
    if decl is None or not (decl.kind == KIND_DISCRETE or decl.kind == KIND_OUTPUT
                            and getattr(decl, "type_name", "Real") != "Real"):
        return False
    value = _initial_value(b, ctx, node, fixed_starts=False)
    if value is None:
        return False
    sym.decl = decl.evolve(start=value, fixed=True)
    return True


def _initial_value(b: Any, ctx: Ctx, node: Any, fixed_starts: bool) -> Any:
    """The number ``b`` is at initialization when that is known when the model is built
    (parameters; ``time`` the start time, 0 in the libraries' examples; with
    ``fixed_starts`` the start values of fixed variables), else None."""
    memo: dict = {"time": INITIAL_TIME, "fixed starts": fixed_starts}
    try:
        value = numeric_value(b, ctx.lex, node, memo)
    except NotConstant:
        return None
    if isinstance(value, S.EnumValue):
        value = value.index
    return value if isinstance(value, (bool, int, float)) else None


def _parameter_value(a: Any, b: Any, ctx: Ctx, node: Any) -> bool:
    """An initial equation ``p = value`` of a parameter declared ``fixed = false`` whose value
    is known when the model is built (from other parameters): the parameter takes it."""
    from ...core.variables import KIND_PARAMETER

    pairs = list(zip(a, b, strict=True)) if isinstance(a, list) and isinstance(b, list) \
        and len(a) == len(b) else [(a, b)]
    found = []
    for x, y in pairs:
        if isinstance(x, list) or isinstance(y, list):
            if not (isinstance(x, list) and isinstance(y, list) and len(x) == len(y)):
                return False
            found.extend(zip(x, y, strict=True))
        else:
            found.append((x, y))
    solved = []
    for x, y in found:
        sym = getattr(x, "sym", None) if isinstance(x, Expr) else None
        decl = getattr(sym, "decl", None)
        if decl is None or decl.kind != KIND_PARAMETER or _unsolved(y):
            return False
        value = _initial_value(y, ctx, node, fixed_starts=True)
        if value is None:
            return False
        solved.append((sym, decl, value))
    for sym, decl, value in solved:
        sym.decl = decl.evolve(value=float(value), fixed=True)
        _remember(sym, value)
    return bool(solved)


def _unsolved(value: Any) -> bool:
    """Whether ``value`` reads a parameter that initial equations still have to determine
    (``fixed=false``, not solved when built): its start value is only a guess."""
    from ...core.expr import Leaf, Op

    stack, seen = [value], set()
    while stack:
        e = stack.pop()
        if isinstance(e, list):
            stack.extend(e)
        elif isinstance(e, Leaf):
            if getattr(getattr(e.sym, "decl", None), "fixed", True) is False:
                return True
        elif isinstance(e, Op) and id(e) not in seen:
            seen.add(id(e))
            stack.extend(e.args)
    return False


def _remember(sym: Any, value: float) -> None:
    """Let later build-time evaluations of the owner see a solved parameter's value."""
    import re

    owner = getattr(sym, "owner", None)
    env = owner.__dict__.get("_mo_env") if owner is not None else None
    if env is None:
        return
    m = re.match(r"^(.*)\[([0-9,]+)\]$", sym.name)
    if m is None:
        env._num[sym.name] = value
        return
    try:
        whole = env.numeric(m.group(1))
    except (KeyError, NotConstant):
        return
    if not isinstance(whole, list):
        return
    whole = env._num[m.group(1)] = _deep_copy(whole)
    idx = [int(i) - 1 for i in m.group(2).split(",")]
    cur = whole
    for i in idx[:-1]:
        cur = cur[i]
    cur[idx[-1]] = value


def _deep_copy(v: Any) -> Any:
    return [_deep_copy(x) for x in v] if isinstance(v, list) else v


def _tuple_equation(eq: A.EqSimple, ctx: Ctx, out: list, initial: bool) -> None:
    """``(a, , b) = f(x)``: one equation per named output."""
    from .calls import call_outputs

    if not isinstance(eq.rhs, A.Call):
        raise fail(ctx.lex, eq, "a tuple equation needs a function call on the right")
    try:
        values = call_outputs(eq.rhs, ctx)
        for item, v in zip(eq.lhs.items, values, strict=False):
            if item is not None:
                a = evaluate(item, ctx)
                if initial and (_discrete_start(a, v, ctx, eq)
                                or _parameter_value(a, v, ctx, eq)):
                    continue
                _equation(a, v, ctx, eq, out)
    except NotConstant as err:
        raise fail(ctx.lex, eq, f"cannot evaluate: {err.what}") from None


def _eval_call_equation(eq: A.EqCall, ctx: Ctx, out: list, initial: bool) -> None:
    call = eq.call
    name = call.func.dotted
    if name == "connect":
        if len(call.args) != 2 or call.kwargs:
            raise fail(ctx.lex, eq, "connect(a, b) takes two connectors")
        a = connect_end(call.args[0], ctx, evaluate)
        b = connect_end(call.args[1], ctx, evaluate)
        if isinstance(a, Missing) or isinstance(b, Missing):
            a, b = resolve(a, b, ctx, eq)
        _connect(a, b, ctx, eq, out)
        return
    if name == "assert":
        from .asserts import assert_equation

        assert_equation(call, ctx, out, initial)
        return
    if name == "reinit":
        raise fail(ctx.lex, eq, "reinit() is allowed only inside a when-equation")
    if name == "terminate":
        raise fail(ctx.lex, eq, "unsupported Modelica construct: terminate()")
    raise fail(ctx.lex, eq, f"{name}(...) is not an equation (write 'expression = "
               "expression')")


def _connect(a: Any, b: Any, ctx: Ctx, node: Any, out: list) -> None:
    if isinstance(a, list) or isinstance(b, list):
        if not (isinstance(a, list) and isinstance(b, list) and len(a) == len(b)):
            raise fail(ctx.lex, node, "connect() of arrays of different sizes")
        for x, y in zip(a, b, strict=True):
            _connect(x, y, ctx, node, out)
        return
    if connect_bus(a, b, ctx, node, out):
        return
    if isinstance(a, Connector) and isinstance(b, Connector) and (a._children or b._children):
        _connect_nested(a, b, ctx, node, out)
        return
    own = _own_output(a, ctx), _own_output(b, ctx)
    if own[0] is not None and own[1] is not None and (own[0] or own[1]):
        # an inside output connected to this block's own output (an outside connector), or
        # two own outputs (specification 9.3: outside outputs are not sources): the outside
        # one takes the other's value
        outer, inner = (a, b) if own[0] else (b, a)
        out.append(Equation(outer, inner))
        return
    out.append(connect(a, b))


def _connect_nested(a: Connector, b: Connector, ctx: Ctx, node: Any, out: list) -> None:
    """Connectors holding connectors (a plug of pins): their connectors are connected pairwise
    by name, their own variables as a connector."""
    if set(a._children) != set(b._children):
        raise fail(ctx.lex, node, f"cannot connect {a.name} ({', '.join(a._children)}) to "
                   f"{b.name} ({', '.join(b._children)}): incompatible connectors")
    for name, child in a._children.items():
        _connect(child, b._children[name], ctx, node, out)
    if a._symbols or b._symbols:
        out.append(connect(a, b))


def _own_output(x: Any, ctx: Ctx) -> bool | None:
    """None unless ``x`` is an output signal; then whether this instance declares it."""
    from ...core.variables import KIND_OUTPUT

    sym = getattr(x, "sym", None) if isinstance(x, Expr) else None
    decl = getattr(sym, "decl", None)
    if decl is None or decl.kind != KIND_OUTPUT:
        return None
    inst = ctx.env.inst if ctx.env is not None else None
    return inst is not None and getattr(sym, "owner", None) is inst


def _eval_if_equation(eq: A.EqIf, ctx: Ctx, out: list, initial: bool) -> None:
    symbolic = []
    for cond, body in eq.branches:
        check_condition(cond, ctx, "an if-equation")
        try:
            c = numeric_value(evaluate(cond, Ctx(ctx.env, ctx.lex, ctx.loops, True)), ctx.lex,
                              cond)
        except NotConstant:
            c = None
        if c is None:
            symbolic.append((evaluate(cond, ctx), body))
            continue
        if c:
            if not symbolic:
                for sub in body:
                    _eval_equation(sub, ctx, out, initial)
                return
            symbolic.append((True, body))
            break
    else:
        if not symbolic:
            for sub in eq.otherwise:
                _eval_equation(sub, ctx, out, initial)
            return
        symbolic.append((True, eq.otherwise))
    branches = []
    for c, body in symbolic:
        eqs: list = []
        for sub in body:
            _eval_equation(sub, ctx, eqs, initial)
        nested = [e for e in eqs if isinstance(e, H.IfEquation)]
        if len(nested) == 1:
            # one nested if-equation: its branches become branches of this one
            inner = nested[0]
            plain = [e for e in eqs if e is not inner]
            for ci, eqs_i in inner.branches:
                branches.append((ci if c is True else c & ci, plain + list(eqs_i)))
            eqs = plain + list(inner.otherwise)
        else:
            eqs = [x for e in eqs for x in (_residuals(e, ctx, eq)
                                             if isinstance(e, H.IfEquation) else [e])]
        for e in eqs:
            if not isinstance(e, Equation):
                raise fail(ctx.lex, eq, "an if-equation with a condition that changes during "
                           "the simulation may hold only equations 'a = b'")
        branches.append((c, eqs))
    otherwise = branches.pop()[1] if branches[-1][0] is True else []
    first_c, first = branches[0]
    try:
        out.append(H.if_equation(first_c, first, otherwise, *branches[1:]))
    except ModelError as err:
        raise fail(ctx.lex, eq, str(err)) from None


def _residuals(ifeq: Any, ctx: Ctx, node: Any) -> list:
    """A nested if-equation as equations ``0 = if c1 then r1 elseif ... else rn`` of the
    residuals of its branches (each branch must hold the same number of equations)."""
    from .arith import _if_else

    branches = list(ifeq.branches) + [(True, ifeq.otherwise)]
    sizes = {len(b) for _, b in branches}
    if len(sizes) != 1:
        raise fail(ctx.lex, node, "the branches of an if-equation with a condition that "
                   "changes during the simulation must hold the same number of equations")
    out = []
    for k in range(sizes.pop()):
        res: Any = None
        for c, eqs in reversed(branches):
            e = eqs[k]
            if not isinstance(e, Equation):
                raise fail(ctx.lex, node, "an if-equation with a condition that changes "
                           "during the simulation may hold only equations 'a = b'")
            r = e.lhs - e.rhs
            res = r if res is None else _if_else(c, r, res, ctx, node)
        out.append(Equation(res, 0.0))
    return out


def _eval_when(eq: A.EqWhen, ctx: Ctx) -> Any:
    from . import runtime

    result = None
    for cond, body in eq.branches:
        c = evaluate(cond, ctx)
        with runtime.discrete_context() as calls:
            stmts = _when_body(body, ctx)
        stmts[:0] = calls
        try:
            if result is None:
                result = H.when(c, *stmts)
            else:
                result.elsewhen(c, *stmts)
        except ModelError as err:
            raise fail(ctx.lex, eq, str(err)) from None
    return result


def _when_body(body: Any, ctx: Ctx) -> list:
    """The statements of one branch of a when-equation."""
    stmts: list = []
    for st in body:
        if isinstance(st, A.EqSimple):
            a = evaluate(st.lhs, ctx)
            b = evaluate(st.rhs, ctx)
            _equation(a, b, ctx, st, stmts)
        elif isinstance(st, A.EqCall) and st.call.func.dotted == "reinit":
            if len(st.call.args) != 2:
                raise fail(ctx.lex, st, "reinit(x, value) takes two arguments")
            x = evaluate(st.call.args[0], ctx)
            v = evaluate(st.call.args[1], ctx)
            xs, vs = (x, v) if isinstance(x, list) else ([x], [v])
            for xi, vi in zip(xs, vs if isinstance(vs, list) else [vs] * len(xs),
                              strict=True):
                try:
                    stmts.append(H.reinit(xi, vi))
                except ModelError as err:
                    raise fail(ctx.lex, st, str(err)) from None
        elif isinstance(st, A.EqCall) and st.call.func.dotted in ("assert",):
            continue
        elif isinstance(st, A.EqCall) and st.call.func.dotted == "terminate":
            raise fail(ctx.lex, st, "unsupported Modelica construct: terminate()")
        else:
            raise fail(ctx.lex, st, "unsupported Modelica construct in a when-equation "
                       "(supported: 'v = expression' and reinit(x, value))")
    return stmts


def _declaration_equations(inst: Element, bindings: list, connector: bool,
                           owner: Element | None = None) -> None:
    """``Real x = expr`` (in the class or from a modifier): the equation ``x = expr``,
    evaluated where the binding is written. A connector's bindings (``Support s(phi = p)``)
    become equations of ``owner``, the component that declares the connector."""
    eqs: list = []
    for sym, m, info in bindings:
        lex = m.lex or info.lex
        if connector and owner is None:
            raise fail(lex, m.pos, f"{info.comp.name}: a top-level connector variable cannot "
                       "have a declaration equation")
        try:
            value = m.value(False)
        except NotConstant as err:
            raise fail(lex, m.pos, f"{info.comp.name}: {err.what}") from None
        _equation(sym.leaf, value, Ctx(None, lex, {}, False), m, eqs)
    (owner if connector else inst)._own_equations().extend(eqs)
