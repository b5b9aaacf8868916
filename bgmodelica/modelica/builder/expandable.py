"""Expandable connectors (specification 9.1.3): a bus whose elements are those its ``connect``
statements name, with the type of what they are connected to.

A bus is built empty, as a component of plain variables and sub-buses. An element appears
when it is used: a declared one from its declaration, an undeclared one in ``connect`` from
the other end. Buses joined by ``connect`` form a group whose members hold the same elements,
equal along the connections (an element added to one member is added to all). Declared
elements that nothing uses are never made. Once the model is built, the equations of every
instance are evaluated, so that each bus has all its elements before flattening.
"""

from __future__ import annotations

from typing import Any

from ...core.component import Component, Connector
from ...core.expr import Equation, Leaf
from ...core.variables import Boolean, Discrete, Integer, Symbol, Variable
from .. import ast as A
from ..errors import ModelicaError
from .base import fail
from .classes import ClassView, class_view, type_ref
from .declarations import _static_decl
from .env import Env, _category


class Bus(Component):
    """An instance of an expandable connector: plain variables and sub-buses."""

    def _bus_init(self, env: Env | None) -> None:
        object.__setattr__(self, "_mo_env", env)
        object.__setattr__(self, "_mo_members", {})
        object.__setattr__(self, "_mo_links", [])


def make_bus(view: ClassView | None, env: Env | None, name: str = "Bus") -> Bus:
    """An empty bus of class ``view`` (None: an undeclared sub-bus)."""
    cls = view.classes.get(("expandable",)) if view is not None else None
    if cls is None:
        cls = type(view.cdef.name if view is not None else name, (Bus,),
                   {"__module__": "bgmodelica.modelica.generated",
                    "__doc__": view.description if view is not None else None})
        if view is not None:
            view.classes[("expandable",)] = cls
    inst = cls()
    inst._bus_init(env)
    if env is not None:
        env.inst = inst
        root = env
        while root.parent is not None:
            root = root.parent
        root.buses.append(inst)
    return inst


def _present(bus: Bus, name: str) -> Any:
    sym = bus._symbols.get(name)
    return sym.leaf if sym is not None else bus._children.get(name)


def _declared(bus: Bus, name: str) -> Any:
    env = bus.__dict__["_mo_env"]
    return env.view.elements.get(name) if env is not None else None


def _plain(decl: Any) -> Any:
    """The declaration of a bus variable connected to a signal declared as ``decl``."""
    kind = getattr(decl, "type_name", "Real")
    if kind == "Boolean":
        return Boolean(description=decl.description)
    if kind == "Integer":
        return Integer(description=decl.description)
    if isinstance(decl, Discrete):
        return Discrete(unit=decl.unit, description=decl.description)
    return Variable(unit=decl.unit, description=decl.description,
                    nominal=getattr(decl, "nominal", 1.0))


def _create(bus: Bus, name: str, like: Any, lex: Any, node: Any) -> Any:
    """Element ``name`` of ``bus``: from its declaration, else shaped as ``like``."""
    info = _declared(bus, name)
    if info is not None:
        tref = type_ref(info)
        cat = _category(info, tref)
        if cat == "var" and not info.comp.dims and not tref.dims:
            return _add_symbol(bus, name, _static_decl(info, tref, (), False)[0])
        if cat == "child" and tref.kind == "class" and not info.comp.dims:
            view = class_view(tref.scope)
            if view.kind == "expandable connector":
                env = Env(view, {}, bus.__dict__["_mo_env"], _path(bus, name))
                return _add_child(bus, name, make_bus(view, env))
        raise fail(info.lex, info.comp, f"unsupported Modelica construct: element {name} of "
                   "an expandable connector (only scalar variables and expandable connectors)")
    if isinstance(like, Bus):
        return _add_child(bus, name, make_bus(None, None, type(like).__name__))
    if isinstance(like, Leaf) and isinstance(like.sym, Symbol):
        return _add_symbol(bus, name, _plain(like.sym.decl))
    what = "a connector" if isinstance(like, Connector) else "this"
    raise fail(lex, node, f"unsupported Modelica construct: connecting {what} to the "
               f"expandable connector element {name} (only signals and expandable connectors)")


def _path(bus: Bus, name: str) -> str:
    env = bus.__dict__["_mo_env"]
    return f"{env.path}.{name}" if env is not None and env.path else name


def _add_symbol(bus: Bus, name: str, decl: Any) -> Any:
    sym = Symbol(name, decl, bus)
    bus._symbols[name] = sym
    return sym.leaf


def _add_child(bus: Bus, name: str, child: Bus) -> Bus:
    object.__setattr__(child, "_name", name)
    bus._children[name] = child
    return child


def _elements(bus: Bus) -> list[str]:
    return list(bus._symbols) + list(bus._children)


