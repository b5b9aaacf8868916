"""Algorithm sections of models (specification 11.1) as equations.

The section is run symbolically; each variable it assigns outside ``when`` becomes
``v = value``, each ``when``-statement a when-equation of the variables its branches assign
(starting from their ``pre`` values). In an initial algorithm the assignments become initial
equations (or start values and parameter values known when the model is built).
"""

from __future__ import annotations

from typing import Any

from .. import ast as A
from .algorithms import _Return, _run, _State
from .base import Ctx, fail


def section_equations(stmts: A.Statements, ctx: Ctx, out: list, initial: bool) -> None:
    """The equations of an algorithm section of a model (specification 11.1): the section is
    run symbolically; each variable it assigns outside ``when`` becomes ``v = value``, each
    ``when``-statement a when-equation of the variables its branches assign (starting from
    their ``pre`` values). In an initial algorithm the assignments become initial
    equations."""
    from .equations import _discrete_start, _equation, _parameter_value
    from .evaluate import evaluate

    names = _targets(stmts)
    leaves = {n: _leaf(n, ctx, stmts) if initial else evaluate(A.Ref(((n, None),), stmts.pos),
                                                                ctx) for n in names}
    local = dict(ctx.loops)
    for n in names:
        local[n] = _pre(leaves[n]) if not initial else _unset(leaves[n])
    state = _State()
    state.whens = []
    state.leaves = leaves
    try:
        _run(tuple(stmts), Ctx(ctx.env, ctx.lex, local, False), state)
    except _Return:
        pass
    in_when: set[str] = set()
    for branches in state.whens:
        for _, assigned, _ in branches:
            in_when |= set(assigned)
    for n in names:
        if n in in_when:
            continue
        if _has_unset(local.get(n)):
            raise fail(ctx.lex, stmts, f"{n} is not assigned on every path of the algorithm")
        if initial and (_discrete_start(leaves[n], local[n], ctx, stmts)
                        or _parameter_value(leaves[n], local[n], ctx, stmts)):
            continue
        _equation(leaves[n], local[n], ctx, stmts, out)
    for branches in state.whens:
        out.append(_when_of(branches, leaves, ctx, stmts))


def _leaf(name: str, ctx: Ctx, node: Any) -> Any:
    """The variable ``name`` an initial algorithm assigns: a parameter (also a Boolean or
    Integer one, otherwise a value when built) as its symbol."""
    from .evaluate import evaluate, member

    env = ctx.env
    inst = env.inst if env is not None else None
    if inst is not None and (name in inst._symbols or name in (
            inst.__dict__.get("_mo_arrays") or ())):
        return member(inst, name, False, ctx.lex, node)
    return evaluate(A.Ref(((name, None),), node.pos), ctx)


def _unset(v: Any) -> Any:
    """``v``'s shape with no value yet (an initial algorithm assigns it)."""
    return [_unset(x) for x in v] if isinstance(v, list) else None


def _has_unset(v: Any) -> bool:
    return any(_has_unset(x) for x in v) if isinstance(v, list) else v is None


def _when_of(branches: list, leaves: dict, ctx: Ctx, node: Any) -> Any:
    from ...core import hybrid as H
    from .equations import _equation

    union: list[str] = []
    for _, assigned, _ in branches:
        union += [n for n in assigned if n not in union]
    result = None
    for cond, assigned, calls in branches:
        eqs: list = list(calls)
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
    from . import runtime
    from .evaluate import evaluate

    branches = []
    for cond, body in st.branches:
        c = evaluate(cond, ctx)
        names = _targets(body)
        local = dict(ctx.loops)
        for n in names:
            local[n] = _pre(state.leaves[n]) if n in state.leaves else None
        with runtime.discrete_context() as calls:
            _run(body, Ctx(ctx.env, ctx.lex, local, False), state)
        branches.append((c, {n: local[n] for n in names}, calls))
    state.whens.append(branches)
