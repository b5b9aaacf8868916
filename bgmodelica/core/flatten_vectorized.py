"""The equations of many components of one class written once for all of them.

``array_of(Resistor, n)``, or a ladder built with a resistor per section, gives ``n``
components of one class. Their ``equations()`` are the same code, so instead of running it
``n`` times (``n`` scalar equations of each kind, each walked and grouped by flattening), it
runs once on a view of the group in which every variable and parameter is the
:class:`~.arrays.ArrayExpr` of the elements' scalars and every connector a view of the
elements' connectors. ``v == R*i`` then comes out as one array equation, lowered as a block
like a hand-written one (:mod:`.flatten_arrays`): the same scalar equations, with the same
origins (each element's path), in fewer, larger CasADi operations.

Only what the view can answer exactly is taken: the elements must be leaf components (no
subcomponents, no added equations) of one class with the same declarations, and every
attribute the equations read must be a variable, a parameter, a connector, a method or
property of the class, or a plain value equal in every element. Anything else (a value that
differs between elements, an ``if`` on a variable, an event, a ``connect``) makes
:func:`array_equations` answer None and the elements are flattened one by one, as before.
"""

from __future__ import annotations

import inspect
from operator import attrgetter, itemgetter, methodcaller
from types import FunctionType, MethodType
from typing import Any

import numpy as np

from .array_marks import mark_leaves
from .arrays import ArrayEquation, ArrayExpr
from .component import Component, Connection, Connector, _own_methods
from .connections import check_connectable
from .expr import Leaf

#: plain attribute values a view hands out when every element has the same one
_PLAIN = (bool, int, float, str, type(None))


class _Varies(Exception):
    """The elements differ in something the equations read: flatten them one by one."""


_SYM, _DECL, _UNIT = attrgetter("sym"), attrgetter("decl"), attrgetter("unit")


class _View:
    """Elements of one class seen as one: attributes are arrays of the elements' ones."""

    __slots__ = ("_items", "_seen", "_deep")
    #: ``connect`` of two views is one :class:`~.component.Connection` of them
    _group_view = True

    def __init__(self, items: list[Any], deep: bool = False) -> None:
        """``deep``: subcomponents are views too (not only connectors)."""
        object.__setattr__(self, "_items", items)
        object.__setattr__(self, "_seen", {})     # name -> array or view, made once
        object.__setattr__(self, "_deep", deep)

    def __getattr__(self, name: str) -> Any:
        seen = self._seen.get(name)
        if seen is not None:
            return seen
        items = self._items
        cls = type(items[0])
        owner = inspect.getattr_static(cls, name, None)
        if name not in items[0].__dict__:
            if isinstance(owner, property) and owner.fget is not None:
                return owner.fget(self)
            if isinstance(owner, staticmethod):
                return owner.__func__
            if isinstance(owner, classmethod):
                return owner.__get__(None, cls)
            if isinstance(owner, FunctionType):
                return MethodType(owner, self)      # a method, bound to the view
            if isinstance(owner, _PLAIN):
                return owner                        # a class constant
        try:
            values = list(map(itemgetter(name), map(_DICT, items)))
        except KeyError:
            raise _Varies(name) from None
        first = values[0]
        if isinstance(first, Leaf):
            if set(map(type, values)) != {Leaf}:
                raise _Varies(name)
            arr = np.empty(len(values), dtype=object)
            arr[:] = values
            decls = list(map(_DECL, map(_SYM, values)))
            mark_leaves(arr, len(set(map(type, decls))) == 1
                        and len(set(map(_UNIT, decls))) == 1)
            found = self._seen[name] = ArrayExpr(arr)
            return found
        if isinstance(first, Connector) or (self._deep and isinstance(first, Component)):
            found = self._seen[name] = _View(values, self._deep)
            return found
        if isinstance(first, _PLAIN) and all(type(v) is type(first) and v == first
                                             for v in values):
            return first
        raise _Varies(name)

    def __setattr__(self, name: str, value: Any) -> None:
        raise _Varies(name)

    @property
    def __class__(self) -> type:           # isinstance(self, ...) as for an element
        return type(self._items[0])

    def __bool__(self) -> bool:
        raise _Varies("truth value")


