"""Components and connectors: acausal building blocks declared as plain Python classes.

A component class declares parameters, variables, connectors and subcomponents in its body and
writes its physics in ``equations()``, which yields ``lhs == rhs`` expressions and
``connect(a, b)`` statements. Equations of base classes are inherited (as Modelica ``extends``):
never call ``super().equations()``.

    class Resistor(OnePort):
        R = Parameter(1.0, unit="Ohm", description="Resistance")

        def equations(self):
            yield self.v == self.R * self.i

Every instance owns its own symbols: inside ``equations()`` ``self.R`` is an expression leaf
(:mod:`bgmodelica.core.expr`), usable with Python operators and with CasADi functions.
Modifiers at construction override a parameter value (``Resistor(R=10)``) or set a variable's
start value, fixed by default (``Capacitor(v=1.0)``; ``Capacitor(v=dict(start=1, fixed=False))``
makes it a guess). A dotted modifier reaches into subcomponents (``Motor(**{"R.R": 2})``).
"""

from __future__ import annotations

import functools
import gc
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import replace
from typing import Any, ClassVar

import numpy as np

from ..errors import DeclarationError, DuplicateNameError
from ..structure.collector import gc_paused, pause, resume
from .array_marks import mark_leaves
from .arrays import (
    ArrayEquation,
    ArrayExpr,
    ComponentArray,
    ElementArray,
    element_names,
    element_values,
    normalize_shape,
)
from .children import build_child, class_blueprint, instantiate
from .connections import Connection, connect
from .expr import Expr
from .variables import (
    KIND_FLOW,
    KIND_INPUT,
    KIND_OUTPUT,
    KIND_POTENTIAL,
    Declaration,
    Symbol,
    element_declarations,
    new_symbols,
)


def _gc_paused_init(init: Callable[..., None]) -> Callable[..., None]:
    """``init`` with the cyclic garbage collector paused until the outermost constructor
    returns: building a model allocates many long-lived objects and few cycles, and the
    collector's rescans of them cost 30-50 % of the construction of a large model."""
    @functools.wraps(init)
    def paused(self: Any, *args: Any, **kwargs: Any) -> None:
        if not gc.isenabled():
            return init(self, *args, **kwargs)
        with gc_paused(new_model=True):
            return init(self, *args, **kwargs)
    return paused


