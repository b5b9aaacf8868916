"""The flat model: every scalar of a component tree under its dotted name, and its equations."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import casadi as ca

from .variables import Declaration, StateSelect


class _Row:
    """An SX scalar attribute kept as row ``at = (column, row)`` of a column until first
    read, then stored in ``slot``; the column is let go (and not pickled with it)."""

    def __init__(self, slot: str) -> None:
        self.slot = slot

    def __get__(self, obj: Any, owner: type | None = None) -> Any:
        if obj is None:
            return self
        value = getattr(obj, self.slot)
        if value is None and obj.at is not None:
            column, row = obj.at
            value = column[row]
            setattr(obj, self.slot, value)
            obj.at = None
        return value

    def __set__(self, obj: Any, value: ca.SX) -> None:
        setattr(obj, self.slot, value)
        obj.at = None


@dataclass(slots=True)
class FlatVariable:
    """One scalar of the flat model.

    name: dotted name (``motor.R.i``; derivatives are ``der(motor.L.i)``).
    decl: declaration metadata (unit, start, fixed, nominal, state_select...).
    component: dotted path of the component that declared it ("" for the top level).
    der_of / der: indices (in :attr:`FlatModel.variables`) linking a variable and its time
    derivative; -1 when absent.
    sx: its SX scalar. Flattening binds the model's symbols as rows of one SX vector (the
    ``at`` pair ``(vector, row)``) and the scalar is taken out on first use: a large model
    then holds one vector instead of a Python object per scalar until a pass needs them.
    """

    name: str
    _sx: ca.SX | None
    decl: Declaration
    component: str
    der_of: int = -1
    der: int = -1
    at: tuple[ca.SX, int] | None = field(default=None, repr=False, compare=False)
    sx = _Row("_sx")

    def relinked(self, der_of: int, der: int) -> FlatVariable:
        """A copy with other derivative links (the symbol stays as it is, bound or not)."""
        return FlatVariable(self.name, self._sx, self.decl, self.component, der_of, der,
                            self.at)

    @property
    def origin(self) -> str:
        return f"{self.name} (declared in {self.component or 'the top-level model'})"

    @property
    def state_select(self) -> StateSelect:
        return getattr(self.decl, "state_select", StateSelect.DEFAULT)


@dataclass(slots=True)
class FlatEquation:
    """A residual equation ``residual == 0`` and where it came from.

    origin: the component path and class that wrote it, or the connection set.
    alias: for equations of the form ``a = s*b`` the variable indices and sign ``(a, b, s)``.
    terms: number of variables of a long sum (a connection set's flow balance), 0 for an
    ordinary equation: passes keep long sums out of whole-model sparsity sweeps, whose cost
    grows with the number of rows times the longest expression.
    residual: its SX scalar; like :attr:`FlatVariable.sx`, a row ``at = (column, row)`` of
    the column it was lowered in until first used.
    """

    _residual: ca.SX | None
    origin: str
    alias: tuple[int, int, float] | None = None
    terms: int = 0
    at: tuple[ca.SX, int] | None = field(default=None, repr=False, compare=False)
    residual = _Row("_residual")

    def describe(self, names: dict[int, str] | None = None, width: int = 100) -> str:
        """``0 = residual   [origin]`` with dotted names when ``names`` (hash -> name) given."""
        res = self.residual
        if names:
            syms = [s for s in ca.symvar(res) if s.element_hash() in names]
            res = ca.substitute(res, ca.vertcat(*syms),
                                ca.vertcat(*[ca.SX.sym(names[s.element_hash()]) for s in syms]))
        text = str(res)
        if len(text) > width:
            text = text[: width - 3] + "..."
        return f"0 = {text}   [{self.origin}]"


@dataclass
class EquationSources:
    """The equations as the user wrote them (expression trees), for passes that read them
    (unit checking, :mod:`bgmodelica.passes.units`).

    groups: equation shape -> members ``(leaf symbols, constants, origin, Equation)``, as
    flattening grouped them. draft: the hybrid part (relations, when-clauses, clocks), a
    :class:`~bgmodelica.core.flatten_hybrid.HybridDraft` or None. bindings: parameters bound to
    expressions ``(dotted name, declaration, origin)``. links: connected signals ``(a, b,
    origin)``. initial: initial equations ``(Equation, origin)``. arrays: array equations
    lowered as blocks ``(ArrayEquation, origin)`` or ``(ArrayEquation, origin, origins)``
    with the origin of each element (a group of components written once).
    """

    groups: dict[Any, list] = field(default_factory=dict)
    draft: Any = None
    bindings: list[tuple[str, Any, str]] = field(default_factory=list)
    links: list[tuple[Any, Any, str]] = field(default_factory=list)
    initial: list[tuple[Any, str]] = field(default_factory=list)
    arrays: list[tuple[Any, ...]] = field(default_factory=list)


def _same_list(memo: tuple | None, items: list) -> bool:
    """Whether a stacked-column memo ``(list, length, column)`` was built from ``items`` as
    it is now (the memo holds the list, so a new list never passes for a freed one)."""
    return memo is not None and memo[0] is items and memo[1] == len(items)


#: per-model memos kept in ``FlatModel.__dict__`` (not pickled)
_MEMOS = frozenset({"_residual_column", "_variable_column", "_parameter_column",
                    "_incidence_memo"})


@dataclass
class FlatModel:
    """Variables, parameters, inputs and equations of a flattened model.

    ``variables`` are the unknowns, derivative variables included (linked by ``der``/
    ``der_of``); ``aliases`` maps eliminated names to ``(kept name, sign)``.
    """

    name: str
    variables: list[FlatVariable]
    parameters: list[FlatVariable]
    inputs: list[FlatVariable]
    equations: list[FlatEquation]
    aliases: dict[str, tuple[str, float]] = field(default_factory=dict)
    discretes: list[FlatVariable] = field(default_factory=list)
    hybrid: HybridPart | None = None
    #: the equations as written (set by flattening, dropped by later passes)
    sources: EquationSources | None = field(default=None, repr=False, compare=False)
    #: Modelica ``initial equation``s: residuals that hold at the start time only (their
    #: origin reads ``initial equation TEXT [component]``); carried to
    #: :attr:`bgmodelica.backends.casadi_dae.CasadiDAE.initial` by the compiler
    initial_equations: list[FlatEquation] = field(default_factory=list)
    #: model assertions (:class:`bgmodelica.core.flatten_hybrid.FlatAssert`), checked on the
    #: results (:mod:`bgmodelica.asserts`)
    asserts: list = field(default_factory=list, repr=False, compare=False)

    def __repr__(self) -> str:
        """One line with the counts (the variables are in :attr:`variables`)."""
        return (f"FlatModel({self.name}: {len(self.variables)} variables, "
                f"{len(self.equations)} equations, {len(self.parameters)} parameters, "
                f"{len(self.inputs)} inputs, {len(self.aliases)} aliases)")

    def stacked_residuals(self) -> ca.SX:
        """Every equation's residual in one SX column, built once while :attr:`equations`
        is the same list (stacking costs a few microseconds per scalar; the passes reuse it)."""
        return self._stacked("_residual_column", self.equations,
                             lambda: [e.residual for e in self.equations])

    def stacked_variables(self) -> ca.SX:
        """Every variable's symbol in one SX column (memoized like
        :meth:`stacked_residuals`); ``take(model.stacked_variables(), idx)`` selects some."""
        return self._stacked("_variable_column", self.variables,
                             lambda: [v.sx for v in self.variables])

    def stacked_parameters(self) -> ca.SX:
        """Every parameter's symbol in one SX column (memoized like
        :meth:`stacked_residuals`)."""
        return self._stacked("_parameter_column", self.parameters,
                             lambda: [p.sx for p in self.parameters])

    def remember_stacked(self, residuals: ca.SX | None = None,
                         variables: ca.SX | None = None, parameters: ca.SX | None = None,
                         like: FlatModel | None = None) -> None:
        """Record columns a pass already holds (same order as the lists) for the
        ``stacked_*`` methods; ``like``: a model whose memoized columns of the same lists
        (the same list objects) carry over."""
        for key, items, col in (("_residual_column", self.equations, residuals),
                                ("_variable_column", self.variables, variables),
                                ("_parameter_column", self.parameters, parameters)):
            if col is not None and col.numel() == len(items):
                self.__dict__[key] = (items, len(items), col)
            elif like is not None and _same_list(like.__dict__.get(key), items):
                self.__dict__[key] = like.__dict__[key]

    def __getstate__(self) -> dict[str, Any]:
        """Pickled without the memoized columns and incidence (rebuilt on demand)."""
        return {k: v for k, v in self.__dict__.items() if k not in _MEMOS}

    def _stacked(self, key: str, items: list, scalars) -> ca.SX:
        memo = self.__dict__.get(key)
        if not _same_list(memo, items):
            memo = (items, len(items), ca.vertcat(*scalars()) if items else ca.SX(0, 1))
            self.__dict__[key] = memo
        return memo[2]

    def index(self) -> dict[str, int]:
        """Name -> index in :attr:`variables`."""
        return {v.name: i for i, v in enumerate(self.variables)}

    @property
    def unknowns(self) -> list[int]:
        """Indices of the unknowns that are not derivatives of another variable."""
        return [i for i, v in enumerate(self.variables) if v.der_of < 0]

    def names(self) -> dict[int, str]:
        """SX node hash -> dotted name, for printing equations."""
        out = {v.sx.element_hash(): v.name for v in self.variables}
        out.update((p.sx.element_hash(), p.name) for p in self.parameters)
        out.update((u.sx.element_hash(), u.name) for u in self.inputs)
        out.update((d.sx.element_hash(), d.name) for d in self.discretes)
        return out

    def describe(self, k: int) -> str:
        """Equation ``k`` printed with dotted names and its origin."""
        return self.equations[k].describe(self.names())

    def parameter_values(self) -> dict[str, object]:
        return {p.name: p.decl.value for p in self.parameters}


class Picked(Sequence):
    """``getattr(items[idx[k]], attr)`` for each ``k``, read when asked for: the passes hand
    these to helpers that take lists of scalars but use them only in rare branches, so that
    a large model's symbols and residuals stay rows of their columns."""

    __slots__ = ("items", "attr", "idx")

    def __init__(self, items: Sequence[Any], attr: str, idx: Sequence[int] | None = None):
        self.items, self.attr = items, attr
        self.idx = range(len(items)) if idx is None else idx

    def __len__(self) -> int:
        return len(self.idx)

    def __getitem__(self, k: int) -> Any:
        return getattr(self.items[self.idx[k]], self.attr)


