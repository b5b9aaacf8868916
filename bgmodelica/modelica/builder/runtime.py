"""Function calls on time-varying values, run on numbers at events.

The builder evaluates a function call by running its body on values (:mod:`.calls`): on
symbolic values for time-varying arguments, which some constructs cannot take (a
``while`` loop whose condition changes with time, an external function such as an FFT,
a subscript that changes with time). Such a call in a *discrete context* -- a branch of a
when-statement of a model's algorithm or of a when-equation -- only needs its value at the
instants the branch fires. There it becomes a :class:`~bgmodelica.core.hybrid.RuntimeCall`:
its outputs are hidden discrete slots, and the event loop runs the same interpreter on the
numeric values of the arguments when the branch fires (where the enclosing ``if``
conditions of the algorithm hold), before the branch's assignments read the outputs.
Outside a discrete context the construct is refused as before (one line, ``file:line``).
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Any

import numpy as np

from ...core import hybrid as H
from ...core.expr import Expr, Op
from .. import scope as S
from .base import Ctx, fail

#: the open discrete contexts (innermost last): each a list of the calls made in it and a
#: list of the symbolic ``if`` conditions around the statement being run
_FRAMES: list[tuple[list, list]] = []

#: scalar output types a runtime call can give (their values live in discrete slots)
_SCALARS = ("Real", "Integer", "Boolean")


@contextmanager
def discrete_context():
    """Run a when-branch body: yields the list that collects its runtime calls."""
    calls: list = []
    _FRAMES.append((calls, []))
    try:
        yield calls
    finally:
        _FRAMES.pop()


@contextmanager
def condition(c: Any, ctx: Ctx):
    """Run statements under the symbolic ``if`` condition ``c`` (guards the calls made)."""
    if not _FRAMES or ctx.env is None:
        yield
        return
    path = _FRAMES[-1][1]
    path.append(c)
    try:
        yield
    finally:
        path.pop()


def negated(c: Any) -> Any:
    return Op("not", (c,)) if isinstance(c, Expr) else not c


def active(ctx: Ctx) -> bool:
    """Whether a call evaluated in ``ctx`` (a model's scope) may run at events."""
    return bool(_FRAMES) and ctx.env is not None


def deferred(scope: S.ClassScope, args: list, kwargs: dict, ctx: Ctx, node: Any,
             all_outputs: bool) -> Any:
    """The outputs of a call of function ``scope`` that runs at events: hidden discrete
    slots, shaped as the declared outputs (a tuple with ``all_outputs``)."""
    from .calls import function_def

    fn = function_def(scope)
    where = fail(ctx.lex, node, fn.name).args[0]
    shapes = _output_shapes(fn, args, kwargs, ctx, node)
    outputs: list[H.RuntimeOutput] = []
    values = []
    for (comp, _, _), shape in zip(fn.outputs, shapes, strict=True):
        values.append(_slots(f"{fn.name}.{comp.name}", shape,
                             comp.type_name == "Boolean", outputs))
    exprs: list = []
    targs = [_template(a, exprs) for a in args]
    tkwargs = {k: _template(v, exprs) for k, v in kwargs.items()}
    kinds = _input_kinds(fn, len(args), kwargs)
    path = _FRAMES[-1][1]
    guard: Any = True
    for c in path:
        guard = c if guard is True else guard & c
    run = NumericCall(scope, targs, tkwargs, kinds, len(exprs), len(outputs), ctx.lex, node)
    _FRAMES[-1][0].append(H.RuntimeCall(run, exprs, guard, outputs, where))
    if all_outputs:
        return tuple(values)
    return values[0] if values else None


class NumericCall:
    """``NumericCall(...)(values)``: the function run on the numbers ``values`` of the
    time-varying arguments; its outputs flattened (row-major) as floats."""

    def __init__(self, scope: S.ClassScope, args: list, kwargs: dict, kinds: dict,
                 n_in: int, n_out: int, lex: Any, node: Any) -> None:
        self.scope, self.args, self.kwargs, self.kinds = scope, args, kwargs, kinds
        self.n_in, self.n_out, self.lex, self.node = n_in, n_out, lex, node

    def __call__(self, values: Any) -> np.ndarray:
        from .calls import apply_function

        vals = np.asarray(values, dtype=float).ravel()
        args = [_fill(a, vals, self.kinds.get(k, "Real")) for k, a in enumerate(self.args)]
        kwargs = {n: _fill(a, vals, self.kinds.get(n, "Real")) for n, a in self.kwargs.items()}
        outs = apply_function(self.scope, args, kwargs, Ctx(None, self.lex, {}, False),
                              self.node, all_outputs=True)
        flat = [np.asarray(_plain(o), dtype=float).ravel() for o in outs]
        got = np.concatenate(flat) if flat else np.zeros(0)
        if got.size != self.n_out:
            raise fail(self.lex, self.node, f"{self.scope.full_name}() returned {got.size} "
                       f"values at an event, {self.n_out} expected from its declaration")
        return got


class _Arg:
    """The position of one time-varying scalar argument in the values of a call."""

    __slots__ = ("k",)

    def __init__(self, k: int) -> None:
        self.k = k


def _template(v: Any, exprs: list) -> Any:
    """``v`` with each time-varying scalar replaced by its :class:`_Arg` (appended to
    ``exprs``)."""
    if isinstance(v, list):
        return [_template(x, exprs) for x in v]
    if isinstance(v, Expr):
        exprs.append(v)
        return _Arg(len(exprs) - 1)
    return v


def _fill(t: Any, vals: np.ndarray, kind: str) -> Any:
    if isinstance(t, list):
        return [_fill(x, vals, kind) for x in t]
    if isinstance(t, _Arg):
        v = float(vals[t.k])
        return int(round(v)) if kind == "Integer" else (v > 0.5 if kind == "Boolean" else v)
    return t


def _plain(v: Any) -> Any:
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    return float(v) if isinstance(v, (bool, np.bool_)) else v


def _input_kinds(fn: Any, n_args: int, kwargs: dict) -> dict:
    """The declared type of each given argument (by position and by name)."""
    kinds: dict = {}
    for k, (comp, _, _) in enumerate(fn.inputs):
        if k < n_args:
            kinds[k] = comp.type_name
        if comp.name in kwargs:
            kinds[comp.name] = comp.type_name
    return kinds


def _output_shapes(fn: Any, args: list, kwargs: dict, ctx: Ctx, node: Any) -> list:
    """The array dimensions of each output, from its declaration (sizes of the given
    arguments are known when the model is built)."""
    from .calls import _initial

    local: dict = dict(kwargs)
    for (comp, _, _), a in zip(fn.inputs, args, strict=False):
        local[comp.name] = a
    shapes = []
    for comp, lex, info in fn.outputs:
        if comp.type_name not in _SCALARS:
            raise fail(ctx.lex, node, f"{fn.name}() on time-varying values at events: output "
                       f"{comp.name} of type {comp.type_name} (Real, Integer or Boolean "
                       "outputs only)")
        try:
            zero = _initial(comp, lex, local, info)
        except Exception:  # noqa: BLE001 -- the size depends on something not known
            zero = None
        if zero is None:
            raise fail(ctx.lex, node, f"{fn.name}() on time-varying values at events: the size "
                       f"of output {comp.name} is not known when the model is built")
        shape = []
        while isinstance(zero, list):
            shape.append(len(zero))
            zero = zero[0] if zero else None
        shapes.append(shape)
    return shapes


def _slots(name: str, shape: list, boolean: bool, outputs: list, index: tuple = ()) -> Any:
    if len(index) == len(shape):
        sub = f"[{','.join(str(i + 1) for i in index)}]" if index else ""
        out = H.RuntimeOutput(name + sub, boolean)
        outputs.append(out)
        return out.leaf
    return [_slots(name, shape, boolean, outputs, (*index, k))
            for k in range(shape[len(index)])]