class Element:
    """Common base of :class:`Component` and :class:`Connector`: declarations and children."""

    _declarations: ClassVar[dict[str, Declaration]] = {}
    _templates: ClassVar[dict[str, Element]] = {}
    #: whether every declaration of the class is a scalar (no array to size at construction)
    _all_scalar: ClassVar[bool] = True
    #: a view of many connectors (``connect`` leaves its checks to the view's reader)
    _group_view: ClassVar[bool] = False
    #: a connector class whose instances ``connect`` checks as in check_connectable's first
    #: case, before anything else (set by Connector.__init_subclass__)
    _plain_connect: ClassVar[bool] = False
    #: equations and connections added to an instance (``connect``, ``equation``): its own
    #: list, made by the first one (:meth:`_own_equations`)
    _equations: Sequence[Any] = ()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        if "__init__" in vars(cls):
            cls.__init__ = _gc_paused_init(vars(cls)["__init__"])  # type: ignore[method-assign]
        decls: dict[str, Declaration] = {}
        templates: dict[str, Element] = {}
        for base in reversed(cls.__mro__[1:]):
            decls.update(getattr(base, "_declarations", {}))
            templates.update(getattr(base, "_templates", {}))
        for name, value in list(vars(cls).items()):
            if isinstance(value, Declaration):
                decls[name] = value
            elif isinstance(value, Element):
                templates[name] = value
        cls._declarations = decls
        cls._templates = templates
        cls._all_scalar = all(d.shape == () for d in decls.values())

    def __new__(cls, *args: Any, **kwargs: Any) -> Element:
        self = super().__new__(cls)
        self.__dict__["_init_call"] = (args, kwargs)     # (kwargs: this call's own dict)
        return self

    def __init__(self, name: str | None = None, **modifiers: Any) -> None:
        enabled = pause(new_model=True)        # as _gc_paused_init, inlined: the outermost
        try:                                   # constructor pauses the collector
            cls = type(self)
            local: dict[str, Any] = {}
            nested: dict[str, Any] = {}
            for k, v in modifiers.items():
                (nested if "." in k else local)[k] = v
            blueprint = class_blueprint(cls)
            if blueprint is None:
                self.__build(name, local)
            else:                              # a plain class: as its first instance, then
                instantiate(blueprint, self, name)     # its modifiers, in the class's order
                if local:
                    symbols, children = self._symbols, self._children
                    for key in cls._declarations:
                        if key in local:
                            sym = symbols[key]
                            sym.decl = sym.decl.with_start(local.pop(key))
                    for key in cls._templates:
                        if key in local:
                            children[key].modify(**_as_modifiers(key, local.pop(key)))
            if local:
                raise DeclarationError(
                    f"{type(self).__name__} has no parameter, variable or subcomponent "
                    f"{', '.join(map(repr, local))}; it has: "
                    f"{', '.join(self._symbols) or 'none'}")
            if nested:
                self.modify(**nested)
        finally:
            if enabled:
                resume()

    def __build(self, name: str | None, local: dict[str, Any]) -> None:
        """The constructor's symbols and subcomponents, ``local`` modifiers applied (and
        popped) as they are made."""
        cls = type(self)
        attrs = self.__dict__
        attrs["_name"] = name
        symbols: dict[str, Symbol] = {}
        attrs["_symbols"] = symbols
        children: dict[str, Element] = {}
        attrs["_children"] = children
        decls = cls._declarations
        if not cls._all_scalar:
            for key, decl in decls.items():
                if decl.shape != ():
                    self._declare_array(key, decl, local.pop(key, None))
                else:
                    if key in local:
                        decl = decl.with_start(local.pop(key))
                    self._declare_scalar(key, decl)
        elif local:
            new_symbols(self, [(key, decl.with_start(local.pop(key)) if key in local else decl)
                               for key, decl in decls.items()], symbols, attrs)
        else:
            new_symbols(self, decls.items(), symbols, attrs)
        for key, template in cls._templates.items():
            child = build_child(key, template)
            if key in local:
                child.modify(**_as_modifiers(key, local.pop(key)))
            if isinstance(child, ComponentArray) or key in symbols:
                self.add(key, child)               # (a name taken twice: _add says so)
            else:                                  # self._add, less the checks a class passed
                child.__dict__["_name"] = key
                children[key] = child
                attrs[key] = child

    def _declare_array(self, key: str, decl: Declaration, modifier: Any) -> None:
        """The scalars ``key[1] .. key[n]`` of an array declaration, and ``self.key`` as
        their :class:`~bgmodelica.core.arrays.ArrayExpr`."""
        where = f"{type(self).__name__}.{key}"
        shape = decl.shape
        if isinstance(shape, str):
            if not isinstance(getattr(self, shape, None), (int, np.integer)):
                raise DeclarationError(
                    f"{where}: shape {shape!r} names no integer attribute; set self.{shape} "
                    "before super().__init__()")
            shape = getattr(self, shape)
        shape = normalize_shape(shape, where)
        scalar = replace(decl, shape=())
        per_field = {f: element_values(getattr(decl, f), shape, where)
                     for f in ("value", "start", "nominal", "min", "max")
                     if hasattr(decl, f) and getattr(decl, f) is not None
                     and not np.isscalar(getattr(decl, f))
                     and not isinstance(getattr(decl, f), Expr)}
        mods = element_values(modifier, shape, where) if modifier is not None else None
        names = element_names(key, shape)
        leaves = []
        symbols = self._symbols
        numeric = isinstance(modifier, (int, float)) or (
            isinstance(modifier, np.ndarray) and modifier.dtype.kind in "biuf")
        decls = element_declarations(scalar, len(names), per_field, mods, numeric)
        for name, elem in zip(names, decls, strict=True):
            sym = symbols[name] = Symbol(name, elem, self)
            leaves.append(sym.leaf)
        items = np.empty(len(leaves), dtype=object)
        items[:] = leaves
        mark_leaves(items, mods is None or numeric or len({d.unit for d in decls}) == 1)
        self.__dict__.setdefault("_arrays", {})[key] = shape
        object.__setattr__(self, key, ArrayExpr(items.reshape(shape)))

    def declare(self, name: str, decl: Declaration) -> Any:
        """Add a parameter or variable (scalar or array) to this instance, e.g. in
        ``__init__`` when its shape is a constructor argument; returns ``self.name``."""
        if not isinstance(decl, Declaration):
            raise DeclarationError(f"declare({name!r}, ...) needs a Parameter or Variable, "
                                   f"got {decl!r}")
        if name in self._symbols or name in self._children or name in self.__dict__:
            raise DuplicateNameError(f"{type(self).__name__}: {name!r} is already declared")
        if decl.shape != ():
            self._declare_array(name, decl, None)
        else:
            self._declare_scalar(name, decl)
        return getattr(self, name)

    def _declare_scalar(self, key: str, decl: Declaration) -> None:
        sym = Symbol(key, decl, self)
        self._symbols[key] = sym
        object.__setattr__(self, key, sym.leaf)

    # -- structure -----------------------------------------------------------------------
    def add(self, name: str, element: Element) -> Element:
        """Add a subcomponent or connector under ``name`` and return it; a
        :class:`~bgmodelica.core.arrays.ComponentArray` adds its elements as
        ``name[1] .. name[n]``."""
        if isinstance(element, ComponentArray):
            for k, item in enumerate(element):
                self._add(f"{name}[{k + 1}]", item, check_name=False)
            self.__dict__.setdefault("_arrays", {})[name] = (len(element),)
            object.__setattr__(self, name, element)
            return element   # type: ignore[return-value]
        return self._add(name, element)

    def _add(self, name: str, element: Element, check_name: bool = True) -> Element:
        if not isinstance(element, Element):
            raise DeclarationError(f"{name!r} is not a component or connector: {element!r}")
        if name in self._children or name in self._symbols:
            raise DuplicateNameError(
                f"{type(self).__name__} {self._name or ''}: a subcomponent or variable named "
                f"{name!r} already exists")
        if check_name and not name.isidentifier():
            raise DeclarationError(f"{name!r} is not a valid component name")
        attr = _class_attribute(type(self), name)
        if attr is not None and (name not in type(self)._templates and callable(attr)
                                 or isinstance(attr, property)):
            raise DeclarationError(
                f"{name!r} cannot name a subcomponent of {type(self).__name__}: it is a method "
                "of the class; choose another name")
        object.__setattr__(element, "_name", name)
        self._children[name] = element
        if check_name:
            object.__setattr__(self, name, element)
        return element

    def __setattr__(self, name: str, value: Any) -> None:
        if isinstance(value, (Element, ComponentArray)) and not name.startswith("_"):
            self.add(name, value)
        elif name in self.__dict__.get("_symbols", {}) or name in self.__dict__.get("_arrays",
                                                                                  {}):
            self.modify(**{name: value})
        else:
            object.__setattr__(self, name, value)

    def modify(self, **modifiers: Any) -> None:
        """Change parameter values / start values, by local or dotted name."""
        for key, value in modifiers.items():
            self.__modify_one(key, value)

    def __modify_one(self, key: str, value: Any) -> None:
        """``self.modify(**{key: value})``."""
        head, _, rest = key.partition(".")
        if rest:
            child = self._children.get(head)
            if child is None:
                raise DeclarationError(f"{type(self).__name__} has no subcomponent {head!r}")
            if type(child).modify is Element.modify:
                child.__modify_one(rest, value)
            else:
                child.modify(**{rest: value})
        elif head in self._symbols:
            sym = self._symbols[head]
            sym.decl = sym.decl.with_start(value)
        elif head in self.__dict__.get("_arrays", {}):
            shape = self._arrays[head]
            names = element_names(head, shape)
            values = element_values(value, shape, f"{type(self).__name__}.{head}")
            for name, v in zip(names, values, strict=True):
                if name in self._symbols:
                    self._symbols[name].decl = self._symbols[name].decl.with_start(v)
                else:
                    self._children[name].modify(**_as_modifiers(name, v))
        elif head in self._children:
            self._children[head].modify(**_as_modifiers(head, value))
        else:
            raise DeclarationError(
                f"{type(self).__name__} has no parameter or variable {head!r}")

    def _own_equations(self) -> list[Any]:
        """This instance's list of added equations (made on first use)."""
        eqs = self.__dict__.get("_equations")
        if eqs is None:
            eqs = self.__dict__["_equations"] = []
        return eqs

    def clone(self) -> Element:
        """A fresh instance built with the same constructor arguments."""
        args, kwargs = self._init_call
        return type(self)(*args, **kwargs)

    @property
    def name(self) -> str | None:
        return self._name

    def symbols(self) -> dict[str, Symbol]:
        return dict(self._symbols)

    def children(self) -> dict[str, Element]:
        return dict(self._children)

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._name or ''})"


