"""Declarations of parameters and variables, and their per-instance symbols.

A declaration (``Parameter``, ``Variable``, ``Potential``, ``Flow``, ``Input``, ``Output``) is
written once in a component class body. Each component instance turns every declaration into a
:class:`Symbol`: the declaration's metadata plus an expression leaf. Inside ``equations()``,
``self.R`` *is* that leaf, so physics reads as plain algebra.
"""

from __future__ import annotations

import functools
import weakref
from collections.abc import Iterable
from dataclasses import dataclass, replace
from enum import IntEnum
from typing import Any

import casadi as ca

from ..errors import DeclarationError
from .expr import Leaf


class StateSelect(IntEnum):
    """State-selection priority, as Modelica's ``stateSelect``."""

    NEVER = -2
    AVOID = -1
    DEFAULT = 0
    PREFER = 1
    ALWAYS = 2


KIND_PARAMETER = "parameter"
KIND_VARIABLE = "variable"
KIND_POTENTIAL = "potential"
KIND_FLOW = "flow"
KIND_INPUT = "input"
KIND_OUTPUT = "output"
KIND_DISCRETE = "discrete"


@dataclass(frozen=True, kw_only=True)
class Declaration:
    """Metadata shared by parameters and variables.

    unit: unit string (SI, Modelica spelling: "V", "A", "rad/s", "N.m", "kg.m2").
    description: one line shown in reports, CSV headers of FMUs, plots.
    """

    unit: str = ""
    description: str = ""
    #: array shape: () for a scalar, an int or tuple of ints for an array (elements named
    #: ``x[1] .. x[n]``), or the name of an integer attribute of the instance (``"n"``) set
    #: before ``super().__init__`` (see :mod:`bgmodelica.core.arrays`)
    shape: Any = ()
    kind = KIND_VARIABLE

    def with_start(self, value: Any) -> Declaration:
        raise NotImplementedError

    def evolve(self, **fields: Any) -> Declaration:
        """A copy with ``fields`` (existing field names, plain values) changed: what
        ``dataclasses.replace`` does, without re-running ``__init__`` (a large array
        declares one copy per element)."""
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        new.__dict__.update(fields)
        return new


@dataclass(frozen=True)
class Parameter(Declaration):
    """A constant of the model, tunable between simulations without recompiling.

    value: default value, a number or an expression of other parameters.
    fixed: False for a parameter the initial equations determine (Modelica ``fixed=false``):
    an unknown of the initialization, ``value`` its guess, constant afterwards.
    """

    value: Any = 0.0
    min: float | None = None
    max: float | None = None
    fixed: bool = True
    kind = KIND_PARAMETER

    def with_start(self, value: Any) -> Parameter:
        new = object.__new__(type(self))     # self.evolve(value=value), inlined: hot path
        fields = new.__dict__
        fields.update(self.__dict__)
        fields["value"] = value
        return new


@dataclass(frozen=True)
class Variable(Declaration):
    """A time-varying unknown.

    start: initial value (a hard condition if ``fixed``, otherwise a guess).
    fixed: whether ``start`` is an initial condition.
    nominal: typical magnitude, used for scaling and error control.
    state_select: priority for being chosen as a state (see :class:`StateSelect`).
    """

    start: float = 0.0
    fixed: bool = False
    nominal: float = 1.0
    min: float | None = None
    max: float | None = None
    state_select: StateSelect = StateSelect.DEFAULT
    kind = KIND_VARIABLE

    def __post_init__(self) -> None:
        if isinstance(self.start, str):
            object.__setattr__(self, "start", _start_number(self.start, self.unit))

    def with_start(self, value: Any) -> Variable:
        if isinstance(value, dict):
            try:
                return replace(self, **value)
            except TypeError as err:
                raise DeclarationError(f"bad modifier {value!r}: {err}") from None
        if isinstance(value, str):
            value = _start_number(value, self.unit)
        new = object.__new__(type(self))     # self.evolve(start=value, fixed=True), inlined
        fields = new.__dict__
        fields.update(self.__dict__)
        fields["start"] = value
        fields["fixed"] = True
        return new


def _start_number(text: str, unit: str) -> float | str:
    """A start value given as text: a number, or a quantity (``"0.5 V"``) converted to the
    declared ``unit``; the text itself when it is neither (refused, with the variable's name,
    by :func:`start_text_error` when the model is flattened)."""
    from .units import quantity_value

    try:
        value = quantity_value("the start value", text, unit)
    except ValueError:
        return text
    return text if isinstance(value, str) else float(value)