#: siblings of one class written once from this many on (arrays of components from two);
#: below it the fixed cost of a group (views, block lowering) outweighs the per-element one
GROUP_FROM = 64


def component_groups(elem: Component) -> list[tuple[list[str], list[Any]]]:
    """Children of ``elem`` whose equations may be written once: its arrays of components
    (``name[1]``, ``name[2]``..., as ``array_of`` makes them, two or more) and, among the
    rest, the components of one class when there are :data:`GROUP_FROM` or more (a
    component per section of a ladder). Each group as ``(child names, children)``."""
    children = elem._children
    out = _array_groups(elem, "")
    if len(children) >= GROUP_FROM:
        taken = {id(c) for _, items in out for c in items}
        out += _class_groups((key, child) for key, child in children.items()
                             if isinstance(child, Component) and id(child) not in taken)
    return out


def tree_groups(components: dict[str, Any], parents: list[tuple[str, Component]],
                ) -> list[tuple[list[str], list[Any]]]:
    """:func:`component_groups` across a whole tree: the arrays of components of every
    parent (``parents``: the components holding components, by path, in tree order), then,
    among the other components without subcomponents (``components``: all but the top
    level, by path, in tree order), those of one class when there are :data:`GROUP_FROM` or
    more, wherever they sit (the resistor of each section of a ladder of sections). Each
    group as ``(paths, components)``; for a flat model, ``component_groups(top)``."""
    out: list[tuple[list[str], list[Any]]] = []
    for path, parent in parents:
        out += _array_groups(parent, f"{path}." if path else "")
    taken = {id(c) for _, items in out for c in items}
    out += _class_groups((path, child) for path, child in components.items()
                         if id(child) not in taken and isinstance(child, Component)
                         and not any(isinstance(c, Component)
                                     for c in child._children.values()))
    return out


def _array_groups(elem: Component, prefix: str) -> list[tuple[list[str], list[Any]]]:
    """The arrays of components of ``elem`` (two elements or more), names after
    ``prefix``."""
    arrays: dict[str, tuple[list[str], list[Any]]] = {}
    if "_arrays" in elem.__dict__:
        for key, child in elem._children.items():
            if key[-1] == "]" and isinstance(child, Component):
                base, _, index = key[:-1].partition("[")
                if index.isdigit():
                    names, items = arrays.setdefault(base, ([], []))
                    names.append(prefix + key)
                    items.append(child)
    return [group for group in arrays.values() if len(group[1]) > 1]


def _class_groups(members: Any) -> list[tuple[list[str], list[Any]]]:
    """``(name, component)`` pairs grouped by class, the groups of :data:`GROUP_FROM` or
    more in the order of their first member."""
    by_class: dict[type, tuple[list[str], list[Any]]] = {}
    for key, child in members:
        names, items = by_class.setdefault(type(child), ([], []))
        names.append(key)
        items.append(child)
    return [group for group in by_class.values() if len(group[1]) >= GROUP_FROM]


def array_equations(items: list[Any],
                    arrays: dict[tuple[str | None, str], ArrayExpr] | None = None,
                    ) -> list[ArrayEquation] | None:
    """The equations of the components ``items`` as array equations (one per equation of
    their class, over all of them), or None when they cannot be written that way.
    ``arrays``, if given, receives the arrays of the elements' scalars the equations read,
    by ``(connector name or None, declaration name)``."""
    if len(items) < 2:
        return None
    written_once = getattr(type(items[0]), "_group_equations", None)
    if written_once is not None:          # a class from Modelica text (its own template)
        return written_once(items, arrays)
    if not _uniform(items):
        return None
    view = _View(items)
    out: list[ArrayEquation] = []
    try:
        for own in _own_methods(type(items[0]), "equations"):
            result = own(view)
            if result is None:
                continue
            for eq in result:
                if not (isinstance(eq, ArrayEquation) and eq.is_block()
                        and eq.shape == (len(items),)):
                    return None
                out.append(eq)
    except Exception:  # noqa: BLE001 -- anything the view cannot answer: one by one instead
        return None
    if arrays is not None:
        for name, seen in view._seen.items():
            if isinstance(seen, ArrayExpr):
                arrays[(None, name)] = seen
            else:
                arrays.update(((name, key), found) for key, found in seen._seen.items()
                              if isinstance(found, ArrayExpr))
    return out


