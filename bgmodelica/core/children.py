"""Subcomponents and connectors a component class declares, built for each instance.

A class attribute ``p = Pin()`` is a template: every instance gets its own copy, built with
the template's constructor arguments (``template.clone()``). Templates are built by the
thousand in a large model, so the first copy of a template whose class runs no code of its
own (:func:`_plain_class`) is described (:func:`_describe`): its class, its declarations
with their modifiers applied, and so on down its subcomponents. Later copies are made from
that description (:func:`_instantiate`): same symbols, same declaration objects (immutable,
so shared), no constructor machinery.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .variables import Symbol

if TYPE_CHECKING:
    from .component import Element

#: a template's description: (class, _init_call, _name, ((key, declaration), ...),
#: ((key, description), ...))
Blueprint = tuple[type, Any, Any, tuple[tuple[str, Any], ...], tuple[tuple[str, Any], ...]]

_KEY = "_blueprint"
_LAYOUT = ("_init_call", "_name", "_symbols", "_children", "_equations")
_PLAIN_CLASSES: dict[type, bool] = {}


def build_child(key: str, template: Element) -> Element:
    """``template.clone()``; an exception of user code names the subcomponent path."""
    made = template.__dict__.get(_KEY)
    if made is not None and made[0] is type(template) and made[1] is template._init_call:
        if made[2] is not None:
            return _instantiate(made[2])
        made = None
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
    call = template._init_call
    template.__dict__[_KEY] = (type(template), call,
                               _describe(child) if _plain_call(call) else None)
    return child


def _instantiate(blueprint: Blueprint) -> Element:
    """A fresh element as :func:`_describe` saw one: what its constructor would make."""
    cls, call, name, decls, kids = blueprint
    self = object.__new__(cls)
    attrs = self.__dict__
    attrs["_init_call"] = call
    attrs["_name"] = name
    symbols: dict[str, Symbol] = {}
    attrs["_symbols"] = symbols
    children: dict[str, Element] = {}
    attrs["_children"] = children
    attrs["_equations"] = []
    for key, decl in decls:
        sym = Symbol(key, decl, self)
        symbols[key] = sym
        attrs[key] = sym.leaf
    for key, kid in kids:
        child = children[key] = attrs[key] = _instantiate(kid)
        child.__dict__["_name"] = key
    return self


def _describe(elem: Element) -> Blueprint | None:
    """The blueprint of a freshly built ``elem`` and its subcomponents, or None when it
    holds anything else than what the general constructor of a plain class makes."""
    attrs = elem.__dict__
    symbols, children = attrs.get("_symbols"), attrs.get("_children")
    if not _plain_class(type(elem)) or type(symbols) is not dict \
            or type(children) is not dict or attrs.get("_equations") != [] \
            or list(attrs) != [*_LAYOUT, *symbols, *children]:
        return None
    decls = []
    for key, sym in symbols.items():
        if type(sym) is not Symbol or sym.name != key or sym.owner is not elem \
                or attrs[key] is not sym.leaf or sym.der_of is not None \
                or sym.pre_of is not None or sym.der is not None or sym.pre is not None \
                or sym._sx is not None or sym._at is not None:
            return None
        decls.append((key, sym.decl))
    kids = []
    for key, child in children.items():
        kid = _describe(child) if attrs[key] is child else None
        if kid is None:
            return None
        kids.append((key, kid))
    return type(elem), attrs["_init_call"], attrs["_name"], tuple(decls), tuple(kids)


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
