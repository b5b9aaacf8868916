"""The hybrid part of flattening: relations become frozen slots, when-clauses and if-equations
are taken apart, and every hidden discrete symbol (``pre``, relation values, sample clocks,
table coefficients, ``initial()``) is found.

:func:`extract` runs on the raw equations before symbols are bound; :func:`lower` turns the
draft into a :class:`~bgmodelica.core.flatmodel.HybridPart` once every symbol has its SX.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import casadi as ca

from ..errors import EquationError
from .expr import RELATIONS, Equation, Expr, Leaf, Op, to_sx, to_text
from .flatmodel import (
    FlatBranch,
    FlatCall,
    FlatRelation,
    FlatSample,
    FlatTable,
    FlatWhen,
    HybridPart,
)
from .hybrid import (
    _INITIAL,
    _TERMINAL,
    Assert,
    IfEquation,
    Reinit,
    RuntimeCall,
    SampleClock,
    TimeTable,
    When,
    _Special,
)
from .variables import KIND_OUTPUT, KIND_PARAMETER, TIME, Boolean, Symbol


class RelationSlot(_Special):
    """The frozen value of one relation ``a < b`` / ``a <= b``."""

    __slots__ = ("op", "a", "b", "where")

    def __init__(self, op: str, a: Any, b: Any, where: str) -> None:
        super().__init__(f"({to_text(a)} {op} {to_text(b)})", Boolean(), None)
        self.op, self.a, self.b, self.where = op, a, b, where


@dataclass
class HybridDraft:
    """What :func:`extract` found, keyed by symbol identity."""

    whens: list[tuple[When, str]] = field(default_factory=list)
    relations: list[RelationSlot] = field(default_factory=list)
    specials: dict[int, _Special] = field(default_factory=dict)    # samples, tables, initial
    pres: dict[int, Symbol] = field(default_factory=dict)          # pre(...) symbols
    targets: dict[int, Symbol] = field(default_factory=dict)       # assigned in when
    target_where: dict[int, str] = field(default_factory=dict)
    asserts: list[tuple[Assert, str]] = field(default_factory=list)   # not events: checked

    @property
    def empty(self) -> bool:
        return not (self.whens or self.relations or self.specials or self.pres)

    def hidden(self) -> list[Symbol]:
        """Slots to add to the model's discrete vector, in a fixed order."""
        out: list[Symbol] = list(self.relations)
        for s in self.specials.values():
            out.append(s)
            if isinstance(s, TimeTable):
                out.append(s.c1)
        return out + list(self.pres.values())


def extract(pending: list[tuple[Any, Any]], where: Callable[[Any], str]
            ) -> tuple[list[tuple[Any, Any]], HybridDraft]:
    """Rewrite ``pending`` ``(statement, component)`` pairs: relations outside ``no_event``
    on continuous quantities become relation slots; if-equations become residual equations;
    when-clauses move to the draft."""
    draft = HybridDraft()
    out: list[tuple[Any, Any]] = []
    rw = _Rewriter(draft)
    for eq, ctx in pending:
        here = where(ctx)
        if isinstance(eq, When):
            for cond, stmts in eq.branches:
                rw.scan(cond, here, live=True)
                for s in stmts:
                    if isinstance(s, Reinit):
                        rw.scan(s.value, here, live=False)
                        continue
                    if isinstance(s, RuntimeCall):
                        for e in (s.guard, *s.args):
                            rw.scan(e, here, live=False)
                        for o in s.outputs:
                            draft.specials.setdefault(id(o), o)
                        continue
                    target = s.lhs.sym if isinstance(s.lhs, Leaf) else None
                    if not isinstance(target, Symbol) or not (
                            target.is_discrete or target.decl.kind == KIND_OUTPUT):
                        raise EquationError(
                            f"{here}: in when(), {s!r} must assign a discrete variable "
                            "(Discrete, Integer, Boolean or an output) on its left side; use "
                            "reinit() for continuous variables")
                    if id(target) in draft.targets and draft.target_where[id(target)] != here:
                        raise EquationError(
                            f"{here}: {target.name} is also assigned in when() of "
                            f"{draft.target_where[id(target)]}; a discrete variable is assigned "
                            "in one when-clause only")
                    draft.targets[id(target)] = target
                    draft.target_where[id(target)] = here
                    rw.scan(s.rhs, here, live=False)
            draft.whens.append((eq, here))
            continue
        if isinstance(eq, Assert):
            draft.asserts.append((eq, here))
            continue
        if isinstance(eq, IfEquation):
            for e in _if_residuals(eq, here):
                out.append((Equation(rw.rewrite(e.lhs, here), 0.0), ctx))
            continue
        if isinstance(eq, Equation) and isinstance(eq.lhs, (Expr, float, int)) \
                and isinstance(eq.rhs, (Expr, float, int)):
            out.append((Equation(rw.rewrite(eq.lhs, here), rw.rewrite(eq.rhs, here)), ctx))
            continue
        if isinstance(eq, Reinit):
            raise EquationError(f"{here}: reinit({eq.target.name}, ...) belongs inside when()")
        out.append((eq, ctx))
    for cond_when, here in draft.whens:
        cond_when.branches[:] = [(rw.rewrite(c, here), stmts)
                                 for c, stmts in cond_when.branches]
    return out, draft