def group_connections(items: list[Any]) -> list[tuple[Any, Any]] | None:
    """The ``connect`` statements of components ``items`` (of one class, holding exactly
    its declarations, subcomponents and connectors), written once for all of them: pairs
    of connector views (their ``_items`` are the ends, member by member), or None when
    their equations are not only connections the view can answer."""
    first = items[0]
    if len(items) < 2 or any(map(_EQUATIONS, items)) or not _as_declared(items):
        return None
    view = _View(items, deep=True)
    out: list[tuple[Any, Any]] = []
    try:
        for own in _own_methods(type(first), "equations"):
            result = own(view)
            if result is None:
                continue
            for eq in result:
                if type(eq) is not Connection or type(eq.a) is not _View \
                        or type(eq.b) is not _View or not isinstance(eq.a, Connector) \
                        or not isinstance(eq.b, Connector):
                    return None
                check_connectable(eq.a._items[0], eq.b._items[0])
                out.append((eq.a, eq.b))
    except Exception:  # noqa: BLE001 -- anything the view cannot answer: one by one instead
        return None
    return out


def _uniform(items: list[Any]) -> bool:
    """Leaf components of one class holding exactly its declarations and connectors (nothing
    added to an instance, no arrays, no equations), connectors without subconnectors.
    Checked with C-level maps: a group may be large."""
    first = items[0]
    if not isinstance(first, Component) or any(map(_EQUATIONS, items)) \
            or not _as_declared(items):
        return False
    for key, c in first._children.items():
        if not isinstance(c, Connector) or type(c)._templates \
                or not _as_declared(list(map(itemgetter(key), map(_CHILDREN, items)))):
            return False
    return True


_SYMBOLS, _CHILDREN = attrgetter("_symbols"), attrgetter("_children")
_EQUATIONS, _DICT = attrgetter("_equations"), attrgetter("__dict__")


def _any_arrays(elements: list[Any]) -> bool:
    """Whether an element has arrays declared on it."""
    return any(map(methodcaller("__contains__", "_arrays"), map(_DICT, elements)))


def _same_keys(items: list[Any]) -> bool:
    """Whether the components (of one class) have the same declarations and connectors, and
    each connector the same declarations (and class)."""
    if _as_declared(items):
        return all(_as_declared(list(map(itemgetter(key), map(_CHILDREN, items))))
                   for key in items[0]._children)
    if len(set(map(tuple, map(_SYMBOLS, items)))) != 1 \
            or len(set(map(tuple, map(_CHILDREN, items)))) != 1:
        return False
    return all(len(set(map(tuple, map(_SYMBOLS, map(itemgetter(key), map(_CHILDREN, items))))))
               == 1 and len(set(map(type, map(itemgetter(key), map(_CHILDREN, items))))) == 1
               for key in items[0]._children)


def _as_declared(elements: list[Any]) -> bool:
    """Whether the elements are of one class and hold exactly its declarations and
    subcomponents, in its order: nothing was added to an instance (which only adds, so
    equal counts say it), no arrays (whose elements are counted one by one)."""
    cls = type(elements[0])
    return set(map(type, elements)) == {cls} and not _any_arrays(elements) \
        and set(map(len, map(_SYMBOLS, elements))) == {len(cls._declarations)} \
        and set(map(len, map(_CHILDREN, elements))) == {len(cls._templates)}
