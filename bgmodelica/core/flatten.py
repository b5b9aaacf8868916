"""Flatten a component tree into a :class:`FlatModel` (Modelica connection semantics).

The tree walk collects every symbol and equation; connection sets become equations in
:mod:`.flatten_connections`, array equations are lowered whole in :mod:`.flatten_arrays`.

Lowering to CasADi is vectorized: every symbol of the model becomes an element of one SX
vector, and equations of the same shape are lowered together (see :mod:`.expr`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import casadi as ca
import numpy as np

from ..errors import DeclarationError, EquationError
from ..validate import (
    check_binding,
    check_binding_cycles,
    check_sx_binding,
    guarded_equations,
)
from . import flatten_arrays, flatten_hybrid
from .arrays import ArrayEquation
from .component import Component, Connection, Connector, Element
from .expr import (
    HYBRID_NODES,
    Equation,
    Expr,
    Leaf,
    Number,
    Op,
    alias_signs,
    lower_group,
    shape_of,
    to_sx,
)
from .flatmodel import EquationSources, FlatEquation, FlatModel, FlatVariable, take
from .flatten_connections import ConnectionLowering
from .flatten_initial import InitialEquationsMixin
from .flatten_vectorized import GROUP_FROM, array_equations, component_groups
from .variables import (
    KIND_INPUT,
    KIND_PARAMETER,
    TIME,
    Symbol,
    lookup,
    start_text_error,
)


def flatten(model: Component, name: str | None = None) -> FlatModel:
    """Flatten ``model`` (the top-level component) into a :class:`FlatModel`."""
    if not isinstance(model, Component):
        raise DeclarationError(f"cannot flatten {model!r}: not a Component")
    return _Flattener(model).run(name or model.name or type(model).__name__)


class _Flattener(ConnectionLowering, InitialEquationsMixin):
    def __init__(self, top: Component) -> None:
        self.top = top
        self.paths: dict[int, str] = {}          # id(element) -> dotted path
        self.origins: dict[int, str] = {}        # id(element) -> "path (Class)"
        self.parents: dict[int, Element] = {}    # id(element) -> parent element
        self.elements: list[Element] = []
        self.pending: list[tuple[Any, Component]] = []   # raw equations with context
        self.connections: list[tuple[Connection, Component]] = []
        self.var_of: dict[int, int] = {}         # id(Symbol) -> variable index
        self.pos: dict[int, int] = {}            # id(Symbol) -> position in self.all_sx
        self.equations: list[FlatEquation] = []
        self.columns: list[ca.SX] = []            # the residuals of self.equations, stacked
        self.draft: flatten_hybrid.HybridDraft | None = None
        self.slot: dict[int, int] = {}            # id(Symbol) -> index in discretes
        self._full: dict[int, str] | None = None  # id(Symbol) -> dotted name (see full)
        self._full_of = 0                         # len(collected) when _full was made
        self.collected: list[tuple[Symbol, FlatVariable]] = []   # every symbol, flat entry
        self.groups: dict[Any, list] = {}         # equation shape -> members (as written)
        self.blocks: list[tuple[ArrayEquation, str]] = []   # array equations lowered whole
        self.initial_sources: list[tuple[Equation, str]] = []   # initial equations as written
        self.array_rows: dict[int, Any] = {}      # declared arrays' rows (flatten_arrays)
        self.written_once: list[Any] = []         # groups of components written once
        self.row_origins: dict[int, list[str]] = {}   # id(their equation) -> element origins

    # -- tree walk -------------------------------------------------------------------------
    def run(self, name: str) -> FlatModel:
        stack: list[tuple[Element, str, Element | None]] = [(self.top, "", None)]
        paths, parents, elements = self.paths, self.parents, self.elements
        connections, pending = self.connections, self.pending
        vectorized: set[int] = set()          # elements whose equations an array wrote
        while stack:
            elem, path, parent = stack.pop()
            key = id(elem)
            if key in paths:
                raise DeclarationError(
                    f"{type(elem).__name__} instance is used twice in the model, as "
                    f"{paths[key] or 'top'} and {path}: create one instance per use")
            paths[key] = path
            if parent is not None:
                parents[key] = parent
            elements.append(elem)
            children = elem._children
            if isinstance(elem, Component):
                if key not in vectorized:
                    for eq in guarded_equations(elem, self.where(elem), path, blocks=True):
                        if isinstance(eq, Connection):
                            connections.append((eq, elem))
                        else:
                            pending.append((eq, elem))
                if len(children) >= GROUP_FROM or "_arrays" in elem.__dict__:
                    self._group_equations(elem, path, vectorized)
            if children:
                prefix = f"{path}." if path else ""
                stack.extend((child, prefix + child_name, elem)
                             for child_name, child in reversed(children.items()))
        asserts: list = []
        if HYBRID_NODES[0]:
            self.pending, draft = flatten_hybrid.extract(self.pending, self.where)
            self.draft = None if draft.empty else draft
            asserts = draft.asserts
        variables, parameters, inputs, discretes, symbols = self._collect_symbols()
        for fv in [v for v in variables if type(getattr(v.decl, "start", 0.0)) is str][:1]:
            raise start_text_error(fv.name, fv.decl)
        self._bind(symbols)
        self._connection_equations()
        self._component_equations()
        initial = self._initial_equations()
        for sym, fv in self.collected:     # initial equations may give values and starts
            if fv.decl is not sym.decl:
                fv.decl = sym.decl
        sources = self._sources(parameters)
        self._check_cycles(parameters)
        parameters = [p if type(p.decl.value) is float else self._lower_binding(p)
                      for p in parameters]
        hybrid = None
        if self.draft is not None:
            hybrid = flatten_hybrid.lower(self.draft, lambda s: self.slot[id(s)],
                                          lambda s: self.full[id(s)])
        flat = FlatModel(name, variables, parameters, inputs, self.equations,
                         discretes=discretes, hybrid=hybrid, sources=sources,
                         initial_equations=initial)
        flat.asserts = [flatten_hybrid.lower_assert(a, here, self.full) for a, here in asserts]
        flat.remember_stacked(ca.vertcat(*self.columns) if self.columns else None,
                              *[take(self.all_sx, self._rows(entries)) for entries in self.entries])
        return flat

    def _group_equations(self, elem: Component, path: str, vectorized: set[int]) -> None:
        """Equations of groups of ``elem``'s children written once per group where exact
        (:mod:`.flatten_vectorized`); those children are then not asked for theirs. Each
        scalar equation keeps its element's origin (``row_origins``)."""
        prefix = f"{path}." if path else ""
        for names, items in component_groups(elem):
            eqs = array_equations(items)
            if eqs is None:
                continue
            cls = type(items[0]).__name__
            wheres = [f"{prefix}{name} ({cls})" for name in names]
            self.origins.update(zip(map(id, items), wheres, strict=True))
            self.origins[id(items)] = \
                f"{prefix}{names[0]} .. {names[-1]} ({len(items)} {cls} components)"
            self.pending.extend((eq, items) for eq in eqs)    # type: ignore[misc]
            self.row_origins.update((id(eq), wheres) for eq in eqs)
            self.written_once.append((items, eqs))  # keeps the ids above unique meanwhile
            vectorized.update(map(id, items))

    def _sources(self, parameters: list[FlatVariable]) -> EquationSources:
        """The equations as written, for passes that read expression trees (units)."""
        bindings = [(p.name, p.decl, f"{p.component or 'top level'}") for p in parameters
                    if isinstance(p.decl.value, Expr)]
        links = [(c.a, c.b, self.where(ctx)) for c, ctx in self.connections
                 if not isinstance(c.a, Connector)]
        blocks = [(eq, where, self.row_origins.get(id(eq))) for eq, where in self.blocks]
        return EquationSources(self.groups, self.draft, bindings, links, self.initial_sources,
                               blocks)

    @property
    def full(self) -> dict[int, str]:
        """id(Symbol) -> dotted name of the symbols collected so far; made on first use
        (messages, hybrid parts and bound parameters need it, most models never do)."""
        if self._full is None or self._full_of != len(self.collected):
            self._full = {id(sym): fv.name for sym, fv in self.collected}
            self._full_of = len(self.collected)
        return self._full

    def where(self, elem: Element) -> str:
        """``path (Class)`` of an element, for equation origins and messages."""
        text = self.origins.get(id(elem))
        if text is None:
            text = self.origins[id(elem)] = \
                f"{self.paths[id(elem)] or 'top level'} ({type(elem).__name__})"
        return text

    # -- symbols ---------------------------------------------------------------------------
    def _collect_symbols(self):
        """Every symbol of the tree with its flat variable, in tree order; also records
        where in that list the unknowns and the parameters are (``entries``)."""
        variables: list[FlatVariable] = []
        parameters: list[FlatVariable] = []
        inputs: list[FlatVariable] = []
        discretes: list[FlatVariable] = []
        symbols = self.collected
        var_entries: list[int] = []                       # positions in symbols, by kind
        par_entries: list[int] = []
        hybrid = self.draft is not None
        targets = self.draft.targets if hybrid else {}
        top_connectors = {id(c) for c in self.top._children.values() if isinstance(c, Connector)}
        var_of, paths = self.var_of, self.paths
        add_symbol, add_variable, add_entry = symbols.append, variables.append, var_entries.append
        for elem in self.elements:
            path = paths[id(elem)]
            owner = path if isinstance(elem, Component) else path.rpartition(".")[0]
            prefix = f"{path}." if path else ""
            top_level = elem is self.top or id(elem) in top_connectors
            for sym in elem._symbols.values():
                full = prefix + sym.name
                decl = sym.decl
                kind = decl.kind
                if hybrid and id(sym) in targets:
                    self.slot[id(sym)] = len(discretes)
                    fv = FlatVariable(full, None, decl, owner)
                    add_symbol((sym, fv))
                    discretes.append(fv)
                elif kind == KIND_PARAMETER:
                    fv = FlatVariable(full, None, decl, owner)
                    par_entries.append(len(symbols))
                    add_symbol((sym, fv))
                    parameters.append(fv)
                elif kind == KIND_INPUT and top_level:
                    fv = FlatVariable(full, None, decl, owner)
                    add_symbol((sym, fv))
                    inputs.append(fv)
                else:
                    below = len(variables)
                    var_of[id(sym)] = below
                    fv = FlatVariable(full, None, decl, owner)
                    add_entry(len(symbols))
                    add_symbol((sym, fv))
                    add_variable(fv)
                    while sym.der is not None:             # derivative chain
                        sym, full = sym.der, f"der({full})"
                        fv.der = len(variables)
                        var_of[id(sym)] = len(variables)
                        fv = FlatVariable(full, None, sym.decl, owner, der_of=below)
                        add_entry(len(symbols))
                        add_symbol((sym, fv))
                        add_variable(fv)
                        below = len(variables) - 1
        if self.draft is not None:
            named = self.full                     # once: the hidden symbols add to the list
            for k, sym in enumerate(self.draft.hidden()):
                if sym.pre_of is not None:
                    owner = named.get(id(sym.pre_of))
                    if owner is None:
                        raise DeclarationError(f"pre({sym.pre_of.name}) refers to a variable "
                                               "that is not part of the model")
                    name = f"pre({owner})"
                else:
                    name = _hidden_name(sym, k)
                self.slot[id(sym)] = len(discretes)
                fv = FlatVariable(name, None, sym.decl, "")
                symbols.append((sym, fv))
                named[id(sym)] = name
                discretes.append(fv)
        self.entries = (var_entries, par_entries)
        return variables, parameters, inputs, discretes, symbols

    def _bind(self, symbols) -> None:
        """Give every symbol an SX scalar: fresh ones become rows of one SX vector (taken out
        when first used), symbols bound before (a model flattened again) keep theirs and
        follow. ``rows``: the row in :attr:`all_sx` of each entry of ``symbols``."""
        old = [k for k, (sym, _) in enumerate(symbols)
               if sym._sx is not None or sym._at is not None]
        fresh = symbols
        self.rows = None                                  # entry k is row k
        if old:
            is_old = np.zeros(len(symbols), dtype=bool)
            is_old[old] = True
            order = np.concatenate((np.flatnonzero(~is_old), old)).astype(np.int64)
            rows = np.empty(len(symbols), dtype=np.int64)
            rows[order] = np.arange(len(symbols))
            self.rows = rows
            fresh = [symbols[k] for k in order[:len(symbols) - len(old)].tolist()]
        big = ca.SX.sym("v", len(fresh))
        pos = self.pos
        for k, (sym, fv) in enumerate(fresh):
            sym._at = fv.at = (big, k)                    # the scalar is taken out when used
            pos[id(sym)] = k
        olds = [symbols[k] for k in old]
        for k, (sym, fv) in enumerate(olds, start=len(fresh)):
            fv.sx = sym.sx
            pos[id(sym)] = k
        pos[id(TIME)] = len(symbols)
        self.all_sx = ca.vertcat(big, *[sym.sx for sym, _ in olds], TIME.sx)

    def _rows(self, entries: list[int]) -> list[int]:
        """Rows in :attr:`all_sx` of the symbols at ``entries`` of the collected list."""
        return entries if self.rows is None else self.rows[entries].tolist()

    def _check_cycles(self, parameters: list[FlatVariable]) -> None:
        """Bindings that depend on themselves, named as a cycle."""
        bound = [p for p in parameters if isinstance(p.decl.value, Expr)]
        if not bound:
            return
        full = self.full
        check_binding_cycles(
            {p.name: [full.get(id(leaf), "?") for leaf in _leaf_symbols(p.decl.value)]
             for p in bound})

    def _lower_binding(self, p: FlatVariable) -> FlatVariable:
        if isinstance(p.decl.value, Expr):
            leaves = _leaf_symbols(p.decl.value)
            for leaf_sym in leaves:
                if id(leaf_sym) not in self.pos:
                    raise DeclarationError(
                        f"parameter {p.name} is bound to {p.decl.value!r}, which uses "
                        f"{getattr(leaf_sym, 'name', leaf_sym)}: not part of this model")
            check_binding(p.name, p.decl.value, leaves, self.full)   # parameters only
            return replace(p, decl=replace(p.decl, value=to_sx(p.decl.value)))
        if isinstance(p.decl.value, ca.SX):
            check_sx_binding(p.name, p.decl.value)
        if not isinstance(p.decl.value, (Number, ca.SX)):
            raise DeclarationError(f"parameter {p.name} has a non-numeric value "
                                   f"{p.decl.value!r}")
        return p

    # -- component equations ---------------------------------------------------------------
    def _component_equations(self) -> None:
        groups: dict[Any, list] = {}
        slow: list[tuple[ca.SX, str]] = []
        last, where = None, ""
        for eq, ctx in self.pending:
            if ctx is not last:                  # a component's equations come together
                last, where = ctx, self.where(ctx)
            if isinstance(eq, ArrayEquation):
                self.blocks.append((eq, where))
                continue
            if type(eq) is Equation:
                leaves: list = []
                consts: list = []
                try:
                    key = (_side_shape(eq.lhs, leaves, consts),
                           _side_shape(eq.rhs, leaves, consts))
                except RecursionError:           # too deep to group: lowered alone
                    slow.append((to_sx(eq.lhs) - to_sx(eq.rhs), where))
                    continue
                except TypeError:
                    if isinstance(eq.lhs, (ca.SX, ca.MX)) or isinstance(eq.rhs, (ca.SX, ca.MX)):
                        slow.append((to_sx(eq.lhs) - to_sx(eq.rhs), where))
                        continue
                    raise EquationError(f"{where}: cannot use {eq!r} as an equation") from None
                if not leaves:
                    raise EquationError(f"{where}: equation {eq!r} has no variables")
                groups.setdefault(key, []).append((leaves, consts, where, eq))
            elif isinstance(eq, ca.SX) and eq.numel() >= 1 and all(
                    eq[k].is_op(ca.OP_EQ) for k in range(eq.numel())):
                for k in range(eq.numel()):
                    slow.append((eq[k].dep(0) - eq[k].dep(1), where))
            else:
                raise EquationError(
                    f"{where}: an equation must be written 'lhs == rhs' with at least one "
                    f"variable, got {eq!r}")
        self.groups = groups
        for key, members in groups.items():
            self._lower(key, members)
        for eq, where in self.blocks:
            self._lower_block(eq, where)
        if slow:
            self._check_slow(slow)
            self.equations.extend(FlatEquation(r, where) for r, where in slow)
            self.columns.extend(r for r, _ in slow)

    def _lower(self, key, members) -> None:
        get = self.pos.get
        idx = [[get(id(sym)) for sym in column]       # leaf k of every member
               for column in zip(*[m[0] for m in members], strict=True)]
        for column in idx:
            if None in column:
                leaves, _, where, eq = members[column.index(None)]
                sym = next(x for x in leaves if id(x) not in self.pos)
                raise self._alien(sym, eq, where)
        leaf_vecs = [self.all_sx[col] for col in idx]
        const_vecs = []
        for k in range(len(members[0][1])):
            col = [m[1][k] for m in members]
            const_vecs.append(col[0] if all(c == col[0] for c in col) else ca.DM(col))
        shape_l, shape_r = key
        n_l, c_l = _count(shape_l, "L"), _count(shape_l, "C")
        lhs = lower_group(shape_l, leaf_vecs[:n_l], const_vecs[:c_l])
        rhs = lower_group(shape_r, leaf_vecs[n_l:], const_vecs[c_l:])
        res = ca.SX(lhs - rhs)
        signs = alias_signs(shape_l, shape_r)
        if signs:
            add, alias_of = self.equations.append, self._alias_of
            for k, (leaves, consts, where, _) in enumerate(members):
                alias = None if any(consts) else \
                    alias_of(signs[0], leaves[0], signs[1], leaves[1])
                add(FlatEquation(None, where, alias, at=(res, k)))
        else:
            self.equations.extend(FlatEquation(None, m[2], at=(res, k))
                                  for k, m in enumerate(members))
        self.columns.append(res)

    def _lower_block(self, eq: ArrayEquation, where: str) -> None:
        """One array equation as one residual column (:mod:`.flatten_arrays`)."""
        res, size = flatten_arrays.residual(eq, where, self.pos, self.all_sx, self._alien,
                                            self.array_rows)
        pairs = flatten_arrays.alias_pairs(eq)
        wheres = self.row_origins.get(id(eq)) or [where] * size
        if pairs is None:
            self.equations.extend(FlatEquation(None, wheres[k], at=(res, k))
                                  for k in range(size))
        else:
            sa, sb, a, b = pairs
            self.equations.extend(
                FlatEquation(None, wheres[k], self._alias_of(sa, la.sym, sb, lb.sym),
                             at=(res, k)) for k, (la, lb) in enumerate(zip(a, b, strict=True)))
        self.columns.append(res)

    def _alien(self, sym: Any, eq: Any, where: str) -> EquationError:
        owner = getattr(sym, "owner", None)
        return EquationError(
            f"{where}: equation {eq!r} uses {getattr(sym, 'name', sym)}"
            + (f" of {type(owner).__name__}" if owner is not None else "")
            + ", which is not part of the model (add its component to the model)")

    def _alias_of(self, sa: float, a: Any, sb: float, b: Any) -> tuple[int, int, float] | None:
        """``sa*a + sb*b = 0`` as the alias link ``a = -sb/sa * b``, if both are variables."""
        ia, ib = self.var_of.get(id(a)), self.var_of.get(id(b))
        if ia is None or ib is None or ia == ib or a.der_of is not None or b.der_of is not None:
            return None
        return (ia, ib, -sb / sa)

    def _check_slow(self, slow) -> None:
        known = {s.element_hash() for s in ca.vertsplit(self.all_sx)}
        for s in ca.symvar(ca.vertcat(*[r for r, _ in slow])):
            if s.element_hash() not in known:
                sym = lookup(s)
                where = next(w for r, w in slow if ca.depends_on(r, s))
                owner = f" of {type(sym.owner).__name__}" if sym else ""
                raise EquationError(
                    f"{where}: equation uses {s}{owner}, which is not part of the model "
                    "(add its component to the model)")


def _side_shape(side: Any, leaves: list, consts: list) -> Any:
    """:func:`shape_of` of one side of an equation (an Expr or a number); TypeError for
    anything else (CasADi sides take the slow path)."""
    kind = type(side)
    if kind is Leaf:
        leaves.append(side.sym)
        return "L"
    if kind is Op:
        return (side.op, *[shape_of(a, leaves, consts) for a in side.args])
    if kind is float or isinstance(side, Number):
        consts.append(float(side))
        return "C"
    if isinstance(side, Expr):
        return shape_of(side, leaves, consts)
    raise TypeError(side)


def _count(shape: Any, kind: str) -> int:
    """Leaves (``kind="L"``) or constants (``"C"``) of an equation shape."""
    if isinstance(shape, str):
        return int(shape == kind)
    return sum(_count(a, kind) for a in shape[1:])


def _leaf_symbols(e: Any) -> list:
    leaves: list = []
    shape_of(e, leaves, [])
    return leaves


def _hidden_name(sym: Symbol, k: int) -> str:
    if isinstance(sym, flatten_hybrid.RelationSlot):
        return f"$relation{k}"
    if sym.name.endswith("()"):
        return sym.name
    return f"${sym.name}{k}"