def _if_residuals(eq: IfEquation, here: str) -> list[Equation]:
    sizes = {len(eqs) for _, eqs in eq.branches} | {len(eq.otherwise)}
    if len(sizes) != 1:
        counts = ", ".join(str(len(eqs)) for _, eqs in eq.branches)
        raise EquationError(
            f"{here}: if-equation branches must have the same number of equations (then/elseif: "
            f"{counts}; else: {len(eq.otherwise)})")
    out = []
    for k in range(len(eq.otherwise)):
        res = _residual(eq.otherwise[k], here)
        for cond, eqs in reversed(eq.branches):
            res = Op("if_else", (cond if isinstance(cond, Expr) else float(cond),
                                 _residual(eqs[k], here), res))
        out.append(Equation(res, 0.0))
    return out


def _residual(e: Any, here: str) -> Any:
    if not isinstance(e, Equation):
        raise EquationError(f"{here}: an if-equation branch holds equations 'a == b', got {e!r}")
    lhs = e.lhs if isinstance(e.lhs, Expr) else float(e.lhs)
    rhs = e.rhs if isinstance(e.rhs, Expr) else float(e.rhs)
    return lhs - rhs


class _Rewriter:
    def __init__(self, draft: HybridDraft) -> None:
        self.draft = draft
        # (id(node), rewritten) -> (node, result): holding the node keeps its id unique (a
        # branch residual is a temporary; a later one at the same address must not hit)
        self.memo: dict[tuple[int, bool], tuple[Any, Any]] = {}
        self.rel_memo: dict[tuple, RelationSlot] = {}

    def scan(self, e: Any, here: str, live: bool) -> None:
        """Record hidden symbols used in ``e`` (no rewriting)."""
        self._walk(e, here, live=False, rewrite=False)

    def rewrite(self, e: Any, here: str) -> Any:
        return self._walk(e, here, live=True, rewrite=True)

    def _walk(self, e: Any, here: str, live: bool, rewrite: bool) -> Any:
        """``e`` with its live relations (outside ``noEvent``, on continuous values) replaced
        by relation slots when ``rewrite``; iterative (long expressions, such as a table's
        chain of ``if_else``, are deeper than Python's recursion limit)."""
        if not isinstance(e, Expr):
            return e
        memo = self.memo
        stack = [(e, live, False)]
        while stack:
            node, lv, ready = stack.pop()
            key = (id(node), lv and rewrite)
            if key in memo:
                continue
            if isinstance(node, Leaf):
                self._note(node.sym)
                memo[key] = (node, node)
                continue
            inner = False if node.op == "noEvent" else lv
            if not ready:
                stack.append((node, lv, True))
                stack.extend((a, inner, False) for a in reversed(node.args)
                             if isinstance(a, Expr) and (id(a), inner and rewrite) not in memo)
                continue
            args = tuple(memo[(id(a), inner and rewrite)][1] if isinstance(a, Expr) else a
                         for a in node.args)
            memo[key] = (node, self._rebuilt(node, args, here, lv and rewrite))
        return memo[(id(e), live and rewrite)][1]

    def _rebuilt(self, e: Op, args: tuple, here: str, live: bool) -> Any:
        """``e`` over its walked ``args``: a relation slot for a live relation."""
        if e.op == "noEvent":
            return Op("noEvent", args)
        if e.op in RELATIONS and live and (_continuous(e.args[0]) or _continuous(e.args[1])):
            a, b = args
            rk = (e.op, id(a), id(b))
            slot = self.rel_memo.get(rk)
            if slot is None:
                slot = RelationSlot(e.op, a, b, here)
                self.rel_memo[rk] = slot
                self.draft.relations.append(slot)
            return slot.leaf
        if all(x is y for x, y in zip(args, e.args, strict=True)):
            return e
        return Op(e.op, args)

    def _note(self, sym: Any) -> None:
        if isinstance(sym, (SampleClock, TimeTable)) or sym is _INITIAL or sym is _TERMINAL:
            self.draft.specials.setdefault(id(sym), sym)
            if isinstance(sym, SampleClock):
                self.scan(sym.start, "", False)
                self.scan(sym.interval, "", False)
        elif isinstance(sym, Symbol) and sym.pre_of is not None:
            self.draft.pres.setdefault(id(sym), sym)


def _continuous(e: Any) -> bool:
    """Whether ``e`` depends on time or a continuous-time variable."""
    stack, seen = [e], set()
    while stack:
        x = stack.pop()
        if isinstance(x, Leaf):
            sym = x.sym
            if sym is TIME:
                return True
            decl = getattr(sym, "decl", None)
            if decl is not None and decl.kind != KIND_PARAMETER and not sym.is_discrete:
                return True
        elif isinstance(x, Op) and id(x) not in seen:
            seen.add(id(x))
            stack.extend(x.args)
    return False