def take(column: ca.SX, idx: list[int]) -> ca.SX:
    """Elements ``idx`` of an SX column (an empty column for no indices): one C++ call
    instead of stacking scalars again."""
    return column[idx] if idx else ca.SX(0, 1)


# -- the hybrid part: relations, when-clauses, clocks and tables (slots index ``discretes``) -----


@dataclass
class FlatRelation:
    """A relation frozen between events: ``indicator > 0`` (strict) or ``>= 0`` holds.

    slot: index in :attr:`FlatModel.discretes` of its value (0/1). time_only: the indicator
    depends on time, parameters and discrete values only (a time event).
    """

    slot: int
    indicator: ca.SX
    strict: bool
    text: str
    origin: str
    time_only: bool = False


@dataclass
class FlatBranch:
    """One ``when``/``elsewhen`` branch: Boolean ``condition``, assignments
    ``(discrete slot, value)`` and reinits ``(variable name, value)``."""

    condition: ca.SX
    text: str
    assignments: list[tuple[int, ca.SX]]
    reinits: list[tuple[str, ca.SX]]
    #: functions run on numbers when the branch fires, before its assignments
    calls: list[FlatCall] = field(default_factory=list)


@dataclass
class FlatCall:
    """A :class:`~bgmodelica.core.hybrid.RuntimeCall` with its ``guard`` and ``args`` as SX
    and its outputs as discrete slots."""

    function: Any
    args: list[ca.SX]
    guard: ca.SX
    outputs: list[int]
    text: str


