"""The equations of many instances of one Modelica class, evaluated once.

A class whose equations are plain ``a = b`` of references to its own parameters, variables
and connectors' variables, numbers, arithmetic, ``der`` and the smooth math functions
(nothing a parameter value could change: no subscripts, ``if``, ``for``, constants or
other calls) gives every instance the same expression trees but for the leaves. The first
instances' equations are evaluated from the syntax tree as usual; once a copy of the first
instance's trees, with each leaf replaced by the second instance's own, equals the second's
(the check), the others get such copies instead of an evaluation: a ladder of 1,000
``Resistor`` instances is evaluated twice and copied 998 times. Flattening may also ask for
the equations of many instances written once, as array equations over them (:meth:`group`),
as it does for the components of a Python class.
"""

from __future__ import annotations

from operator import attrgetter
from typing import Any

import numpy as np

from ...core.array_marks import mark_leaves
from ...core.arrays import ArrayEquation, ArrayExpr, _lazy
from ...core.expr import Equation, Leaf, Op
from ...core.variables import TIME
from .. import ast as A
from .classes import type_ref
from .env import _category

_OPS = frozenset(("+", "-", "*", "/", "^"))
_CALLS = frozenset(("der", "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh",
                    "exp", "log", "sqrt", "abs"))
_PLACES = (int, float)
_EQUATIONS = attrgetter("_equations")


class EquationTemplate:
    """What is known of one class's equations: ``state`` is "new" (not looked at),
    "off" (evaluate every instance), "learning" (a first instance's trees are kept) or
    "ready" (copies are made)."""

    def __init__(self, view: Any) -> None:
        self.view = view
        self.state = "new"
        self.trees: list[Equation] = []
        self.places: dict[int, tuple[str | None, str, bool]] = {}   # id(symbol) -> place

    def make(self, inst: Any) -> list[Equation] | None:
        """The equations of ``inst`` as copies, when the template is ready."""
        if self.state != "ready":
            return None
        return self._copy(inst)

    def learn(self, inst: Any, out: list[Any]) -> None:
        """Take note of the equations ``out`` evaluated for ``inst``."""
        if self.state == "new":
            self.state = "off"
            if _plain_class(self.view) and self._keep(inst, out):
                self.state = "learning"
        elif self.state == "learning":
            self.state = "ready" if _same(self._copy(inst), out) else "off"

    def group(self, items: list[Any], arrays: dict | None = None) -> list[Any] | None:
        """The equations of the instances ``items`` (of this class) written once, as array
        equations over them (see :func:`~bgmodelica.core.flatten_vectorized.array_equations`,
        which asks); None when the class's equations are not plain or an instance has
        equations of its own (declaration equations)."""
        for inst in items[:2]:
            if self.state in ("new", "learning"):
                inst.equations()                      # evaluates, and learns
        if self.state != "ready" or any(map(_EQUATIONS, items)):
            return None
        columns: dict[int, ArrayExpr] = {}
        try:
            for key, (sub, name, is_der) in self.places.items():
                holders = items if sub is None else [inst._children[sub] for inst in items]
                symbols = [h._symbols[name] for h in holders]
                if is_der:
                    symbols = [sym.derivative() for sym in symbols]
                leaves = np.empty(len(items), dtype=object)
                leaves[:] = [sym.leaf for sym in symbols]
                decls = [sym.decl for sym in symbols]
                mark_leaves(leaves, len({type(d) for d in decls}) == 1
                            and len({d.unit for d in decls}) == 1)
                columns[key] = ArrayExpr(leaves)
                if arrays is not None and not is_der:
                    arrays[(sub, name)] = columns[key]
        except (KeyError, AttributeError):
            return None

        def copy(e: Any) -> Any:
            kind = type(e)
            if kind is Leaf:
                return columns.get(id(e.sym), e)
            if kind is Op:
                return _lazy(e.op, *map(copy, e.args))
            return float(e)

        out = [ArrayEquation(copy(eq.lhs), copy(eq.rhs)) for eq in self.trees]
        if not all(eq.shape == (len(items),) and eq.is_block() for eq in out):
            return None
        return out

    def _keep(self, inst: Any, out: list[Any]) -> bool:
        """Keep ``out`` as the trees to copy, with the place of each leaf in ``inst``."""
        owners = {id(inst): None}
        owners.update((id(child), name) for name, child in inst._children.items())
        places: dict[int, tuple[str | None, str, bool]] = {}

        def walk(e: Any) -> bool:
            if type(e) is Leaf:
                sym = e.sym
                if sym is TIME:
                    return True
                base, is_der = (sym.der_of, True) if sym.der_of is not None else (sym, False)
                if base.der_of is not None or id(base.owner) not in owners:
                    return False
                places[id(sym)] = (owners[id(base.owner)], base.name, is_der)
                return True
            if type(e) is Op:
                return all(map(walk, e.args))
            return type(e) in _PLACES

        if not all(type(eq) is Equation and walk(eq.lhs) and walk(eq.rhs) for eq in out):
            return False
        self.trees, self.places = list(out), places
        return True

    def _copy(self, inst: Any) -> list[Equation]:
        swap: dict[int, Leaf] = {}
        for key, (sub, name, is_der) in self.places.items():
            holder = inst if sub is None else inst._children[sub]
            sym = holder._symbols[name]
            swap[key] = (sym.derivative() if is_der else sym).leaf

        def copy(e: Any) -> Any:
            kind = type(e)
            if kind is Leaf:
                return swap.get(id(e.sym), e)
            if kind is Op:
                return Op(e.op, tuple(map(copy, e.args)))
            return e

        return [Equation(copy(eq.lhs), copy(eq.rhs)) for eq in self.trees]


def _same(a: list[Any], b: list[Any]) -> bool:
    """Whether two lists of equations are the same trees with the same leaves' symbols."""
    def same(x: Any, y: Any) -> bool:
        if type(x) is not type(y):
            return False
        if type(x) is Leaf:
            return x.sym is y.sym
        if type(x) is Op:
            return x.op == y.op and len(x.args) == len(y.args) \
                and all(map(same, x.args, y.args))
        return x == y

    return len(a) == len(b) and all(
        type(q) is Equation and same(p.lhs, q.lhs) and same(p.rhs, q.rhs)
        for p, q in zip(a, b, strict=True))


def _plain_class(view: Any) -> bool:
    """Whether every equation of the class is ``a = b`` of plain terms (see the module)."""
    return bool(view.equations) and all(
        type(eq) is A.EqSimple and _plain(eq.lhs, view) and _plain(eq.rhs, view)
        for eq, _ in view.equations)


def _plain(node: Any, view: Any) -> bool:
    kind = type(node)
    if kind is A.Num:
        return True
    if kind is A.Ref:
        if node.global_ or any(subs for _, subs in node.parts) or len(node.parts) > 2:
            return False
        info = view.elements.get(node.parts[0][0])
        if info is None:
            return node.dotted == "time"
        category = _category(info, type_ref(info))
        return category in ("param", "var") and len(node.parts) == 1 \
            or category == "child" and len(node.parts) == 2
    if kind is A.BinOp:
        return node.op in _OPS and _plain(node.a, view) and _plain(node.b, view)
    if kind is A.Unary:
        return node.op in ("-", "+") and _plain(node.a, view)
    if kind is A.Call:
        return node.func.dotted in _CALLS and not node.kwargs and node.iterator is None \
            and all(_plain(a, view) for a in node.args)
    return False