def lower(draft: HybridDraft, slot_of: Callable[[Symbol], int],
          name_of: Callable[[Symbol], str]) -> HybridPart:
    """The :class:`HybridPart` of a draft whose symbols are bound (``slot_of`` gives a hidden
    or discrete symbol's index in the model's discrete vector, ``name_of`` a variable's
    dotted name)."""
    part = HybridPart()
    slot_sx = {slot_of(sym): sym.sx for sym in draft.targets.values()}
    for r in draft.relations:
        a, b = to_sx(r.a), to_sx(r.b)
        ind = ca.SX(b - a)
        text = f"{to_text(r.a)} {r.op} {to_text(r.b)}"
        part.relations.append(FlatRelation(slot_of(r), ind, r.op == "<", text, r.where,
                                           _time_only(r.a) and _time_only(r.b)))
    for w, here in draft.whens:
        branches = []
        for cond, stmts in w.branches:
            assigns, reinits, calls = [], [], []
            for s in stmts:
                if isinstance(s, RuntimeCall):
                    calls.append(FlatCall(s.function, [to_sx(a) for a in s.args],
                                          to_sx(s.guard), [slot_of(o) for o in s.outputs],
                                          s.text))
                elif isinstance(s, Reinit):
                    reinits.append((name_of(s.target), to_sx(s.value)))
                else:
                    assigns.append((slot_of(s.lhs.sym), to_sx(s.rhs)))
            assigns, reinits = _simultaneous(assigns, reinits, here, slot_sx)
            branches.append(FlatBranch(to_sx(cond), to_text(cond), assigns, reinits, calls))
        part.whens.append(FlatWhen(branches, here))
    part.pre = [(slot_of(p), name_of(p.pre_of)) for p in draft.pres.values()]
    for s in draft.specials.values():
        if isinstance(s, SampleClock):
            part.samples.append(FlatSample(slot_of(s), to_sx(s.start), to_sx(s.interval), ""))
        elif isinstance(s, TimeTable):
            part.tables.append(FlatTable(slot_of(s), slot_of(s.c1), s.times, s.values,
                                         s.interpolation, s.extrapolation, "", s.source))
        elif s is _INITIAL:
            part.initial = slot_of(s)
        elif s is _TERMINAL:
            part.terminal = slot_of(s)
    return part


def _simultaneous(assigns: list[tuple[int, ca.SX]], reinits: list[tuple[str, ca.SX]],
                  here: str, slot_sx: dict[int, ca.SX]) -> tuple[list, list]:
    """Make a when-body's assignments simultaneous equations, as in Modelica: a right side
    that reads a variable assigned in the same body sees its new value."""
    if not assigns:
        return assigns, reinits
    targets = [t for t, _ in assigns]
    syms = ca.vertcat(*[slot_sx[t] for t in targets])
    values = [v for _, v in assigns]
    for _ in range(len(values) + 1):
        pending = [k for k, v in enumerate(values) if ca.depends_on(v, syms)]
        if not pending:
            break
        values = list(ca.substitute(values, [syms], [ca.vertcat(*values)]))
    else:
        raise EquationError(f"{here}: the assignments of a when-clause depend on each other in a "
                            "cycle; use pre() for the previous values")
    rvals = [v for _, v in reinits]
    if rvals:
        rvals = list(ca.substitute(rvals, [syms], [ca.vertcat(*values)]))
    return (list(zip(targets, values, strict=True)),
            [(n, v) for (n, _), v in zip(reinits, rvals, strict=True)])


def _time_only(e: Any) -> bool:
    """No continuous-time variable in ``e`` (time, parameters and discrete values only)."""
    if isinstance(e, Leaf):
        return e.sym is TIME or not _continuous(e)
    if isinstance(e, Op):
        return all(_time_only(a) for a in e.args)
    return True


def lower_assert(a: Assert, here: str, full: dict[int, str]) -> FlatAssert:
    """An assertion as an SX condition of one fresh symbol per quantity it reads, with their
    names (full dotted names; ``time``)."""
    symbols: list = []
    names: list[str] = []
    made: dict[int, ca.SX] = {}

    def leaf(sym: Any) -> ca.SX:
        got = made.get(id(sym))
        if got is None:
            name = "time" if sym is TIME else full.get(id(sym), getattr(sym, "name", "?"))
            got = made[id(sym)] = ca.SX.sym(name)
            symbols.append(got)
            names.append(name)
        return got

    cond = to_sx(a.condition, leaf) if isinstance(a.condition, Expr) \
        else ca.SX(float(a.condition))
    return FlatAssert(cond, symbols, names, a.message, here, a.level)


@dataclass
class FlatAssert:
    """A flattened assertion (:mod:`bgmodelica.asserts` checks it on results)."""

    condition: ca.SX
    symbols: list
    names: list[str]
    message: str
    where: str
    level: str = "error"
