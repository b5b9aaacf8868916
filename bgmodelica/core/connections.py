"""Connections: ``connect(a, b)`` of two connectors (potentials equal, flows summed to zero)
or of two causal signals, and the checks that they may be connected."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca

from ..errors import ConnectError
from .arrays import ArrayExpr, ElementArray, connect_arrays
from .expr import Leaf
from .variables import KIND_INPUT, KIND_OUTPUT, Symbol, lookup


@dataclass(frozen=True)
class Connection:
    """``connect(a, b)``: two connectors, or two causal signals."""

    a: Any
    b: Any


def connect(a: Any, b: Any) -> Any:
    """Join two connectors (potentials equal, flows sum to zero) or two signals; arrays of
    connectors or signals are joined elementwise (a list of :class:`Connection`)."""
    cls = type(a)
    if cls is type(b) and getattr(cls, "_plain_connect", False) and _same_declarations(a, b):
        return Connection(a, b)           # the common case: two connectors of one class
    if isinstance(a, (ElementArray, ArrayExpr)) or isinstance(b, (ElementArray, ArrayExpr)):
        return connect_arrays(_as_array(a), _as_array(b), connect)
    if getattr(type(a), "_group_view", False) or getattr(type(b), "_group_view", False):
        return Connection(a, b)           # views of many connectors: checked by their reader
    check_connectable(a, b)
    return Connection(a, b)


def _symbol_of(x: Any) -> Symbol | None:
    """The declared symbol behind a leaf expression or an SX symbol, else None."""
    if isinstance(x, Leaf) and isinstance(x.sym, Symbol):
        return x.sym
    if isinstance(x, ca.SX) and x.numel() == 1 and x.is_symbolic():
        return lookup(x)
    return None


def _describe(x: Any) -> str:
    from .component import Element

    if isinstance(x, Element):
        return f"{type(x).__name__} {x.name or '?'}"
    sym = _symbol_of(x)
    return f"{sym.decl.kind} variable {sym.name}" if sym else repr(x)


def check_connectable(a: Any, b: Any) -> None:
    """Raise :class:`ConnectError` unless ``a`` and ``b`` may be connected."""
    from .component import Connector

    if isinstance(a, Connector) and isinstance(b, Connector):
        if type(a) is type(b) and _same_declarations(a, b):
            return
        sa, sb = a.signature(), b.signature()
        for name in sa.keys() & sb.keys():
            if sa[name] != sb[name] and {sa[name], sb[name]} != {KIND_INPUT, KIND_OUTPUT}:
                raise ConnectError(
                    f"cannot connect {_describe(a)} to {_describe(b)}: {name} is a {sa[name]} "
                    f"variable in one and a {sb[name]} variable in the other")
        if sa.keys() != sb.keys():
            raise ConnectError(
                f"cannot connect {_describe(a)} ({', '.join(sa)}) to {_describe(b)} "
                f"({', '.join(sb)}): incompatible connector types")
        for name in sa:
            ua, ub = a._symbols[name].decl.unit, b._symbols[name].decl.unit
            if ua and ub and ua != ub:
                raise ConnectError(
                    f"cannot connect {_describe(a)} to {_describe(b)}: {name} has unit "
                    f"{ua!r} in one and {ub!r} in the other")
        return
    syms = []
    for x in (a, b):
        sym = _symbol_of(x)
        if sym is None:
            raise ConnectError(
                f"cannot connect {_describe(a)} to {_describe(b)}: connect() joins two "
                "connectors or two signal variables (Input/Output)")
        syms.append(sym)
    kinds = {s.decl.kind for s in syms}
    if not kinds <= {KIND_INPUT, KIND_OUTPUT}:
        raise ConnectError(
            f"cannot connect {_describe(a)} to {_describe(b)}: only connectors or causal "
            "signals (Input/Output) can be connected; connect the connectors that hold them")
    if kinds == {KIND_OUTPUT}:
        raise ConnectError(f"cannot connect two outputs: {_qualified(syms[0])} and "
                           f"{_qualified(syms[1])} (an output is connected to inputs)")


def _same_declarations(a: Any, b: Any) -> bool:
    """Whether two connectors declare the same variables with the same kinds and units
    (the common case, two instances of one class, checked without building signatures)."""
    sa, sb = a._symbols, b._symbols
    if len(sa) != len(sb):
        return False
    for name, sym in sa.items():
        other = sb.get(name)
        if other is None:
            return False
        da, db = sym.decl, other.decl
        if da is not db and (da.kind != db.kind or da.unit != db.unit):
            return False
    return True


def _as_array(x: Any) -> Any:
    return ElementArray(list(x)) if isinstance(x, ArrayExpr) else x


def _qualified(sym: Symbol) -> str:
    owner = getattr(sym.owner, "name", None)
    return f"{owner}.{sym.name}" if owner else sym.name
