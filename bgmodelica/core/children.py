"""Subcomponents and connectors a component class declares, built for each instance.

A class attribute ``p = Pin()`` is a template: every instance gets its own copy, built with
the template's constructor arguments (``template.clone()``). Templates are built by the
thousand in a large model, so the first copy of a template whose class runs no code of its
own (:func:`_plain_class`) is described (:func:`_describe`): its class, its declarations
with their modifiers applied, and so on down its subcomponents. Later copies are made from
that description (:func:`instantiate`): same symbols, same declaration objects (immutable,
so shared), no constructor machinery. Instances of such a class built directly start the
same way, from a description of the class's first instance (:func:`class_blueprint`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .expr import Leaf
from .variables import Symbol, new_symbols

if TYPE_CHECKING:
    from .component import Element

#: a template's description: a step per element of the tree, parents first:
#: (class, _init_call, _name, ((key, declaration), ...), index of the parent step or -1)
Blueprint = tuple[tuple[type, Any, Any, tuple[tuple[str, Any], ...], int], ...]

_KEY = "_blueprint"
_LAYOUT = ("_init_call", "_name", "_symbols", "_children")
_PLAIN_CLASSES: dict[type, bool] = {}
_CLASS_BLUEPRINTS: dict[type, Blueprint | None] = {}


def build_child(key: str, template: Element) -> Element:
    """``template.clone()``; an exception of user code names the subcomponent path."""
    call = template._init_call
    known = template.__dict__.get(_KEY)
    if known is not None and known[0] is type(template) and known[1] is call:
        if known[2] is not None:
            return instantiate(known[2])
    else:
        known = None
    try:
        child = template.clone()
    except Exception as err:  # noqa: BLE001 -- user code: say where, no traceback
        from ..errors import ModelError, UserCodeError
        from ..validate import nested_user_error, user_error

        if isinstance(err, UserCodeError):
            raise nested_user_error(err, key, type(template).__name__) from err.__cause__
        if isinstance(err, ModelError):
            raise
        raise nested_user_error(user_error(err, f"{type(template).__name__}()"), key,
                                type(template).__name__) from err
    if known is None:
        steps: list[Any] = []
        plain = _plain_call(call) and _describe(child, -1, steps)
        template.__dict__[_KEY] = (type(template), call, tuple(steps) if plain else None)
    return child


def class_blueprint(cls: type) -> Blueprint | None:
    """How to make ``cls()`` for a plain class (:func:`_plain_class`), worked out from the
    first one built; None for other classes (and while that first one is built)."""
    if cls in _CLASS_BLUEPRINTS:
        return _CLASS_BLUEPRINTS[cls]
    _CLASS_BLUEPRINTS[cls] = None
    if not _plain_tree(cls):
        return None
    try:
        first = cls()
    except Exception:  # noqa: BLE001 -- the general constructor says what is wrong, each time
        return None
    steps: list[Any] = []
    if _describe(first, -1, steps):
        _CLASS_BLUEPRINTS[cls] = tuple(steps)
    return _CLASS_BLUEPRINTS[cls]


def instantiate(blueprint: Blueprint, root: Element | None = None,
                root_name: str | None = None) -> Element:
    """A fresh element as :func:`_describe` saw one: what its constructor would make; with
    ``root``, that element (new, its ``_init_call`` set) is filled instead of making one,
    named ``root_name``."""
    new = object.__new__
    made: list[tuple[dict[str, Any], dict[str, Any]]] = []
    for cls, call, name, decls, parent in blueprint:
        if parent < 0 and root is not None:
            self = root
            attrs = self.__dict__
            attrs["_name"] = root_name
        else:
            self = new(cls)
            attrs = self.__dict__
            attrs["_init_call"] = call
            attrs["_name"] = name
        symbols: dict[str, Symbol] = {}
        attrs["_symbols"] = symbols
        children: dict[str, Element] = {}
        attrs["_children"] = children
        new_symbols(self, decls, symbols, attrs)
        if parent < 0:
            root = self
        else:
            up_attrs, up_children = made[parent]
            up_attrs[name] = up_children[name] = self
        made.append((attrs, children))
    return root  # type: ignore[return-value]


def _describe(elem: Element, parent: int, steps: list[Any]) -> bool:
    """Append the steps that make a freshly built ``elem`` and its subcomponents to
    ``steps``; False when it holds anything else than what the general constructor of a
    plain class makes."""
    attrs = elem.__dict__
    symbols, children = attrs.get("_symbols"), attrs.get("_children")
    if not _plain_class(type(elem)) or type(symbols) is not dict \
            or type(children) is not dict \
            or list(attrs) != [*_LAYOUT, *symbols, *children]:
        return False
    decls = []
    for key, sym in symbols.items():
        if type(sym) is not Symbol or sym.name != key or sym.owner is not elem \
                or attrs[key] is not sym.leaf or type(sym.leaf) is not Leaf \
                or sym.der_of is not None or sym.pre_of is not None or sym.der is not None \
                or sym.pre is not None or sym._sx is not None or sym._at is not None:
            return False
        decls.append((key, sym.decl))
    here = len(steps)
    steps.append((type(elem), attrs["_init_call"], attrs["_name"], tuple(decls), parent))
    return all(attrs[key] is child and child._name == key and _describe(child, here, steps)
               for key, child in children.items())


def _plain_tree(cls: type) -> bool:
    """Whether ``cls()`` runs only :class:`Element`'s code, down its subcomponents (so that
    building a first one to describe runs no code of the user's once more)."""
    return _plain_class(cls) and all(
        _plain_call(t._init_call) and _plain_tree(type(t)) for t in cls._templates.values())


def _plain_call(call: Any) -> bool:
    """Whether constructor arguments are keywords of immutable values (numbers, text): a
    copy made from a description then equals one the constructor makes from them."""
    args, kwargs = call
    return not args and "name" not in kwargs and all(
        isinstance(v, (int, float, str)) for v in kwargs.values())


def _plain_class(cls: type) -> bool:
    """Whether constructing ``cls`` runs only :class:`Element`'s own code, on scalar
    declarations (worked out once per class)."""
    found = _PLAIN_CLASSES.get(cls)
    if found is None:
        from .component import Element

        found = _PLAIN_CLASSES[cls] = issubclass(cls, Element) and all(
            getattr(cls, m) is getattr(Element, m)
            for m in ("__new__", "__init__", "__setattr__", "add", "_add", "modify",
                      "_declare_array", "_declare_scalar")) \
            and all(d.shape == () for d in cls._declarations.values())
    return found