@dataclass
class FlatWhen:
    branches: list[FlatBranch]
    origin: str


@dataclass
class FlatSample:
    """``sample(start, interval)``: slot true at ``start + k*interval`` (expressions of
    parameters)."""

    slot: int
    start: ca.SX
    interval: ca.SX
    origin: str


@dataclass
class FlatTable:
    """A time table: the expression ``c0 + c1*time`` with coefficients in two slots."""

    c0: int
    c1: int
    times: object          # numpy arrays
    values: object
    interpolation: str
    extrapolation: str
    origin: str
    source: object = None   # (file path, column) of a table read from a file


@dataclass
class HybridPart:
    """Everything event-related in a flat model. ``pre`` lists ``(slot, variable name)``:
    the slot holds the variable's left limit; ``initial``/``terminal`` are slots or -1."""

    relations: list[FlatRelation] = field(default_factory=list)
    whens: list[FlatWhen] = field(default_factory=list)
    samples: list[FlatSample] = field(default_factory=list)
    tables: list[FlatTable] = field(default_factory=list)
    pre: list[tuple[int, str]] = field(default_factory=list)
    initial: int = -1
    terminal: int = -1

    def expressions(self) -> list[ca.SX]:
        """Every SX held, in a fixed order (see :meth:`with_expressions`)."""
        out = [r.indicator for r in self.relations]
        for w in self.whens:
            for b in w.branches:
                out.append(b.condition)
                out += [v for _, v in b.assignments] + [v for _, v in b.reinits]
                for c in b.calls:
                    out += [c.guard, *c.args]
        for s in self.samples:
            out += [s.start, s.interval]
        return out

    def with_expressions(self, exprs: list[ca.SX]) -> HybridPart:
        """A copy holding ``exprs`` (same order as :meth:`expressions`)."""
        it = iter(exprs)
        rels = [FlatRelation(r.slot, next(it), r.strict, r.text, r.origin, r.time_only)
                for r in self.relations]
        whens = []
        for w in self.whens:
            branches = []
            for b in w.branches:
                cond = next(it)
                assigns = [(s, next(it)) for s, _ in b.assignments]
                reinits = [(n, next(it)) for n, _ in b.reinits]
                calls = []
                for c in b.calls:
                    guard = next(it)
                    calls.append(FlatCall(c.function, [next(it) for _ in c.args], guard,
                                          list(c.outputs), c.text))
                branches.append(FlatBranch(cond, b.text, assigns, reinits, calls))
            whens.append(FlatWhen(branches, w.origin))
        samples = [FlatSample(s.slot, next(it), next(it), s.origin) for s in self.samples]
        return HybridPart(rels, whens, samples, list(self.tables), list(self.pre),
                          self.initial, self.terminal)