_TYPE_NAMES = frozenset(dir(type))


def _class_attribute(cls: type, name: str) -> Any:
    """``getattr(cls, name, None)``, answered without a failed lookup when no class of the
    MRO (nor ``type``) has ``name``: the common case of a new subcomponent's name."""
    for klass in cls.__mro__:
        if name in klass.__dict__:
            return getattr(cls, name, None)
    if type(cls) is type and name not in _TYPE_NAMES:
        return None
    return getattr(cls, name, None)


def _as_modifiers(name: str, value: Any) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise DeclarationError(f"modifier for subcomponent {name!r} must be a dict of values")
    return value


class Connector(Element):
    """A port: potential and flow variables (or causal signals) and nothing else."""

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        for name, decl in cls._declarations.items():
            if decl.kind not in (KIND_POTENTIAL, KIND_FLOW, KIND_INPUT, KIND_OUTPUT):
                raise DeclarationError(
                    f"connector {cls.__name__}.{name}: only Potential, Flow, Input and Output "
                    "variables belong in a connector")
        cls._plain_connect = not issubclass(cls, (ElementArray, ArrayExpr)) \
            and not cls._group_view

    def signature(self) -> dict[str, str]:
        return {name: sym.decl.kind for name, sym in self._symbols.items()}


class Component(Element):
    """A model: declarations, subcomponents, and equations (see module docstring)."""

    def equations(self) -> Iterable[Any]:
        """Yield this class's own equations ``lhs == rhs`` and ``connect(a, b)`` statements."""
        return ()

    def _repr_html_(self) -> str:
        """Jupyter view: parameters with units, balance, bond-graph drawing
        (:func:`bgmodelica.notebook.component_html`)."""
        from ..notebook import component_html

        return component_html(self)

    def initial_equations(self) -> Iterable[Any]:
        """Yield this class's own *initial equations* ``lhs == rhs`` (Modelica ``initial
        equation``): conditions that hold at the start time only, e.g. ``der(self.x) == 0``
        (start at rest) or ``self.y == self.y0`` (an algebraic variable's initial value).
        They join the fixed start values in the initialization (see
        :mod:`bgmodelica.backends.casadi_init`); inherited like :meth:`equations`."""
        return ()

    def initial_equation(self, *eqs: Any) -> None:
        """Imperative form: add initial equations ``lhs == rhs`` to this component."""
        self.__dict__.setdefault("_initial_equations", []).extend(eqs)

    def all_initial_equations(self) -> Iterator[Any]:
        """Initial equations of every class in the hierarchy (base classes first), then
        added ones."""
        for own in _own_methods(type(self), "initial_equations"):
            result = own(self)
            if result is not None:
                yield from result
        yield from self.__dict__.get("_initial_equations", ())

    def connect(self, a: Any, b: Any) -> None:
        """Imperative form of ``connect`` for models assembled in code."""
        made = connect(a, b)
        eqs = self.__dict__.get("_equations")
        if eqs is None:
            eqs = self.__dict__["_equations"] = []
        if isinstance(made, list):
            eqs.extend(made)
        else:
            eqs.append(made)

    def equation(self, *eqs: Any) -> None:
        """Imperative form: add equations ``lhs == rhs`` to this component."""
        self._own_equations().extend(eqs)

    def all_equations(self, blocks: bool = False) -> Iterator[Any]:
        """Equations of every class in the hierarchy (base classes first), then added ones;
        array equations and lists of connections come out as their scalar items (with
        ``blocks``, array equations that flattening lowers whole stay whole)."""
        for own in _own_methods(type(self), "equations"):
            result = own(self)
            if result is not None:
                for item in result:
                    if isinstance(item, (ArrayEquation, list)):
                        yield from _scalar_items(item, blocks)
                    else:
                        yield item
        for item in self._equations:
            if isinstance(item, (ArrayEquation, list)):
                yield from _scalar_items(item, blocks)
            else:
                yield item


_OWN_METHODS: dict[tuple[type, str], tuple[Callable[..., Any], ...]] = {}


def _own_methods(cls: type, name: str) -> tuple[Callable[..., Any], ...]:
    """The methods ``name`` defined by ``cls`` and its bases, base classes first."""
    found = _OWN_METHODS.get((cls, name))
    if found is None:
        found = _OWN_METHODS[cls, name] = tuple(
            own for klass in reversed(cls.__mro__)
            if (own := vars(klass).get(name)) is not None)
    return found


def _scalar_items(item: Any, blocks: bool = False) -> Iterator[Any]:
    """The scalar equations of an array equation (or the equation itself, as a block), the
    connections of a list of them (as ``connect`` over arrays makes); anything else as it
    is."""
    if isinstance(item, ArrayEquation):
        if blocks and item.is_block():
            item.shape                          # noqa: B018 - sides that do not match: say so
            yield item
        else:
            yield from item.equations()
    elif item and all(isinstance(c, Connection) for c in item):
        yield from item
    else:
        yield item

