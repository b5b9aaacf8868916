"""Power ports, bond-flow orientation, value resolution and the element base class (see
:mod:`bgmodelica.bondgraph.elements` for the conventions)."""

from __future__ import annotations

import inspect
import math
from typing import Any, ClassVar

import casadi as ca

from ..core import expressions as _expressions
from ..core.component import Component, Connector
from ..core.expr import Equation as _Equation
from ..core.expr import Expr as _Expr
from ..core.variables import (
    Declaration,
    Flow,
    Potential,
    Symbol,
    lookup,
)
from ..core.variables import time as _time
from .errors import BondError, ModulusError

__all__ = ["PowerPort", "BGElement", "orientation", "bond_flow", "declare", "resolve",
           "element_path"]


class PowerPort(Connector):
    """Bond-graph power port: effort ``e`` and flow ``f`` (positive into the element)."""

    e = Potential(description="Effort")
    f = Flow(description="Flow into the element that owns the port")

    def __init__(self, name: str | None = None, **modifiers: Any) -> None:
        for attr in ("_sign", "_peer", "_inner", "_outer", "_owner"):
            object.__setattr__(self, attr, None)
        object.__setattr__(self, "_default", 1)
        super().__init__(name, **modifiers)

    @property
    def orientation(self) -> int:
        return orientation(self)

    @property
    def bonded(self) -> bool:
        return self._peer is not None or self._outer is not None


def orientation(port: PowerPort) -> int:
    """+1 if the half-arrow of the bond on ``port`` points into its element, -1 if out. For a
    port exposed by a subsystem the outer bond decides; an unbonded port has its default."""
    p = port
    for _ in range(1000):
        if p._sign is not None:
            return p._sign
        if p._outer is None:
            return p._default
        p = p._outer
    raise BondError(f"port {port.name}: exposure chain loops")  # pragma: no cover


def bond_flow(port: PowerPort) -> Any:
    """The bond's flow along its half-arrow, seen from ``port``."""
    return port.f if orientation(port) > 0 else -port.f


_MATH: dict[str, Any] = {name: getattr(_expressions, name) for name in (
    "sin", "cos", "tan", "exp", "log", "sqrt", "atan2", "tanh", "fabs", "sign")}
_MATH.update(abs=_expressions.fabs, pi=math.pi, time=_time)
_NUMBER = (int, float)


def is_expression(x: Any) -> bool:
    """A number, an equation-language expression or a CasADi SX scalar."""
    if isinstance(x, _NUMBER) and not isinstance(x, bool):
        return True
    if isinstance(x, (ca.SX, ca.MX)):
        return x.numel() == 1
    return _Expr is not None and isinstance(x, _Expr)


def is_equation(x: Any) -> bool:
    """Whether ``x`` is an equation ``lhs == rhs`` (equation object or SX ``==`` node)."""
    if _Equation is not None and isinstance(x, _Equation):
        return True
    return isinstance(x, ca.SX) and x.numel() == 1 and x.is_op(ca.OP_EQ)


def symbol_name(x: Any) -> str | None:
    """Name of the declared symbol behind a leaf / SX symbol, else None."""
    sym = getattr(x, "sym", None)
    if sym is not None and hasattr(sym, "decl"):
        return sym.name
    if isinstance(x, ca.SX) and x.numel() == 1 and x.is_symbolic():
        found = lookup(x)
        return found.name if found is not None else None
    return None


def element_path(elem: Any) -> str:
    """Dotted path of an element through the bond graphs that own it."""
    parts = []
    e = elem
    while e is not None and (e is elem or getattr(e, "_bg_owner", None) is not None):
        if e.name:
            parts.append(e.name)
        e = getattr(e, "_bg_owner", None)
    return ".".join(reversed(parts)) or type(elem).__name__


class _Namespace(dict):
    """Names visible to a string expression: the owning bond graph's parameters, variables and
    elements, then those of the enclosing bond graphs, then math functions."""

    def __init__(self, owner: Any) -> None:
        super().__init__()
        scopes = []
        o = owner
        while o is not None:
            scopes.append(o)
            o = getattr(o, "_bg_owner", None)
        for scope in reversed(scopes):          # inner scopes win
            for k in scope._symbols:
                self[k] = getattr(scope, k)
            for k, child in scope._children.items():
                self[k] = child