def add(bus: Bus, name: str, like: Any = None, lex: Any = None, node: Any = None) -> Any:
    """Make element ``name`` in ``bus`` and in every bus of its group; returns it."""
    made = _create(bus, name, like, lex, node)
    seen = {id(bus)}
    stack = [bus]
    while stack:
        here = stack.pop()
        mine = _present(here, name)
        for other in here.__dict__["_mo_links"]:
            if id(other) in seen:
                continue
            seen.add(id(other))
            theirs = _present(other, name)
            if theirs is None:
                theirs = _create(other, name, mine, lex, node)
            _tie(mine, theirs, other, lex, node)
            stack.append(other)
    return made


def _tie(x: Any, y: Any, owner: Bus, lex: Any, node: Any) -> None:
    if isinstance(x, Bus) and isinstance(y, Bus):
        merge(x, y, lex, node)
    elif isinstance(x, Bus) or isinstance(y, Bus):
        raise fail(lex, node, f"bus element {y.name if isinstance(y, Bus) else x.name} is an "
                   "expandable connector in one bus and a variable in the other")
    else:
        owner._own_equations().append(Equation(y, x))


def _connected(a: Bus, b: Bus) -> bool:
    seen = {id(a)}
    stack = [a]
    while stack:
        for other in stack.pop().__dict__["_mo_links"]:
            if other is b:
                return True
            if id(other) not in seen:
                seen.add(id(other))
                stack.append(other)
    return False


def merge(a: Bus, b: Bus, lex: Any, node: Any) -> None:
    """``connect(a, b)`` of two buses: both groups get the union of their elements."""
    if a is b or _connected(a, b):
        return
    for name in _elements(a):
        if _present(b, name) is None:
            add(b, name, _present(a, name), lex, node)
    for name in _elements(b):
        if _present(a, name) is None:
            add(a, name, _present(b, name), lex, node)
    a.__dict__["_mo_links"].append(b)
    b.__dict__["_mo_links"].append(a)
    for name in _elements(a):
        _tie(_present(a, name), _present(b, name), b, lex, node)


def declared_member(bus: Bus, name: str) -> Any:
    """A declared element of ``bus`` made on first use; None if ``name`` is not declared."""
    if _declared(bus, name) is None:
        return None
    return add(bus, name)


class Missing:
    """``bus.name`` in a ``connect``, where the bus neither has nor declares ``name``."""

    def __init__(self, bus: Bus, name: str) -> None:
        self.bus, self.name = bus, name


def connect_end(node: Any, ctx: Any, evaluate: Any) -> Any:
    """One argument of ``connect``: its value, or :class:`Missing` for a new bus element."""
    try:
        return evaluate(node, ctx)
    except ModelicaError:
        if not (isinstance(node, A.Ref) and len(node.parts) > 1 and not node.parts[-1][1]):
            raise
        try:
            owner = evaluate(A.Ref(node.parts[:-1], node.pos, node.global_), ctx)
        except ModelicaError:
            owner = None
        if not isinstance(owner, Bus):
            raise
        return Missing(owner, node.parts[-1][0])


def resolve(a: Any, b: Any, ctx: Any, node: Any) -> tuple[Any, Any]:
    """The ends of a ``connect``, with a new bus element made after the other end."""
    if isinstance(a, Missing) and isinstance(b, Missing):
        raise fail(ctx.lex, node, f"connect of {a.name} and {b.name}: neither end is declared "
                   "or connected elsewhere")
    if isinstance(a, Missing):
        a = add(a.bus, a.name, b, ctx.lex, node)
    if isinstance(b, Missing):
        b = add(b.bus, b.name, a, ctx.lex, node)
    return a, b


def _on_bus(x: Any) -> bool:
    return isinstance(x, Bus) or (isinstance(x, Leaf) and isinstance(x.sym, Symbol)
                                  and isinstance(x.sym.owner, Bus))


def connect_bus(a: Any, b: Any, ctx: Any, node: Any, out: list) -> bool:
    """``connect(a, b)`` where an end is a bus or a bus variable; False for other ends."""
    on_a, on_b = _on_bus(a), _on_bus(b)
    if not (on_a or on_b):
        return False
    if isinstance(a, Bus) and isinstance(b, Bus):
        merge(a, b, ctx.lex, node)
        return True
    if isinstance(a, Bus) or isinstance(b, Bus):
        raise fail(ctx.lex, node, "unsupported Modelica construct: connecting an expandable "
                   "connector to a connector that is not expandable")
    if not (isinstance(a, Leaf) and isinstance(b, Leaf)):
        raise fail(ctx.lex, node, "unsupported Modelica construct: connecting a bus variable "
                   "to a connector (only signals)")
    out.append(Equation(a, b) if on_a else Equation(b, a))
    return True


def evaluate_all(root: Any, equations_of: Any) -> None:
    """Evaluate the equations of every instance below ``root`` now (each bus then has all
    its elements when flattened); kept for the first flattening."""
    stack = [root]
    while stack:
        inst = stack.pop()
        stack.extend(inst._children.values())
        env = inst.__dict__.get("_mo_env")
        if env is None or isinstance(inst, (Bus, Connector)) or env.cached is not None:
            continue
        env.cached = (equations_of(env, env.view.equations),
                      equations_of(env, env.view.initial, initial=True))
