"""Flatten a component tree into a :class:`FlatModel` (Modelica connection semantics).

Connection sets are formed over (connector, side) elements: a connector is an *inside* element
in the context of the component that owns it, and an *outside* element in its own component's
``connect`` statements. In each set potentials are equal and flows sum to zero, inside flows
counted positive and outside flows negative. A connector not connected as an inside element
gets ``flow = 0``.
"""

from __future__ import annotations

from typing import Any

import casadi as ca

from ..errors import ConnectError, DeclarationError, EquationError
from .component import Component, Connection, Connector, Element
from .expressions import residual_of, signed_terms
from .flatmodel import FlatEquation, FlatModel, FlatVariable
from .variables import (
    KIND_FLOW,
    KIND_INPUT,
    KIND_PARAMETER,
    Symbol,
    lookup,
    time,
)


def flatten(model: Component, name: str | None = None) -> FlatModel:
    """Flatten ``model`` (the top-level component) into a :class:`FlatModel`."""
    if not isinstance(model, Component):
        raise DeclarationError(f"cannot flatten {model!r}: not a Component")
    return _Flattener(model).run(name or model.name or type(model).__name__)


class _Flattener:
    def __init__(self, top: Component) -> None:
        self.top = top
        self.paths: dict[int, str] = {}          # id(element) -> dotted path
        self.parents: dict[int, Element] = {}    # id(element) -> parent element
        self.elements: list[Element] = []
        self.equations: list[FlatEquation] = []
        self.pending: list[tuple[Any, Component]] = []   # raw equations with context
        self.connections: list[tuple[Connection, Component]] = []

    # -- tree walk -------------------------------------------------------------------------
    def run(self, name: str) -> FlatModel:
        stack: list[tuple[Element, str, Element | None]] = [(self.top, "", None)]
        while stack:
            elem, path, parent = stack.pop()
            if id(elem) in self.paths:
                raise DeclarationError(
                    f"{type(elem).__name__} instance is used twice in the model, as "
                    f"{self.paths[id(elem)] or 'top'} and {path}: create one instance per use")
            self.paths[id(elem)] = path
            if parent is not None:
                self.parents[id(elem)] = parent
            self.elements.append(elem)
            if isinstance(elem, Component):
                for eq in elem.all_equations():
                    if isinstance(eq, Connection):
                        self.connections.append((eq, elem))
                    else:
                        self.pending.append((eq, elem))
            for child_name, child in reversed(list(elem._children.items())):
                stack.append((child, _join(path, child_name), elem))
        variables, parameters, inputs, sym_index = self._collect_symbols()
        self._component_equations()
        self._connection_equations(sym_index, variables)
        self._check_references(variables, parameters, inputs)
        self._mark_aliases(sym_index, variables)
        return FlatModel(name, variables, parameters, inputs, self.equations)

    def where(self, elem: Element) -> str:
        return f"{self.paths[id(elem)] or 'top level'} ({type(elem).__name__})"

    # -- symbols ---------------------------------------------------------------------------
    def _collect_symbols(self):
        variables: list[FlatVariable] = []
        parameters: list[FlatVariable] = []
        inputs: list[FlatVariable] = []
        sym_index: dict[int, int] = {}     # SX hash -> variable index
        top_connectors = {id(c) for c in self.top._children.values() if isinstance(c, Connector)}
        for elem in self.elements:
            path = self.paths[id(elem)]
            owner = path if isinstance(elem, Component) else path.rpartition(".")[0]
            for sym in elem._symbols.values():
                full = _join(path, sym.name)
                flat = FlatVariable(full, sym.sx, sym.decl, owner)
                kind = sym.decl.kind
                if kind == KIND_PARAMETER:
                    parameters.append(flat)
                elif kind == KIND_INPUT and (elem is self.top or id(elem) in top_connectors):
                    inputs.append(flat)
                else:
                    sym_index[sym.sx.element_hash()] = len(variables)
                    variables.append(flat)
                    self._add_derivatives(sym, full, owner, variables, sym_index)
        return variables, parameters, inputs, sym_index

    @staticmethod
    def _add_derivatives(sym: Symbol, full: str, owner: str, variables: list[FlatVariable],
                         sym_index: dict[int, int]) -> None:
        below = len(variables) - 1
        while sym.der is not None:
            sym = sym.der
            full = f"der({full})"
            variables[below].der = len(variables)
            sym_index[sym.sx.element_hash()] = len(variables)
            variables.append(FlatVariable(full, sym.sx, sym.decl, owner, der_of=below))
            below = len(variables) - 1

    # -- equations -------------------------------------------------------------------------
    def _component_equations(self) -> None:
        for eq, ctx in self.pending:
            where = self.where(ctx)
            for res in residual_of(eq, where):
                self.equations.append(FlatEquation(res, where))

    def _connection_equations(self, sym_index: dict[int, int], variables) -> None:
        parent: dict[tuple[int, int], tuple[int, int]] = {}

        def find(x):
            parent.setdefault(x, x)
            root = x
            while parent[root] != root:
                root = parent[root]
            while parent[x] != root:
                parent[x], x = root, parent[x]
            return root

        connectors: dict[int, Connector] = {}
        signal_links: list[tuple[ca.SX, ca.SX, Component]] = []
        for conn, ctx in self.connections:
            ends = []
            for end in (conn.a, conn.b):
                if isinstance(end, Connector):
                    if id(end) not in self.paths:
                        raise ConnectError(
                            f"{self.where(ctx)}: connect() uses a {type(end).__name__} that is "
                            "not part of the model (add its component to the model first)")
                    side = 1 if self.parents.get(id(end)) is ctx else 0   # 1 = outside
                    connectors[id(end)] = end
                    ends.append((id(end), side))
            if len(ends) == 2:
                parent[find(ends[0])] = find(ends[1])
            else:
                signal_links.append((conn.a, conn.b, ctx))
        for elem in self.elements:
            if isinstance(elem, Connector):
                connectors[id(elem)] = elem
                find((id(elem), 0))
        sets: dict[tuple[int, int], list[tuple[int, int]]] = {}
        for key in list(parent):
            sets.setdefault(find(key), []).append(key)
        for members in sets.values():
            self._one_set(members, connectors, sym_index)
        for a, b, ctx in signal_links:
            self.equations.append(FlatEquation(a - b, f"connect in {self.where(ctx)}"))

    def _one_set(self, members, connectors, sym_index) -> None:
        members.sort(key=lambda m: self.paths[m[0]])
        first = connectors[members[0][0]]
        names = " -- ".join(self.paths[m[0]] for m in members)
        origin = f"connection set {{{names}}}" if len(members) > 1 else (
            f"unconnected connector {self.paths[members[0][0]]}")
        for var_name, sym in first._symbols.items():
            if sym.decl.kind == KIND_FLOW:
                total = ca.SX(0)
                for cid, side in members:
                    total += (-1 if side else 1) * connectors[cid]._symbols[var_name].sx
                self.equations.append(FlatEquation(total, origin))
            else:
                ref = sym.sx
                for cid, _ in members[1:]:
                    other = connectors[cid]._symbols[var_name].sx
                    self.equations.append(FlatEquation(ref - other, origin))

    # -- checks ----------------------------------------------------------------------------
    def _check_references(self, variables, parameters, inputs) -> None:
        if not self.equations:
            return
        known = {v.sx.element_hash() for v in variables}
        known.update(p.sx.element_hash() for p in parameters)
        known.update(u.sx.element_hash() for u in inputs)
        known.add(time.element_hash())
        for p in parameters:
            value = p.decl.value
            if isinstance(value, ca.SX):
                for s in ca.symvar(value):
                    if s.element_hash() not in known:
                        raise DeclarationError(
                            f"parameter {p.name} is bound to {value}, which uses {s}: "
                            "not a parameter of this model")
        for s in ca.symvar(ca.vertcat(*[e.residual for e in self.equations])):
            if s.element_hash() not in known:
                sym = lookup(s)
                culprit = next(e for e in self.equations if ca.depends_on(e.residual, s))
                owner = f" of {type(sym.owner).__name__}" if sym else ""
                raise EquationError(
                    f"{culprit.origin}: equation uses {s}{owner}, which is not part of the "
                    "model (add its component to the model)")

    def _mark_aliases(self, sym_index: dict[int, int], variables) -> None:
        for eq in self.equations:
            terms = signed_terms(eq.residual)
            if terms is None or len(terms) != 2:
                continue
            (sa, a), (sb, b) = terms
            ia, ib = sym_index.get(a.element_hash()), sym_index.get(b.element_hash())
            if ia is None or ib is None or ia == ib:
                continue
            if variables[ia].der_of >= 0 or variables[ib].der_of >= 0:
                continue
            eq.alias = (ia, ib, -sb / sa)


def _join(path: str, name: str) -> str:
    return f"{path}.{name}" if path else name