def resolve(expr: Any, elem: BGElement, what: str) -> Any:
    """Turn a value/modulus given as number, expression, callable or string into a scalar
    expression of the model."""
    owner = getattr(elem, "_bg_owner", None)
    where = f"{elem.kind} {element_path(elem)}"
    if isinstance(expr, _NUMBER):
        return float(expr)
    if isinstance(expr, str):
        if owner is None:
            raise ModulusError(f"{where}: the {what} {expr!r} is a string but the element is not "
                               "part of a bond graph", element_path(elem))
        ns = _Namespace(owner)
        try:
            value = eval(expr, {"__builtins__": {}, **_MATH}, ns)  # noqa: S307
        except NameError as err:
            names = sorted(k for k in ns if not k.startswith("_"))
            raise ModulusError(f"{where}: the {what} {expr!r} uses an unknown name ({err}); "
                               f"known names: {', '.join(names)}", element_path(elem)) from None
        except AttributeError as err:
            raise ModulusError(f"{where}: the {what} {expr!r} uses an unknown variable ({err})",
                               element_path(elem)) from None
        except SyntaxError as err:
            raise ModulusError(f"{where}: the {what} {expr!r} is not an expression ({err.msg})",
                               element_path(elem)) from None
        return _scalar(value, where, what, elem)
    if callable(expr) and not is_expression(expr):
        try:
            value = expr(owner if owner is not None else elem)
        except (AttributeError, NameError, KeyError) as err:
            raise ModulusError(f"{where}: the {what} function refers to an unknown variable "
                               f"({err})", element_path(elem)) from None
        return _scalar(value, where, what, elem)
    return _scalar(expr, where, what, elem)


def _scalar(value: Any, where: str, what: str, elem: Any) -> Any:
    if isinstance(value, (Component, Connector)):
        raise ModulusError(f"{where}: the {what} is the component {value.name!r}, not an "
                           "expression (use one of its variables)", element_path(elem))
    if not is_expression(value):
        raise ModulusError(f"{where}: the {what} {value!r} is not a scalar number or "
                           "expression", element_path(elem))
    return float(value) if isinstance(value, _NUMBER) else value


def _law(law: Any, args: list[Any], elem: BGElement) -> list[Any]:
    try:
        n = len(inspect.signature(law).parameters)
    except (TypeError, ValueError):
        n = len(args)
    call = list(args) + [getattr(elem, "_bg_owner", None)]
    try:
        eq = law(*call[: max(n, len(args))])
    except (AttributeError, NameError, KeyError) as err:
        raise ModulusError(f"{elem.kind} {element_path(elem)}: the constitutive law refers to an "
                           f"unknown variable ({err})", element_path(elem)) from None
    eqs = eq if isinstance(eq, (list, tuple)) else [eq]
    for x in eqs:
        if not is_equation(x):
            raise ModulusError(f"{elem.kind} {element_path(elem)}: the constitutive law must "
                               f"return an equation 'lhs == rhs', got {x!r}",
                               element_path(elem))
    return list(eqs)


def declare(elem: Any, name: str, decl: Declaration) -> Any:
    """Add a declaration to one instance (a signal input created on demand)."""
    sym = Symbol(name, decl, elem)
    elem._symbols[name] = sym
    leaf = getattr(sym, "leaf", None)
    value = leaf if leaf is not None else sym.sx
    object.__setattr__(elem, name, value)
    return value


class BGElement(Component):
    """Base of bond-graph elements. Keyword arguments of every element: ``label`` (drawing
    text after the colon and symbol in causal equations), ``pos`` (drawing position hint),
    ``priority`` (storage elements: higher gets integral causality first)."""

    kind: ClassVar[str] = ""
    _main: ClassVar[str | None] = None          # parameter whose name makes the default label
    _port_defaults: ClassVar[dict[str, int]] = {"port": 1}

    def __init__(self, name: str | None = None, *, label: str | None = None,
                 pos: tuple[float, float] | None = None, priority: int = 0,
                 **modifiers: Any) -> None:
        object.__setattr__(self, "_label", label)
        object.__setattr__(self, "_pos", pos)
        object.__setattr__(self, "_priority", priority)
        object.__setattr__(self, "_bg_owner", None)
        super().__init__(name, **modifiers)
        for pname, port in self._children.items():
            if isinstance(port, PowerPort):
                object.__setattr__(port, "_owner", self)
                object.__setattr__(port, "_default", self._port_defaults.get(pname, 1))

    # -- description for the pure graph ----------------------------------------------------
    def label(self) -> str:
        if self._label is not None:
            return self._label
        if self._main and self._main in self._symbols:
            name = symbol_name(self._symbols[self._main].decl.value)
            if name is not None:
                return name
        return self.name or self.kind

    def modulus_text(self) -> str:
        return ""

    def mode_text(self) -> str:
        """Text of the Boolean mode of a switched element (empty for the others)."""
        return ""

    def power_ports(self) -> list[PowerPort]:
        return [p for p in self._children.values() if isinstance(p, PowerPort)]

    def free_port(self) -> PowerPort | None:
        for p in self.power_ports():
            if not p.bonded:
                return p
        return None


# -- sources ---------------------------------------------------------------------------------