def start_text_error(name: str, decl: Variable) -> DeclarationError:
    """The error for a start value ``decl.start`` given as text that is not a number."""
    from .units import quantity_value

    try:
        quantity_value(name, decl.start, decl.unit)
    except ValueError as err:
        return DeclarationError(f"start value of {name} = {decl.start!r}: {err}")
    return DeclarationError(f"start value of {name} = {decl.start!r} is not a number (nor a "
                            "number with a unit such as '0.5 V')")


@dataclass(frozen=True)
class Potential(Variable):
    """Connector variable made equal across a connection (voltage, angle, effort)."""

    kind = KIND_POTENTIAL


@dataclass(frozen=True)
class Flow(Variable):
    """Connector variable summed to zero across a connection (current, torque, flow).

    Positive when it flows *into* the component that owns the connector.
    """

    kind = KIND_FLOW


@dataclass(frozen=True)
class Input(Variable):
    """Causal signal input; set by a connected output, or an input of the whole model."""

    kind = KIND_INPUT


@dataclass(frozen=True)
class Output(Variable):
    """Causal signal output; defined by an equation of its component."""

    kind = KIND_OUTPUT


@dataclass(frozen=True)
class BooleanInput(Input):
    """A Boolean signal input (0/1), e.g. Modelica's ``BooleanInput``."""

    type_name = "Boolean"


@dataclass(frozen=True)
class BooleanOutput(Output):
    """A Boolean signal output (0/1)."""

    type_name = "Boolean"


@dataclass(frozen=True)
class IntegerInput(Input):
    """An Integer signal input."""

    type_name = "Integer"


@dataclass(frozen=True)
class IntegerOutput(Output):
    """An Integer signal output."""

    type_name = "Integer"


@dataclass(frozen=True)
class Discrete(Variable):
    """A discrete-time Real: constant between events, changed only at event instants.

    Assigned inside ``when(...)`` (a discrete state, whose ``start`` is its value before the
    first event) or defined by an ordinary equation of relations and ``pre()`` values
    (evaluated at every event iteration). ``start`` is also the initial ``pre`` value.
    """

    kind = KIND_DISCRETE
    type_name = "Real"

    def with_start(self, value: Any) -> Discrete:
        if isinstance(value, dict):
            return super().with_start(value)   # type: ignore[return-value]
        return replace(self, start=value, fixed=True)


@dataclass(frozen=True)
class Integer(Discrete):
    """A discrete Integer (e.g. a mode or a counter); see :class:`Discrete`."""

    start: float = 0
    type_name = "Integer"


@dataclass(frozen=True)
class Boolean(Discrete):
    """A discrete Boolean (stored as 0/1); see :class:`Discrete`."""

    start: float = False
    type_name = "Boolean"


def element_declarations(scalar: Declaration, n: int, per_field: dict[str, list],
                         mods: list | None, numeric: bool) -> list[Declaration]:
    """The ``n`` element declarations of an array: ``scalar`` with element ``k`` of each
    ``per_field`` list, then ``with_start(mods[k])`` (``numeric``: the modifier is a number
    or a numeric array). Plain start/value modifiers copy ``scalar`` once per element, in
    place; dicts of fields and declaration types with their own rule go through
    ``with_start``."""
    varying = list(per_field.items())
    const: dict[str, Any] = {}
    rule = type(scalar).with_start
    if mods is not None:
        if (not numeric and any(isinstance(m, dict) for m in mods)) \
                or rule not in (Parameter.with_start, Variable.with_start):
            return [scalar.evolve(**{f: v[k] for f, v in varying}).with_start(mods[k])
                    for k in range(n)]
        if rule is Parameter.with_start:
            varying.append(("value", mods))
        else:
            varying.append(("start", mods))
            const["fixed"] = True
    if not varying:
        return [scalar] * n
    cls, base, new = type(scalar), scalar.__dict__, object.__new__
    out = []
    for k in range(n):
        elem = new(cls)
        d = elem.__dict__
        d.update(base)
        for f, values in varying:
            d[f] = values[k]
        d.update(const)
        out.append(elem)
    return out

class Symbol:
    """One declared scalar of one component instance.

    Attributes: ``name`` (local), ``decl`` (its :class:`Declaration`), ``owner`` (the component
    or connector instance), ``leaf`` (the expression node used in equations), ``sx`` (its CasADi
    SX scalar, created on first use or bound by flattening), and, once ``der`` has been taken,
    ``der`` (the Symbol of its time derivative).
    """

    __slots__ = ("name", "decl", "_sx", "_at", "owner", "der", "der_of", "pre", "pre_of",
                 "leaf", "__weakref__")

    def __init__(self, name: str, decl: Declaration, owner: Any, der_of: Symbol | None = None,
                 pre_of: Symbol | None = None):
        self.name = name
        self.decl = decl
        self._sx: ca.SX | None = None
        self._at: tuple[ca.SX, int] | None = None    # (vector, row) bound by flattening
        self.owner = owner
        self.der: Symbol | None = None
        self.der_of = der_of
        self.pre: Symbol | None = None
        self.pre_of = pre_of
        self.leaf = Leaf(self)

    @property
    def sx(self) -> ca.SX:
        """The SX scalar of this symbol: an element of the vector flattening bound it to, or
        a fresh symbol (created on first use)."""
        sx = self._sx
        if sx is None:
            if self._at is not None:
                column, row = self._at
                sx = self._sx = column[row]
                self._at = None
            else:
                sx = self._sx = ca.SX.sym(self.name)
                _REGISTRY[sx.element_hash()] = self
        return sx

    def derivative(self) -> Symbol:
        """The symbol of this variable's time derivative (created once)."""
        if self.decl.kind == KIND_PARAMETER:
            raise DeclarationError(f"der() of parameter {self.name!r}: parameters are constant")
        if self.der is None:
            self.der = Symbol(f"der({self.name})", _derivative_declaration(self.decl.unit),
                              self.owner, der_of=self)
        return self.der

    def previous(self) -> Symbol:
        """The symbol of ``pre(self)``: the left limit at an event instant (created once)."""
        if self.decl.kind == KIND_PARAMETER:
            raise DeclarationError(f"pre() of parameter {self.name!r}: parameters are constant")
        if self.pre is None:
            start = getattr(self.decl, "start", 0.0)
            self.pre = Symbol(f"pre({self.name})", Discrete(unit=self.decl.unit, start=start),
                              self.owner, pre_of=self)
        return self.pre

    @property
    def is_discrete(self) -> bool:
        return self.decl is not None and self.decl.kind == KIND_DISCRETE

    def __repr__(self) -> str:
        return f"Symbol({self.name!r}, {type(self.decl).__name__})"


def new_symbols(owner: Any, decls: Iterable[tuple[str, Declaration]],
                symbols: dict[str, Symbol], attrs: dict[str, Any]) -> None:
    """A :class:`Symbol` of ``owner`` per ``(key, declaration)``, in ``symbols[key]``, its
    leaf in ``attrs[key]``: ``Symbol(key, decl, owner)`` made in one loop (an element's
    symbols are made by the hundred thousand in a large model)."""
    new = object.__new__
    for key, decl in decls:
        sym = new(Symbol)                     # as Symbol.__init__, without its frame
        sym.name = key
        sym.decl = decl
        sym._sx = sym._at = sym.der = sym.der_of = sym.pre = sym.pre_of = None
        sym.owner = owner
        leaf = new(Leaf)
        leaf.sym = sym
        sym.leaf = leaf
        symbols[key] = sym
        attrs[key] = leaf


class _Time:
    """The model time as a leaf symbol."""

    name = "time"
    decl = None

    def __init__(self) -> None:
        self.sx = ca.SX.sym("time")
        self.leaf = Leaf(self)


def derivative_unit(unit: str) -> str:
    """Unit of the time derivative of a quantity in ``unit``."""
    if not unit or unit == "1":
        return "1/s"
    return f"{unit}/s"


@functools.lru_cache(maxsize=256)
def _derivative_declaration(unit: str) -> Variable:
    """The declaration of a derivative of a quantity in ``unit`` (immutable, so shared)."""
    return Variable(unit=derivative_unit(unit))


#: SX node hash -> Symbol, so ``der(x)`` can find the declaration behind an SX scalar.
_REGISTRY: weakref.WeakValueDictionary[int, Symbol] = weakref.WeakValueDictionary()

TIME = _Time()
#: The model time [s], shared by all models (an expression leaf; ``TIME.sx`` is its SX).
time = TIME.leaf


def lookup(sx: ca.SX) -> Symbol | None:
    """The Symbol behind an SX scalar symbol, or None (time or a foreign symbol)."""
    return _REGISTRY.get(sx.element_hash())
